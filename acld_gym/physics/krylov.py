r"""The converged plant's construction: damped modes of a fine mesh by inverse iteration,
and the Galerkin projection onto the rational Krylov subspace at them
(see :mod:`acld_gym.physics.plant`)."""

from __future__ import annotations

import dataclasses

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from acld_gym.physics.model import ParametricModel, first_order, parametric_model
from acld_gym.physics.params import BeamParameters, Mesh
from acld_gym.physics.plant import Plant, _project, _restriction, band_of

__all__ = ["damped_modes", "build_converged_plant", "RITZ_RTOL", "REFINEMENT"]

#: Refinement of the thesis mesh for ``mesh="converged"`` (each section's element count
#: times this): 128 + 128 + 384 elements, 2305 DOFs.
REFINEMENT = 128


#: The coarse mesh's refinement used only to find starting guesses of the modes.
_GUESS_REFINEMENT = 4


#: Smallest relative distance between Ritz values for the Ritz basis to be unique.
RITZ_RTOL = 1e-6


def _qep(M, C, K, s: complex):
    return (K + s * C + (s * s) * M).tocsc()


def damped_modes(
    pm: ParametricModel, guesses: np.ndarray, iterations: int = 3, inner: int = 4
) -> np.ndarray:
    r"""The damped eigenvalues of the (sparse) model nearest to ``guesses`` [1/s].

    Inverse iteration on the linearized pencil
    :math:`\begin{bmatrix}0 & I\\ -K & -C\end{bmatrix} z = \lambda
    \begin{bmatrix}I & 0\\ 0 & M\end{bmatrix} z`, with the shift moved to the
    current estimate ``iterations`` times (``inner`` solves each): the guesses are
    within a few percent and the neighbours far, so this converges to round-off.
    Returns the eigenvalues with Im > 0.
    """
    M, C, K, _ = pm.combine()
    n = pm.n_dofs
    eye = sp.identity(n, format="csc")
    A = sp.bmat([[None, eye], [-K, -C]], format="csc").astype(complex)
    B = sp.bmat([[eye, None], [None, M]], format="csc").astype(complex)
    out = []
    for g in guesses:
        sigma = complex(g)
        z = np.ones(2 * n, dtype=complex)  # deterministic start
        for _ in range(iterations):
            lu = spla.splu((A - sigma * B).tocsc())
            for _ in range(inner):
                y = lu.solve(B @ z)
                nu = np.vdot(z, y) / np.vdot(z, z)
                z = y / np.linalg.norm(y)
            sigma = sigma + 1.0 / nu
        out.append(complex(sigma.real, abs(sigma.imag)))
    return np.array(out)


def _mode_guesses(params: BeamParameters, band: float) -> np.ndarray:
    """Oscillatory poles below 1.3 x ``band`` on a coarse refinement (starting guesses;
    a coarse mesh's frequencies are too high by a few percent)."""
    coarse = parametric_model(params, Mesh().refined(_GUESS_REFINEMENT))
    M, C, K, Pc = coarse.combine()
    A = first_order(M.toarray(), C.toarray(), K.toarray(), Pc, coarse.Fd, np.zeros(coarse.n_dofs))[
        0
    ]
    lam = np.linalg.eigvals(A)
    lam = lam[(lam.imag > 1e-9 * np.abs(lam)) & (lam.imag < 1.3 * band)]
    return lam[np.argsort(lam.imag)]


def build_converged_plant(dt: float, params: BeamParameters, refinement: int) -> Plant:
    """Build the converged plant from the fine mesh (no cache; see
    :func:`acld_gym.physics.truth.converged_plant`)."""
    band = band_of(dt)
    fine = parametric_model(params, Mesh().refined(refinement))
    lam = damped_modes(fine, _mode_guesses(params, band))
    lam = lam[lam.imag < band]
    # The shifts define the subspace, so they must not depend on the machine: the modes
    # are only determined to ~1e-8 (relative) in double precision, so round them to six
    # significant digits (well inside each resonance's half-power band, zeta ~ 1e-3).
    shifts = np.array([float(f"{w:.6g}") for w in lam.imag])
    M, C, K, Pc = fine.combine()
    F = np.column_stack([Pc / np.linalg.norm(Pc), fine.Fd / np.linalg.norm(fine.Fd)])
    cols = [spla.splu(K.tocsc()).solve(F)]
    for w in shifts:
        X = spla.splu(_qep(M, C, K, 1j * w).astype(complex)).solve(F.astype(complex))
        cols += [X.real, X.imag]
    X = np.hstack(cols)
    X /= np.sqrt(np.einsum("ij,ij->j", X, M @ X))[None, :]  # M-unit columns: QR well scaled
    Q, R = np.linalg.qr(X)
    d = np.abs(np.diag(R))
    if d.min() < 1e-8 * d.max():
        raise np.linalg.LinAlgError(
            "converged_plant: the Krylov vectors are linearly dependent (a shift repeats?)"
        )
    Mq, Kq = Q.T @ (M @ Q), Q.T @ (K @ Q)
    ritz, Phi = sla.eigh(0.5 * (Kq + Kq.T), 0.5 * (Mq + Mq.T))
    gaps = np.diff(ritz) / ritz[1:]
    if gaps.min() < RITZ_RTOL:
        raise np.linalg.LinAlgError(
            "converged_plant: two Ritz values are too close for a unique Ritz basis"
        )
    V = Q @ Phi
    part = V.T @ F.sum(axis=1)
    if np.min(np.abs(part)) < 1e-8 * np.max(np.abs(part)):
        raise np.linalg.LinAlgError(
            "converged_plant: a Ritz vector has no participation in "
            "the inputs; its sign is undefined"
        )
    V *= np.sign(part)[None, :]
    coarse = parametric_model(params, Mesh())
    physical = _restriction(coarse, fine, refinement) @ V
    provenance = {
        "mesh": "converged",
        "refinement": refinement,
        "fe_dofs": fine.n_dofs,
        "elements": " + ".join(str(x) for x in dataclasses.astuple(fine.mesh)),
        "band_rad_s": band,
        "shifts_rad_s": [0.0, *shifts.tolist()],
        "fine_modes": [[z.real, z.imag] for z in lam.tolist()],
        "ritz_rad_s": np.sqrt(ritz).tolist(),
    }
    return _project(fine, V, "converged", physical, provenance)
