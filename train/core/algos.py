"""One entry point for every benchmark algorithm: :func:`train_algo`."""

from __future__ import annotations

import gc
import multiprocessing
import time
from typing import Any

import numpy as np

from acld_gym.util.blas import one_blas_thread

from ..config import TrainConfig
from .evaluate import CurveCallback, validation_seeds
from .progress import Progress
from .sb3_train import train_sb3
from .search import train_random_search
from .threshold import ABSOLUTE_LEVEL, RestartRule

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


def _train_once(cfg: TrainConfig, seed: int, env_id: str, timed, progress) -> tuple[Any, dict]:
    if cfg.algo == "vrs":
        return train_random_search(cfg, seed, env_id, timed)
    return train_sb3(cfg, seed, env_id, timed, progress=progress)


def _run(
    cfg: TrainConfig,
    seed: int,
    env_id: str,
    callback: CurveCallback | None,
    child: bool = False,
    progress: Progress | None = None,
) -> tuple[Any, dict, dict]:
    """One run: ``(policy, record, times)``, ``record["curve"]`` its learning curve (ending
    at the run's last step), ``times`` the wall and CPU time of the curve's evaluations
    (``eval_seconds``, ``eval_cpu_seconds``) and the run's whole CPU time
    (``cpu_seconds``). ``child``: the run is a worker process's (the policy returned
    without its training state). ``progress``: the run's console lines (a line per
    learning-curve point, with its validation score, and per validation check; their
    time is off the training time, as the curve's). Either way the run has one BLAS
    thread, as in the command-line entry points: on some CPUs' kernels one thread and two
    round differently (an AMD EPYC with OpenBLAS's Haswell kernels: validation costs one
    ulp apart, and a training run amplifies that), so a run must not depend on its
    caller's setting."""
    times = {"eval_seconds": 0.0, "eval_cpu_seconds": 0.0}
    c0 = time.process_time()
    if progress is not None:
        progress.start()
    curve: list = []

    def timed(steps, policy):  # evaluation time is not training time
        w, c = time.perf_counter(), time.process_time()
        if callback is not None:
            curve.append({"steps": int(steps), **(callback(steps, policy) or {})})
        if progress is not None:
            progress.point(steps, policy, env_id)
        times["eval_seconds"] += time.perf_counter() - w
        times["eval_cpu_seconds"] += time.process_time() - c

    with one_blas_thread():
        policy, record = _train_once(cfg, seed, env_id, timed, progress)
        if callback is not None and (not curve or record["steps"] > curve[-1]["steps"]):
            timed(record["steps"], policy)  # the curve reaches the run's last step
    record["curve"] = curve
    if child and hasattr(policy, "portable"):
        policy = policy.portable()
    times["cpu_seconds"] = time.process_time() - c0
    return policy, record, times


def _children_cpu_seconds() -> float | None:
    """CPU time of this process's ended child processes (None where unknown)."""
    try:  # Unix only
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
        self,
        cfg: TrainConfig,
        seeds: list[int],
        env_id: str,
        callback,
        workers: int,
        progress: Progress | None = None,
    ) -> None:
        self.worker_cpu_seconds = 0.0
        n = len(seeds)
        self._progress = [
            None if progress is None else progress.for_run(k, n, cfg.timesteps) for k in range(n)
        ]
        self._outcomes = (
            (
                _run(cfg, s, env_id, callback, False, p)
                for s, p in zip(seeds, self._progress, strict=True)
            )
            if workers == 1
            else self._at_once(cfg, seeds, env_id, callback, workers)
        )

    def __iter__(self):
        return self._outcomes

    def close(self) -> None:
        self._outcomes.close()

    def _at_once(self, cfg: TrainConfig, seeds: list[int], env_id: str, callback, workers: int):
        before = _children_cpu_seconds()
        pool = multiprocessing.get_context("spawn").Pool(workers)
        reported, pending, p = 0.0, [], None
        try:
            pending = [
                pool.apply_async(_run, (cfg, s, env_id, callback, True, p))
                for s, p in zip(seeds, self._progress, strict=True)
            ]
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
    progress: Progress | None = None,
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
    cost is at most that, which is then the lowest: the threshold is resolved on
    ``env_id`` and the selection's own validation loads before the first run,
    :meth:`train.core.threshold.RestartRule.resolve`), with ``record["steps"]`` all
    runs' steps, ``record["curve"]`` the returned run's curve (its steps count from the
    start of that run: the curve is the training of the policy returned; the budget spent
    is ``record["steps"]``) and ``record["restarts"]``: each run's seed, chosen step, cost,
    curve and, for a run followed by another, ``"retried"``, the reason; ``"retries"``,
    those reasons; ``"threshold"`` and ``"rule"`` (how it was resolved).

    A retry is never silent: the threshold and each run's outcome (retried, returned, or
    the lowest returned when none met it) are said on the console through ``progress``
    (:meth:`train.core.progress.Progress.say`, whatever its ``quiet``; a plain one when
    None), which also gives a line per evaluation unless quiet.

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
    say = (progress or Progress(quiet=True)).say
    rule = RestartRule.parse(cfg.restart_above)
    resolved = None  # the threshold on this level's (and the selection's) validation loads
    if rule is not None:
        resolved = rule.resolve(env_id, validation_seeds(cfg.select_config.episodes))
        say(f"retry threshold {_threshold_text(resolved)}; up to {len(seeds)} runs")
    threshold = None if resolved is None else resolved["threshold"]
    t0, c0 = time.perf_counter(), time.process_time()
    best, runs, total = None, [], 0  # only the best run so far is kept alive (model, buffer)
    evals = [0.0, 0.0]  # the curve's evaluations (one process): wall and CPU time
    outcomes = _Runs(cfg, seeds, env_id, callback, workers, progress)
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
            if runs:
                _say_outcome(say, runs, k, len(seeds), threshold, resolved, best[0])
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
            record["restarts"]["rule"] = resolved
            record["restarts"]["retries"] = [r["retried"] for r in runs if "retried" in r]
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


def _threshold_text(resolved: dict) -> str:
    """``0.5250 (1.0299 * lqg: lqg's 0.5098 on 256 validation loads)``."""
    t = f"{resolved['threshold']:.4f}"
    if resolved["reference"] is None:
        return f"{t} (an absolute validation cost of {ABSOLUTE_LEVEL})"
    ref = resolved["reference"]
    return (
        f"{t} ({resolved['rule']}: {ref}'s {resolved['reference_cost']:.4f} on "
        f"{resolved['loads']} validation loads)"
    )


def _say_outcome(say, runs, k, n, threshold, resolved, best) -> None:
    """Say run ``k``'s outcome of ``n`` (its cost; retried, with the reason, which
    ``runs[k]["retried"]`` records; returned; or, the last above the threshold, the
    lowest returned)."""
    run, cost = runs[k], runs[k]["cost"]
    head = f"run {k + 1} of {'up to ' if threshold is not None else ''}{n} (seed {run['seed']})"
    if threshold is None:
        say(f"{head}: validation cost {cost:.4f}")
        if k + 1 == n:
            say(f"the lowest of the {n} runs returned: run {best + 1}")
    elif cost <= threshold:
        say(f"{head}: validation cost {cost:.4f}, at or below the threshold: returned")
    elif k + 1 < n:
        run["retried"] = (
            f"run {k + 1} (seed {run['seed']}): validation cost {cost:.4f} above the "
            f"threshold {_threshold_text(resolved)}"
        )
        say(f"retry: {run['retried']}; training run {k + 2}")
    else:
        say(
            f"{head}: validation cost {cost:.4f}, above the threshold too: none of the {n} "
            f"runs met it; the lowest returned, run {best + 1} ({runs[best]['cost']:.4f})"
        )
