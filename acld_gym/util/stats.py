"""Aggregate statistics of the RL benchmark (``train.core``) and of the policy score
(:mod:`baselines.evaluation.score`): the interquartile mean (IQM) and 95 %
stratified-bootstrap confidence intervals (Agarwal et al. 2021, as ``rliable`` 1.2.0
computes them: IQM = 25 %-trimmed mean of all run x task scores; the bootstrap
resamples the runs with replacement within each task; percentile interval)."""

from __future__ import annotations

import numpy as np

__all__ = ["iqm", "stratified_bootstrap_ci", "iqm_with_ci"]


def iqm(scores) -> float:
    """Interquartile mean: the mean of the sorted scores after dropping
    ``floor(n / 4)`` from each end (``scipy.stats.trim_mean(x, 0.25)``), all
    entries of ``scores`` pooled."""
    x = np.sort(np.asarray(scores, dtype=np.float64).ravel())
    if x.size == 0:
        raise ValueError("iqm of no scores")
    k = int(0.25 * x.size)
    return float(x[k : x.size - k].mean())


def stratified_bootstrap_ci(
    scores, statistic=iqm, reps: int = 2000, confidence: float = 0.95, seed: int = 0
) -> tuple[float, float]:
    """Percentile confidence interval of ``statistic`` over a (runs, tasks) score
    matrix (a 1-D array is one task): each replicate draws, for every task
    independently, as many runs as there are with replacement.

    Parameters
    ----------
    scores : array_like, shape (n_runs,) or (n_runs, n_tasks)
        One score per run (seed) and task (load case).
    statistic : callable
        Aggregate of a (n_runs, n_tasks) matrix (default :func:`iqm`).
    reps : int
        Bootstrap replicates.
    confidence : float
        Coverage of the interval (0.95: the 2.5 and 97.5 percentiles).
    seed : int
        Seed of the resampling.

    Returns
    -------
    low : float
        The interval's lower end: the ``(1 - confidence) / 2`` quantile of the replicates'
        statistic (the score's units).
    high : float
        Its upper end, the ``(1 + confidence) / 2`` quantile; the pair is returned as a
        tuple ``(low, high)``.
    """
    x = np.asarray(scores, dtype=np.float64)
    if x.ndim == 1:
        x = x[:, None]
    if x.ndim != 2 or x.shape[0] < 1:
        raise ValueError(f"scores must be (runs,) or (runs, tasks), got shape {x.shape}")
    rng = np.random.default_rng(seed)
    n, m = x.shape
    idx = rng.integers(0, n, size=(reps, n, m))  # per replicate and task: runs drawn
    samples = np.take_along_axis(np.broadcast_to(x, (reps, n, m)), idx, axis=1)
    stats = np.array([statistic(s) for s in samples])
    tail = 100.0 * (1.0 - confidence) / 2.0
    lo, hi = np.percentile(stats, [tail, 100.0 - tail])
    return float(lo), float(hi)


def iqm_with_ci(scores, reps: int = 2000, seed: int = 0) -> dict:
    """``{"iqm", "ci_low", "ci_high", "n"}`` of a (runs,) or (runs, tasks) score array."""
    x = np.asarray(scores, dtype=np.float64)
    lo, hi = stratified_bootstrap_ci(x, iqm, reps=reps, seed=seed)
    return {"iqm": iqm(x), "ci_low": lo, "ci_high": hi, "n": int(x.shape[0])}
