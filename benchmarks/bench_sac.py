"""SAC's training speed with the package's n-step replay buffer
(:class:`train.core.buffers.FlatNStepReplayBuffer`) against stable-baselines3's own
(``NStepReplayBuffer``), timed in the same run: one batch's sampling from a buffer the
size of the SAC recipe's (``train/recipes/sac.yaml``: 1M transitions of 64 sub-envs,
5-step returns, batches of 2048), and the recipe's ``learn`` (collection + updates) for
``--timesteps`` env steps after ``learning_starts``, both buffers from the same seed (the
two runs' parameters are compared: they must be equal, as tests/train/test_buffers.py
checks on a tiny run).

Not a timed test: ``python benchmarks/bench_sac.py [--timesteps 100000] [--repeats 3]``.
"""

from __future__ import annotations

import argparse
import time
from dataclasses import replace

import numpy as np
import torch
from stable_baselines3.common.buffers import NStepReplayBuffer

from train.config import load_config
from train.core.buffers import FlatNStepReplayBuffer

SB3 = "SB3 NStepReplayBuffer"


def filled_buffer(
    cls,
    size: int,
    n_envs: int,
    rows: int,
    n_steps: int,
    gamma: float,
    done_rate: float,
    obs_dim: int = 5,
):
    """A replay buffer ``cls`` of ``size`` rows of ``n_envs`` sub-envs (n-step returns:
    ``n_steps``, ``gamma``; ``obs_dim``-value observations, 1-value actions) after ``rows`` adds
    (wrapped when rows > size) of random transitions, each ending an episode with
    probability ``done_rate``, half of those by the time limit; seeded, so two buffers
    filled alike hold the same data."""
    from gymnasium import spaces

    buf = cls(
        size,
        spaces.Box(-np.inf, np.inf, (obs_dim,), np.float32),
        spaces.Box(-1.0, 1.0, (1,), np.float32),
        device="cpu",
        n_envs=n_envs,
        n_steps=n_steps,
        gamma=gamma,
        handle_timeout_termination=True,
    )
    rng = np.random.default_rng(0)
    for _ in range(rows):
        done = rng.random(n_envs) < done_rate
        truncated = done & (rng.random(n_envs) < 0.5)
        buf.add(
            rng.normal(size=(n_envs, obs_dim)).astype(np.float32),
            rng.normal(size=(n_envs, obs_dim)).astype(np.float32),
            rng.uniform(-1, 1, (n_envs, 1)).astype(np.float32),
            rng.normal(size=n_envs).astype(np.float32),
            done,
            [{"TimeLimit.truncated": bool(t)} for t in truncated],
        )
    return buf


def sample_ms(blocks: int = 20, batches: int = 50) -> dict[str, list[float]]:
    """Milliseconds per batch sampled from a buffer of the recipe's size, sub-envs, n-step
    returns and batch size (3000 rows full of 10-value observations: v1's 9 and log c),
    SB3's and the flat one alternating in ``blocks`` blocks of ``batches`` batches each, so
    that drift in the machine's speed hits both: ``{name: [ms per batch of each block]}``."""
    cfg = load_config("sac")
    m = cfg.model
    bufs = {
        name: filled_buffer(
            cls, m["buffer_size"], cfg.n_envs, 3000, m["n_steps"], m["gamma"], 1e-3, obs_dim=10
        )
        for name, cls in ((SB3, NStepReplayBuffer), ("flat", FlatNStepReplayBuffer))
    }
    out: dict[str, list[float]] = {name: [] for name in bufs}
    np.random.seed(0)  # noqa: NPY002 (SB3 samples from numpy's global generator)
    for _ in range(blocks):
        for name, buf in bufs.items():
            t0 = time.perf_counter()
            for _ in range(batches):
                buf.sample(m["batch_size"])
            out[name].append((time.perf_counter() - t0) / batches * 1e3)
    return out


def learn(flat: bool, timesteps: int) -> tuple[float, dict]:
    """(env steps/s of the SAC recipe's ``learn`` after ``learning_starts``, its final
    parameters) with the flat buffer or SB3's own."""
    from train.core.sb3_train import make_model
    from train.vec import make_vec_env

    cfg = load_config("sac")
    kwargs = {}
    if not flat:  # SB3's own n-step buffer, as SB3 sets it up when n_steps > 1
        m = cfg.model
        cfg = replace(cfg, model={**m, "n_steps": 1})
        kwargs = {
            "replay_buffer_class": NStepReplayBuffer,
            "replay_buffer_kwargs": {"n_steps": m["n_steps"], "gamma": m["gamma"]},
        }
    venv = make_vec_env(cfg, 0)
    model = make_model(cfg, venv, 0, **kwargs)
    expected = FlatNStepReplayBuffer if flat else NStepReplayBuffer
    assert type(model.replay_buffer) is expected, type(model.replay_buffer)
    start = cfg.model["learning_starts"]
    model.learn(start, reset_num_timesteps=False)
    t0 = time.perf_counter()
    model.learn(timesteps, reset_num_timesteps=False)
    rate = timesteps / (time.perf_counter() - t0)
    venv.close()
    return rate, model.policy.state_dict()


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__)
    p.add_argument("--timesteps", type=int, default=100_000)
    p.add_argument("--repeats", type=int, default=3)
    a = p.parse_args()
    torch.set_num_threads(1)
    ms = sample_ms()
    print(f"sample(2048) of the recipe's buffer [ms] (median of {len(ms[SB3])} blocks)")
    for name, r in ms.items():
        print(f"  {name:<24} {np.median(r):8.3f}   (blocks: {min(r):.3f}-{max(r):.3f})")
    ratio = np.array(ms["flat"]) / np.array(ms[SB3])
    span = f"{ratio.min():.2f}-{ratio.max():.2f}"
    print(f"  flat / SB3 per block: median {np.median(ratio):.2f} ({span})")
    print(f"SAC recipe learn, {a.timesteps} env steps after learning_starts [env steps/s]")
    rates: dict[str, list[float]] = {SB3: [], "flat": []}
    params = {}
    for _ in range(a.repeats):  # interleaved, so that drift in the machine's speed hits both
        for name, flat in ((SB3, False), ("flat", True)):
            rate, params[name] = learn(flat, a.timesteps)
            rates[name].append(rate)
    for name, r in rates.items():
        print(f"  {name:<24} {np.median(r):8.0f}   (runs: {', '.join(f'{x:.0f}' for x in r)})")
    same = all(torch.equal(params["flat"][k], v) for k, v in params[SB3].items())
    print(f"  same final parameters: {same}")
    pairs = np.array(rates["flat"]) / np.array(rates[SB3])
    print(f"  flat / SB3 per pair of runs: {', '.join(f'{x:.2f}' for x in pairs)}")


if __name__ == "__main__":
    from acld_gym.util.blas import one_blas_thread

    with one_blas_thread():  # as the package's entry points run (acld_gym.util.blas)
        main()
