r"""The converged plant's construction: damped modes of a fine mesh by inverse iteration,
and the Galerkin projection onto the rational Krylov subspace at them
(see :mod:`acld_gym.physics.plant`)."""

from __future__ import annotations

import dataclasses

import numpy as np
import scipy.linalg as sla
import scipy.sparse.linalg as spla

from acld_gym.physics.model import parametric_model
from acld_gym.physics.params import BeamParameters, Mesh
from acld_gym.physics.plant import Plant, _project, _restriction, band_of
from acld_gym.physics.spectrum import damped_modes, modes_below

__all__ = [
    "damped_modes",
    "build_converged_plant",
    "ritz_signs",
    "subspace_basis",
    "BASIS_RTOL",
    "RITZ_RTOL",
    "PARTICIPATION_RTOL",
    "REFINEMENT",
    "SHIFT_MARGIN",
]

#: Refinement of the thesis mesh for ``mesh="converged"`` (each section's element count
#: times this): 128 + 128 + 384 elements, 2305 DOFs.
REFINEMENT = 128


#: The Krylov shifts are the modes below this multiple of the band: a resonance just above
#: the band's edge, not interpolated, would dominate the in-band error there (38 % at
#: dt = 6.4365e-3 s, whose band ends 1e-9 below the 976 rad/s mode). With 1.3 the in-band
#: error against the fine mesh is at most 3.1e-4 (measured over 82 dt from 1e-4 to 1e-2 s,
#: including each mode at 1 and 1.3 x the band's edge; the worst with the 976 rad/s mode
#: just above 1.3 x the band) and 1e-5 for most, and the default 1 ms plant keeps its four
#: shifts (its next mode, 8558 rad/s, is 1.36 x its band).
SHIFT_MARGIN = 1.3

#: Smallest relative distance between Ritz values for the Ritz basis to be unique.
RITZ_RTOL = 1e-6

#: Singular values of the (M-normalized) Krylov vectors below this fraction of the largest
#: are dropped from the subspace (:func:`subspace_basis`).
BASIS_RTOL = 1e-10

#: Relative participation in the inputs below which a Ritz vector is signed by its largest
#: entry instead (:func:`ritz_signs`).
PARTICIPATION_RTOL = 1e-8


def _qep(M, C, K, s: complex):
    return (K + s * C + (s * s) * M).tocsc()


def subspace_basis(X: np.ndarray, rtol: float = BASIS_RTOL) -> np.ndarray:
    """An orthonormal basis of the columns of ``X``: its left singular vectors whose
    singular values exceed ``rtol`` times the largest.

    The rational Krylov vectors at many shifts are nearly dependent (their singular values
    decay smoothly: down to 1e-15 of the largest with the 14 shifts of dt = 1e-4), and the
    directions below :data:`BASIS_RTOL` are rounding, not data: kept (as a plain QR keeps
    them) they add spurious stiff modes (up to 1.4e9 1/s at dt = 1e-4) and nothing to the
    accuracy (the projection's error against the fine mesh stays 1.0e-5 with or without
    them, dt = 1e-3 to 1e-4)."""
    U, s, _ = np.linalg.svd(X, full_matrices=False)
    return U[:, s > rtol * s[0]]


def ritz_signs(V: np.ndarray, g: np.ndarray) -> np.ndarray:
    """The sign (+/-1) of each column of ``V`` that makes it canonical: that of its
    participation :math:`v^T g` in the inputs ``g``, or, where that participation is below
    :data:`PARTICIPATION_RTOL` of the largest (a Ritz vector of the viscoelastic layer's
    internal coordinates, which the inputs barely excite), that of its entry of largest
    magnitude (the first such entry).

    A participation is known only to about 1e-6 of the largest (the Krylov solves'
    accuracy), so a vector's sign near the threshold, like the coordinates' last digits,
    can differ between machines; the default plant is read from its shipped file."""
    part = V.T @ g
    idx = np.argmax(np.abs(V), axis=0)
    entry = V[idx, np.arange(V.shape[1])]
    weak = np.abs(part) < PARTICIPATION_RTOL * np.max(np.abs(part))
    return np.where(weak, np.sign(entry), np.sign(part))


def build_converged_plant(dt: float, params: BeamParameters, refinement: int) -> Plant:
    """Build the converged plant from the fine mesh (no cache; see
    :func:`acld_gym.physics.truth.converged_plant`)."""
    band = band_of(dt)
    fine = parametric_model(params, Mesh().refined(refinement))
    # Every resonance below SHIFT_MARGIN x the band, each once, enumerated on the fine mesh
    # itself (a coarse mesh lacks some of its modes: acld_gym.physics.spectrum).
    lam = modes_below(fine, SHIFT_MARGIN * band)
    # The shifts define the subspace, so they must not depend on the machine: the modes
    # are only determined to ~1e-8 (relative) in double precision, so round them to six
    # significant digits (well inside each resonance's half-power band, zeta ~ 1e-3).
    shifts = np.unique([float(f"{w:.6g}") for w in lam.imag])
    M, C, K, Pc = fine.combine()
    F = np.column_stack([Pc / np.linalg.norm(Pc), fine.Fd / np.linalg.norm(fine.Fd)])
    cols = [spla.splu(K.tocsc()).solve(F)]
    for w in shifts:
        X = spla.splu(_qep(M, C, K, 1j * w).astype(complex)).solve(F.astype(complex))
        cols += [X.real, X.imag]
    X = np.hstack(cols)
    X /= np.sqrt(np.einsum("ij,ij->j", X, M @ X))[None, :]  # M-unit columns: well scaled
    Q = subspace_basis(X)
    Mq, Kq = Q.T @ (M @ Q), Q.T @ (K @ Q)
    ritz, Phi = sla.eigh(0.5 * (Kq + Kq.T), 0.5 * (Mq + Mq.T))
    gaps = np.diff(ritz) / ritz[1:]
    if gaps.min() < RITZ_RTOL:
        raise np.linalg.LinAlgError(
            "converged_plant: two Ritz values are too close for a unique Ritz basis"
        )
    V = Q @ Phi
    V *= ritz_signs(V, F.sum(axis=1))[None, :]
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
