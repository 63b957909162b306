r"""The assembled, clamped ACLD beam and its state-space form (thesis sec. 2.6-2.7).

.. math::

    M \ddot q + C \dot q + K q = P_c V(t) + F_d f(t), \qquad y = q_{tip}

with state :math:`x = [q; \dot q]` (19 + 19 = 38 states for the thesis mesh):

.. math::

    A = \begin{bmatrix} 0 & I \\ -M^{-1}K & -M^{-1}C \end{bmatrix},\quad
    B = \begin{bmatrix} 0 \\ M^{-1}P_c \end{bmatrix},\quad
    E = \begin{bmatrix} 0 \\ M^{-1}F_d \end{bmatrix},\quad
    C_y = e_{tip}^T .
"""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import cached_property
from typing import Any

import numpy as np
import scipy.linalg as sla

from .assembly import DofMap, assemble, number_dofs
from .params import PRESETS, BeamParameters, Mesh, split_overrides

__all__ = ["BeamModel", "build_model"]


@dataclass(frozen=True, eq=False)
class BeamModel:
    """Clamped ACLD beam: second-order matrices and first-order state space.

    Attributes
    ----------
    params, mesh : the inputs.
    dofs : global DOF numbering (before clamping).
    M, C, K : mass [kg], damping [N s/m] and stiffness [N/m] after the clamp
        (mixed units per DOF: m, rad, and the GHM coordinates).
    Pc : generalized force per volt on the PZT [N/V].
    Fd : generalized force of a unit transverse tip load [N/N].
    tip_index : index of the tip deflection in ``q`` (and in ``x``).
    """

    params: BeamParameters
    mesh: Mesh
    dofs: DofMap = field(repr=False)
    M: np.ndarray = field(repr=False)
    C: np.ndarray = field(repr=False)
    K: np.ndarray = field(repr=False)
    Pc: np.ndarray = field(repr=False)
    Fd: np.ndarray = field(repr=False)
    tip_index: int = 0

    @property
    def n_dofs(self) -> int:
        """Number of DOFs after the clamp."""
        return self.M.shape[0]

    @property
    def n_states(self) -> int:
        """Number of first-order states, 2 * n_dofs."""
        return 2 * self.n_dofs

    @cached_property
    def _matrices(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        n = self.n_dofs
        lu = sla.lu_factor(self.M)
        minv = sla.lu_solve(lu, np.column_stack([self.K, self.C, self.Pc, self.Fd]))
        A = np.zeros((2 * n, 2 * n))
        A[:n, n:] = np.eye(n)
        A[n:, :n] = -minv[:, :n]
        A[n:, n:] = -minv[:, n:2 * n]
        B = np.zeros((2 * n, 1))
        B[n:, 0] = minv[:, 2 * n]
        E = np.zeros((2 * n, 1))
        E[n:, 0] = minv[:, 2 * n + 1]
        Cy = np.zeros((1, 2 * n))
        Cy[0, self.tip_index] = 1.0
        for arr in (A, B, E, Cy):
            arr.setflags(write=False)
        return A, B, E, Cy

    def state_space(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """``(A, B, E, Cy)``: state matrix, voltage input [V], tip-load input [N],
        tip-deflection output [m]. Arrays are read-only and shared between calls."""
        return self._matrices

    @cached_property
    def poles(self) -> np.ndarray:
        """Eigenvalues of A [1/s], sorted by magnitude."""
        ev = np.linalg.eigvals(self.state_space()[0])
        return ev[np.argsort(np.abs(ev))]

    def natural_frequencies(self) -> np.ndarray:
        """Damped natural frequencies [rad/s] of the oscillatory modes, ascending.

        These are the imaginary parts of the complex pole pairs of A (one value
        per pair); overdamped (real) poles are not modes and are left out.
        """
        p = self.poles
        im = p.imag[p.imag > 1e-9 * np.abs(p)]
        return np.sort(im)

    def undamped_frequencies(self) -> np.ndarray:
        """sqrt(eig(K, M)) [rad/s], ascending: the undamped second-order system
        with the GHM coordinates kept as (undamped) mini-oscillators, so the
        spectrum holds their modes (about 707 and 959 rad/s) beside the beam's."""
        w2 = sla.eigh(self.K, self.M, eigvals_only=True)
        return np.sqrt(np.clip(w2, 0.0, None))

    def static_tip_deflection(self, force: float = 1.0) -> float:
        """Static tip deflection [m] under a tip load ``force`` [N] (K q = F_d f)."""
        return float(np.linalg.solve(self.K, self.Fd * force)[self.tip_index])


def build_model(params: BeamParameters | None = None, mesh: Mesh | None = None, *,
                preset: str | None = None, **overrides: Any) -> BeamModel:
    """Assemble the clamped ACLD beam.

    Parameters
    ----------
    params : physical parameters (default: the thesis's MATLAB values).
    mesh : element counts (default: the thesis's 1 + 1 + 3).
    preset : ``"matlab"`` (default) or ``"table1"``; only when ``params`` is None.
    **overrides : any field of :class:`BeamParameters` or :class:`Mesh`, e.g.
        ``build_model(patch_length=0.1, n_after=6)``.

    Returns
    -------
    BeamModel

    Examples
    --------
    >>> m = build_model()
    >>> m.n_states, m.tip_index
    (38, 17)
    """
    if preset is not None:
        if params is not None:
            raise ValueError("preset: give either params or preset, not both")
        if preset not in PRESETS:
            raise ValueError(f"preset must be one of {sorted(PRESETS)}, got {preset!r}")
        params = PRESETS[preset]()
    pkw, mkw = split_overrides(overrides)
    params = BeamParameters() if params is None else params
    mesh = Mesh() if mesh is None else mesh
    if pkw:
        params = BeamParameters(**{**params.__dict__, **pkw})
    if mkw:
        mesh = Mesh(**{**mesh.__dict__, **mkw})
    dofs = number_dofs(params, mesh)
    M, C, K, Pc = assemble(params, dofs)
    free = dofs.free
    Fd = np.zeros(dofs.n_dofs)
    Fd[dofs.node_dofs[-1]["w"]] = 1.0
    sel = np.ix_(free, free)
    return BeamModel(params=params, mesh=mesh, dofs=dofs, M=M[sel], C=C[sel], K=K[sel],
                     Pc=Pc[free], Fd=Fd[free],
                     tip_index=dofs.reduced_index(len(dofs.node_x) - 1, "w"))
