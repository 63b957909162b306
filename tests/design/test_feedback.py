"""Tests of acld_gym.design.feedback: LQR (thesis eqs. 65-67) and SMC (eqs. 68-72).

Provenance:
* thesis = /work/shared/seed/rodriguez-2006-acld-smc-lqr-thesis.txt ch. 4 and Table 1:
  LQR weight Q = 1e11 S_R^T S_R, R = 1; sliding surface s = LQR gain for Q = 1e6;
  equivalent control -(sB)^-1 sA x_r; switching gain eta = 1.5 |(sB)^-1 s S_L^T B_hat|.
* Independent LQR: python-control ``control.lqr`` (with scipy's CARE as fallback).
"""

from __future__ import annotations

import numpy as np
import pytest
import scipy.linalg as sla
from numpy.testing import assert_allclose

from acld_gym.design.feedback import THESIS_LQR_WEIGHT, lqr, passive, smc
from acld_gym.design.pipeline import design
from acld_gym.design.reduction import ReducedModel


@pytest.fixture(scope="module")
def d():
    return design()


def _transformed(r: ReducedModel, T: np.ndarray) -> ReducedModel:
    Ti = np.linalg.inv(T)
    return ReducedModel(
        A=T @ r.A @ Ti, B=T @ r.B, C=r.C @ Ti, E=T @ r.E, SL=r.SL @ T.T, SR=r.SR @ Ti, hsv=r.hsv
    )


def test_lqr_closed_loop_stable(d):
    r = d.reduced
    K = d.lqr.a
    assert d.lqr.c == 0.0 and not np.any(d.lqr.s)
    assert np.max(np.linalg.eigvals(r.A - np.outer(r.B[:, 0], K)).real) < 0


def test_lqr_gain_matches_independent_solution(d):
    r = d.reduced
    Q = THESIS_LQR_WEIGHT * r.SR.T @ r.SR
    Q = 0.5 * (Q + Q.T)
    try:
        import control

        K_ref, _, _ = control.lqr(r.A, r.B, Q, np.eye(1))
        K_ref = np.asarray(K_ref)[0]
    except Exception:  # pragma: no cover - fallback if python-control is unavailable
        X = sla.solve_continuous_are(r.A, r.B, Q, np.eye(1))
        K_ref = (r.B.T @ X)[0]
    assert_allclose(d.lqr.a, K_ref, rtol=1e-5)


def test_lqr_basis_invariance(d):
    r = d.reduced
    rng = np.random.default_rng(2)
    T = rng.standard_normal((r.order, r.order)) + 3 * np.eye(r.order)
    assert abs(np.linalg.det(T)) > 1e-3
    r2 = _transformed(r, T)
    # The feedback on the full state, -K S_L^T x, must not depend on the basis.
    assert_allclose(lqr(r2).a @ T, d.lqr.a, rtol=1e-5, atol=1e-8 * np.abs(d.lqr.a).max())
    f2 = smc(r2)
    f1 = d.smc
    assert_allclose(f2.s @ T, f1.s, rtol=1e-5, atol=1e-8 * np.abs(f1.s).max())
    assert_allclose(f2.a @ T, f1.a, rtol=1e-5, atol=1e-8 * np.abs(f1.a).max())
    assert f2.c == pytest.approx(f1.c, rel=1e-6)


def test_smc_gains_match_formulas(d):
    r = d.reduced
    f = d.smc
    # Sliding surface = LQR gain at Q = 1e6 (Table 1).
    assert_allclose(f.s, lqr(r, weight=1e6).a)
    sb = float(f.s @ r.B[:, 0])
    assert_allclose(f.a, (f.s @ r.A) / sb)
    eta = 1.5 * abs(float(f.s @ r.E[:, 0]) / sb)
    assert abs(f.c) == pytest.approx(eta, rel=1e-12)
    assert np.sign(f.c) == np.sign(sb)
    assert f.eps == 1.0


def test_smc_reaching_condition(d):
    # Outside the boundary layer (|sigma| > eps) with E = 0:
    # sigma_dot = s A x - sb (s A x / sb) - sb c sign(sigma) = -sb c sign(sigma),
    # and sb c = |sb| eta > 0, so sigma sigma_dot < 0.
    r = d.reduced
    f = d.smc
    rng = np.random.default_rng(3)
    n_checked = 0
    for _ in range(200):
        x = rng.standard_normal(r.order) * 1e-3
        sigma = float(f.s @ x)
        if abs(sigma) <= f.eps:
            x = x * (2 * f.eps / max(abs(sigma), 1e-300))
            sigma = float(f.s @ x)
        u = f.voltage(x)
        sdot = float(f.s @ (r.A @ x + r.B[:, 0] * u))
        assert sigma * sdot < 0
        sb = float(f.s @ r.B[:, 0])
        assert sdot == pytest.approx(
            -sb * f.c * np.sign(sigma), rel=1e-6, abs=1e-9 * abs(float(f.s @ r.A @ x))
        )
        n_checked += 1
    assert n_checked == 200


def test_voltage_clips(d):
    rng = np.random.default_rng(4)
    X = rng.standard_normal((50, d.reduced.order)) * 1e-2
    for fb in (d.lqr, d.smc):
        v = fb.voltage(X)
        vc = fb.voltage(X, 120.0)
        assert np.max(np.abs(v)) > 120.0  # the test states do exceed the limit
        assert np.max(np.abs(vc)) <= 120.0
        assert_allclose(vc, np.clip(v, -120.0, 120.0))
    assert_allclose(d.lqr.voltage(X[0]), -(X[0] @ d.lqr.a))


def test_passive_zero():
    fb = passive(6)
    assert fb.voltage(np.ones(6)) == 0.0
    assert fb.name == "passive"


@pytest.mark.parametrize("w", [0.0, -1.0])
def test_lqr_bad_weight(d, w):
    with pytest.raises(ValueError, match="weight"):
        lqr(d.reduced, weight=w)


def test_lqr_bad_R(d):
    with pytest.raises(ValueError, match="R"):
        lqr(d.reduced, R=0.0)


@pytest.mark.parametrize("eps", [0.0, -0.5])
def test_smc_bad_eps(d, eps):
    with pytest.raises(ValueError, match="eps"):
        smc(d.reduced, eps=eps)


def test_design_bad_controller(d):
    with pytest.raises(ValueError, match="controller"):
        d.feedback("pid")
