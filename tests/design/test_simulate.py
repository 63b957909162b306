"""Tests of acld_gym.design.simulate: the exact piecewise-affine closed-loop simulator.

Provenance:
* thesis = /work/shared/seed/rodriguez-2006-acld-smc-lqr-thesis.txt ch. 5 (load case 1,
  120 V voltage limit, thesis observer).
* Independent references: exact zero-order-hold discretization of the passive plant
  (the case-1 load is piecewise constant on the 1e-4 s grid) with scipy.linalg.expm;
  a 100x finer sampling of the same simulator; scipy's Radau (slow test).
"""

from __future__ import annotations

import numpy as np
import pytest
import scipy.linalg as sla
from numpy.testing import assert_allclose

from acld_gym.design.pipeline import design
from acld_gym.design.simulate import ClosedLoop, simulate
from acld_gym.physics.loads import thesis_load


@pytest.fixture(scope="module")
def d():
    return design()


@pytest.fixture(scope="module")
def sim(d):
    A, B, E, Cy = d.plant
    obs = d.observer("thesis")

    def run(fb, load=1, **kw):
        return simulate(A, B, E, Cy, obs, fb, thesis_load(load), **kw)

    return run


def _zoh_passive(A, E, Cy, dt, nsteps, f):
    """Exact discretization of x' = A x + E f(t) for f constant on each step."""
    _, (dd, _) = sla.matrix_balance(A, permute=False, separate=True)
    As = A * dd[None, :] / dd[:, None]
    Es = E / dd[:, None]
    n = A.shape[0]
    M = np.zeros((n + 1, n + 1))
    M[:n, :n] = As * dt
    M[:n, n] = Es[:, 0] * dt
    Phi = sla.expm(M)
    Ad, Ed = Phi[:n, :n], Phi[:n, n]
    xs = np.zeros(n)
    y = [0.0]
    Cs = Cy[0] * dd
    for k in range(nsteps):
        xs = Ad @ xs + Ed * f[k]
        y.append(Cs @ xs)
    return np.array(y)


def test_passive_matches_exact_zoh(d, sim):
    A, _, E, Cy = d.plant
    dt, t_end = 1e-4, 0.05
    res = sim(d.passive, t_end=t_end, v_max=None, dt=dt)
    n = int(round(t_end / dt))
    assert res.t.size == n + 1
    f = thesis_load(1)(np.arange(n) * dt + 0.5 * dt)
    y_ref = _zoh_passive(A, E, Cy, dt, n, f)
    pk = np.max(np.abs(y_ref))
    assert pk > 1e-4  # ~0.675 mm
    assert np.max(np.abs(res.y - y_ref)) / pk < 1e-6
    assert np.all(res.voltage == 0.0)
    assert_allclose(res.load, thesis_load(1)(res.t))


@pytest.mark.parametrize("ctrl,tol", [("lqr", 1e-5), ("smc", 1e-3)])
def test_saturated_accuracy_vs_fine_sampling(d, sim, ctrl, tol):
    # Measured: LQR ~3e-7, SMC ~2.3e-4 (region switches located on the 24 ns grid).
    fb = d.feedback(ctrl)
    r1 = sim(fb, t_end=0.03, v_max=120.0)
    r2 = sim(fb, t_end=0.03, v_max=120.0, dt=1e-6, refine=12)
    idx = np.searchsorted(r2.t, r1.t - 1e-13)
    assert_allclose(r2.t[idx], r1.t, atol=1e-12)
    err = np.max(np.abs(r1.y - r2.y[idx])) / np.max(np.abs(r2.y))
    assert err < tol


@pytest.mark.slow
def test_lqr_saturated_vs_radau(d):
    from scipy.integrate import solve_ivp

    A, B, E, Cy = d.plant
    obs = d.observer("thesis")
    loop = ClosedLoop(A, B, E, Cy, obs, d.lqr, 120.0)

    def F(z):
        return loop.F0 + np.outer(loop.bu, loop.voltage_row(loop.region(z)))

    def rhs(t, z):
        return F(z) @ z

    def jac(t, z):
        return F(z)

    z0 = np.zeros(loop.N)
    z0[loop.ix_one] = 1.0
    z0[loop.ix_c] = 1.0  # load on during [0, 1e-3)
    t_end = 0.01
    t1 = np.linspace(0, 1e-3, 11)
    s1 = solve_ivp(rhs, (0, 1e-3), z0, method="Radau", jac=jac, rtol=1e-9, atol=1e-14, t_eval=t1)
    z = s1.y[:, -1].copy()
    z[loop.ix_c] = 0.0
    t2 = np.linspace(1e-3, t_end, 91)
    s2 = solve_ivp(rhs, (1e-3, t_end), z, method="Radau", jac=jac, rtol=1e-9, atol=1e-14, t_eval=t2)
    assert s1.success and s2.success
    y_ref = np.concatenate([s1.y[loop.ix_x].T @ loop.Cy, (s2.y[loop.ix_x].T @ loop.Cy)[1:]])
    res = loop.run(thesis_load(1), t_end)
    # The sample at t = 1e-3 is the state at that time (continuous), fine to compare.
    err = np.max(np.abs(res.y - y_ref)) / np.max(np.abs(y_ref))
    assert err < 1e-5


def test_saturation_respected(d, sim):
    sat = sim(d.lqr, t_end=0.02, v_max=120.0)
    assert np.max(np.abs(sat.voltage)) <= 120.0 + 1e-9
    assert np.max(np.abs(sat.voltage)) == pytest.approx(120.0)
    free = sim(d.lqr, t_end=0.02, v_max=None)
    assert np.max(np.abs(free.voltage)) > 120.0
    smc = sim(d.smc, load=3, t_end=0.02, v_max=120.0)
    assert np.max(np.abs(smc.voltage)) <= 120.0 + 1e-9
    # Voltage is the law applied to the recorded estimate.
    assert_allclose(sat.voltage, d.lqr.voltage(sat.xr, 120.0))


def test_unsaturated_lqr_loop_is_stiff(d):
    # The module docstring's claim: poles near -1e7 1/s (measured ~-1.3e7).
    A, B, E, Cy = d.plant
    loop = ClosedLoop(A, B, E, Cy, d.observer("thesis"), d.lqr, None)
    F = loop.F0 + np.outer(loop.bu, loop.voltage_row((0, 0)))
    ev = np.linalg.eigvals(F)
    assert np.min(ev.real) < -1e6
    # And the loop is stable apart from the constant-1 and load-hold states (eig 0).
    assert np.sum(np.abs(ev) < 1e-6) == 2
    assert np.max(ev.real[np.abs(ev) >= 1e-6]) < 0


def test_harmonic_load_loop_dimension(d):
    A, B, E, Cy = d.plant
    loop = ClosedLoop(A, B, E, Cy, d.observer("kalman"), d.lqr, 120.0, (179.0,))
    assert loop.N == 38 + 6 + 1 + 2 + 1


@pytest.mark.parametrize(
    "kw", [{"t_end": 0.0}, {"t_end": -1.0}, {"v_max": 0.0}, {"v_max": -120.0}, {"dt": 0.0}]
)
def test_bad_args(d, sim, kw):
    args = {"t_end": 0.01, "v_max": 120.0} | kw
    with pytest.raises(ValueError):
        sim(d.lqr, **args)


def test_discrete_observer_rejected(d):
    from acld_gym.design.discrete import discretize
    from acld_gym.design.observer import discrete_kalman

    A, B, E, Cy = d.plant
    r = d.reduced
    sd = discretize(r.A, r.B, r.E, 1e-3)
    obs = discrete_kalman(sd.Ad, sd.Bd, sd.Ed, r.C)
    with pytest.raises(ValueError, match="observer"):
        simulate(A, B, E, Cy, obs, d.lqr, thesis_load(1), t_end=0.01)
