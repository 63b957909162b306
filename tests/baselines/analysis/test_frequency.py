"""Multisine, frequency response and peaks (baselines.analysis.frequency), and the compliance
test through the env against the exact loop's response."""

import numpy as np
import pytest

from baselines.analysis.compliance import compliance_test
from baselines.analysis.excitation import PulseSuperposition
from baselines.analysis.frequency import (
    band_peak,
    frequency_response,
    multisine,
    transient_residual,
)
from baselines.analysis.linear import ObserverLoop, small_signal_law
from baselines.policies import LQRPolicy

DT = 1e-3


def test_multisine_excites_exactly_its_lines_at_unit_rms():
    ms = multisine(DT, resolution=2.0)
    x = ms.period()
    assert ms.n_period == round(2 * np.pi / (2.0 * DT))
    assert np.sqrt(np.mean(x**2)) == pytest.approx(1.0)
    X = np.abs(np.fft.rfft(x))
    on = np.zeros(X.size, bool)
    on[ms.bins] = True
    assert X[~on].max() < 1e-9 * X[on].min()
    assert np.ptp(X[on]) < 1e-9 * X[on].max()  # a flat spectrum
    assert ms.frequencies[0] >= 20.0 and ms.frequencies[-1] <= 0.98 * np.pi / DT
    assert np.max(np.abs(x)) < 4.0  # Schroeder's phases: a low crest factor


def test_frequency_response_of_a_known_filter():
    """y_k = sum_{m<k} f_m a^{k-1-m} has H(z) = 1 / (z - a)."""
    ms = multisine(DT, resolution=5.0)
    f = ms.signal(1.0, periods=3)
    y = np.zeros(f.size + 1)
    for k in range(f.size):
        y[k + 1] = 0.9 * y[k] + f[k]
    H = frequency_response(ms, f, y)
    z = np.exp(1j * ms.frequencies * DT)
    np.testing.assert_allclose(H, 1 / (z - 0.9), rtol=1e-9)


@pytest.mark.parametrize("offset", [0.0, 0.27, 0.5])
def test_band_peak_reads_a_resonance_between_lines(offset):
    w0, zeta, step = 1000.0, 0.002, 0.5
    w = w0 + step * (np.arange(-40, 41) + offset)
    H = 1.0 / (w0**2 - w**2 + 2j * zeta * w0 * w)
    exact = 1.0 / (2 * zeta * w0**2 * np.sqrt(1 - zeta**2))
    peak, where = band_peak(w, H, 900, 1100)
    assert peak == pytest.approx(exact, rel=2e-4)
    assert where == pytest.approx(w0 * np.sqrt(1 - 2 * zeta**2), abs=0.01)
    if offset == 0.5:  # the largest line alone is low by 1 / sqrt(1 + (0.25 / 2)^2)
        assert np.abs(H).max() < 0.993 * exact
    with pytest.raises(ValueError, match="no line"):
        band_peak(w, H, 10, 20)


def test_transient_residual():
    ms = multisine(DT, resolution=0.5)
    assert transient_residual([1.15], ms) == pytest.approx(np.exp(-1.15 * ms.n_period * DT))
    assert transient_residual([], ms) == 0.0


@pytest.fixture(scope="module")
def measured(passive):
    """The compliance test of LQR through the env, 1 rad/s lines (a shorter run)."""
    ms = multisine(DT, resolution=1.0)
    frig = PulseSuperposition(n_steps=2 * ms.n_period)
    test = compliance_test(LQRPolicy(), frig, ms, passive[1], 120.0, 0.0, [10.0])
    return test, frig


def test_measured_compliance_is_the_exact_loops(measured):
    test, frig = measured
    assert test.valid and test.max_voltage_V < 120
    loop = ObserverLoop.from_env(frig.env)
    law, _ = small_signal_law(LQRPolicy(), 9, 120.0)
    # the passive beam's transient left after one 6.3 s period: exp(-1.15 1/s * 6.3 s), 7e-4
    np.testing.assert_allclose(test.passive, loop.compliance(None, test.omega), rtol=1e-3)
    exact = loop.compliance(law, test.omega)
    err = np.abs(test.closed - exact) / np.abs(exact)
    assert np.median(err) < 3e-3  # the basis's residual noise
    for peaks, which in ((test.passive_peaks, None), (test.closed_peaks, law)):
        for p, w in peaks:  # the exact peak, on a fine grid about the measured one
            wd = np.linspace(w - 10.0, w + 10.0, 4001)
            h = np.abs(loop.compliance(which, wd))
            assert 0 < np.argmax(h) < wd.size - 1  # the exact peak itself, not an edge
            assert p == pytest.approx(h.max(), rel=0.01)


def test_lqr_lowers_every_peak(measured):
    drops = measured[0].peak_reduction_db
    assert drops[0] > 10 and drops[1] > 1 and drops[2] > 10
