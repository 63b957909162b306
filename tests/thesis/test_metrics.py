"""Tests of acld_gym.thesis.metrics: Table 2's peak and settling time (5% band), and ISE.

Provenance: the module docstrings (settling = last time |y| is outside 5% of its peak)
and analytic results for synthetic signals.
"""

from __future__ import annotations

import numpy as np
import pytest

from acld_gym.thesis.metrics import ise, max_abs, peak, settling_time


def test_peak_and_max_abs():
    y = np.array([0.1, -0.7, 0.5])
    assert peak(y) == 0.7
    assert max_abs(y) == 0.7


def test_settling_time_decaying_sinusoid():
    # y = e^{-a t} cos(w t): |y| <= e^{-a t}, so the last exit from the 5% band lies
    # just before t* = ln(20)/a, at the last extremum of |cos| that still exceeds it.
    a, w = 5.0, 2 * np.pi * 50.0
    dt = 1e-5
    t = np.arange(0.0, 1.5, dt)
    y = np.exp(-a * t) * np.cos(w * t)
    ts = settling_time(t, y)
    # Analytic: the last crossing of |y| = 0.05 (peak is y(0) = 1).
    tf = np.arange(0.0, 1.5, 1e-7)
    yf = np.abs(np.exp(-a * tf) * np.cos(w * tf))
    t_last = tf[np.flatnonzero(yf > 0.05)[-1]]
    assert abs(ts - t_last) <= dt
    assert ts < np.log(20) / a
    assert ts > np.log(20) / a - 1 / 50.0  # within one period of the envelope crossing


def test_settling_time_band_argument():
    t = np.linspace(0, 1, 101)
    y = np.exp(-t * 3)
    assert settling_time(t, y, band=0.5) == pytest.approx(t[t < np.log(2) / 3][-1])


def test_settling_time_unsettled_returns_last_sample():
    t = np.linspace(0, 1, 11)
    assert settling_time(t, np.ones(11)) == 1.0


def test_zero_response():
    t = np.linspace(0, 1, 11)
    z = np.zeros(11)
    assert settling_time(t, z) == 0.0
    assert peak(z) == 0.0
    assert ise(t, z) == 0.0


def test_ise_constant():
    t = np.linspace(0, 2, 201)
    assert ise(t, np.full(201, 3.0)) == pytest.approx(18.0, rel=1e-12)
    # Nonuniform spacing.
    t2 = np.array([0.0, 0.5, 2.0])
    assert ise(t2, np.array([1.0, 2.0, 2.0])) == pytest.approx(4 * 0.5 + 4 * 1.5)
