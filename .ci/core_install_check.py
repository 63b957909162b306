"""What a core install (``pip install acld-gym``, no extras) must do, checked from outside
the checkout: ``gym.make`` of every registered id, ``python -m baselines.evaluate`` for
passive, LQR, SMC and the bound (MPC skipped with one line naming the extra where osqp is
missing), and ``TrainedAgent.load`` plus a rollout of every shipped agent, with numpy only.
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


def check_evaluate() -> str:
    from baselines.evaluate import main
    from baselines.policies import mpc_available

    out = io.StringIO()
    with contextlib.redirect_stdout(out):
        code = main(["--score-episodes", "5", "--quiet"])
    text = out.getvalue()
    assert code == 0, text
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
        "python -m baselines.evaluate: "
        + ", ".join(sorted(rows))
        + ("" if mpc_available() else f" ({skipped[0]})")
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
    checks = (check_envs, check_evaluate, check_agents)
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
