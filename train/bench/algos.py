"""One entry point for every benchmark algorithm: :func:`train_algo`."""

from __future__ import annotations

import gc
import time
from typing import Any

import numpy as np

from acld_gym.util.blas import one_blas_thread

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


def _run(
    cfg: TrainConfig,
    seed: int,
    env_id: str,
    callback: CurveCallback | None,
    child: bool = False,
) -> tuple[Any, dict, dict]:
    """One run: ``(policy, record, times)``, ``record["curve"]`` its learning curve (ending
    at the run's last step), ``times`` the wall and CPU time of the curve's evaluations
    (``eval_seconds``, ``eval_cpu_seconds``) and the run's whole CPU time
    (``cpu_seconds``). ``child``: the run is a worker process's (the policy returned
    without its training state). Either way the run has one BLAS thread, as in the
    command-line entry points: on some CPUs' kernels one thread and two round differently
    (an AMD EPYC with OpenBLAS's Haswell kernels: validation costs one ulp apart, and a
    training run amplifies that), so a run must not depend on its caller's setting."""
    times = {"eval_seconds": 0.0, "eval_cpu_seconds": 0.0}
    c0 = time.process_time()
    curve: list = []

    def timed(steps, policy):  # evaluation time is not training time
        w, c = time.perf_counter(), time.process_time()
        if callback is not None:
            curve.append({"steps": int(steps), **(callback(steps, policy) or {})})
        times["eval_seconds"] += time.perf_counter() - w
        times["eval_cpu_seconds"] += time.process_time() - c

    with one_blas_thread():
        policy, record = _train_once(cfg, seed, env_id, timed)
        if callback is not None and (not curve or record["steps"] > curve[-1]["steps"]):
            timed(record["steps"], policy)  # the curve reaches the run's last step
    record["curve"] = curve
    if child and hasattr(policy, "portable"):
        policy = policy.portable()
    times["cpu_seconds"] = time.process_time() - c0
    return policy, record, times


def _children_cpu_seconds() -> float | None:
    """CPU time of this process's ended child processes (None where unknown)."""
    try:
        import resource
    except ImportError:  # pragma: no cover - not on Unix
        return None
    ru = resource.getrusage(resource.RUSAGE_CHILDREN)
    return ru.ru_utime + ru.ru_stime


class _Runs:
    """The runs of ``seeds`` as :func:`_run` returns them, in order, as an iterator: one
    after the other in this process (``workers`` 1), or up to ``workers`` at once in
    worker processes, each run started as soon as a worker is free. The caller stops when
    it has what it needs and calls :meth:`close`, which ends the runs still going; then
    :attr:`worker_cpu_seconds` is the workers' CPU time, the unused runs' included (0 with
    one worker: the runs' CPU time is this process's)."""

    def __init__(
        self, cfg: TrainConfig, seeds: list[int], env_id: str, callback, workers: int
    ) -> None:
        self.worker_cpu_seconds = 0.0
        self._outcomes = (
            (_run(cfg, s, env_id, callback) for s in seeds)
            if workers == 1
            else self._at_once(cfg, seeds, env_id, callback, workers)
        )

    def __iter__(self):
        return self._outcomes

    def close(self) -> None:
        self._outcomes.close()

    def _at_once(self, cfg: TrainConfig, seeds: list[int], env_id: str, callback, workers: int):
        import multiprocessing

        before = _children_cpu_seconds()
        pool = multiprocessing.get_context("spawn").Pool(workers)
        reported, pending, p = 0.0, [], None
        try:
            pending = [pool.apply_async(_run, (cfg, s, env_id, callback, True)) for s in seeds]
            for p in pending:
                out = p.get()
                reported += out[2]["cpu_seconds"]
                yield out
        finally:
            pool.terminate()
            pool.join()
            after = _children_cpu_seconds()
            self.worker_cpu_seconds += (
                reported if before is None or after is None else after - before
            )
            # release the pool's semaphores now, while this process's resource tracker
            # runs: a Ray Tune trial's process outlives its tracker (Ray ends a trial's
            # children), and semaphores collected at its exit made the tracker relaunch
            # and print a KeyError traceback for each
            del pending, p, pool  # (a pending result holds its pool)
            gc.collect()


def train_algo(
    cfg: TrainConfig,
    seed: int,
    env_id: str,
    callback: CurveCallback | None = None,
    workers: int = 1,
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
    curve.

    ``workers`` > 1 trains up to that many of the runs at once, in worker processes
    (``spawn``; ``callback`` must then pickle), the next starting as soon as one ends. The
    runs are the same and are taken in the same order, so the policy and record are those
    of ``workers=1`` (``record["restarts"]["workers"]`` says how many ran at once); only
    the time changes. A run started ahead but not needed (an earlier one met
    ``restart_above``) is ended and counts in neither the steps nor the runs, but in the
    CPU time, which is all the workers'. The learning curve's evaluations then overlap
    training in other processes and are not taken off the wall time (an upper bound);
    the CPU time is the workers' whole."""
    if isinstance(workers, bool) or not isinstance(workers, int) or workers < 1:
        raise ValueError(f"workers must be a positive integer, got {workers!r}")
    seeds = restart_seeds(seed, cfg.restarts)
    workers = min(workers, len(seeds))
    t0, c0 = time.perf_counter(), time.process_time()
    best, runs, total = None, [], 0  # only the best run so far is kept alive (model, buffer)
    evals = [0.0, 0.0]  # the curve's evaluations (one process): wall and CPU time
    threshold = cfg.restart_above
    if threshold == "lqr":  # the level to beat, on the selection's own validation loads
        threshold = lqr_validation_cost(env_id, validation_seeds(cfg.select_config.episodes))
    outcomes = _Runs(cfg, seeds, env_id, callback, workers)
    try:
        for k, (policy, record, times) in enumerate(outcomes):
            evals[0] += times["eval_seconds"]
            evals[1] += times["eval_cpu_seconds"]
            total += record["steps"]
            if cfg.restarts > 1:
                sel = record["select"]
                runs.append(
                    {
                        "seed": seeds[k],
                        "steps": sel["steps"],
                        "cost": sel["cost"],
                        "curve": record["curve"],
                    }
                )
            if best is None or (runs and runs[-1]["cost"] < runs[best[0]]["cost"]):
                best = (k, policy, record)  # the first of equal costs is kept
            policy = record = None
            if threshold is not None and runs[-1]["cost"] <= threshold:
                break  # a good enough run: no more restarts
    finally:
        outcomes.close()  # ends the runs started ahead (workers > 1)
    chosen, policy, record = best
    if runs:
        record["steps"] = total
        record["restarts"] = {"chosen": chosen, "runs": runs}
        if threshold is not None:
            record["restarts"]["threshold"] = threshold
        if workers > 1:
            record["restarts"]["workers"] = workers
    wall, own_cpu = time.perf_counter() - t0, time.process_time() - c0
    if workers == 1:  # everything ran here: the times less the evaluations'
        record["train_seconds"] = wall - evals[0]
        record["train_cpu_seconds"] = own_cpu - evals[1]
    else:  # the evaluations overlapped other runs' training: kept in, an upper bound
        record["train_seconds"] = wall
        record["train_cpu_seconds"] = own_cpu + outcomes.worker_cpu_seconds
    return policy, record
