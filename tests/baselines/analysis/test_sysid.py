"""ERA (baselines.analysis.sysid) and the mode rule (baselines.analysis.modes) on synthetic
pulse responses whose modes are known exactly."""

import numpy as np
import pytest

from baselines.analysis.modes import (
    Mode,
    band_edges,
    poles_and_residues,
    select_modes,
    window_energy,
)
from baselines.analysis.sysid import EraRealization, identify, order_check

DT = 1e-3
W = np.array([200.0, 1000.0, 2500.0])
Z = np.array([0.01, 0.002, 0.05])


def pulse_response(w=W, zeta=Z, amp=(1.0, 0.3, 0.05), n=2000, real_pole=None):
    """h_k = sum_j Re(a_j z_j^k) for the sampled poles of (w, zeta), plus a real pole."""
    s = -zeta * w + 1j * w * np.sqrt(1 - zeta**2)
    z = np.exp(s * DT)
    k = np.arange(n)
    h = np.real((np.asarray(amp) * np.exp(1j * np.arange(len(w)))) @ (z[:, None] ** k))
    if real_pole is not None:
        h = h + real_pole[0] * real_pole[1] ** k
    return h


def test_era_recovers_known_modes_at_the_minimal_order():
    ident = identify(pulse_response(), DT)
    assert ident.order == 6 and ident.fit_error < 1e-9
    modes = ident.modes(band_edges(W, DT))
    for m, w, zeta in zip(modes, W, Z, strict=True):
        assert m.frequency_rad_s == pytest.approx(w, rel=1e-9)
        assert m.damping_ratio == pytest.approx(zeta, rel=1e-7)
    # noise-free data of order 6 have no seventh singular value above round-off: no check
    assert ident.check is None and order_check(ident, band_edges(W, DT))["check_order"] is None


def test_modes_do_not_depend_on_the_data_sign_or_scale():
    edges = band_edges(W, DT)
    a = identify(pulse_response(), DT).modes(edges)
    b = identify(-3e-4 * pulse_response(), DT).modes(edges)
    for x, y in zip(a, b, strict=True):
        assert x.frequency_rad_s == pytest.approx(y.frequency_rad_s, rel=1e-10)
        assert x.damping_ratio == pytest.approx(y.damping_ratio, rel=1e-8)


def test_a_weak_real_pole_takes_an_order_but_is_no_mode():
    h = pulse_response(real_pole=(0.5, 0.9))
    ident = identify(h, DT)
    assert ident.order == 7  # 6 oscillatory + 1 real
    modes = ident.modes(band_edges(W, DT))
    assert [round(m.frequency_rad_s) for m in modes] == [200, 1000, 2500]


def test_noise_floor_stops_the_order_before_round_off():
    rng = np.random.default_rng(0)
    h = pulse_response() + 1e-6 * rng.normal(size=2000)
    ident = identify(h, DT)
    assert 6 <= ident.order <= 20 and ident.fit_error < 1e-4
    m = ident.modes(band_edges(W, DT))
    assert m[0].damping_ratio == pytest.approx(Z[0], rel=1e-3)
    check = order_check(ident, band_edges(W, DT))
    assert check["check_order"] == ident.order + 4 and check["damping_change"] < 1e-2


def test_bad_data_is_refused():
    with pytest.raises(ValueError, match="pulse response"):
        EraRealization(np.zeros(100))
    with pytest.raises(ValueError, match="pulse response"):
        EraRealization(np.array([1.0, np.nan] * 10))
    with pytest.raises(ValueError, match="rows"):
        EraRealization(pulse_response(n=50), rows=49)
    with pytest.raises(ValueError, match="order"):
        EraRealization(pulse_response(n=200)).model(500)


# --- the mode rule ----------------------------------------------------------------------
def test_the_most_energetic_pole_of_each_band_is_its_mode():
    # two poles in band 1: the stronger one (larger residue) is the mode, not the nearer one
    z = np.exp(np.array([-2 + 190j, -1 + 205j, -5 + 1000j]) * DT)
    r = np.array([1.0, 0.1, 0.5])
    modes = select_modes(z, r, DT, band_edges([200.0, 1000.0], DT), 1000)
    assert modes[0].frequency_rad_s == pytest.approx(abs(-2 + 190j))
    assert modes[1].frequency_rad_s == pytest.approx(abs(-5 + 1000j))
    # an empty band gives None; a heavily damped pair is no mode
    heavy = np.exp(np.array([-600 + 1000j]) * DT)
    assert select_modes(heavy, np.ones(1), DT, band_edges([200.0, 1000.0], DT), 100) == [None, None]


def test_residues_do_not_depend_on_the_realization():
    rng = np.random.default_rng(1)
    A = np.diag([0.9, 0.5, -0.3]) + 0.05 * rng.normal(size=(3, 3))
    B, C = rng.normal(size=3), rng.normal(size=3)
    T = rng.normal(size=(3, 3))
    z1, r1 = poles_and_residues(A, B, C)
    z2, r2 = poles_and_residues(np.linalg.solve(T, A @ T), np.linalg.solve(T, B), C @ T)
    o1, o2 = np.argsort(z1), np.argsort(z2)
    np.testing.assert_allclose(z1[o1], z2[o2], rtol=1e-12)
    np.testing.assert_allclose(r1[o1], r2[o2], rtol=1e-9)
    h = [C @ np.linalg.matrix_power(A, k) @ B for k in range(5)]
    np.testing.assert_allclose(np.real(r1 @ (z1[:, None] ** np.arange(5))), h, atol=1e-12)


def test_mode_reading_and_window_energy():
    m = Mode.of_pole(np.exp((-3 + 400j) * DT), DT)
    assert m.frequency_rad_s == pytest.approx(abs(-3 + 400j))
    assert m.damping_ratio == pytest.approx(3 / abs(-3 + 400j))
    e = window_energy(np.array([1.0 + 0j, 0.5]), np.array([2.0, 1.0]), 10)
    np.testing.assert_allclose(e, [40.0, (1 - 0.25**10) / 0.75])
    edges = band_edges([1000.0, 100.0], DT)
    assert edges[0] == 0 and edges[1] == pytest.approx(np.sqrt(1e5))
    assert edges[-1] == pytest.approx(np.pi / DT)
    with pytest.raises(ValueError, match="frequencies"):
        band_edges([0.0], DT)
