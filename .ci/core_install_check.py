"""What a core install (``pip install acld-gym``, no extras) must do, checked from outside
the checkout: ``gym.make`` of every registered id; the ``acld-gym`` command
(:mod:`train.console`): ``--version``, ``--help`` listing every subcommand, ``acld-gym
evaluate`` (``python -m baselines.evaluate``) for passive, LQR, SMC and the bound (MPC
skipped with one line naming the extra where osqp is missing), and ``acld-gym train``
ending with one line naming the train extra; and ``TrainedAgent.load`` plus a rollout of
every shipped agent, with numpy only.
``--compiled``: the env's compiled step (``acld_gym.envs._stepcore``) must be in use.

Run by ``.ci/run`` in a clean venv with the wheel installed, and by
``tests/test_core_install.py`` with the extras' imports blocked. Prints one line per check
and ``core install: N passed, 0 failed``; exits 1 on the first failure.
"""

from __future__ import annotations

import contextlib
import io
import json
import sys
import warnings

#: Packages of the extras: none of them may be imported by what a core install runs.
EXTRAS = ("torch", "stable_baselines3", "sb3_contrib", "tensorboard", "yaml", "ray")
#: Relative tolerance of an agent's case-1 ISE against its shipped comparison row.
RTOL = 1e-2


def check_envs() -> str:
    import gymnasium as gym
    import numpy as np

    import acld_gym
    from acld_gym.envs.presets import PRESETS

    for env_id in PRESETS:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", DeprecationWarning)  # v0: "out of date"
            env = gym.make(env_id)
        env.reset(seed=0)
        obs, reward, *_ = env.step(np.array([60.0], np.float32))
        assert np.all(np.isfinite(obs)) and np.isfinite(reward), env_id
        env.close()
    from acld_gym.envs.beam_env import COMPILED_STEP

    assert COMPILED_STEP or "--compiled" not in sys.argv, "the compiled step is missing"
    return (
        f"gym.make of {len(PRESETS)} ids ({', '.join(PRESETS)}), acld-gym "
        f"{acld_gym.__version__}, compiled step: {COMPILED_STEP}"
    )


def _console(argv: list[str]) -> tuple[int, str, str]:
    """``acld-gym ARGV`` in this process: (exit status, stdout, stderr)."""
    from train.console import main

    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        try:
            code = main(argv)
        except SystemExit as exc:  # argparse's --help and usage errors
            code = exc.code
    return code, out.getvalue(), err.getvalue()


def check_command() -> str:
    from importlib.metadata import version

    from baselines.policies import mpc_available
    from train.console import COMMANDS

    code, text, err = _console(["--version"])
    assert (code, text) == (0, f"acld-gym {version('acld-gym')}\n"), (code, text, err)
    code, text, err = _console(["--help"])
    listed = {line.split()[0] for line in text.splitlines() if line.startswith("  ")}
    assert code == 0 and set(COMMANDS) <= listed, (code, text, err)
    code, text, err = _console(["train", "ppo"])
    assert code == 1 and len(err.splitlines()) == 1 and "acld-gym[train]" in err, (code, err)
    extra = err.strip()
    code, text, err = _console(["evaluate", "--score-episodes", "5", "--quiet"])
    assert code == 0, text + err
    rows = {
        line.split()[0]
        for line in text.splitlines()
        if line.startswith("  ")
        and line.split()
        and line.split()[0] in ("passive", "lqr", "smc", "mpc", "bound")
    }
    want = {"passive", "lqr", "smc", "bound"} | ({"mpc"} if mpc_available() else set())
    assert rows == want, (rows, text)
    skipped = [line for line in text.splitlines() if line.startswith("mpc skipped")]
    assert mpc_available() or (len(skipped) == 1 and "acld-gym[baselines]" in skipped[0]), text
    return (
        f"acld-gym --version, --help ({len(COMMANDS)} commands); acld-gym evaluate: "
        + ", ".join(sorted(rows))
        + ("" if mpc_available() else f" ({skipped[0]})")
        + f"; {extra}"
    )


def check_agents() -> str:
    from acld_gym.envs.beam_env import ACLDBeamEnv
    from baselines.evaluate import metrics_row, rollout
    from train.agent import TrainedAgent
    from train.compare import AGENTS_DIR, agent_names

    rows = json.loads((AGENTS_DIR / "compare.json").read_text())
    names = agent_names()
    assert names, f"no shipped agent under {AGENTS_DIR}"
    for name in names:
        agent = TrainedAgent.load(AGENTS_DIR / name)
        ise = metrics_row(1, name, rollout(agent, ACLDBeamEnv(load_case=1), seed=0)).ise
        ref = next(r["ise"] for r in rows if r["case"] == 1 and r["policy"] == name)
        assert abs(ise - ref) <= RTOL * ref, (name, ise, ref)
    return f"TrainedAgent.load + case-1 rollout of {len(names)} agents ({', '.join(names)})"


def main() -> int:
    checks = (check_envs, check_command, check_agents)
    for check in checks:
        try:
            print(f"ok   {check()}", flush=True)
        except Exception as exc:  # report which check failed, then fail
            print(f"FAIL {check.__name__}: {type(exc).__name__}: {exc}", flush=True)
            return 1
    loaded = sorted(m for m in sys.modules if m.split(".")[0] in EXTRAS)
    if loaded:
        print(f"FAIL extras imported: {loaded}")
        return 1
    print(f"core install: {len(checks)} passed, 0 failed")
    return 0


if __name__ == "__main__":
    sys.exit(main())
