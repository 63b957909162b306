"""The guide page "Train on any level with any library" (docs/any-library.md): its scripts
(docs/examples/) run end to end (in this process) on a tiny budget on ACLDBeam-v1 and on
another level and print a finite score, refuse each bad argument in one line before training
or loading anything (zoo_score.py takes the level and the algorithm from the run's own
args.yml, read as plain data), the docs' rl-zoo3 commands run torch on one thread, CleanRL's
additions run as the diff gives them, the rl-zoo3 files hold the scripts' hyperparameters on
every registered id, and the page includes every example verbatim (pymdownx.snippets)."""

from __future__ import annotations

import ast
import contextlib
import io
import math
import os
import re
import runpy
import shlex
import subprocess
import sys
import types
from collections import OrderedDict
from functools import partial
from pathlib import Path

import gymnasium as gym
import numpy as np
import pytest
import torch
import yaml
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from acld_gym.envs.presets import PRESETS, preset
from train.scoring import SCORE_LINE

ROOT = Path(__file__).resolve().parent.parent
EXAMPLES = ROOT / "docs" / "examples"
PAGE = ROOT / "docs" / "any-library.md"
OTHER = "ACLDBeamHard-v1"  # observes the sensor: the scripts leave ObserveModes out


def _run(args: list[str], cwd: Path, timeout: int = 600) -> str:
    env = dict(os.environ, PYTHONPATH=str(ROOT), OMP_NUM_THREADS="1")
    done = subprocess.run(
        [sys.executable, *args], cwd=cwd, env=env, capture_output=True, text=True, timeout=timeout
    )
    assert done.returncode == 0, done.stderr[-3000:]
    return done.stdout


@contextlib.contextmanager
def _as_found():
    """The process-wide state a script or rl-zoo3 run in this process changes, put back as
    it was: torch's threads, the global random generators (SB3's ``set_random_seed``),
    gymnasium's registry and ``TimeLimit`` (rl-zoo3 registers its NoVel ids and replaces
    ``TimeLimit`` when first imported)."""
    import random

    from gymnasium.envs import registration
    from gymnasium.wrappers import common

    registry, threads = dict(gym.envs.registry), torch.get_num_threads()
    rngs = random.getstate(), np.random.get_state(), torch.get_rng_state()  # noqa: NPY002
    modules = (gym.wrappers, common, registration)  # rl-zoo3 sets TimeLimit in each
    limits = [vars(m).get("TimeLimit") for m in modules]
    try:
        yield
    finally:
        gym.envs.registry.clear()
        gym.envs.registry.update(registry)
        torch.set_num_threads(threads)
        random.setstate(rngs[0])
        np.random.set_state(rngs[1])  # noqa: NPY002  (the global state SB3 seeds)
        torch.set_rng_state(rngs[2])
        for module, limit in zip(modules, limits, strict=True):
            if limit is None:
                vars(module).pop("TimeLimit", None)
            else:
                module.TimeLimit = limit


def _run_here(args: list[str], cwd: Path, monkeypatch, capsys) -> str:
    """``python ARGS`` (a script path, or ``-m module`` and its arguments) run in this
    process as ``__main__`` (runpy) in ``cwd``, as :func:`_run` runs it in a fresh
    interpreter (each of those paid 2-3 s of CPU to import torch, SB3 and rl-zoo3 again);
    its standard output. A failure raises here, with its traceback."""
    module = args[1] if args[0] == "-m" else None
    argv = args[2:] if module else args[1:]
    monkeypatch.chdir(cwd)
    monkeypatch.setattr(sys, "argv", [module or args[0], *argv])
    capsys.readouterr()
    with _as_found():
        try:
            if module:
                runpy.run_module(module, run_name="__main__", alter_sys=True)
            else:
                runpy.run_path(args[0], run_name="__main__")
        except SystemExit as stop:  # a script's sys.exit(0) is a success
            assert stop.code in (0, None), (stop.code, capsys.readouterr().err[-3000:])
    return capsys.readouterr().out


def _check_score(stdout: str, env_id: str, episodes: int) -> None:
    """The last line is a score of ``env_id`` on ``episodes`` test loads, every number
    finite, the ratios positive."""
    m = SCORE_LINE.match(stdout.strip().splitlines()[-1])
    assert m, stdout[-2000:]
    assert m["id"] == env_id and int(m["n"]) == episodes
    values = [float(m[k]) for k in ("iqm", "lo", "hi", "c1", "c2", "c3", "cr")]
    assert all(math.isfinite(v) for v in values)
    assert float(m["lo"]) <= float(m["iqm"]) <= float(m["hi"])
    assert all(v > 0 for v in values[3:])


# one level each (the other script's level): the suite's time, both kinds of observation
@pytest.mark.parametrize(
    "script, steps, env_id", [("sb3_ppo.py", 16_384, "ACLDBeam-v1"), ("sb3_sac.py", 12_000, OTHER)]
)
def test_sb3_script_runs_on_a_tiny_budget(script, steps, env_id, tmp_path, monkeypatch, capsys):
    """The script trains, scores and, with ``--save DIR``, keeps the model and its
    ``VecNormalize`` statistics, which score the same once loaded (the page's way to score
    a saved model)."""
    from stable_baselines3 import PPO, SAC

    from acld_gym.wrappers import ObserveModes, UnitAction
    from train.scoring import score

    saved = tmp_path / "kept" / "run"
    args = [str(EXAMPLES / script), env_id, "--timesteps", str(steps), "--episodes", "2"]
    out = _run_here([*args, "--save", str(saved)], tmp_path, monkeypatch, capsys)
    _check_score(out, env_id, 2)
    algo, headroom = (PPO, 1.0) if script == "sb3_ppo.py" else (SAC, 3.0)
    wrappers = [partial(UnitAction, headroom=headroom)]
    if env_id != "ACLDBeamHard-v1":
        wrappers.append(partial(ObserveModes, modes=1))
    if script == "sb3_ppo.py":  # the page's block on this folder, on the script's level
        block = PAGE.read_text().split('```py title="score a saved model"\n')[1].split("```")[0]
        block = block.replace("runs/ppo-v1", str(saved)).replace('"ACLDBeam-v1"', repr(env_id))
        block = block.replace("wrappers=wrappers,", "wrappers=wrappers, episodes=2,")
        capsys.readouterr()
        exec(compile(block, "any-library.md", "exec"), {})
        assert capsys.readouterr().out.strip() == out.strip().splitlines()[-1]
    model = algo.load(saved / "model.zip", device="cpu")
    again = score(
        model, env_id, wrappers=wrappers, episodes=2, vec_normalize=saved / "vecnormalize.pkl"
    )
    assert str(again) == out.strip().splitlines()[-1]


# -- bad arguments: one line, before anything is trained or loaded -----------------------------


def _fake_run(root: Path, algo: str, env_id: str, **more) -> Path:
    """A run folder of rl-zoo3: ``<env id>/args.yml`` written as rl-zoo3's ExpManager writes
    it (PyYAML's dump of an OrderedDict of the arguments: a python tag; ``more`` changes or
    adds arguments), and empty files in the places of its other files."""
    run = root / "logs" / algo / f"{env_id}_1"
    (run / env_id).mkdir(parents=True)
    args = {"algo": algo, "env": env_id, "seed": 0, "gym_packages": ["acld_gym"]}
    args |= {"hyperparams": {"n_envs": 8}, "env_kwargs": None, "n_timesteps": 2048} | more
    (run / env_id / "args.yml").write_text(yaml.dump(OrderedDict(sorted(args.items()))))
    for name in (f"{env_id}/config.yml", f"{env_id}/vecnormalize.pkl", f"{env_id}.zip"):
        (run / name).write_text("")  # never read: the tests stop the script before
    return run


def _error_line(stderr: str, script: str) -> str:
    """The one error line of a refusal: argparse's usage and ``<script>: error: ...`` (or
    that line alone), no traceback."""
    assert "Traceback" not in stderr, stderr
    lines = stderr.strip().splitlines()
    errors = [line for line in lines if "error" in line]
    assert len(errors) == 1 and errors[0] == lines[-1], stderr
    assert lines[-1].startswith(f"{script}: error: "), stderr
    assert all(line.startswith(("usage: ", " ")) for line in lines[:-1]), stderr
    return lines[-1]


@pytest.fixture
def refused(monkeypatch, capsys):
    """``refused(script, *args)``: docs/examples/<script> run in this process as
    ``__main__`` (runpy) with those arguments, every step that builds an env, trains, loads
    or scores replaced by a failure; its exit status and its one error line."""
    import rl_zoo3.utils
    from stable_baselines3 import PPO, SAC
    from stable_baselines3.common.base_class import BaseAlgorithm

    import acld_gym.envs
    import train.scoring

    def never(*args, **kwargs):
        raise AssertionError("the script went past its argument checks")

    monkeypatch.setattr(gym, "make_vec", never)
    monkeypatch.setattr(acld_gym.envs, "SB3VecEnv", never)
    for cls, name in ((PPO, "learn"), (SAC, "learn"), (BaseAlgorithm, "load")):
        monkeypatch.setattr(cls, name, never)
    monkeypatch.setattr(rl_zoo3.utils, "get_saved_hyperparams", never)
    monkeypatch.setattr(train.scoring, "score", never)

    def run(script: str, *args: str) -> tuple[int, str]:
        monkeypatch.setattr(sys, "argv", [script, *map(str, args)])
        capsys.readouterr()
        with pytest.raises(SystemExit) as stop:
            runpy.run_path(str(EXAMPLES / script), run_name="__main__")
        code, err = stop.value.code, capsys.readouterr().err
        if isinstance(code, str):  # sys.exit("message"): the interpreter prints it, status 1
            code, err = 1, err + code + "\n"
        return code, _error_line(err, script)

    return run


BAD_ARGS = [
    (
        ["--save", "/dev/null/x"],
        "argument --save: expected a folder that can hold files, got '/dev/null/x': "
        "'/dev/null' is not a folder",
    ),
    (["ACLDBeam-v9"], "argument env_id: invalid choice: 'ACLDBeam-v9'"),
    (["--episodes", "0"], "argument --episodes: expected an integer in [1, 100], got 0"),
    (
        ["ACLDBeamLab-v1", "--episodes", "101"],
        "argument --episodes: expected an integer in [1, 100]",
    ),
    (["--episodes", "2.5"], "argument --episodes: invalid int value: '2.5'"),
    (["--timesteps", "0"], "argument --timesteps: expected an integer in [1, inf], got '0'"),
    (["--timesteps", "-5"], "argument --timesteps: expected an integer in [1, inf]"),
    (["--timesteps", "1e6"], "argument --timesteps: expected an integer, got '1e6'"),
    (["--seed", "-1"], "argument --seed: expected an integer in [0, 4294967295], got '-1'"),
    (["--seed", str(2**32)], "argument --seed: expected an integer in [0, 4294967295]"),
    (["--seed", "x"], "argument --seed: expected an integer, got 'x'"),
]


@pytest.mark.parametrize("script", ["sb3_ppo.py", "sb3_sac.py"])
@pytest.mark.parametrize("args, message", BAD_ARGS, ids=[" ".join(a) for a, _ in BAD_ARGS])
def test_sb3_scripts_refuse_each_bad_argument_before_training(script, args, message, refused):
    if script == "sb3_sac.py":  # SAC's budget must exceed its learning_starts (10,000)
        message = message.replace("[1, inf]", "[10001, inf]")
    code, line = refused(script, *args)
    assert code == 2 and line.startswith(f"{script}: error: {message}"), line


def test_the_checks_let_a_good_command_line_through_to_training(refused):
    """The stand-ins above do stop a script that passes its checks (the refusals are the
    checks', not theirs)."""
    with pytest.raises(AssertionError, match="past its argument checks"):
        refused(
            "sb3_ppo.py", "ACLDBeamHard-v1", "--timesteps", "1", "--seed", "0", "--episodes", "100"
        )


def test_zoo_score_takes_the_level_from_the_run_and_refuses_a_mismatch(refused, tmp_path):
    """The level and the algorithm are the run's own (its args.yml): a wrong algorithm or
    level, a folder that is no run, or ``--episodes`` out of range is one line naming the
    argument, before anything is loaded; with the run's algorithm and no level it gets past
    the checks to loading the run (here a stand-in that fails)."""
    run = _fake_run(tmp_path, "ppo", "ACLDBeamLab-v1")
    code, line = refused("zoo_score.py", "sac", run)
    assert code == 2 and line.endswith(f"argument algo: {run} is an rl-zoo3 ppo run, not sac")
    code, line = refused("zoo_score.py", "ppo", run, "ACLDBeam-v1")
    assert code == 2
    assert line.endswith(f"argument env_id: {run} trained on ACLDBeamLab-v1, not ACLDBeam-v1")
    for folder in (tmp_path, run / "ACLDBeamLab-v1", tmp_path / "nowhere"):
        code, line = refused("zoo_score.py", "ppo", folder)
        assert code == 2 and "argument run: expected rl-zoo3's run folder" in line, line
    code, line = refused("zoo_score.py", "ppo", run, "--episodes", "0")
    assert code == 2 and "argument --episodes: expected an integer in [1, 100], got 0" in line
    (run / "ACLDBeamLab-v1.zip").unlink()  # a run that stopped before saving its model
    code, line = refused("zoo_score.py", "ppo", run)
    assert code == 1 and line.endswith(
        f"{run / 'ACLDBeamLab-v1.zip'}: not found (a run that did not finish?)"
    )
    (run / "ACLDBeamLab-v1.zip").write_text("")
    # the run's own level, its own algorithm: through the checks (no level given, or the same)
    for level in ([], ["ACLDBeamLab-v1"]):
        with pytest.raises(AssertionError, match="past its argument checks"):
            refused("zoo_score.py", "ppo", run, *level, "--episodes", "2")


def test_zoo_score_reads_args_yml_as_plain_data(refused, tmp_path):
    """A run whose args.yml names no level of this package, or is damaged, or tags a python
    call, is one line naming the file (exit 1); the tag's call is never made."""
    run = _fake_run(tmp_path, "ppo", "ACLDBeam-v1", env="os:system")
    code, line = refused("zoo_score.py", "ppo", run)
    assert code == 1 and f"{run / 'ACLDBeam-v1' / 'args.yml'}: not rl-zoo3's args.yml" in line
    assert "env must be one of this package's ids" in line
    marker = tmp_path / "ran"
    args_yml = run / "ACLDBeam-v1" / "args.yml"
    for text in (
        f"!!python/object/apply:os.system [touch {marker}]\n",
        "!!python/object/apply:collections.OrderedDict [[[algo, "
        f"!!python/object/apply:os.system [touch {marker}]], [env, ACLDBeam-v1]]]\n",
        "algo: ppo\nenv: ACLDBeam-v1\n",  # a plain mapping: not what rl-zoo3 writes
        "[" * 5000,
        "",
    ):
        args_yml.write_text(text)
        code, line = refused("zoo_score.py", "ppo", run)
        assert not marker.exists()
        assert code == 1 and str(args_yml) in line, (text[:80], line)


@settings(
    max_examples=40, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture]
)
@given(damage=st.one_of(st.binary(max_size=200), st.integers(0, 400)))
def test_a_damaged_args_yml_is_one_line(damage, refused, tmp_path_factory):
    """Random bytes, or rl-zoo3's own file cut short, as args.yml: one line and exit 1 (or,
    where the cut leaves a readable record, through the checks)."""
    run = _fake_run(tmp_path_factory.mktemp("run"), "ppo", "ACLDBeam-v1")
    args_yml = run / "ACLDBeam-v1" / "args.yml"
    whole = args_yml.read_bytes()
    args_yml.write_bytes(damage if isinstance(damage, bytes) else whole[:damage])
    try:
        code, line = refused("zoo_score.py", "ppo", run)
    except AssertionError as exc:  # a record complete enough to pass: the stand-in's stop
        assert "past its argument checks" in str(exc) and isinstance(damage, int)
        return
    assert code == 1 and str(args_yml) in line


@pytest.mark.parametrize(
    "script, args, message",
    [
        ("sb3_ppo.py", ["ACLDBeamLab-v1", "--episodes", "0"], "argument --episodes"),
        ("zoo_score.py", ["sac", "{run}"], "argument algo"),
    ],
)
def test_a_refusal_as_a_user_sees_it(script, args, message, tmp_path):
    """In its own interpreter, as a user runs it: exit status 2, argparse's one error line,
    no traceback, nothing written, within the time an interpreter takes to start."""
    run = _fake_run(tmp_path / "in", "ppo", "ACLDBeamLab-v1")
    args = [a.format(run=run) for a in args]
    work = tmp_path / "work"
    work.mkdir()
    env = dict(os.environ, PYTHONPATH=str(ROOT), OMP_NUM_THREADS="1")
    done = subprocess.run(
        [sys.executable, str(EXAMPLES / script), *args],
        cwd=work,
        env=env,
        capture_output=True,
        text=True,
        timeout=120,  # training the default budget takes minutes
    )
    assert done.returncode == 2 and done.stdout == ""
    assert f"{script}: error: {message}" in _error_line(done.stderr, script)
    assert not any(work.iterdir())


def _shell_commands(page: Path) -> list[str]:
    """The commands of the page's ```bash blocks, continued lines joined, comments cut."""
    text = page.read_text()
    commands = []
    for block in re.findall(r"^```bash[^\n]*\n(.*?)^```", text, flags=re.S | re.M):
        for command in block.replace("\\\n", " ").splitlines():
            commands.append(" ".join(command.split("  #")[0].split()))
    return commands


def test_every_rl_zoo3_command_of_the_docs_runs_torch_on_one_thread():
    """Every ``python -m rl_zoo3.<train | enjoy | ...>`` of the docs sets torch's threads
    with rl-zoo3's own flag (its default is torch's, one per core: 4.5x the wall time of the
    same run on the shared 2-core machine, issue 69's walkthrough)."""
    found = {}
    for page in sorted((ROOT / "docs").rglob("*.md")):
        for command in _shell_commands(page):
            if command.startswith("python -m rl_zoo3."):
                found[command] = page.name
                words = shlex.split(command)
                assert "--num-threads" in words, (page, command)
                assert words[words.index("--num-threads") + 1] == "1", (page, command)
    assert {"any-library.md", "training.md"} <= set(found.values()), found


def _page_zoo(algo: str, env_id: str) -> tuple[list[str], list[str]]:
    """The page's rl-zoo3 training command and zoo_score.py command for ``algo`` (arguments
    after ``python``), on the level ``env_id`` instead of the page's, the repository's files
    by absolute path (the commands run in a temporary folder)."""
    commands = _shell_commands(PAGE)
    (train,) = [c for c in commands if c.startswith(f"python -m rl_zoo3.train --algo {algo} ")]
    (score,) = [c for c in commands if c.startswith(f"python docs/examples/zoo_score.py {algo} ")]
    page_env = shlex.split(train)[shlex.split(train).index("--env") + 1]
    out = []
    for command in (train, score):
        command = command.replace(page_env, env_id)
        for folder in ("train/zoo/", "docs/examples/"):
            command = command.replace(f" {folder}", f" {ROOT / folder}/")
        out.append(shlex.split(command)[1:])
    return out[0], out[1]


@pytest.mark.parametrize("algo, env_id", [("ppo", "ACLDBeam-v1"), ("sac", OTHER)])
def test_rl_zoo3_trains_from_the_mlp_file_and_zoo_score_scores_it(
    algo, env_id, tmp_path, monkeypatch, capsys
):
    """The page's commands: rl-zoo3 trains from ``train/zoo/<algo>_mlp.yml`` (2048 steps,
    8 sub-envs, torch on one thread as the page's command says) and
    ``docs/examples/zoo_score.py`` scores the run, with no level given (the run's own) and
    with the wrappers and the ``VecNormalize`` it saved."""
    train, score = _page_zoo(algo, env_id)
    assert train[train.index("--num-threads") + 1] == "1" and "-f" in train
    train += ["-n", "2048", "--hyperparams", "n_envs:8"]
    if algo == "sac":
        train.append("learning_starts:1024")
    _run_here(train, tmp_path, monkeypatch, capsys)
    run = tmp_path / "logs" / algo / f"{env_id}_1"
    assert score[:3] == [str(EXAMPLES / "zoo_score.py"), algo, str(run.relative_to(tmp_path))]
    assert not any(a in PRESETS for a in score), score  # the level is the run's
    out = _run_here([*score, "--episodes", "2"], tmp_path, monkeypatch, capsys)
    _check_score(out, env_id, 2)


# -- CleanRL: the diff's additions, run as they stand in the patched file --------------------


def _new_side(diff: str) -> list[list[str]]:
    """Each hunk of a unified diff as the lines of the patched file (context and ``+``)."""
    hunks: list[list[str]] = []
    for line in diff.splitlines():
        if line.startswith("@@"):
            hunks.append([])
        elif hunks and not line.startswith(("-", "---", "+++")):
            hunks[-1].append(line[1:])
    return hunks


def _added(diff: str) -> list[list[str]]:
    """Each hunk's added lines (without the ``+``)."""
    hunks: list[list[str]] = []
    for line in diff.splitlines():
        if line.startswith("@@"):
            hunks.append([])
        elif hunks and line.startswith("+") and not line.startswith("+++"):
            hunks[-1].append(line[1:])
    return hunks


def test_cleanrl_diff_is_the_documented_additions():
    """The diff changes CleanRL's file at the pinned commit by the documented additions
    only: ``make_env`` wraps the level with UnitAction, the reward per load and (where the
    level observes the estimate) ObserveModes; torch on one thread; the score at the end."""
    diff = (EXAMPLES / "cleanrl_ppo.diff").read_text()
    assert diff.startswith("--- a/cleanrl/ppo_continuous_action.py\n")
    removed = [line[1:] for line in diff.splitlines() if line[:1] == "-" and line[:3] != "---"]
    assert removed == [
        '    env_id: str = "HalfCheetah-v4"',
        "            env = gym.make(env_id)",
        "        env = gym.wrappers.TransformObservation(env, lambda obs: np.clip(obs, -10, 10))",
    ]
    added = "\n".join(sum(_added(diff), []))
    for needed in ("torch.set_num_threads(1)", 'reward_scale="passive"', "score(policy"):
        assert needed in added
    # each hunk's header counts its lines (so `patch` and `git apply` take it)
    for m in re.finditer(r"^@@ -\d+,(\d+) \+\d+,(\d+) @@\n(.*?)(?=^@@|\Z)", diff, re.M | re.S):
        lines = m[3].splitlines()
        assert sum(not line.startswith("+") for line in lines) == int(m[1])
        assert sum(not line.startswith("-") for line in lines) == int(m[2])


@pytest.mark.parametrize("env_id", ["ACLDBeam-v1", OTHER])
def test_cleanrl_additions_train_env_and_score_run(env_id):
    """The patched ``make_env`` (whole, from the diff's hunk) builds CleanRL's vector env on
    the level, and the added scoring block scores an actor on it (a finite score)."""
    diff = (EXAMPLES / "cleanrl_ppo.diff").read_text()
    new = _new_side(diff)
    imports = "\n".join(_added(diff)[0])
    (make_env,) = ["\n".join(h) for h in new if any(x.startswith("def make_env") for x in h)]
    make_env = make_env[make_env.index("def make_env") :]
    make_env = make_env[: make_env.index("    return thunk") + len("    return thunk")]
    namespace = {"gym": gym, "np": np, "torch": torch}
    exec(imports + "\n" + make_env, namespace)
    make = namespace["make_env"]
    envs = gym.vector.SyncVectorEnv([make(env_id, i, False, "t", 0.99) for i in range(2)])
    obs, _ = envs.reset(seed=0)
    for _ in range(50):  # the running statistics move
        obs, *_ = envs.step(envs.action_space.sample())
    estimate = preset(env_id).obs_mode == "estimate"
    assert envs.single_observation_space.shape == ((3,) if estimate else (9,))
    actor = torch.nn.Linear(envs.single_observation_space.shape[0], 1)
    scoring = "\n".join(line[4:] for line in _added(diff)[-1])
    namespace |= {
        "envs": envs,
        "agent": types.SimpleNamespace(actor_mean=actor),
        "args": types.SimpleNamespace(env_id=env_id, score_episodes=1),
    }
    printed = io.StringIO()
    with contextlib.redirect_stdout(printed), torch.no_grad():
        exec(scoring, namespace)
    _check_score(printed.getvalue(), env_id, 1)
    envs.close()


# -- the rl-zoo3 files hold the scripts' hyperparameters, on every registered id ---------------


def _model_kwargs(script: str, algo: str) -> dict:
    """The keyword arguments of the script's ``PPO(...)`` / ``SAC(...)`` call (literals;
    ``learning_rate`` and ``seed`` as source text) and its sub-env count."""
    tree = ast.parse((EXAMPLES / script).read_text())
    calls = [n for n in ast.walk(tree) if isinstance(n, ast.Call)]
    (model,) = [c for c in calls if isinstance(c.func, ast.Name) and c.func.id == algo.upper()]
    out = {"policy": ast.literal_eval(model.args[0])}
    for kw in model.keywords:
        if kw.arg == "policy_kwargs":
            out[kw.arg] = eval(ast.unparse(kw.value))
        else:
            try:
                out[kw.arg] = ast.literal_eval(kw.value)
            except ValueError:
                out[kw.arg] = ast.unparse(kw.value)
    (make_vec,) = [c for c in calls if ast.unparse(c.func) == "gym.make_vec"]
    out["n_envs"] = ast.literal_eval(make_vec.args[1])
    return out


@pytest.mark.parametrize("algo", ["ppo", "sac"])
def test_zoo_mlp_file_holds_the_scripts_settings_on_every_id(algo):
    zoo = yaml.safe_load((ROOT / f"train/zoo/{algo}_mlp.yml").read_text())
    assert sorted(zoo) == sorted(PRESETS)
    script = _model_kwargs(f"sb3_{algo}.py", algo)
    assert script.pop("seed") == "args.seed"
    lr = script.pop("learning_rate")
    headroom = 3.0 if algo == "sac" else None
    for env_id, hp in zoo.items():
        hp = dict(hp)
        wrappers = hp.pop("env_wrapper")
        unit = (
            {"acld_gym.wrappers.UnitAction": {"headroom": headroom}}
            if headroom
            else "acld_gym.wrappers.UnitAction"
        )
        modes = [{"acld_gym.wrappers.ObserveModes": {"modes": 1}}]
        assert wrappers == [unit] + modes * (preset(env_id).obs_mode == "estimate"), env_id
        assert hp.pop("env_kwargs") == {"load_case": "random", "reward_scale": "passive"}
        assert hp.pop("n_timesteps") == (2e6 if algo == "ppo" else 3e5)
        normalize = hp.pop("normalize")
        zoo_lr = hp.pop("learning_rate")
        if isinstance(zoo_lr, str):  # rl-zoo3's lin_<start>: start * progress
            assert lr == f"lambda progress: {float(zoo_lr[4:])} * progress"
        else:
            assert zoo_lr == lr
        hp["policy_kwargs"] = eval(hp["policy_kwargs"])
        assert hp == script, env_id
        assert normalize in (True, "dict(norm_reward=False)")


def test_scripts_set_one_torch_thread_and_take_a_budget_and_a_seed():
    for script in ("sb3_ppo.py", "sb3_sac.py", "zoo_score.py"):
        text = (EXAMPLES / script).read_text()
        assert "torch.set_num_threads(1)  # " in text, script
        assert len(text.splitlines()) <= 50, script
    for script in ("sb3_ppo.py", "sb3_sac.py"):
        text = (EXAMPLES / script).read_text()
        assert '"--timesteps"' in text and '"--seed"' in text and "score(model" in text


# -- the page ---------------------------------------------------------------------------


def test_page_includes_every_example_verbatim_and_is_in_the_nav():
    """Every file of docs/examples/ is included in a fenced block by a snippet line (the
    built page shows the file as it is), and no ```python block holds one (the docs test
    runs those)."""
    text = PAGE.read_text()
    fences = re.findall(r"^```(\w+)[^\n]*\n(.*?)^```", text, flags=re.S | re.M)
    included = {}
    for lang, body in fences:
        for path in re.findall(r'^--8<-- "([^"]+)"$', body, flags=re.M):
            assert body.strip() == f'--8<-- "{path}"', "a snippet is alone in its block"
            assert lang != "python"
            included[path] = lang
    files = {str(p.relative_to(ROOT)) for p in EXAMPLES.iterdir() if p.is_file()}
    zoo = {"train/zoo/ppo_mlp.yml", "train/zoo/sac_mlp.yml"}
    assert set(included) == files | zoo
    assert {included[f] for f in files if f.endswith(".py")} == {"py"}
    assert included["docs/examples/cleanrl_ppo.diff"] == "diff"
    nav = yaml.safe_load((ROOT / "mkdocs.yml").read_text().replace("!!python/name:", ""))["nav"]
    guide = next(item["Guide"] for item in nav if isinstance(item, dict) and "Guide" in item)
    assert {"Train on any level with any library": "any-library.md"} in guide


def test_page_states_its_measured_runs_from_the_data():
    """The page's figures are the generated block (train.leaderboard.guide_page, checked to
    regenerate exactly in tests/train/test_leaderboard_guide.py) with the machine they ran
    on; every registered level is named."""
    text = PAGE.read_text()
    assert text.count("<!-- guide-runs:start -->") == 1
    assert "guide-run -- COMMAND" in text and "acld-gym leaderboard render" in text
    for env_id in PRESETS:
        assert env_id in text


def _first_v1_runs() -> list[dict]:
    """The first committed ACLDBeam-v1 run of each guide script (results/guide/runs.json)."""
    from train.leaderboard.guide import GUIDE_FILE, read_runs

    path = ROOT / "results" / GUIDE_FILE
    runs = read_runs(path) if path.is_file() else []
    first: dict[str, dict] = {}
    for r in runs:
        if r["env_id"] == "ACLDBeam-v1" and r["command"].startswith("python docs/examples/"):
            first.setdefault(r["client"], r)
    return list(first.values())


@pytest.mark.slow
@pytest.mark.parametrize("run", _first_v1_runs(), ids=lambda r: r["client"])
def test_a_recorded_run_is_what_its_command_prints(run, tmp_path):
    """A guide script's recorded ACLDBeam-v1 run, run again by its command at its stated
    budget, prints its figures: the score and ISE / LQR to 0.03 (another CPU's kernels
    move a training run by round-off)."""
    from train.leaderboard.guide import parse_score

    args = shlex.split(run["command"])[1:]
    out = _run([str(ROOT / args[0]), *args[1:]], tmp_path, timeout=3600)
    got = parse_score(out)
    want = [run["score"]["iqm"], *run["ise_rel_lqr"].values()]
    have = [got["score"]["iqm"], *got["ise_rel_lqr"].values()]
    assert np.allclose(have, want, atol=0.03, rtol=0), (have, want)
