"""acld_gym.util.stats: the IQM and its bootstrap interval, shared by the benchmark and the
score (the benchmark's own checks against scipy are in tests/train/test_benchmark.py)."""

import numpy as np
import pytest

import train.core.stats as bench_stats
from acld_gym.util import stats


def test_the_benchmark_imports_the_same_functions():
    for name in ("iqm", "iqm_with_ci", "stratified_bootstrap_ci"):
        assert getattr(bench_stats, name) is getattr(stats, name)


def test_interval_shrinks_as_episodes_are_added():
    rng = np.random.default_rng(0)
    x = rng.normal(0.3, 1.0, 1600)
    widths = []
    for n in (25, 100, 400, 1600):
        lo, hi = stats.stratified_bootstrap_ci(x[:n], reps=1000)
        assert lo <= stats.iqm(x[:n]) <= hi
        widths.append(hi - lo)
    assert all(b < a for a, b in zip(widths, widths[1:], strict=False))
    # about 1 / sqrt(n): sixteen times the episodes, a quarter of the width
    assert widths[-1] / widths[1] == pytest.approx(0.25, rel=0.2)


def test_iqm_ignores_the_tails():
    x = np.arange(8.0)  # drops 0, 1 and 6, 7
    assert stats.iqm(np.append(x[:6], [1e9, 1e9])) == pytest.approx(np.mean(x[2:6]))
    with pytest.raises(ValueError, match="no scores"):
        stats.iqm([])
