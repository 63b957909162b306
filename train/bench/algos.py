"""One entry point for every benchmark algorithm: :func:`train_algo`."""

from __future__ import annotations

import time
from typing import Any

import numpy as np

from ..config import TrainConfig
from .evaluate import CurveCallback
from .sb3_train import train_sb3
from .search import train_random_search

__all__ = ["restart_seeds", "train_algo"]


def restart_seeds(seed: int, restarts: int) -> list[int]:
    """The seeds of a trial's ``restarts`` runs: ``seed`` itself first (one run is the
    plain recipe), then 32-bit seeds drawn from ``numpy.random.SeedSequence((seed, k))``,
    which no other trial's seed list shares by construction (``seed + k`` would make
    seed 0's second run seed 1's first)."""
    derived = [int(np.random.SeedSequence((seed, k)).generate_state(1)[0])
               for k in range(1, restarts)]
    return [int(seed), *derived]


def _train_once(cfg: TrainConfig, seed: int, env_id: str, timed) -> tuple[Any, dict]:
    if cfg.algo == "vrs":
        return train_random_search(cfg, seed, env_id, timed)
    return train_sb3(cfg, seed, env_id, timed)


def train_algo(
    cfg: TrainConfig,
    seed: int,
    env_id: str,
    callback: CurveCallback | None = None,
) -> tuple[Any, dict]:
    """Train ``cfg`` with ``seed`` on ``env_id``; returns ``(policy, record)`` with
    ``record["train_seconds"]`` and ``record["train_cpu_seconds"]`` (wall and CPU time
    of training, evaluations excluded; on a shared machine the CPU time is the fairer
    measure).

    With ``cfg.restarts`` > 1 the runs follow one another (seeds :func:`restart_seeds`),
    the learning curve of run k at steps offset by ``k * cfg.timesteps``; the policy and
    record returned are those of the run whose selected check has the lowest validation
    cost, with ``record["steps"]`` all runs' steps and ``record["restarts"]`` each run's
    seed, chosen step and cost."""
    spent = [0.0, 0.0]
    last = [-1]
    offset = [0]

    def timed(steps, policy):  # evaluation time is not training time
        last[0] = offset[0] + steps
        t0, c0 = time.perf_counter(), time.process_time()
        if callback is not None:
            callback(last[0], policy)
        spent[0] += time.perf_counter() - t0
        spent[1] += time.process_time() - c0

    t0, c0 = time.perf_counter(), time.process_time()
    best, runs = None, []  # only the best run so far is kept alive (its model, its buffer)
    for k, run_seed in enumerate(restart_seeds(seed, cfg.restarts)):
        run = (k, *_train_once(cfg, run_seed, env_id, timed))
        offset[0] += run[2]["steps"]
        if cfg.restarts > 1:
            sel = run[2]["select"]
            runs.append({"seed": run_seed, "steps": sel["steps"], "cost": sel["cost"]})
        if best is None or (runs and runs[-1]["cost"] < runs[best[0]]["cost"]):
            best = run  # the first of equal costs is kept
        run = None
    chosen, policy, record = best
    if runs:
        record["steps"] = offset[0]
        record["restarts"] = {"chosen": chosen, "runs": runs}
    record["train_seconds"] = time.perf_counter() - t0 - spent[0]
    record["train_cpu_seconds"] = time.process_time() - c0 - spent[1]
    if callback is not None and record["steps"] > last[0]:
        callback(record["steps"], policy)  # the learning curve ends at the final policy
    return policy, record
