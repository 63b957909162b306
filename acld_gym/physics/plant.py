r"""The plant the environment simulates (the "truth model"), apart from the design model.

Two meshes (``mesh=``):

* ``"thesis"``: the thesis's mesh, 1 + 1 + 3 elements, 19 DOFs, 38 states: the
  finite-element model itself. The thesis chose it "so as to limit the time of
  numerical simulation" (sec. 2.6); its modes 2 and 3 are 14 % and 50 % too high.
  Table 2 and ``ACLDBeam-v0`` use it.
* ``"converged"``: the same beam on a mesh refined
  :data:`acld_gym.physics.krylov.REFINEMENT` = 128 times
  (2305 DOFs; modes 1-4 within 0.005 % of their Richardson limits, see
  :mod:`acld_gym.physics.convergence`), projected by Galerkin onto a rational Krylov
  subspace: the responses to the voltage and to the tip load at
  :math:`s = 0` and at :math:`s = j\omega_i` for every mode below 1.3 times the band
  :math:`2\pi / \Delta t` (twice the control's Nyquist frequency; the margin:
  :data:`acld_gym.physics.krylov.SHIFT_MARGIN`),

  .. math::

      \mathcal V = \operatorname{span}\{(K + sC + s^2 M)^{-1} [P_c, F_d]\}
      \quad (\text{real and imaginary parts}),

  18 vectors for the default 1 ms period, 36 states (directions below 1e-10 of the
  largest singular value are rounding and dropped:
  :func:`acld_gym.physics.krylov.subspace_basis`; 86 states at 0.1 ms). The modes are
  enumerated on the fine mesh itself (:mod:`acld_gym.physics.spectrum`). Interpolating at the
  resonances makes the projection match the fine mesh's frequency responses to
  about 1e-5 (relative H-infinity) in the band.

Both are second-order models in generalized coordinates q,

.. math::

    M \ddot q + C \dot q + K q = P_c V + F_d f, \qquad y = c^T q,

whose matrices are sums of fixed unit matrices times material coefficients
(:data:`acld_gym.physics.elements.TERM_COEFFICIENTS`), projected once:
:math:`M(p) = \sum_t m_t(p)\, V^T U_t V`. A randomized plant (the env's
``param_noise``) is therefore the Galerkin projection of the whole beam with the
perturbed parameters, for microseconds of work, and it is stable whatever the
draw: M and K stay symmetric positive definite and C positive definite (its
Rayleigh part :math:`\hat a M` alone is) -- an energy argument that survives any
Galerkin projection.

The coordinates are canonical (the same on every machine): for ``"thesis"`` the
FE DOFs; for ``"converged"`` the Ritz vectors of the subspace (eigenvectors of the
projected undamped pencil, mass-normalized, ordered by Ritz value, each signed so
that its participation in :math:`P_c / \|P_c\| + F_d / \|F_d\|` is positive, or its
largest entry where that participation is below 1e-8 of the largest:
:func:`acld_gym.physics.krylov.ritz_signs`).
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field
from functools import cached_property, lru_cache

import numpy as np
import scipy.linalg as sla

from acld_gym.physics.elements import PIEZO_COEFFICIENT, TERM_COEFFICIENTS
from acld_gym.physics.interop import statespace
from acld_gym.physics.model import (
    ParametricModel,
    first_order,
    oscillatory_modes,
    parametric_model,
)
from acld_gym.physics.params import BeamParameters, Mesh

__all__ = ["Plant", "fe_plant", "thesis_plant", "band_of"]


def band_of(dt: float) -> float:
    """The frequency band the plant must be accurate in: 2 pi / dt, twice the Nyquist
    frequency of the control period ``dt`` [s] (rad/s)."""
    return 2.0 * np.pi / dt


@dataclass(frozen=True, eq=False)
class Plant:
    """A second-order plant in generalized coordinates (module docstring).

    Attributes
    ----------
    name : ``"thesis"`` or ``"converged"``.
    params : the nominal parameters (their material fields are randomized).
    units : projected unit matrices :math:`V^T U_t V` (r x r) per term.
    piezo : projected piezo unit vector (r,); :math:`P_c = E_c d_{31}\\,` piezo.
    Fd : projected unit tip load (r,).
    c : tip-deflection output (r,): :math:`y = c^T q` [m].
    physical : (19, r) map from q to the thesis mesh's 19 DOFs (identity for
        ``"thesis"``); the thesis's state weights (LQR Q = 1e11 I, observer Q = I)
        are defined on those DOFs.
    node_x, node_w : node positions [m] and the (nodes, r) map from q to the
        transverse displacement of every node [m] (for drawing).
    provenance : how it was built (mesh, DOFs, Krylov shifts, Ritz values...).
    """

    name: str
    params: BeamParameters
    units: dict[str, np.ndarray] = field(repr=False)
    piezo: np.ndarray = field(repr=False)
    Fd: np.ndarray = field(repr=False)
    c: np.ndarray = field(repr=False)
    physical: np.ndarray = field(repr=False)
    node_x: np.ndarray = field(repr=False)
    node_w: np.ndarray = field(repr=False)
    provenance: dict = field(default_factory=dict, repr=False)

    @property
    def n_coordinates(self) -> int:
        """Generalized coordinates r."""
        return self.Fd.shape[0]

    @property
    def n_states(self) -> int:
        """First-order states, 2 r."""
        return 2 * self.n_coordinates

    def matrices(self, params: BeamParameters | None = None):
        """``(M, C, K, Pc)`` (r x r, r) for the material parameters of ``params``
        (default: the nominal ones)."""
        p = self.params if params is None else params
        M = C = K = 0.0
        for name, U in self.units.items():
            coef = TERM_COEFFICIENTS[name]
            if "M" in coef:
                M = M + coef["M"](p) * U
            if "C" in coef:
                C = C + coef["C"](p) * U
            if "K" in coef:
                K = K + coef["K"](p) * U
        return M, C, K, PIEZO_COEFFICIENT(p) * self.piezo

    def state_space(self, params: BeamParameters | None = None):
        """Read-only ``(A, B, E, Cy)`` of the state :math:`x = [q; \\dot q]`: voltage
        input [V], tip-load input [N], tip-deflection output [m]."""
        if params is None:
            return self._nominal
        M, C, K, Pc = self.matrices(params)
        return first_order(M, C, K, Pc, self.Fd, self.c)

    @cached_property
    def _nominal(self):
        M, C, K, Pc = self.matrices()
        return first_order(M, C, K, Pc, self.Fd, self.c)

    def to_statespace(self, params: BeamParameters | None = None):
        """The plant as a ``control.StateSpace`` (:mod:`acld_gym.physics.interop`)."""
        A, B, E, C = self.state_space(params)
        return statespace(A, B, E, C, f"plant-{self.name}")

    def physical_state(self) -> np.ndarray:
        """(38, 2 r) map from the state x to the thesis mesh's state [q; dq/dt]."""
        return sla.block_diag(self.physical, self.physical)

    def natural_frequencies(self) -> np.ndarray:
        """Damped natural frequencies [rad/s] of the oscillatory modes, ascending."""
        return self.modes().imag

    def modes(self) -> np.ndarray:
        """Oscillatory eigenvalues :math:`\\sigma + j\\omega` (:math:`\\omega > 0`) by
        frequency [1/s]."""
        return oscillatory_modes(self.state_space()[0])


# --- the two presets -----------------------------------------------------------------
def _restriction(coarse: ParametricModel, fine: ParametricModel, factor: int) -> np.ndarray:
    """(coarse DOFs, fine DOFs) selection: the coarse mesh's nodes are every ``factor``-th
    node of the fine mesh, and its GHM coordinates z1, z2 (at the patch's ends) are those
    of the fine mesh's first and last patch elements."""
    S = np.zeros((coarse.n_dofs, fine.n_dofs))
    cd, fd = coarse.dofs, fine.dofs
    for node, names in enumerate(cd.node_dofs):
        if node == 0:
            continue  # clamped
        for name in names:
            S[cd.reduced_index(node, name), fd.reduced_index(node * factor, name)] = 1.0
    cz, fz = cd.z_dofs, fd.z_dofs
    for k in range(0, len(cz), 2):  # each coarse ACLD element: z1 -> first, z2 -> last fine one
        e = k // 2
        S[cd.reduced_of(cz[k]), fd.reduced_of(fz[2 * factor * e])] = 1.0
        S[cd.reduced_of(cz[k + 1]), fd.reduced_of(fz[2 * factor * (e + 1) - 1])] = 1.0
    return S


def _project(
    pm: ParametricModel, V: np.ndarray, name: str, physical: np.ndarray, provenance: dict
) -> Plant:
    units = {k: V.T @ (U @ V) for k, U in pm.terms.units.items()}
    units = {k: 0.5 * (U + U.T) for k, U in units.items()}  # exactly symmetric
    nodes = range(1, len(pm.dofs.node_x))
    W = np.zeros((len(pm.dofs.node_x), V.shape[1]))
    W[1:] = V[[pm.dofs.reduced_index(j, "w") for j in nodes]]
    return Plant(
        name=name,
        params=pm.params,
        units=units,
        piezo=V.T @ pm.terms.piezo,
        Fd=V.T @ pm.Fd,
        c=V[pm.tip_index].copy(),
        physical=physical,
        node_x=np.asarray(pm.dofs.node_x),
        node_w=W,
        provenance=provenance,
    )


@lru_cache(maxsize=8)
def fe_plant(params: BeamParameters | None = None, mesh: Mesh | None = None) -> Plant:
    """A finite-element model itself as a :class:`Plant` (coordinates: its FE DOFs; the
    thesis's state weights then apply to those DOFs directly)."""
    pm = parametric_model(params, mesh)
    eye = np.eye(pm.n_dofs)
    default = pm.mesh == Mesh()
    return _project(
        pm,
        eye,
        "thesis" if default else "fe",
        eye,
        {
            "mesh": "thesis" if default else "custom",
            "elements": " + ".join(str(x) for x in dataclasses.astuple(pm.mesh)),
            "fe_dofs": pm.n_dofs,
        },
    )


def thesis_plant() -> Plant:
    """The thesis's 38-state finite-element model (1 + 1 + 3 elements) as a :class:`Plant`."""
    return fe_plant()
