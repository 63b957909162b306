"""Tests of acld_gym.design.numerics: diagonal balancing and the scaled Lyapunov/Riccati solves.

Provenance: the module docstring (diagonal similarity D^-1 A D keeps the spectrum;
CARE gain K = R^-1 B^T X); the checks are against scipy.linalg directly.
"""

from __future__ import annotations

import numpy as np
import pytest
import scipy.linalg as sla
from numpy.testing import assert_allclose

from acld_gym.design.numerics import (
    balancing_scaling,
    care_gain,
    lyap_controllability,
    lyap_observability,
)
from acld_gym.design.pipeline import design


@pytest.fixture(scope="module")
def plant():
    return design().plant


def _sorted_eigs(A):
    ev = np.linalg.eigvals(A)
    return ev[np.lexsort((ev.imag, ev.real))]


def test_balancing_is_similarity_preserving_eigenvalues(plant):
    A, B, _, Cy = plant
    sc = balancing_scaling(A)
    assert np.all(sc.d > 0)
    # Parlett-Reinsch scaling uses powers of two (exact in floating point).
    assert_allclose(np.log2(sc.d), np.round(np.log2(sc.d)), atol=0)
    As, Bs, Cs = sc.system(A, B, Cy)
    # Explicit similarity D^-1 A D.
    D = np.diag(sc.d)
    assert_allclose(As, np.linalg.solve(D, A @ D), rtol=1e-12, atol=0)
    assert_allclose(Bs, np.linalg.solve(D, B), rtol=1e-12)
    assert_allclose(Cs, Cy @ D, rtol=1e-12)
    ev, evs = _sorted_eigs(A), _sorted_eigs(As)
    assert_allclose(evs, ev, rtol=1e-6)


def test_balancing_reduces_norm_spread(plant):
    A = plant[0]
    sc = balancing_scaling(A)
    As = sc.system(A, np.zeros((A.shape[0], 1)), np.zeros((1, A.shape[0])))[0]
    spread = lambda M: np.ptp(np.log10(np.linalg.norm(M, axis=0) + 1e-300))  # noqa: E731
    assert spread(As) < spread(A)


def test_care_gain_matches_scipy_on_small_system():
    rng = np.random.default_rng(0)
    n = 4
    A = rng.standard_normal((n, n)) - 3 * np.eye(n)
    B = rng.standard_normal((n, 1))
    Q = np.eye(n)
    R = np.array([[2.0]])
    K, X = care_gain(A, B, Q, R)
    X0 = sla.solve_continuous_are(A, B, Q, R)
    assert_allclose(X, X0, rtol=1e-10, atol=1e-12)
    assert_allclose(K, np.linalg.solve(R, B.T @ X0), rtol=1e-10, atol=1e-12)
    # Stabilizing solution.
    assert np.max(np.linalg.eigvals(A - B @ K).real) < 0


def test_care_gain_scalar_R_accepted():
    A = np.array([[0.0, 1.0], [-1.0, -0.1]])
    B = np.array([[0.0], [1.0]])
    K1, _ = care_gain(A, B, np.eye(2), 1.0)
    K2, _ = care_gain(A, B, np.eye(2), np.eye(1))
    assert_allclose(K1, K2)


def test_lyapunov_residuals_small(plant):
    A, B, _, Cy = plant
    As, Bs, Cs = balancing_scaling(A).system(A, B, Cy)
    P = lyap_controllability(As, Bs)
    Q = lyap_observability(As, Cs)
    assert_allclose(P, P.T)
    assert_allclose(Q, Q.T)
    rP = As @ P + P @ As.T + Bs @ Bs.T
    rQ = As.T @ Q + Q @ As + Cs.T @ Cs
    scaleP = 2 * np.linalg.norm(As) * np.linalg.norm(P) + np.linalg.norm(Bs) ** 2
    scaleQ = 2 * np.linalg.norm(As) * np.linalg.norm(Q) + np.linalg.norm(Cs) ** 2
    assert np.linalg.norm(rP) / scaleP < 1e-10
    assert np.linalg.norm(rQ) / scaleQ < 1e-10
    # Gramians of a stable system are positive semidefinite.
    assert np.min(np.linalg.eigvalsh(P)) > -1e-10 * np.max(np.linalg.eigvalsh(P))
    assert np.min(np.linalg.eigvalsh(Q)) > -1e-10 * np.max(np.linalg.eigvalsh(Q))
