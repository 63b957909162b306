"""acld_gym.physics.spectrum.modes_below and the converged plant's basis and signs
(acld_gym.physics.krylov), against dense references.

Reference: numpy's dense eigenvalues of the first-order state matrix of a coarse mesh
(small enough for a dense solve), filtered to the same sector.
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st

from acld_gym.physics.krylov import ritz_signs, subspace_basis
from acld_gym.physics.model import first_order, parametric_model
from acld_gym.physics.params import BeamParameters, Mesh
from acld_gym.physics.spectrum import ZETA_MAX, modes_below


@pytest.fixture(scope="module")
def mesh8():
    pm = parametric_model(BeamParameters(), Mesh().refined(8))
    M, C, K, Pc = pm.combine()
    A = first_order(M.toarray(), C.toarray(), K.toarray(), Pc, pm.Fd, np.zeros(pm.n_dofs))[0]
    return pm, np.linalg.eigvals(A)


def _dense_sector(lam: np.ndarray, w_max: float) -> np.ndarray:
    lam = lam[(lam.imag > 1e-9 * np.abs(lam)) & (lam.imag < w_max)]
    lam = lam[-lam.real <= ZETA_MAX * np.abs(lam)]
    return lam[np.argsort(lam.imag)]


@settings(max_examples=6, deadline=None)
@given(w_max=st.floats(2e3, 2.5e5))
@example(w_max=59211.0)  # a mode found from two centres, one copy 3e-4 off before refining
def test_modes_below_finds_every_mode_once(mesh8, w_max):
    pm, dense = mesh8
    ref = _dense_sector(dense, w_max)
    got = modes_below(pm, w_max)
    # Away from the range's edge (a mode within round-off of w_max may fall either side).
    if np.any(np.abs(dense.imag - w_max) < 1e-6 * w_max):
        return
    assert got.size == ref.size
    # The dense reference is accurate to ~5e-10 (A's norm is ~1e7 times its lowest modes).
    assert np.max(np.abs(got - ref) / np.abs(ref), initial=0.0) < 1e-8


def test_subspace_basis_drops_only_rounding_directions():
    rng = np.random.default_rng(1)
    X = rng.standard_normal((50, 6))
    noise, data = 1e-14 * rng.standard_normal(50), 1e-6 * rng.standard_normal(50)
    X = np.column_stack([X, X[:, 0] + noise, X[:, 2] + data])
    Q = subspace_basis(X)
    assert Q.shape == (50, 7)  # the near copy goes; a new direction at 1e-6 is data, stays
    assert np.allclose(Q.T @ Q, np.eye(7), atol=1e-12)
    # Every column of X is in the span (to the dropped 1e-14).
    assert np.max(np.abs(X - Q @ (Q.T @ X))) < 1e-12


def test_ritz_signs_fall_back_to_the_largest_entry():
    V = np.array(
        [
            [1.0, -2.0, 0.3, 0.5],
            [0.5, 1.0, -0.9, -0.7],
            [0.1, 0.2, 0.1, 0.0],
        ]
    )
    g = np.array([1.0, 0.0, 0.0])
    # Columns 0, 1: participation v^T g = 1, -2 decides. Columns 2, 3: participation 0.3
    # and 0.5 decide too; with g orthogonal to a column, its largest entry decides.
    assert ritz_signs(V, g).tolist() == [1.0, -1.0, 1.0, 1.0]
    g = np.array([0.0, 0.0, 1.0])  # participations 0.1, 0.2, 0.1, 0.0
    assert ritz_signs(V, g).tolist() == [1.0, 1.0, 1.0, -1.0]  # column 3: entry -0.7
    signed = V * ritz_signs(V, g)[None, :]
    assert np.all(signed.T @ g >= 0)
