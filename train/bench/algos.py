"""One entry point for every benchmark algorithm: :func:`train_algo`."""

from __future__ import annotations

import time
from typing import Any

import numpy as np

from ..config import TrainConfig
from .evaluate import CurveCallback, lqr_validation_cost, validation_seeds
from .sb3_train import train_sb3
from .search import train_random_search

__all__ = ["restart_seeds", "train_algo"]


def restart_seeds(seed: int, restarts: int) -> list[int]:
    """The seeds of a trial's ``restarts`` runs: ``seed`` itself first (one run is the
    plain recipe), then 32-bit seeds drawn from ``numpy.random.SeedSequence((seed, k))``,
    which no other trial's seed list shares by construction (``seed + k`` would make
    seed 0's second run seed 1's first)."""
    derived = [
        int(np.random.SeedSequence((seed, k)).generate_state(1)[0]) for k in range(1, restarts)
    ]
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

    ``callback(steps, policy)`` evaluates the policy a run has at ``steps`` env steps of
    that run; its value (a mapping, or None) is a point of the learning curve, and
    ``record["curve"]`` is the list of ``{"steps": steps, **point}``, ending at the run's
    last step (where a run selects a checkpoint, the policy returned is that check's).

    With ``cfg.restarts`` > 1 the runs follow one another (seeds :func:`restart_seeds`);
    the policy and record returned are those of the run whose selected check has the
    lowest validation cost (with ``cfg.restart_above``, the runs stop at the first whose
    cost is at most that, which is then the lowest; ``"lqr"``: LQR's cost on the same
    validation loads, ``record["restarts"]["threshold"]``), with ``record["steps"]`` all runs'
    steps, ``record["curve"]`` the returned run's curve (its steps count from the start of
    that run: the curve is the training of the policy returned; the budget spent is
    ``record["steps"]``) and ``record["restarts"]`` each run's seed, chosen step, cost and
    curve."""
    spent = [0.0, 0.0]
    curve: list = []  # the current run's

    def timed(steps, policy):  # evaluation time is not training time
        t0, c0 = time.perf_counter(), time.process_time()
        if callback is not None:
            curve.append({"steps": int(steps), **(callback(steps, policy) or {})})
        spent[0] += time.perf_counter() - t0
        spent[1] += time.process_time() - c0

    t0, c0 = time.perf_counter(), time.process_time()
    best, runs, total = None, [], 0  # only the best run so far is kept alive (model, buffer)
    threshold = cfg.restart_above
    if threshold == "lqr":  # the level to beat, on the selection's own validation loads
        seeds = validation_seeds(cfg.select_config.episodes)
        threshold = lqr_validation_cost(env_id, seeds)
    for k, run_seed in enumerate(restart_seeds(seed, cfg.restarts)):
        curve = []
        policy, record = _train_once(cfg, run_seed, env_id, timed)
        if callback is not None and (not curve or record["steps"] > curve[-1]["steps"]):
            timed(record["steps"], policy)  # the curve reaches the run's last step
        record["curve"] = curve
        total += record["steps"]
        if cfg.restarts > 1:
            sel = record["select"]
            runs.append(
                {"seed": run_seed, "steps": sel["steps"], "cost": sel["cost"], "curve": curve}
            )
        if best is None or (runs and runs[-1]["cost"] < runs[best[0]]["cost"]):
            best = (k, policy, record)  # the first of equal costs is kept
        policy = record = None
        if threshold is not None and runs[-1]["cost"] <= threshold:
            break  # a good enough run: no more restarts
    chosen, policy, record = best
    if runs:
        record["steps"] = total
        record["restarts"] = {"chosen": chosen, "runs": runs}
        if threshold is not None:
            record["restarts"]["threshold"] = threshold
    record["train_seconds"] = time.perf_counter() - t0 - spent[0]
    record["train_cpu_seconds"] = time.process_time() - c0 - spent[1]
    return policy, record
