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

from acld_gym.physics.assembly import AssembledTerms, DofMap, assemble_terms, number_dofs
from acld_gym.physics.interop import statespace
from acld_gym.physics.params import PRESETS, BeamParameters, Mesh, split_overrides

__all__ = [
    "BeamModel",
    "ParametricModel",
    "first_order",
    "oscillatory_modes",
    "build_model",
    "parametric_model",
    "resolve",
]


def oscillatory_modes(A: np.ndarray) -> np.ndarray:
    """The eigenvalues :math:`\\sigma + j\\omega` of ``A`` with :math:`\\omega > 0`, by
    frequency [1/s]: one per oscillatory mode (real, overdamped poles are no modes)."""
    lam = np.linalg.eigvals(A)
    lam = lam[lam.imag > 1e-9 * np.abs(lam)]
    return lam[np.argsort(lam.imag)]


def first_order(
    M: np.ndarray, C: np.ndarray, K: np.ndarray, Pc: np.ndarray, Fd: np.ndarray, c: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    r"""First-order form of :math:`M\ddot q + C\dot q + Kq = P_c V + F_d f`,
    :math:`y = c^T q`, with state :math:`x = [q; \dot q]` (module docstring).

    Returns read-only ``(A, B, E, Cy)``.
    """
    n = M.shape[0]
    lu = sla.lu_factor(M)
    minv = sla.lu_solve(lu, np.column_stack([K, C, Pc, Fd]))
    A = np.zeros((2 * n, 2 * n))
    A[:n, n:] = np.eye(n)
    A[n:, :n] = -minv[:, :n]
    A[n:, n:] = -minv[:, n : 2 * n]
    B = np.zeros((2 * n, 1))
    B[n:, 0] = minv[:, 2 * n]
    E = np.zeros((2 * n, 1))
    E[n:, 0] = minv[:, 2 * n + 1]
    Cy = np.zeros((1, 2 * n))
    Cy[0, :n] = c
    for arr in (A, B, E, Cy):
        arr.setflags(write=False)
    return A, B, E, Cy


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
        c = np.zeros(self.n_dofs)
        c[self.tip_index] = 1.0
        return first_order(self.M, self.C, self.K, self.Pc, self.Fd, c)

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
        return oscillatory_modes(self.state_space()[0]).imag

    def undamped_frequencies(self) -> np.ndarray:
        """sqrt(eig(K, M)) [rad/s], ascending: the undamped second-order system
        with the GHM coordinates kept as (undamped) mini-oscillators, so the
        spectrum holds their modes (about 707 and 959 rad/s) beside the beam's."""
        w2 = sla.eigh(self.K, self.M, eigvals_only=True)
        return np.sqrt(np.clip(w2, 0.0, None))

    def to_statespace(self):
        """The model as a ``control.StateSpace`` (inputs voltage [V] and tip load [N],
        output tip deflection [m]; :mod:`acld_gym.physics.interop`)."""
        A, B, E, C = self.state_space()
        return statespace(A, B, E, C, "beam")

    def static_tip_deflection(self, force: float = 1.0) -> float:
        """Static tip deflection [m] under a tip load ``force`` [N] (K q = F_d f)."""
        return float(np.linalg.solve(self.K, self.Fd * force)[self.tip_index])


@dataclass(frozen=True, eq=False)
class ParametricModel:
    """The clamped model as parameter-free sparse unit matrices (one per term of
    :data:`acld_gym.physics.elements.TERM_COEFFICIENTS`): ``M(p) = sum_t m_t(p) U_t`` and so on.

    The geometry (lengths, thicknesses, mesh) is fixed; :meth:`combine` gives the
    matrices for any material parameters. Used for fine meshes (sparse) and for
    parameter randomization (acld_gym.physics.truth).

    Attributes
    ----------
    params, mesh, dofs : the inputs and the DOF numbering.
    terms : clamped sparse unit matrices and piezo unit vector.
    Fd : generalized force of a unit tip load (clamped).
    tip_index : index of the tip deflection in the clamped DOFs.
    """

    params: BeamParameters
    mesh: Mesh
    dofs: DofMap = field(repr=False)
    terms: AssembledTerms = field(repr=False)
    Fd: np.ndarray = field(repr=False)
    tip_index: int = 0

    @property
    def n_dofs(self) -> int:
        return self.Fd.shape[0]

    def combine(self, params: BeamParameters | None = None):
        """Sparse clamped ``(M, C, K)`` and ``Pc`` for ``params`` (default: ``self.params``;
        only its material fields matter, the geometry is this model's)."""
        return self.terms.combine(self.params if params is None else params)


def resolve(
    params: BeamParameters | None = None,
    mesh: Mesh | None = None,
    *,
    preset: str | None = None,
    **overrides: Any,
) -> tuple[BeamParameters, Mesh]:
    """The ``(params, mesh)`` that :func:`build_model` would use for these arguments."""
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
    return params, mesh


def parametric_model(
    params: BeamParameters | None = None,
    mesh: Mesh | None = None,
    *,
    preset: str | None = None,
    **overrides: Any,
) -> ParametricModel:
    """Assemble the clamped model's unit matrices (arguments as :func:`build_model`)."""
    params, mesh = resolve(params, mesh, preset=preset, **overrides)
    dofs = number_dofs(params, mesh)
    terms = assemble_terms(params, dofs)
    free = dofs.free
    Fd = np.zeros(dofs.n_dofs)
    Fd[dofs.node_dofs[-1]["w"]] = 1.0
    clamped = AssembledTerms(
        units={k: U[free][:, free] for k, U in terms.units.items()}, piezo=terms.piezo[free]
    )
    return ParametricModel(
        params=params,
        mesh=mesh,
        dofs=dofs,
        terms=clamped,
        Fd=Fd[free],
        tip_index=dofs.reduced_index(len(dofs.node_x) - 1, "w"),
    )


def build_model(
    params: BeamParameters | None = None,
    mesh: Mesh | None = None,
    *,
    preset: str | None = None,
    **overrides: Any,
) -> BeamModel:
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
    pm = parametric_model(params, mesh, preset=preset, **overrides)
    M, C, K, Pc = pm.combine()
    return BeamModel(
        params=pm.params,
        mesh=pm.mesh,
        dofs=pm.dofs,
        M=M.toarray(),
        C=C.toarray(),
        K=K.toarray(),
        Pc=Pc,
        Fd=pm.Fd,
        tip_index=pm.tip_index,
    )
