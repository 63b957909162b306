r"""The plant the environment simulates (the "truth model"), apart from the design model.

Two meshes (``mesh=``):

* ``"thesis"``: the thesis's mesh, 1 + 1 + 3 elements, 19 DOFs, 38 states: the
  finite-element model itself. The thesis chose it "so as to limit the time of
  numerical simulation" (sec. 2.6); its modes 2 and 3 are 14 % and 50 % too high.
  Table 2 and ``ACLDBeam-v0`` use it.
* ``"converged"``: the same beam on a mesh refined :data:`REFINEMENT` = 128 times
  (2305 DOFs; modes 1-4 within 0.005 % of their Richardson limits, see
  :mod:`acld_gym.convergence`), projected by Galerkin onto a rational Krylov
  subspace: the responses to the voltage and to the tip load at
  :math:`s = 0` and at :math:`s = j\omega_i` for every mode below the band
  :math:`2\pi / \Delta t` (twice the control's Nyquist frequency),

  .. math::

      \mathcal V = \operatorname{span}\{(K + sC + s^2 M)^{-1} [P_c, F_d]\}
      \quad (\text{real and imaginary parts}),

  18 vectors for the default 1 ms period, 36 states. Interpolating at the
  resonances makes the projection match the fine mesh's frequency responses to
  about 1e-5 (relative H-infinity) in the band.

Both are second-order models in generalized coordinates q,

.. math::

    M \ddot q + C \dot q + K q = P_c V + F_d f, \qquad y = c^T q,

whose matrices are sums of fixed unit matrices times material coefficients
(:data:`acld_gym.elements.TERM_COEFFICIENTS`), projected once:
:math:`M(p) = \sum_t m_t(p)\, V^T U_t V`. A randomized plant (the env's
``param_noise``) is therefore the Galerkin projection of the whole beam with the
perturbed parameters, for microseconds of work, and it is stable whatever the
draw: M and K stay symmetric positive definite and C positive definite (its
Rayleigh part :math:`\hat a M` alone is) -- an energy argument that survives any
Galerkin projection.

The coordinates are canonical (the same on every machine): for ``"thesis"`` the
FE DOFs; for ``"converged"`` the Ritz vectors of the subspace (eigenvectors of the
projected undamped pencil, mass-normalized, ordered by Ritz value, each signed so
that its participation in :math:`P_c / \|P_c\| + F_d / \|F_d\|` is positive).
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field
from functools import cached_property, lru_cache

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from .elements import PIEZO_COEFFICIENT, TERM_COEFFICIENTS
from .model import ParametricModel, first_order, parametric_model
from .params import BeamParameters, Mesh

__all__ = ["Plant", "MESHES", "REFINEMENT", "fe_plant", "thesis_plant", "converged_plant", "plant",
           "band_of", "damped_modes"]

#: Truth-plant presets of the ``mesh`` option.
MESHES = ("converged", "thesis")
#: Refinement of the thesis mesh for ``mesh="converged"`` (each section's element count
#: times this): 128 + 128 + 384 elements, 2305 DOFs.
REFINEMENT = 128
#: The coarse mesh's refinement used only to find starting guesses of the modes.
_GUESS_REFINEMENT = 4
#: Smallest relative distance between Ritz values for the Ritz basis to be unique.
RITZ_RTOL = 1e-6


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
        """The plant as a ``control.StateSpace`` (:mod:`acld_gym.interop`)."""
        from .interop import statespace

        A, B, E, C = self.state_space(params)
        return statespace(A, B, E, C, f"plant-{self.name}")

    def physical_state(self) -> np.ndarray:
        """(38, 2 r) map from the state x to the thesis mesh's state [q; dq/dt]."""
        return sla.block_diag(self.physical, self.physical)

    def natural_frequencies(self) -> np.ndarray:
        """Damped natural frequencies [rad/s] of the oscillatory modes, ascending."""
        lam = np.linalg.eigvals(self.state_space()[0])
        return np.sort(lam.imag[lam.imag > 1e-9 * np.abs(lam)])

    def modes(self) -> np.ndarray:
        """Oscillatory eigenvalues :math:`\\sigma + j\\omega` (:math:`\\omega > 0`) by
        frequency [1/s]."""
        lam = np.linalg.eigvals(self.state_space()[0])
        lam = lam[lam.imag > 1e-9 * np.abs(lam)]
        return lam[np.argsort(lam.imag)]


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


def _project(pm: ParametricModel, V: np.ndarray, name: str, physical: np.ndarray,
             provenance: dict) -> Plant:
    units = {k: V.T @ (U @ V) for k, U in pm.terms.units.items()}
    units = {k: 0.5 * (U + U.T) for k, U in units.items()}  # exactly symmetric
    nodes = range(1, len(pm.dofs.node_x))
    W = np.zeros((len(pm.dofs.node_x), V.shape[1]))
    W[1:] = V[[pm.dofs.reduced_index(j, "w") for j in nodes]]
    return Plant(name=name, params=pm.params, units=units, piezo=V.T @ pm.terms.piezo,
                 Fd=V.T @ pm.Fd, c=V[pm.tip_index].copy(), physical=physical,
                 node_x=np.asarray(pm.dofs.node_x), node_w=W, provenance=provenance)


@lru_cache(maxsize=8)
def fe_plant(params: BeamParameters | None = None, mesh: Mesh | None = None) -> Plant:
    """A finite-element model itself as a :class:`Plant` (coordinates: its FE DOFs; the
    thesis's state weights then apply to those DOFs directly)."""
    pm = parametric_model(params, mesh)
    eye = np.eye(pm.n_dofs)
    default = pm.mesh == Mesh()
    return _project(pm, eye, "thesis" if default else "fe", eye,
                    {"mesh": "thesis" if default else "custom",
                     "elements": " + ".join(str(x) for x in dataclasses.astuple(pm.mesh)),
                     "fe_dofs": pm.n_dofs})


def thesis_plant() -> Plant:
    """The thesis's 38-state finite-element model (1 + 1 + 3 elements) as a :class:`Plant`."""
    return fe_plant()


def _qep(M, C, K, s: complex):
    return (K + s * C + (s * s) * M).tocsc()


def damped_modes(pm: ParametricModel, guesses: np.ndarray, iterations: int = 3,
                 inner: int = 4) -> np.ndarray:
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
    A = first_order(M.toarray(), C.toarray(), K.toarray(), Pc, coarse.Fd,
                    np.zeros(coarse.n_dofs))[0]
    lam = np.linalg.eigvals(A)
    lam = lam[(lam.imag > 1e-9 * np.abs(lam)) & (lam.imag < 1.3 * band)]
    return lam[np.argsort(lam.imag)]


@lru_cache(maxsize=4)
def converged_plant(dt: float = 1e-3, params: BeamParameters | None = None,
                    refinement: int = REFINEMENT) -> Plant:
    """The mesh-converged plant for control period ``dt`` [s] (module docstring).

    Read from its versioned file when one exists (:mod:`acld_gym.plant_cache`: the
    default plant ships with the package), else built (about 0.5 s) and cached.

    Why a file: the Krylov vectors come from solves on the fine mesh, accurate to about
    1e-6 (relative; the systems are ill-conditioned near the resonances), so a plant
    built on another CPU's BLAS kernels differs in its coordinates at that level. The
    shipped file makes the default plant, and everything observed in its coordinates,
    bit-identical on every machine.

    Parameters
    ----------
    dt : control period [s]; the plant is accurate up to :func:`band_of` (dt).
    params : nominal parameters (default: the thesis's MATLAB values).
    refinement : refinement factor of the thesis mesh (default :data:`REFINEMENT`).
    """
    from .plant_cache import cached

    params = BeamParameters() if params is None else params
    return cached(params, float(dt), int(refinement),
                  lambda: build_converged_plant(float(dt), params, int(refinement)))


def build_converged_plant(dt: float, params: BeamParameters, refinement: int) -> Plant:
    """Build the converged plant from the fine mesh (no cache; see :func:`converged_plant`)."""
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
        raise np.linalg.LinAlgError("converged_plant: the Krylov vectors are linearly "
                                    "dependent (a shift repeats?)")
    Mq, Kq = Q.T @ (M @ Q), Q.T @ (K @ Q)
    ritz, Phi = sla.eigh(0.5 * (Kq + Kq.T), 0.5 * (Mq + Mq.T))
    gaps = np.diff(ritz) / ritz[1:]
    if gaps.min() < RITZ_RTOL:
        raise np.linalg.LinAlgError("converged_plant: two Ritz values are too close for a "
                                    "unique Ritz basis")
    V = Q @ Phi
    part = V.T @ F.sum(axis=1)
    if np.min(np.abs(part)) < 1e-8 * np.max(np.abs(part)):
        raise np.linalg.LinAlgError("converged_plant: a Ritz vector has no participation in "
                                    "the inputs; its sign is undefined")
    V *= np.sign(part)[None, :]
    coarse = parametric_model(params, Mesh())
    physical = _restriction(coarse, fine, refinement) @ V
    provenance = {"mesh": "converged", "refinement": refinement, "fe_dofs": fine.n_dofs,
                  "elements": " + ".join(str(x) for x in dataclasses.astuple(fine.mesh)),
                  "band_rad_s": band, "shifts_rad_s": [0.0, *shifts.tolist()],
                  "fine_modes": [[z.real, z.imag] for z in lam.tolist()],
                  "ritz_rad_s": np.sqrt(ritz).tolist()}
    return _project(fine, V, "converged", physical, provenance)


def plant(mesh: str = "converged", dt: float = 1e-3) -> Plant:
    """The nominal plant of ``mesh`` (:data:`MESHES`) for control period ``dt`` [s]."""
    if mesh == "converged":
        return converged_plant(float(dt))
    if mesh == "thesis":
        return thesis_plant()
    raise ValueError(f"mesh must be one of {list(MESHES)}, got {mesh!r}")
