r"""Finite-element matrices of the Timoshenko beam element and the ACLD element.

The matrices are obtained, as in the thesis's derivation (ch. 2 and
``BalamuraganNarayananDerivation.m``), by integrating products of the linear
shape functions over the element, here with Gauss-Legendre quadrature: two
points integrate every (quadratic) integrand exactly, and the transverse-shear
terms use one-point *reduced* integration to avoid shear locking (Reddy;
``TimoshenkoFEM2.m``).

Kinematics of the ACLD element (Balamurugan & Narayanan 2002). Per node: axial
displacement :math:`u`, transverse displacement :math:`w`, rotation
:math:`\theta` and VEM shear angle :math:`\gamma`; plus two GHM dissipation
coordinates :math:`z` per element. The axial displacements of the VEM and PZT
mid-planes are

.. math::

    u_s = u - \tfrac{t_b + t_s}{2}\,\theta + \tfrac{t_s}{2}\,\gamma, \qquad
    u_c = u - h\,\theta + t_s\,\gamma, \qquad h = t_s + \tfrac{t_b + t_c}{2}.

The piezoelectric load vector follows from the virtual work of the induced
strain, :math:`\delta W = E_c d_{31} b V \int \delta(\partial u_c/\partial x)\,dx`.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from acld_gym.physics.params import BeamParameters

__all__ = [
    "ElementMatrices",
    "ElementTerms",
    "timoshenko_element",
    "acld_element",
    "timoshenko_terms",
    "acld_terms",
    "combine_terms",
    "TERM_COEFFICIENTS",
    "PIEZO_COEFFICIENT",
    "BEAM_NODE_DOFS",
    "ACLD_NODE_DOFS",
]

#: Nodal degrees of freedom of the plain Timoshenko element, in order.
BEAM_NODE_DOFS = ("u", "w", "theta")
#: Nodal degrees of freedom of the ACLD element, in order (then z1, z2 per element).
ACLD_NODE_DOFS = ("u", "w", "theta", "gamma")

_GAUSS2 = np.polynomial.legendre.leggauss(2)
_GAUSS1 = np.polynomial.legendre.leggauss(1)


@dataclass(frozen=True)
class ElementMatrices:
    """Mass, damping, stiffness and piezo force vector of one element (local DOFs)."""

    M: np.ndarray
    C: np.ndarray
    K: np.ndarray
    Pc: np.ndarray


class _Shape:
    """Linear shape functions of one field, as rows over the element's nodal DOFs."""

    def __init__(self, node_dofs: tuple[str, ...], length: float):
        self.node_dofs = node_dofs
        self.length = length
        self.n = 2 * len(node_dofs)

    def N(self, name: str, x: float) -> np.ndarray:
        k = self.node_dofs.index(name)
        row = np.zeros(self.n)
        row[k] = 1.0 - x / self.length
        row[k + len(self.node_dofs)] = x / self.length
        return row

    def dN(self, name: str) -> np.ndarray:
        k = self.node_dofs.index(name)
        row = np.zeros(self.n)
        row[k] = -1.0 / self.length
        row[k + len(self.node_dofs)] = 1.0 / self.length
        return row

    def integrate(self, integrand, points: int = 2) -> np.ndarray:
        """Gauss-Legendre quadrature of ``integrand(x)`` over [0, L_e]."""
        xi, wt = _GAUSS2 if points == 2 else _GAUSS1
        half = 0.5 * self.length
        return sum(w * half * integrand(half * (1.0 + s)) for s, w in zip(xi, wt, strict=True))


def _outer(row: np.ndarray) -> np.ndarray:
    return np.outer(row, row)


# --- parameter-affine form -------------------------------------------------------
# Every element matrix is a sum of parameter-free "unit" matrices (geometry and shape
# functions only) times a coefficient that is a product of material parameters:
#
#     M = sum_t m_t(p) U_t,   C = sum_t c_t(p) U_t,   K = sum_t k_t(p) U_t,   Pc = e(p) u.
#
# The table below owns that structure. The environment's parameter randomization
# relies on it: a randomized plant is the same unit matrices with new coefficients
# (acld_gym.physics.truth), so its reduced matrices are sums of precomputed small matrices.
#: term -> {"M" | "C" | "K": coefficient(p)}; Rayleigh damping C = a M + b K acts on the
#: beam, PZT and VEM layers, not on the GHM dissipation coordinates.
TERM_COEFFICIENTS: dict[str, dict[str, Callable[[BeamParameters], float]]] = {
    "beam.inertia": {
        "M": lambda p: p.beam_density,
        "C": lambda p: p.rayleigh_mass * p.beam_density,
    },
    "beam.stiffness": {
        "K": lambda p: p.beam_youngs_modulus,
        "C": lambda p: p.rayleigh_stiffness * p.beam_youngs_modulus,
    },
    "beam.shear": {
        "K": lambda p: p.shear_correction * p.beam_shear_modulus,
        "C": lambda p: p.rayleigh_stiffness * p.shear_correction * p.beam_shear_modulus,
    },
    "pzt.inertia": {"M": lambda p: p.pzt_density, "C": lambda p: p.rayleigh_mass * p.pzt_density},
    "pzt.stiffness": {
        "K": lambda p: p.pzt_youngs_modulus,
        "C": lambda p: p.rayleigh_stiffness * p.pzt_youngs_modulus,
    },
    "pzt.shear": {
        "K": lambda p: p.shear_correction * p.pzt_shear_modulus,
        "C": lambda p: p.rayleigh_stiffness * p.shear_correction * p.pzt_shear_modulus,
    },
    "vem.inertia": {"M": lambda p: p.vem_density, "C": lambda p: p.rayleigh_mass * p.vem_density},
    "vem.stiffness": {
        "K": lambda p: p.vem_youngs_modulus,
        "C": lambda p: p.rayleigh_stiffness * p.vem_youngs_modulus,
    },
    "vem.shear": {
        "K": lambda p: p.ghm_kappa * (1.0 + p.ghm_alpha),
        "C": lambda p: p.rayleigh_stiffness * p.ghm_kappa * (1.0 + p.ghm_alpha),
    },
    "ghm.coupling": {"K": lambda p: p.ghm_alpha * p.ghm_kappa},
    "ghm.dissipation": {
        "M": lambda p: p.ghm_alpha * p.ghm_kappa / p.ghm_omega**2,
        "C": lambda p: 2.0 * p.ghm_zeta * p.ghm_alpha * p.ghm_kappa / p.ghm_omega,
    },
}
#: Coefficient of the piezo unit vector: E_c d_31 [N/(V m)] (the width is geometry).
PIEZO_COEFFICIENT: Callable[[BeamParameters], float] = lambda p: p.pzt_youngs_modulus * p.d31  # noqa: E731


@dataclass(frozen=True)
class ElementTerms:
    """An element's unit matrices (``units[term]``, local DOFs) and piezo unit vector."""

    units: dict[str, np.ndarray]
    piezo: np.ndarray

    def combine(self, p: BeamParameters) -> ElementMatrices:
        """The element's matrices for the material parameters of ``p``."""
        return ElementMatrices(*combine_terms(self.units, self.piezo, p))


def combine_terms(units: dict, piezo, p: BeamParameters):
    """``(M, C, K, Pc)`` = the coefficient-weighted sums of ``units`` (dense or sparse,
    local or assembled) for the material parameters of ``p``."""
    out = {}
    for name, unit in units.items():
        for which, coef in TERM_COEFFICIENTS[name].items():
            term = coef(p) * unit
            out[which] = term if which not in out else out[which] + term
    return out["M"], out["C"], out["K"], PIEZO_COEFFICIENT(p) * piezo


def _layer_units(
    sh: _Shape, area: float, inertia: float, axial=None, axial_rate=None
) -> tuple[np.ndarray, np.ndarray]:
    """Inertia and axial/bending stiffness units of one layer,

    .. math::

        U_m = \\int A N_w^T N_w + I N_\\theta^T N_\\theta + A N_a^T N_a, \\qquad
        U_k = \\int I N_\\theta'^T N_\\theta' + A N_a'^T N_a'

    with :math:`N_a` the layer's axial displacement (``axial(x)``; default the beam
    axis, u) and :math:`N_a'` its derivative (``axial_rate()``).
    """
    axial = axial or (lambda x: sh.N("u", x))
    axial_rate = axial_rate or (lambda: sh.dN("u"))
    Um = sh.integrate(
        lambda x: (
            area * _outer(sh.N("w", x))
            + inertia * _outer(sh.N("theta", x))
            + area * _outer(axial(x))
        )
    )
    Uk = sh.integrate(lambda x: inertia * _outer(sh.dN("theta")) + area * _outer(axial_rate()))
    return Um, Uk


def _shear_unit(sh: _Shape, area: float) -> np.ndarray:
    """:math:`A \\int_{1pt} (N_\\theta - N_w')^T (N_\\theta - N_w')`: transverse shear with
    one-point reduced integration (no shear locking)."""
    return sh.integrate(lambda x: area * _outer(sh.N("theta", x) - sh.dN("w")), points=1)


def timoshenko_terms(p: BeamParameters, length: float) -> ElementTerms:
    """Unit matrices of the plain-beam element, DOFs ``[u1 w1 theta1 u2 w2 theta2]``.

    .. math::

        M = \\rho_b U_m, \\quad K = E_b U_k + k G_b U_s, \\quad C = \\hat a M + \\hat b K.
    """
    sh = _Shape(BEAM_NODE_DOFS, length)
    Um, Uk = _layer_units(sh, p.beam_area, p.beam_inertia)
    return ElementTerms(
        units={
            "beam.inertia": Um,
            "beam.stiffness": Uk,
            "beam.shear": _shear_unit(sh, p.beam_area),
        },
        piezo=np.zeros(sh.n),
    )


def timoshenko_element(p: BeamParameters, length: float) -> ElementMatrices:
    """Plain-beam element, DOFs ``[u1 w1 theta1 u2 w2 theta2]`` (``TimoshenkoFEM2.m``).

    .. math::

        K = E I \\int N_\\theta'^T N_\\theta'
            + k G A \\int_{1pt} (N_\\theta - N_w')^T (N_\\theta - N_w')
            + E A \\int N_u'^T N_u', \\quad
        M = \\rho \\int (A N_w^T N_w + I N_\\theta^T N_\\theta + A N_u^T N_u),

    and Rayleigh damping :math:`C = \\hat a M + \\hat b K`.
    """
    return timoshenko_terms(p, length).combine(p)


def acld_terms(p: BeamParameters, length: float) -> ElementTerms:
    """Unit matrices of the ACLD element, DOFs ``[u1 w1 theta1 gamma1 u2 w2 theta2 gamma2
    z1 z2]`` (see :func:`acld_element` for the physics)."""
    sh = _Shape(ACLD_NODE_DOFS, length)
    tb, ts, h = p.beam_thickness, p.vem_thickness, p.pzt_offset

    def u_c(x):
        return sh.N("u", x) - h * sh.N("theta", x) + ts * sh.N("gamma", x)

    def du_c():
        return sh.dN("u") - h * sh.dN("theta") + ts * sh.dN("gamma")

    def u_s(x):
        return sh.N("u", x) - 0.5 * (tb + ts) * sh.N("theta", x) + 0.5 * ts * sh.N("gamma", x)

    def du_s():
        return sh.dN("u") - 0.5 * (tb + ts) * sh.dN("theta") + 0.5 * ts * sh.dN("gamma")

    n = sh.n

    def pad(U: np.ndarray) -> np.ndarray:  # nodal DOFs -> nodal + the two z
        out = np.zeros((n + 2, n + 2))
        out[:n, :n] = U
        return out

    units: dict[str, np.ndarray] = {}
    # Beam and PZT are Timoshenko layers; the PZT's axial motion is u_c, not u.
    Um, Uk = _layer_units(sh, p.beam_area, p.beam_inertia)
    units["beam.inertia"], units["beam.stiffness"] = pad(Um), pad(Uk)
    units["beam.shear"] = pad(_shear_unit(sh, p.beam_area))
    Um, Uk = _layer_units(sh, p.pzt_area, p.pzt_inertia, u_c, du_c)
    units["pzt.inertia"], units["pzt.stiffness"] = pad(Um), pad(Uk)
    units["pzt.shear"] = pad(_shear_unit(sh, p.pzt_area))
    # VEM: inertia, bending and extension (with E_s), shear with the GHM
    # high-frequency modulus kappa (1 + alpha).
    As = p.vem_area
    Um, Uk = _layer_units(sh, As, p.vem_inertia, u_s, du_s)
    units["vem.inertia"], units["vem.stiffness"] = pad(Um), pad(Uk)
    units["vem.shear"] = pad(sh.integrate(lambda x: As * _outer(sh.N("gamma", x))))

    # GHM dissipation coordinates z (linear over the element).
    def Nz(x):
        return np.array([1.0 - x / length, x / length])

    Uqz = sh.integrate(lambda x: As * np.outer(sh.N("gamma", x), Nz(x)))
    Uz = sh.integrate(lambda x: As * np.outer(Nz(x), Nz(x)))
    coupling = np.zeros((n + 2, n + 2))
    coupling[:n, n:], coupling[n:, :n], coupling[n:, n:] = -Uqz, -Uqz.T, Uz
    dissipation = np.zeros((n + 2, n + 2))
    dissipation[n:, n:] = Uz
    units["ghm.coupling"], units["ghm.dissipation"] = coupling, dissipation
    piezo = np.zeros(n + 2)
    piezo[:n] = p.width * sh.integrate(lambda x: du_c(), points=1)
    return ElementTerms(units=units, piezo=piezo)


def acld_element(p: BeamParameters, length: float) -> ElementMatrices:
    """ACLD element, DOFs ``[u1 w1 theta1 gamma1 u2 w2 theta2 gamma2 z1 z2]``
    (``BalamuruganNarayananFEM2.m``).

    The 8 nodal DOFs carry beam, PZT and VEM layers with Rayleigh damping; the
    two GHM dissipation coordinates :math:`z` couple to the VEM shear angle:

    .. math::

        K_s = A_s \\kappa (1 + \\alpha) \\int N_\\gamma^T N_\\gamma, \\quad
        K_{qz} = A_s \\alpha \\kappa \\int N_\\gamma^T N_z, \\quad
        K_z = A_s \\alpha \\kappa \\int N_z^T N_z, \\quad
        M_z = K_z / \\omega^2, \\quad C_z = 2 \\zeta K_z / \\omega .

    The piezoelectric load vector is :math:`E_c d_{31} b \\int N_{u_c}'`.
    """
    return acld_terms(p, length).combine(p)
