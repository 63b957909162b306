"""Env-steps per second of ACLDBeam-v1: single env, native vector env, SB3 adapter, each
beside the bare product of the same shape timed in the same run.

The single env is the N = 1 case of the one batched step (``acld_gym.envs.batch``); the
vector env's N = 1024 step is one product of its (1024 x nz) state rows with the fused
(nz x m) matrix, so the reference is that product alone (``numpy.matmul``, one BLAS
thread), timed interleaved with the env in the same run. The machine may be shared: every
rate is the best of ``--repeats`` windows (the least disturbed one), and each window of the
vector env holds exactly one autoreset of every sub-env (1001 steps of 1000-step
episodes), so the rates include the resets: drawing a random load and the sensor noise
for the episode costs tens of microseconds per sub-env and episode.

Then the single env's step taken apart (resets excluded): the compiled step, its
matrix-vector product alone (timed in C, mean over the states of an episode), the numpy
reference step, and a no-op Python env with the same API (the floor of any pure-Python
Gymnasium env).

Not a timed test: run ``python benchmarks/bench_env.py [--repeats 8]``. Actions are
pre-generated uniform random voltages (beyond +/-120 V sometimes, so the clipping path is
exercised).
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import time

import gymnasium as gym
import numpy as np

import acld_gym  # noqa: F401  (registers ACLDBeam-v1)
from acld_gym.envs.beam_env import COMPILED_STEP, ACLDBeamEnv
from acld_gym.envs.sb3 import SB3VecEnv
from acld_gym.envs.vector_env import ACLDBeamVectorEnv

EPISODE = 1000  # steps of an episode (ACLDBeam-v1's default 1 s at 1 ms)


def _rate(step, n_batch: int, steps: int) -> float:
    """Env-steps/s of ``steps`` calls of ``step(j)``."""
    t0 = time.perf_counter()
    for j in range(steps):
        step(j)
    return steps * n_batch / (time.perf_counter() - t0)


def _single_stepper(env):
    acts = np.random.default_rng(0).uniform(-150, 150, (4096, 1)).astype(np.float32)
    env.reset(seed=0)

    def step(j):
        _, _, te, tr, _ = env.step(acts[j % 4096])
        if te or tr:
            env.reset()

    return step


def _vector_stepper(n: int, **kw):
    env = ACLDBeamVectorEnv(num_envs=n, max_episode_steps=EPISODE, **kw)
    acts = np.random.default_rng(0).uniform(-150, 150, (64, n, 1)).astype(np.float32)
    env.reset(seed=0)
    return env, (lambda j: env.step(acts[j % 64]))


def _sb3_stepper(n: int):
    venv = SB3VecEnv(num_envs=n, load_case="random")
    acts = np.random.default_rng(0).uniform(-150, 150, (64, n, 1)).astype(np.float32)
    venv.seed(0)
    venv.reset()

    def step(j):
        venv.step_async(acts[j % 64])
        venv.step_wait()

    return step


def _bare_product(env: ACLDBeamVectorEnv):
    """The N = 1024 step's product alone: state rows (N x nz) times G^T (nz x m)."""
    b = env.batch
    Z, GT, out = b.Z.copy(), b.GT.copy(), np.empty_like(b.OUT)
    return (
        lambda j: np.matmul(Z, GT, out=out)
    ), f"{Z.shape[0]}x{Z.shape[1]} @ {GT.shape[0]}x{GT.shape[1]}"


class _NoOpEnv(gym.Env):
    """The Gymnasium API with no physics: same spaces, a 10-entry info dict (the floor)."""

    observation_space = gym.spaces.Box(-np.inf, np.inf, (9,), np.float32)
    action_space = gym.spaces.Box(-120.0, 120.0, (1,), np.float32)

    def reset(self, *, seed=None, options=None):
        super().reset(seed=seed)
        self.k = 0
        return np.zeros(9, np.float32), {}

    def step(self, action):
        v = float(action[0])
        self.k += 1
        info = {
            "tip_deflection": 0.0,
            "voltage": v,
            "requested_voltage": v,
            "clipped": False,
            "tip_load": 0.0,
            "time": self.k * 1e-3,
            "xr_true": np.zeros(8),
            "terminated_by": None,
            "reward_deflection": 0.0,
            "reward_voltage": -v * v,
        }
        return np.zeros(9, np.float32), -v * v, False, self.k >= EPISODE, info


def _episode_step_us(env, acts, episodes: int) -> float:
    """Mean wall time of ``env.step`` over whole episodes, resets not counted [us]."""
    total, n = 0.0, 0
    for e in range(episodes):
        env.reset(seed=e)
        t0 = time.perf_counter()
        for a in acts:
            env.step(a)
        total += time.perf_counter() - t0
        n += len(acts)
    return 1e6 * total / n


def _product_us(env, acts) -> float:
    """Mean wall time of the compiled step's product alone, over the states of an
    episode (columns with z_j = 0 are skipped, so the cost depends on the state) [us]."""
    env.reset(seed=0)
    times = []
    for k, a in enumerate(acts):
        env.step(a)
        if k % 50 == 25:
            times.append(env.batch.core.product_seconds(4000))
    return 1e6 * float(np.mean(times))


def bench_breakdown(episodes: int) -> list[tuple[str, float]]:
    """Microseconds per single-env step (resets excluded): the compiled step, its
    product, the numpy reference step, and a no-op env with the same API."""
    acts = np.random.default_rng(0).uniform(-150, 150, (EPISODE, 1)).astype(np.float32)
    env = ACLDBeamEnv(load_case="random")
    env.reset(seed=0)
    GT = env.batch.GT
    rows = []
    if COMPILED_STEP:
        t_step = min(_episode_step_us(env, acts, episodes) for _ in range(3))
        t_prod = _product_us(env, acts)
        rows += [
            ("single env step, compiled (acld_gym.envs._stepcore) [us]", t_step),
            (f"  of which the fused {GT.shape[1]} x {GT.shape[0]} product [us]", t_prod),
            ("  the rest: call, action check, loads, reward, obs, info [us]", t_step - t_prod),
            ("  product's share of the step [%]", 100 * t_prod / t_step),
        ]
    else:
        rows.append(("(acld_gym.envs._stepcore not built: numpy steps only)", float("nan")))
    ref = ACLDBeamEnv(load_case="random")
    ref.compiled_step = False
    rows.append(
        (
            "single env step, numpy reference path [us]",
            _episode_step_us(ref, acts, max(1, episodes // 10)),
        )
    )
    noop = _single_stepper(_NoOpEnv())
    rows.append(
        (
            "no-op Gymnasium env in Python, same spaces and info [us]",
            1e6 / max(_rate(noop, 1, 5 * EPISODE) for _ in range(3)),
        )
    )
    return rows


def _first_make_seconds() -> float:
    """Wall time of ``import acld_gym; gym.make("ACLDBeam-v1")`` in a new interpreter."""
    code = "import gymnasium as gym, acld_gym; gym.make('ACLDBeam-v1')"
    t0 = time.perf_counter()
    subprocess.run([sys.executable, "-c", code], check=True)
    return time.perf_counter() - t0


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument(
        "--repeats",
        type=int,
        default=8,
        help="windows per measurement; the best is reported (default 8)",
    )
    args = ap.parse_args(argv)
    r = max(1, args.repeats)
    print(
        f"ACLDBeam-v1 env-steps/s (obs 'estimate'; {os.cpu_count()} CPUs, numpy "
        f"{np.__version__}, best of {r} windows; compiled step: {COMPILED_STEP})"
    )
    startup = [_first_make_seconds() for _ in range(3)]
    print(
        "first gym.make('ACLDBeam-v1') in a fresh process (import included), 3 runs [s]: "
        + ", ".join(f"{t:.2f}" for t in startup)
    )
    # The main comparison: N = 1024 on case 1 and on random loads, and the bare product,
    # interleaved window by window so that all three see the same machine.
    big = {case: _vector_stepper(1024, load_case=case) for case in (1, "random")}
    bare, shape = _bare_product(big[1][0])
    best = {"bare": 0.0, 1: 0.0, "random": 0.0}
    for _ in range(r):
        best["bare"] = max(best["bare"], _rate(bare, 1024, 300))
        for case, (_, step) in big.items():
            best[case] = max(best[case], _rate(step, 1024, EPISODE + 1))
    rows = [
        (f"bare product of the N=1024 step's shape ({shape}, numpy)", best["bare"]),
        ("ACLDBeamVectorEnv N=1024, load_case=1", best[1]),
        ("ACLDBeamVectorEnv N=1024, load_case='random'", best["random"]),
    ]
    width = 64
    for name, rate in rows:
        print(f"{name:<{width}}  {rate:>12,.0f}  ({rate / best['bare']:.2f} of the product)")
    print()
    others = [
        (
            "single ACLDBeamEnv (raw class), load_case='random'",
            _single_stepper(ACLDBeamEnv(load_case="random")),
            1,
            EPISODE,
        ),
        (
            "single gym.make (OrderEnforcing, PassiveEnvChecker), 'random'",
            _single_stepper(gym.make("ACLDBeam-v1", load_case="random")),
            1,
            EPISODE,
        ),
        (
            "ACLDBeamVectorEnv N=1, 'random'",
            _vector_stepper(1, load_case="random")[1],
            1,
            EPISODE + 1,
        ),
        (
            "ACLDBeamVectorEnv N=64, 'random'",
            _vector_stepper(64, load_case="random")[1],
            64,
            EPISODE + 1,
        ),
        ("SB3VecEnv N=64, 'random' (infos as list of dicts)", _sb3_stepper(64), 64, EPISODE + 1),
    ]
    for name, step, n, steps in others:
        rate = max(_rate(step, n, steps) for _ in range(r))
        print(f"{name:<{width}}  {rate:>12,.0f}")
    print()
    for name, us in bench_breakdown(episodes=200):
        print(f"{name:<{width}}  {us:>12.2f}")


if __name__ == "__main__":
    from acld_gym.util.blas import one_blas_thread

    with one_blas_thread():  # as the package's entry points run (acld_gym.util.blas)
        main()
