"""``python -m train.leaderboard collect`` on a tiny benchmark folder (two seeds of the random
search on a tiny budget, trained by the benchmark's own ``run_trials``): a valid results
file whose numbers are ``train.scoring.score``'s on those agents, whose effort is the
evaluation's, whose IQM over the seeds is the package's; the references and each algorithm
are replaced independently (issue 67). A reduced run (a few test episodes) keeps it fast."""

from __future__ import annotations

import json
import shutil

import gymnasium as gym
import numpy as np
import pytest
import yaml

from acld_gym.util.stats import iqm_with_ci
from acld_gym.util.validate import run_main
from baselines.analysis.score import score_policies
from baselines.policies import LQRPolicy, PassivePolicy
from baselines.rollout import metrics_row, rollout
from tests.train.leaderboard_cli import PROG, run
from train.agent import TrainedAgent
from train.core.trials import agent_dir, run_trials
from train.leaderboard.cli import main
from train.leaderboard.collect import collect_references, merge, write_level
from train.leaderboard.schema import CASES, EFFORT_CASES, read_level
from train.scoring import score

ENV_ID = "ACLDBeam-v1"
EPISODES = 4


@pytest.fixture(scope="module")
def bench(tmp_path_factory):
    """A ``python -m train.benchmark`` folder: ``vrs`` seeds 0 and 1, 8000 env steps."""
    vrs = yaml.safe_load(open("train/recipes/vrs.yaml"))
    vrs.update(timesteps=8000, loads={1: 1, "random": 1}, eval_points=1)
    vrs["model"] = {**vrs["model"], "n_directions": 2, "top_directions": 1}
    out = tmp_path_factory.mktemp("bench")
    trial = {"name": "vrs", "config": vrs, "env_id": ENV_ID, "random_episodes": 2, "quiet": True}
    run_trials([{**trial, "seed": s} for s in (0, 1)], out, "local")
    return out


@pytest.fixture(scope="module")
def collected(bench, tmp_path_factory):
    results = tmp_path_factory.mktemp("results")
    argv = [
        "collect",
        "--env-id",
        ENV_ID,
        "--benchmark",
        str(bench),
        "--score-episodes",
        str(EPISODES),
        "--results",
        str(results),
        "--quiet",
    ]
    assert run_main(lambda: main(argv), PROG) == 0
    return results / f"{ENV_ID}.json"


def test_collect_gives_a_valid_file_with_the_scoring_functions_numbers(bench, collected):
    level = read_level(collected)
    assert level["references"] is None and set(level["agents"]) == {"vrs"}
    algo = level["agents"]["vrs"]
    assert [s["seed"] for s in algo["seeds"]] == [0, 1]
    for s in algo["seeds"]:
        agent = TrainedAgent.load(agent_dir(bench, "vrs", s["seed"]))
        want = score(agent, ENV_ID, episodes=EPISODES)
        got = s["score"]
        assert (got["iqm"], got["ci_low"], got["ci_high"]) == (want.iqm, *want.ci)
        assert got["n_episodes"] == EPISODES and got["test_set"] == want.test_set
        assert s["ise_rel_lqr"] == {str(c): v for c, v in want.ise_rel_lqr.items()}
        # effort: the evaluation's time at the limit after settling, the same episode
        for c in EFFORT_CASES:
            env = gym.make(ENV_ID, load_case=int(c))
            row = metrics_row(int(c), "agent", rollout(agent, env, seed=0))
            assert s["effort"][c]["settled_limit_fraction"] == row.limit_fraction
            assert s["effort"][c]["settled_rms_voltage_V"] <= row.max_voltage_V
        trial = json.loads((bench / "trials" / f"vrs-s{s['seed']}.json").read_text())
        assert s["train_seconds"] == trial["train_seconds"] and s["runs"] == trial["runs"]
        assert s["retries"] == trial["retries"] and s["steps"] == trial["steps"]
    scores = np.array([s["score"]["iqm"] for s in algo["seeds"]])
    assert algo["iqm"]["score"] == iqm_with_ci(scores)
    for c in CASES:
        col = np.array([s["ise_rel_lqr"][c] for s in algo["seeds"]])
        assert algo["iqm"]["ise_rel_lqr"][c] == iqm_with_ci(col)
    prov = algo["provenance"]
    assert prov["commands"][0].startswith(f"{PROG} collect --env-id {ENV_ID} --benchmark")
    assert any("train.benchmark" in c for c in prov["commands"][1:])
    assert prov["machine"]["cores"] >= 1 and prov["machine"]["cpu"]


def test_references_and_each_algorithm_are_replaced_independently(bench, collected, tmp_path):
    path = tmp_path / collected.name
    shutil.copy(collected, path)
    policies = {
        "passive": PassivePolicy.for_env(gym.make(ENV_ID).unwrapped),
        "lqr": LQRPolicy.for_env(gym.make(ENV_ID).unwrapped),
    }
    refs = collect_references(ENV_ID, "cmd", episodes=2, policies=policies)
    write_level(path, merge(read_level(path), refs))
    level = read_level(path)
    assert level["agents"] == read_level(collected)["agents"]  # kept
    got = level["references"]["policies"]
    assert set(got) == {"passive", "lqr", "bound"}
    want = score_policies(policies, ENV_ID, 2)
    for name in got:
        assert got[name]["score"]["iqm"] == want[name].iqm
    assert got["passive"]["score"]["iqm"] == 0.0 and got["bound"]["score"]["iqm"] == 1.0
    assert all(got["lqr"]["ise_rel_lqr"][c] == 1.0 for c in CASES)
    assert all(got["bound"]["ise_rel_lqr"][c] < 1.0 for c in CASES)
    # another algorithm added, then vrs collected again: the references and the other stay
    other = dict(level["agents"]["vrs"], algo="ppo")
    write_level(path, merge(level, agents={"ppo": other}))
    argv = [
        "collect",
        "--env-id",
        ENV_ID,
        "--benchmark",
        str(bench),
        "--algos",
        "vrs",
        "--score-episodes",
        "2",
        "--results",
        str(tmp_path),
        "--quiet",
    ]
    assert run_main(lambda: main(argv), PROG) == 0
    after = read_level(path)
    assert after["references"] == level["references"] and after["agents"]["ppo"] == other
    assert after["agents"]["vrs"]["seeds"][0]["score"]["n_episodes"] == 2


def test_a_trial_of_another_level_or_a_missing_algorithm_is_one_line(bench, tmp_path, capsys):
    copy = tmp_path / "bench"
    shutil.copytree(bench, copy)
    base = ["collect", "--env-id", ENV_ID, "--benchmark", copy, "--results", tmp_path]
    code, _, err = run([*base, "--algos", "ppo"], capsys)
    assert code == 2 and len(err.splitlines()) == 1 and "no trial of ['ppo']" in err
    record = copy / "trials" / "vrs-s1.json"
    rec = json.loads(record.read_text())
    record.write_text(json.dumps(dict(rec, env_id="ACLDBeamLab-v1")))
    code, _, err = run(base, capsys)
    assert code == 2 and len(err.splitlines()) == 1, err
    assert f"{record}: env_id: expected {ENV_ID}" in err
    record.write_text(json.dumps(dict(rec, train_seconds="slow")))
    code, _, err = run(base, capsys)
    assert code == 2 and f"{record}: train_seconds: expected a number" in err
    record.write_text(json.dumps(rec))
    meta = copy / "agents" / "vrs-s0" / "metadata.json"
    meta.write_text(meta.read_text()[:40])
    code, _, err = run(base, capsys)
    assert code == 2 and len(err.splitlines()) == 1 and str(meta) in err, err
    assert not (tmp_path / f"{ENV_ID}.json").exists()
