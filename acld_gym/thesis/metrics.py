"""Response metrics used in the thesis's Table 2 and the benchmark tables."""

from __future__ import annotations

import numpy as np

__all__ = ["peak", "settling_time", "ise", "max_abs"]


def peak(y: np.ndarray) -> float:
    """Maximum |y| (same unit as y)."""
    return float(np.max(np.abs(y)))


def settling_time(t: np.ndarray, y: np.ndarray, band: float = 0.05) -> float:
    """Last time |y| is outside ``band`` times its peak [s].

    Zero for an identically zero response. A response still outside the band
    at the last sample returns ``t[-1]`` (not settled within the window).
    """
    a = np.abs(np.asarray(y))
    pk = a.max()
    if pk == 0.0:
        return 0.0
    out = np.flatnonzero(a > band * pk)
    return float(t[out[-1]])


def ise(t: np.ndarray, y: np.ndarray) -> float:
    """Integral of y^2 over the samples, rectangle rule on the sample spacing [m^2 s]."""
    dt = np.diff(t)
    return float(np.sum(np.asarray(y)[1:] ** 2 * dt))


def max_abs(v: np.ndarray) -> float:
    """Maximum |v|."""
    return float(np.max(np.abs(v)))
