"""Env-steps per second of ACLDBeam-v1: single env, native vector env, SB3 adapter.

Then the single env's step taken apart (resets excluded): the compiled step, its
matrix-vector product alone (timed in C, mean over the states of an episode), the
numpy reference step, and a no-op Python env with the same API (the floor of any
pure-Python Gymnasium env).

Not a timed test: run ``python benchmarks/bench_env.py [--seconds 2]``. Actions
are pre-generated uniform random voltages (beyond +/-120 V sometimes, so the
clipping path is exercised); episodes (1000 steps) autoreset as in training, so
the rates include the resets: drawing a random load and tabulating it for the
episode costs about 0.4 ms per sub-env and episode (0.4 us per env-step).
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

KW = dict(load_case="random")


def _timed(step, n_batch: int, seconds: float) -> float:
    """Calls ``step(j)`` for about ``seconds``; returns env-steps/s."""
    j, t0 = 0, time.perf_counter()
    while True:
        for _ in range(50):
            step(j)
            j += 1
        dt = time.perf_counter() - t0
        if dt >= seconds:
            return j * n_batch / dt


def bench_single(env, seconds: float) -> float:
    acts = np.random.default_rng(0).uniform(-150, 150, (4096, 1)).astype(np.float32)
    env.reset(seed=0)

    def step(j):
        _, _, te, tr, _ = env.step(acts[j % 4096])
        if te or tr:
            env.reset()

    return _timed(step, 1, seconds)


def bench_vector(n: int, seconds: float, **kw) -> float:
    env = ACLDBeamVectorEnv(num_envs=n, max_episode_steps=1000, **(kw or KW))
    acts = np.random.default_rng(0).uniform(-150, 150, (64, n, 1)).astype(np.float32)
    env.reset(seed=0)
    return _timed(lambda j: env.step(acts[j % 64]), n, seconds)


def bench_sb3(n: int, seconds: float) -> float:
    venv = SB3VecEnv(num_envs=n, **KW)
    acts = np.random.default_rng(0).uniform(-150, 150, (64, n, 1)).astype(np.float32)
    venv.seed(0)
    venv.reset()

    def step(j):
        venv.step_async(acts[j % 64])
        venv.step_wait()

    return _timed(step, n, seconds)


class _NoOpEnv(gym.Env):
    """The Gymnasium API with no physics: same spaces, a 7-entry info dict (the floor)."""

    observation_space = gym.spaces.Box(-np.inf, np.inf, (7,), np.float32)
    action_space = gym.spaces.Box(-120.0, 120.0, (1,), np.float32)

    def reset(self, *, seed=None, options=None):
        super().reset(seed=seed)
        self.k = 0
        return np.zeros(7, np.float32), {}

    def step(self, action):
        v = float(action[0])
        self.k += 1
        info = {
            "tip_deflection": 0.0,
            "voltage": v,
            "tip_load": 0.0,
            "time": self.k * 1e-3,
            "xr_true": np.zeros(6),
            "clipped": False,
            "requested_voltage": v,
        }
        return np.zeros(7, np.float32), -v * v, False, self.k >= 1000, info


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
            times.append(env._core.product_seconds(4000))
    return 1e6 * float(np.mean(times))


def bench_breakdown(seconds: float) -> list[tuple[str, float]]:
    """Microseconds per single-env step (resets excluded): the compiled step, its
    product, the numpy reference step, and a no-op env with the same API."""
    acts = np.random.default_rng(0).uniform(-150, 150, (1000, 1)).astype(np.float32)
    episodes = max(1, int(seconds / 1e-3))  # ~1 ms per episode compiled
    env = ACLDBeamEnv(**KW)
    env.reset(seed=0)
    G = env._G
    rows = []
    if COMPILED_STEP:
        t_step = _episode_step_us(env, acts, episodes)
        t_prod = _product_us(env, acts)
        rows += [
            ("single env step, compiled (acld_gym.envs._stepcore) [us]", t_step),
            (f"  of which the fused {G.shape[0]} x {G.shape[1]} product [us]", t_prod),
            ("  the rest: call, action check, reward, obs, info [us]", t_step - t_prod),
            ("  product's share of the step [%]", 100 * t_prod / t_step),
        ]
    else:
        rows.append(("(acld_gym.envs._stepcore not built: numpy steps only)", float("nan")))
    ref = ACLDBeamEnv(**KW)
    ref.compiled_step = False
    rows.append(
        (
            "single env step, numpy reference path [us]",
            _episode_step_us(ref, acts, max(1, episodes // 5)),
        )
    )
    rows.append(
        (
            "no-op Gymnasium env in Python, same spaces and info [us]",
            1e6 / bench_single(_NoOpEnv(), seconds),
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
    ap.add_argument("--seconds", type=float, default=2.0, help="time per measurement [s]")
    args = ap.parse_args(argv)
    s = args.seconds
    print(
        f"ACLDBeam-v1 env-steps/s (load_case='random', obs 'estimate'; {os.cpu_count()} CPUs, "
        f"numpy {np.__version__}, {s:g} s each; compiled step: {COMPILED_STEP})"
    )
    startup = [_first_make_seconds() for _ in range(3)]
    print(
        "first gym.make('ACLDBeam-v1') in a fresh process (import included), 3 runs [s]: "
        + ", ".join(f"{t:.2f}" for t in startup)
    )
    rows = [
        ("single ACLDBeamEnv (raw class)", bench_single(ACLDBeamEnv(**KW), s)),
        (
            "single gym.make (OrderEnforcing, PassiveEnvChecker)",
            bench_single(gym.make("ACLDBeam-v1", **KW), s),
        ),
    ]
    for n in (1, 64, 1024):
        rows.append((f"ACLDBeamVectorEnv N={n}", bench_vector(n, s)))
    rows.append(
        ("ACLDBeamVectorEnv N=1024, load_case=1 (cheap resets)", bench_vector(1024, s, load_case=1))
    )
    rows.append(("SB3VecEnv N=64 (infos as list of dicts)", bench_sb3(64, s)))
    width = max(len(name) for name, _ in rows)
    for name, rate in rows:
        print(f"{name:<{width}}  {rate:>12,.0f}")
    print()
    for name, us in bench_breakdown(s):
        print(f"{name:<{width}}  {us:>12.2f}")


if __name__ == "__main__":
    from acld_gym.util.blas import one_blas_thread

    with one_blas_thread():  # as the package's entry points run (acld_gym.util.blas)
        main()
