"""Training throughput (env steps/s) of PPO on the native batched env through the SB3
adapter vs SB3's ``SubprocVecEnv`` over single envs, with the PPO recipe
(``train/recipes/ppo.yaml``) on fewer sub-envs; both envs from the one factory,
:func:`train.vec.make_vec_env`.

Not a timed test: ``python benchmarks/bench_train.py [--timesteps 40960] [--n-envs 8]``.
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from train.config import load_config


def env_rate(backend: str, n_envs: int, steps: int) -> float:
    """Env steps/s of the wrapped training env alone (random actions)."""
    from train.vec import make_vec_env

    cfg = load_config("ppo").with_overrides(n_envs=n_envs)
    venv = make_vec_env(cfg, 0, backend=backend)
    venv.reset()
    acts = np.random.default_rng(0).uniform(-1, 1, (64, n_envs, 1)).astype(np.float32)
    t0 = time.perf_counter()
    for k in range(steps // n_envs):
        venv.step_async(acts[k % 64])
        venv.step_wait()
    rate = (steps // n_envs) * n_envs / (time.perf_counter() - t0)
    venv.close()
    return rate


def train_rate(backend: str, n_envs: int, steps: int) -> float:
    """Env steps/s of PPO's ``learn`` (collection + updates) on the recipe's model."""
    from train.core.sb3_train import make_model
    from train.vec import make_vec_env

    cfg = load_config("ppo")
    cfg = cfg.with_overrides(
        n_envs=n_envs,
        model={  # one minibatch per rollout
            **cfg.model,
            "batch_size": n_envs * cfg.model["n_steps"],
        },
    )
    venv = make_vec_env(cfg, 0, backend=backend)
    model = make_model(cfg, venv, 0)
    t0 = time.perf_counter()
    model.learn(steps)
    rate = model.num_timesteps / (time.perf_counter() - t0)
    venv.close()
    return rate


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__)
    p.add_argument("--timesteps", type=int, default=40_960)
    p.add_argument("--n-envs", type=int, default=8)
    a = p.parse_args()
    print(f"PPO training env, {a.n_envs} sub-envs, {a.timesteps} steps")
    for backend in ("native", "subproc"):
        e = env_rate(backend, a.n_envs, a.timesteps)
        t = train_rate(backend, a.n_envs, a.timesteps)
        print(f"{backend:>8}: env alone {e:10.0f} steps/s   PPO training {t:8.0f} steps/s")


if __name__ == "__main__":
    from acld_gym.util.blas import one_blas_thread

    with one_blas_thread():  # as the package's entry points run (acld_gym.util.blas)
        main()
