"""One entry point for every benchmark algorithm: :func:`train_algo`."""

from __future__ import annotations

import time
from typing import Any

from ..config import TrainConfig
from .evaluate import CurveCallback
from .sb3_train import train_sb3
from .search import train_random_search

__all__ = ["train_algo"]


def train_algo(
    cfg: TrainConfig,
    seed: int,
    env_id: str,
    callback: CurveCallback | None = None,
) -> tuple[Any, dict]:
    """Train ``cfg`` with ``seed`` on ``env_id``; returns ``(policy, record)`` with
    ``record["train_seconds"]`` and ``record["train_cpu_seconds"]`` (wall and CPU time
    of training, evaluations excluded; on a shared machine the CPU time is the fairer
    measure)."""
    spent = [0.0, 0.0]
    last = [-1]

    def timed(steps, policy):  # evaluation time is not training time
        last[0] = steps
        t0, c0 = time.perf_counter(), time.process_time()
        if callback is not None:
            callback(steps, policy)
        spent[0] += time.perf_counter() - t0
        spent[1] += time.process_time() - c0

    t0, c0 = time.perf_counter(), time.process_time()
    if cfg.algo == "vrs":
        policy, record = train_random_search(cfg, seed, env_id, timed)
    else:
        policy, record = train_sb3(cfg, seed, env_id, timed)
    record["train_seconds"] = time.perf_counter() - t0 - spent[0]
    record["train_cpu_seconds"] = time.process_time() - c0 - spent[1]
    if callback is not None and record["steps"] > last[0]:
        callback(record["steps"], policy)  # the learning curve ends at the final policy
    return policy, record
