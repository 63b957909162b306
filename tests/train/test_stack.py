"""One training stack: ``python -m train`` runs one trial of ``python -m train.benchmark``
(the same config schema, env factory, training and evaluator), for PPO and SAC on a tiny
budget, and its agent loads and acts in volts."""

import json
import shutil

import numpy as np
import pytest
import yaml

from acld_gym.envs.beam_env import ACLDBeamEnv
from baselines.evaluate import rollout
from train.agent import TrainedAgent
from train.cli import build_parser, configure


def _tiny(tmp_path, algo):
    data = yaml.safe_load(open(f"train/recipes/{algo}.yaml"))
    if algo == "ppo":
        data.update(timesteps=1536, n_envs=4, eval_points=1, whiten_steps=256)
        data["model"] = {**data["model"], "n_steps": 128, "batch_size": 256, "n_epochs": 1}
    else:
        data.update(timesteps=600, n_envs=4, eval_points=1, whiten_steps=128)
        data["model"] = {
            **data["model"],
            "learning_starts": 200,
            "buffer_size": 2000,
            "batch_size": 64,
        }
    # two runs per seed (the recipe: up to 3 or 4), each ending in a check on 4 validation
    # loads (the recipe: 256 or 64), which also set the retry threshold's level: a tiny run
    # is above it, so both runs are trained, one after another or at once
    data.update(
        restarts=2, select={"episodes": 4, "every": data["timesteps"], "start": data["timesteps"]}
    )
    path = tmp_path / f"tiny_{algo}.yaml"
    path.write_text(yaml.safe_dump(data))
    return path


def test_the_default_config_is_the_benchmark_recipe():
    from train.config import read_config

    for algo in ("ppo", "sac"):
        args = build_parser().parse_args([algo, "--seed", "7"])
        assert (
            configure(args)
            == read_config(algo)
            == (algo, yaml.safe_load(open(f"train/recipes/{algo}.yaml")))
        )


def test_overrides_of_the_command_line():
    args = build_parser().parse_args(
        ["ppo", "--timesteps", "300000", "--n-envs", "4", "--load-case", "2"]
        + ["--param-noise", "0.02"]
    )
    name, data = configure(args)
    assert name == "ppo" and data["timesteps"] == 300000 and data["n_envs"] == 4
    assert data["loads"] == {2: 1}
    assert data["env_kwargs"]["param_noise"] == 0.02
    assert data["env_kwargs"]["reward_scale"] == "passive"  # the recipe's options stay
    # a budget that the recipe's whitening (counted in it) would use up is refused
    short = build_parser().parse_args(["ppo", "--timesteps", "20000"])
    with pytest.raises(ValueError, match=r"timesteps \(20000\) must be more than whiten_steps"):
        configure(short)
    odd = build_parser().parse_args(["ppo", "--n-envs", "3"])  # the recipe pairs its sub-envs
    with pytest.raises(ValueError, match="overrides: paired_loads needs an even number"):
        configure(odd)


@pytest.mark.parametrize("algo, cpus", [("ppo", 1), ("sac", 2)])
def test_train_cli_is_a_benchmark_trial(algo, cpus, tmp_path, capsys, monkeypatch, v1_references):
    """``python -m train ALGO --seed N`` and ``python -m train.benchmark --seeds N`` give the
    same agent, bit for bit, the one training its runs one after another, the other asked
    for ``--cpus-per-trial`` runs at once (1, PPO; 2, SAC); it loads (validated) and acts in
    volts. The benchmark's trial hands ``train_algo`` ``workers=cpus`` (asserted), which
    trains here one run after another: that two runs at once in worker processes are the
    same runs, the same policy and record, is
    tests/train/test_restarts.py::test_runs_at_once_are_the_runs_one_after_another's (the
    two worker processes had cost this test ~9 s of CPU importing torch and SB3)."""
    import inspect

    from train.benchmark import main as bench_main
    from train.cli import main as train_main
    from train.core import algos

    cfg = _tiny(tmp_path, algo)
    a = tmp_path / "cli"
    assert (
        train_main(
            [algo, "--config", str(cfg), "--seed", "3", "--random-episodes", "1", "--out", str(a)]
        )
        == 0
    )
    out = capsys.readouterr().out
    assert "ISE / LQR" in out and "case random" in out
    # a line per learning-curve point with its validation score: the run's start and end
    assert sum("validation cost" in line and "(32 loads)" in line for line in out.splitlines()) >= 2
    (tmp_path / "bench").mkdir()  # the session's references (tests/conftest.py), read back
    shutil.copyfile(v1_references, tmp_path / "bench" / "references-ACLDBeam-v1.json")
    recipe = yaml.safe_load(cfg.read_text())  # a run is retried only while it fails:
    runs, timesteps = recipe["restarts"], recipe["timesteps"]  # the budget is the most
    assert recipe["restart_above"] is not None and runs > 1
    assert f"for up to {runs * timesteps} env steps (up to {runs} runs of {timesteps})" in out
    real, asked = algos.train_algo, []

    def train_here(*args, **kwargs):
        call = inspect.signature(real).bind(*args, **kwargs)
        asked.append(call.arguments.get("workers", 1))
        call.arguments["workers"] = 1
        return real(*call.args, **call.kwargs)

    monkeypatch.setattr(algos, "train_algo", train_here)
    assert (
        bench_main(
            [
                "--config",
                str(cfg),
                "--seeds",
                "3",
                "--backend",
                "local",
                "--cpus-per-trial",
                str(cpus),
                "--random-episodes",
                "1",
                "--no-bound",
                "--quiet",  # (the lines per curve point: the command above)
                "--out",
                str(tmp_path / "bench"),
            ]
        )
        == 0
    )
    assert asked == [cpus]
    b = tmp_path / "bench" / "agents" / f"tiny_{algo}-s3"
    pa, pb = np.load(a / "policy.npz"), np.load(b / "policy.npz")
    assert sorted(pa.files) == sorted(pb.files)
    assert all(np.array_equal(pa[k], pb[k]) for k in pa.files)
    for f in ("policy.npz", "metadata.json", "learning_curve.csv", "trial.json"):
        assert (a / f).is_file(), f
    meta = json.loads((a / "metadata.json").read_text())
    assert meta["training"] == "from scratch" and meta["teacher"] is None
    assert meta["seed"] == 3 and meta["command"].startswith(f"python -m train {algo}")
    trial = json.loads((a / "trial.json").read_text())
    bench = json.loads((tmp_path / "bench" / "trials" / f"tiny_{algo}-s3.json").read_text())
    assert trial["final_ise"] == bench["final_ise"] and trial["config"] == bench["config"]
    agent = TrainedAgent.load(a)
    traj = rollout(agent, ACLDBeamEnv(load_case=1), seed=0)
    assert np.all(np.abs(traj.voltage) <= 120.0) and np.abs(traj.voltage).max() > 0


def _documented_commands(module: str) -> list[list[str]]:
    """The arguments of every ``python -m <module> ...`` line, or its ``acld-gym`` command's,
    of the README and the docs' shell blocks (line continuations joined, comments dropped,
    brace lists expanded to their first item). The research record (``studies/studies.md``)
    is not among them: its commands ran on the versions it names, and some of its ablations
    set options since removed (studies/README.md lists them)."""
    import re
    import shlex
    from pathlib import Path

    from train.console import module_names

    command = module_names()[module].removeprefix("acld-gym ")
    root = Path(__file__).resolve().parents[2]
    out = []
    pages = [root / "README.md", *sorted((root / "docs").rglob("*.md"))]
    for page in pages:
        for block in re.findall(r"^```bash\n(.*?)^```", page.read_text(), flags=re.S | re.M):
            for line in block.replace("\\\n", " ").splitlines():
                line = re.sub(r"\{([^,}]+)(,[^}]*)?\}", r"\1", line.split("  #")[0])
                words = shlex.split(line, comments=True)
                if words[:3] == ["python", "-m", module]:
                    out.append(words[3:])
                elif words[:2] == ["acld-gym", command]:
                    out.append(words[2:])
    return out


def test_documented_train_commands_parse():
    """Every ``python -m train ...`` the README and the docs show is a valid command for
    the one stack (its flags and its config)."""
    commands = _documented_commands("train")
    assert len(commands) >= 3
    for argv in commands:
        configure(build_parser().parse_args(argv))


def test_documented_benchmark_commands_parse():
    from train.benchmark import build_parser as bench_parser
    from train.config import read_config

    commands = _documented_commands("train.benchmark")
    assert len(commands) >= 5
    for argv in commands:
        args = bench_parser().parse_args(argv)
        for spec in [*(args.algos or []), *args.config]:
            read_config(spec)


def test_train_sb3_trains_on_the_env_its_factory_builds_and_checks_its_layers():
    """``train_sb3(make_env=...)``: a probe's own training env (benchmarks/time_critic.py)
    without patching the module; the factory is called once with the run's config, seed and
    env id, and a factory that does not return the recipe's outer ``VecNormalize`` is
    refused by name."""
    from tests.train.tiny_sb3 import tiny_ppo
    from train.core.sb3_train import train_sb3
    from train.vec import make_vec_env

    calls = []

    def factory(cfg, seed, env_id):
        calls.append((cfg, seed, env_id))
        return make_vec_env(cfg, seed, env_id)

    cfg = tiny_ppo()
    _, record = train_sb3(cfg, 3, "ACLDBeam-v1", make_env=factory)
    assert calls == [(cfg, 3, "ACLDBeam-v1")] and record["steps"] >= cfg.timesteps
    with pytest.raises(TypeError, match="make_env must return a VecNormalize.*VecWhiten"):
        train_sb3(cfg, 3, "ACLDBeam-v1", make_env=lambda c, s, e: make_vec_env(c, s, e).venv)
