"""The recipes on every registered id (issue 67): a tiny run of the PPO recipe on each level
with its retry threshold resolved there, a line per evaluation with the current validation
score, every retry said with its reason; ``python -m train`` and ``python -m train.benchmark``
name the env in their banner and their default output folder."""

import json
from pathlib import Path

import pytest

from acld_gym.envs.presets import PRESETS
from tests.train.tiny_sb3 import tiny_ppo
from train.config import load_config
from train.core import evaluate, trials
from train.core.algos import train_algo
from train.core.progress import Progress

LEVELS = sorted(PRESETS)


@pytest.mark.parametrize("env_id", LEVELS)
def test_a_tiny_run_of_the_ppo_recipe_on_each_level(env_id, capsys):
    """The recipe shrunk to 1536 env steps per run on 4 sub-envs, two runs, its own
    threshold (``1.0299 * lqg``) resolved on the level's 4 validation loads of the
    selection: an untrained policy is far above it, so the first run is retried, and
    said so; each evaluation is a line with its validation score."""
    rule = load_config("ppo").restart_above
    cfg = tiny_ppo(
        restarts=2, restart_above=rule, select={"episodes": 4, "every": 1536, "start": 1536}
    )
    policy, record = train_algo(cfg, 0, env_id, progress=Progress(f"ppo {env_id}"))
    rs = record["restarts"]
    lqg = rs["rule"]["reference_cost"]
    assert rs["rule"]["reference"] == "lqg" and rs["threshold"] == pytest.approx(1.0299 * lqg)
    assert 0 < lqg < 2 and len(rs["runs"]) == 2  # no tiny run gets near the engineer
    assert rs["retries"] == [rs["runs"][0]["retried"]]
    out = capsys.readouterr().out.splitlines()
    assert f"  [ppo {env_id}] retry threshold {rs['threshold']:.4f} (1.0299 * lqg" in out[0]
    assert any(line.startswith(f"  [ppo {env_id}] retry: run 1 (seed 0)") for line in out)
    points = [line for line in out if "validation cost" in line and "(32 loads)" in line]
    assert len(points) >= 4  # two curve points a run: step 0 and the first due
    assert f"  [ppo {env_id} run 2/2] 0 / 1,536 env steps" in "\n".join(points)
    checks = [line for line in out if "check: validation cost" in line]
    assert len(checks) == 2 and all("(4 loads)" in line for line in checks)
    # the returned policy acts on the level's observation
    cost = evaluate.validation_cost(policy, env_id, evaluate.validation_seeds(4))
    assert cost == pytest.approx(record["select"]["cost"], rel=1e-5)


def test_quiet_says_only_the_threshold_and_the_retries(capsys):
    cfg = tiny_ppo(restarts=2, restart_above="1.0299 * lqg", select={"episodes": 2, "every": 1536})
    train_algo(cfg, 0, "ACLDBeam-v1", progress=Progress("q", quiet=True))
    out = capsys.readouterr().out.splitlines()
    assert [line.split("]")[1].split(" ")[1] for line in out] == ["retry", "retry:", "run"]
    assert "env steps" not in "\n".join(out)


@pytest.fixture
def fake_training(monkeypatch):
    """``run_trial`` replaced by one that records its arguments and returns a record of
    two runs, the first retried; the CLI's evaluation and saving stubbed."""
    seen = {}

    def fake_run_trial(name, data, seed, env_id, random_episodes, **kw):
        seen.update(name=name, seed=seed, env_id=env_id, **kw)
        rec = {
            "train_seconds": 12.0,
            "validation_cost": 0.61,
            "runs": 2,
            "retries": ["run 1 (seed 0): validation cost 0.7000 above the threshold 0.5250"],
            "final_ise": {"1": 1.0, "2": 1.0, "3": 1.0, "random": 1.0},
        }
        return rec, "policy"

    def fake_save(policy, rec, out, files):
        seen["out"] = Path(out)

    monkeypatch.setattr(trials, "run_trial", fake_run_trial)
    monkeypatch.setattr(trials, "save_agent", fake_save)
    monkeypatch.setattr(evaluate, "lqr_ise", lambda env_id, eps: {c: 1.0 for c in eps})
    return seen


@pytest.mark.parametrize("env_id", ["ACLDBeamLab-v1", "ACLDBeamHard-v1"])
def test_train_names_the_env_in_its_banner_and_default_output(
    env_id, fake_training, tmp_path, monkeypatch, capsys
):
    from train.cli import main

    monkeypatch.chdir(tmp_path)
    assert main(["ppo", "--env-id", env_id, "--seed", "3", "--quiet"]) == 0
    assert fake_training["out"] == Path("runs") / env_id / "ppo-s3"
    assert fake_training["env_id"] == env_id and fake_training["quiet"] is True
    out = capsys.readouterr().out.splitlines()
    assert out[0].startswith(f"training PPO (ppo, from scratch) on {env_id} for up to ")
    assert "above 1.0299 * lqg" in out[0] and f"-> runs/{env_id}/ppo-s3/" in out[0]
    # the retry is in the last word too
    assert "trained in 12 s, 2 runs (1 retry: run 1 (seed 0): validation cost 0.7000" in out[1]
    # --out is kept
    assert main(["ppo", "--env-id", env_id, "--out", "mine"]) == 0
    assert fake_training["out"] == Path("mine") and fake_training["quiet"] is False


def test_the_benchmark_names_the_env_in_its_banner_and_default_output(
    tmp_path, monkeypatch, capsys
):
    import train.benchmark as benchmark

    class Stop(Exception):
        pass

    seen = {}

    def fake_references(env_id, cache, *a, **k):
        seen["cache"] = Path(cache)
        raise Stop

    monkeypatch.chdir(tmp_path)
    monkeypatch.setattr(
        benchmark, "resumed_references", lambda env_id, out, *a: fake_references(env_id, out / "r")
    )
    with pytest.raises(Stop):
        benchmark.main(["--algos", "ppo", "--seeds", "0", "--env-id", "ACLDBeamHard-v1"])
    out = capsys.readouterr().out
    assert out.startswith("benchmark on ACLDBeamHard-v1: ppo x seeds 0: 1 runs to train")
    assert "-> runs/ACLDBeamHard-v1/benchmark/" in out
    assert seen["cache"] == Path("runs/ACLDBeamHard-v1/benchmark/r")


def test_a_trials_record_keeps_its_retries():
    rec = {"train_seconds": 3.2, "runs": 3, "retries": ["a", "b"]}
    assert trials.trained_line(rec) == "trained in 3 s, 3 runs (2 retries: a; b)"
    assert trials.trained_line({"train_seconds": 1.0, "runs": 1, "retries": []}) == (
        "trained in 1 s"
    )
    old = json.loads(json.dumps({"train_seconds": 1.0}))  # a record of acld-gym <= 0.19
    assert trials.trained_line(old) == "trained in 1 s"
