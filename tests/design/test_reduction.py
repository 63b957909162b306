"""Tests of acld_gym.design.reduction: Schur balanced truncation of the 38-state beam.

Provenance:
* thesis = /work/shared/seed/rodriguez-2006-acld-smc-lqr-thesis.txt, sec. 3.3 and Fig. 5
  (order 6 kept; the first six Hankel singular values dominate).
* Safonov & Chiang (1989): S_L^T S_R = I, ||G - G_r||_inf <= 2 sum_{i>k} sigma_i.
* Independent HSVs from modal Gramians (diagonalisation A = V L V^-1): for a stable
  diagonal system the Lyapunov solutions are P_ij = -b_i conj(b_j)/(l_i + conj(l_j)),
  Q_ij = -conj(c_i) c_j/(conj(l_i) + l_j).
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest
import scipy.linalg as sla
from numpy.testing import assert_allclose

from acld_gym.design.pipeline import design
from acld_gym.design.reduction import (
    frequency_response,
    hinf_norm,
    schur_balanced_truncation,
)


@pytest.fixture(scope="module")
def d():
    return design()


def _modal_hsv(A, B, C):
    lam, V = np.linalg.eig(A)
    Vi = np.linalg.inv(V)
    b = Vi @ B[:, 0]
    c = C[0] @ V
    P = -np.outer(b, b.conj()) / (lam[:, None] + lam.conj()[None, :])
    Q = -np.outer(c.conj(), c) / (lam.conj()[:, None] + lam[None, :])
    return np.sort(np.sqrt(np.abs(np.linalg.eigvals(P @ Q))))[::-1]


def test_reduced_model_stable(d):
    assert d.reduced.order == 6
    assert np.max(np.linalg.eigvals(d.reduced.A).real) < 0


def test_hsv_agree_with_modal_gramians(d):
    A, B, _, Cy = d.plant
    h = _modal_hsv(A, B, Cy)
    assert_allclose(d.reduced.hsv[:8], h[:8], rtol=1e-3)
    assert np.all(np.diff(d.reduced.hsv) <= 0)  # descending


def test_raw_lyapunov_gives_wrong_hsv(d):
    # Documents why acld_gym.design.numerics balances first: scipy's Lyapunov solver on the
    # raw A (cond ~1e15) gives a first HSV ~2.2e-5 instead of ~5.1e-6 (measured).
    A, B, _, Cy = d.plant
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        P = sla.solve_continuous_lyapunov(A, -B @ B.T)
        Q = sla.solve_continuous_lyapunov(A.T, -Cy.T @ Cy)
    raw = np.sqrt(np.max(np.abs(np.linalg.eigvals(P @ Q))))
    assert abs(raw - d.reduced.hsv[0]) / d.reduced.hsv[0] > 0.5


def test_hinf_error_within_bound(d):
    A, B, _, Cy = d.plant
    r = d.reduced
    n, k = A.shape[0], r.order
    Ad = sla.block_diag(A, r.A)
    Bd = np.vstack([B, r.B])
    Cd = np.hstack([Cy, -r.C])
    assert Ad.shape == (n + k, n + k)
    err, _ = hinf_norm(Ad, Bd, Cd)
    assert 0 < err <= r.error_bound
    assert r.error_bound == pytest.approx(2 * np.sum(r.hsv[k:]))


def test_first_six_hsv_dominate(d):
    # Thesis Fig. 5: a clear gap after the sixth value (measured ratio ~9.4).
    h = d.reduced.hsv
    assert h[5] / h[6] > 5


def test_projections_biorthogonal(d):
    r = d.reduced
    assert_allclose(r.SL.T @ r.SR, np.eye(r.order), atol=1e-8)


def test_reduced_keeps_first_three_frequencies(d):
    ev = np.linalg.eigvals(d.reduced.A)
    wr = np.sort(ev.imag[ev.imag > 0])
    w_full = d.truth.natural_frequencies()[:3]
    assert wr.size == 3
    assert_allclose(wr, w_full, rtol=1e-3)


def test_tip_load_dc_gain_preserved(d):
    A, _, E, Cy = d.plant
    r = d.reduced
    g_full = (-Cy @ np.linalg.solve(A, E)).item()
    g_red = (-r.C @ np.linalg.solve(r.A, r.E)).item()
    assert g_full > 0
    assert abs(g_red - g_full) / abs(g_full) < 0.05


def test_invariance_under_diagonal_state_scaling(d):
    A, B, E, Cy = d.plant
    rng = np.random.default_rng(1)
    dd = np.exp(rng.uniform(-3, 3, A.shape[0]))
    A2 = A * dd[None, :] / dd[:, None]  # x = D x'  =>  A' = D^-1 A D
    B2, E2, C2 = B / dd[:, None], E / dd[:, None], Cy * dd[None, :]
    r1 = d.reduced
    r2 = schur_balanced_truncation(A2, B2, C2, 6, E=E2)
    assert_allclose(r2.hsv[:10], r1.hsv[:10], rtol=1e-6)
    w = np.array([10.0, 178.6, 500.0, 1115.4, 3970.0, 1e4])
    assert_allclose(
        frequency_response(r2.A, r2.B, r2.C, w), frequency_response(r1.A, r1.B, r1.C, w), rtol=1e-6
    )
    assert_allclose(
        frequency_response(r2.A, r2.E, r2.C, w), frequency_response(r1.A, r1.E, r1.C, w), rtol=1e-6
    )


def test_frequency_response_matches_direct_solve():
    A = np.array([[0.0, 1.0], [-4.0, -0.4]])
    B = np.array([[0.0], [1.0]])
    C = np.array([[1.0, 0.0]])
    w = np.array([0.5, 2.0, 7.0])
    g = frequency_response(A, B, C, w)
    assert_allclose(g, 1.0 / (4.0 - w**2 + 0.4j * w), rtol=1e-12)
    norm, wp = hinf_norm(A, B, C, wmin=0.1, wmax=100.0)
    # |G| peaks at w = sqrt(4 - 0.08), value 1/(0.4 sqrt(4 - 0.04)).
    assert norm == pytest.approx(1 / (0.4 * np.sqrt(3.96)), rel=1e-5)
    assert wp == pytest.approx(np.sqrt(3.92), rel=1e-2)


@pytest.mark.parametrize("order", [0, 38, 2.5, -1])
def test_bad_order_raises(d, order):
    A, B, _, Cy = d.plant
    with pytest.raises(ValueError, match="order"):
        schur_balanced_truncation(A, B, Cy, order)


def test_unstable_A_raises():
    A = np.array([[0.1, 1.0], [0.0, -1.0]])
    B = np.ones((2, 1))
    C = np.ones((1, 2))
    with pytest.raises(ValueError, match="stable"):
        schur_balanced_truncation(A, B, C, 1)
