"""Tests of acld_gym.physics.loads: the thesis's tip loads (ch. 5).

Provenance: thesis = /work/shared/seed/rodriguez-2006-acld-smc-lqr-thesis.txt ch. 5:
case 1 = 1 N pulse for 1 ms; case 2 = the same plus a second pulse at 0.1 s;
case 3 = 0.1 sin(179 t) N for 0.193 s (5.5 cycles).
"""

from __future__ import annotations

import numpy as np
import pytest
from numpy.testing import assert_allclose, assert_array_equal

from acld_gym.physics.loads import Harmonic, Pulse, TipLoad, thesis_load


def test_case1_values():
    f = thesis_load(1)
    assert f(0.0) == 1.0
    assert f(0.0005) == 1.0
    assert f(0.001) == 0.0  # left-closed interval: off at the end edge
    assert f(0.05) == 0.0
    assert_array_equal(f.breakpoints(), [0.0, 0.001])
    assert f.harmonic_frequencies == ()


def test_case2_second_pulse():
    f = thesis_load(2)
    assert_allclose(f(np.array([0.0, 0.0005, 0.001, 0.05, 0.1, 0.1005, 0.101, 0.2])),
                    [1, 1, 0, 0, 1, 1, 0, 0])
    assert_allclose(f.breakpoints(), [0.0, 0.001, 0.1, 0.101])


def test_case3_harmonic():
    f = thesis_load(3)
    t = np.linspace(0, 0.192, 500)
    assert_allclose(f(t), 0.1 * np.sin(179.0 * t), atol=1e-15)
    assert f(0.193) == 0.0
    assert np.all(f(np.linspace(0.1931, 1.0, 50)) == 0.0)
    assert_allclose(f.breakpoints(), [0.0, 0.193])
    assert f.harmonic_frequencies == (179.0,)
    # 0.193 s is about 5.5 cycles of 179 rad/s.
    assert 179.0 * 0.193 / (2 * np.pi) == pytest.approx(5.5, abs=0.01)


def _eval_piece(piece, t):
    return piece.const + sum(a * np.sin(w * t + ph) for a, w, ph in piece.harmonics)


@pytest.mark.parametrize("case", [1, 2, 3])
def test_piece_reproduces_load(case):
    f = thesis_load(case)
    edges = np.concatenate([f.breakpoints(), [1.0]])
    for t0, t1 in zip(edges[:-1], edges[1:], strict=True):
        p = f.piece(t0, t1)
        ts = np.linspace(t0, t1, 7)[:-1] + 1e-12
        for t in ts:
            assert _eval_piece(p, t) == pytest.approx(float(f(t)), abs=1e-12)


def test_piece_with_phase_and_offset_start():
    f = TipLoad((Harmonic(2.0, 50.0, 0.3, 0.2, phase=0.7), Pulse(0.35, 0.1, -1.5)))
    p = f.piece(0.35, 0.45)
    assert p.const == -1.5
    assert len(p.harmonics) == 1
    for t in (0.36, 0.4, 0.44):
        assert _eval_piece(p, t) == pytest.approx(float(f(t)), abs=1e-12)
        assert float(f(t)) == pytest.approx(2.0 * np.sin(50.0 * (t - 0.3) + 0.7) - 1.5)


@pytest.mark.parametrize("case", [0, 4, "1"])
def test_bad_case(case):
    with pytest.raises(ValueError, match="case"):
        thesis_load(case)


@pytest.mark.parametrize("dur", [0.0, -1e-3])
def test_pulse_bad_duration(dur):
    with pytest.raises(ValueError, match="duration"):
        Pulse(0.0, dur, 1.0)


def test_pulse_nonfinite():
    with pytest.raises(ValueError):
        Pulse(np.inf, 1e-3, 1.0)
    with pytest.raises(ValueError):
        Pulse(0.0, 1e-3, np.nan)


def test_harmonic_bad_args():
    with pytest.raises(ValueError, match="duration"):
        Harmonic(1.0, 10.0, 0.0, 0.0)
    with pytest.raises(ValueError, match="frequency"):
        Harmonic(1.0, 0.0, 0.0, 1.0)
