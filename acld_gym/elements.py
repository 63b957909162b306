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

from dataclasses import dataclass

import numpy as np

from .params import BeamParameters

__all__ = ["ElementMatrices", "timoshenko_element", "acld_element", "BEAM_NODE_DOFS",
           "ACLD_NODE_DOFS"]

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


def _beam_layer(sh: _Shape, E: float, G: float, rho: float, A: float, I: float,
                k_shear: float) -> tuple[np.ndarray, np.ndarray]:
    """Timoshenko layer on the beam axis: bending, reduced-integration shear,
    extension (stiffness) and transverse/rotary plus axial inertia (mass).

    .. math::

        K = E I \\int N_\\theta'^T N_\\theta'
            + k G A \\int_{1pt} (N_\\theta - N_w')^T (N_\\theta - N_w')
            + E A \\int N_u'^T N_u', \\quad
        M = \\rho \\int (A N_w^T N_w + I N_\\theta^T N_\\theta + A N_u^T N_u)
    """
    K = sh.integrate(lambda x: E * I * _outer(sh.dN("theta")) + E * A * _outer(sh.dN("u")))
    K = K + sh.integrate(lambda x: k_shear * G * A * _outer(sh.N("theta", x) - sh.dN("w")),
                         points=1)
    M = sh.integrate(lambda x: rho * (A * _outer(sh.N("w", x)) + I * _outer(sh.N("theta", x))
                                      + A * _outer(sh.N("u", x))))
    return M, K


def timoshenko_element(p: BeamParameters, length: float) -> ElementMatrices:
    """Plain-beam element, DOFs ``[u1 w1 theta1 u2 w2 theta2]`` (``TimoshenkoFEM2.m``).

    Rayleigh damping :math:`C = \\hat a M + \\hat b K`.
    """
    sh = _Shape(BEAM_NODE_DOFS, length)
    M, K = _beam_layer(sh, p.beam_youngs_modulus, p.beam_shear_modulus, p.beam_density,
                       p.beam_area, p.beam_inertia, p.shear_correction)
    C = p.rayleigh_mass * M + p.rayleigh_stiffness * K
    return ElementMatrices(M=M, C=C, K=K, Pc=np.zeros(sh.n))


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
    """
    sh = _Shape(ACLD_NODE_DOFS, length)
    tb, ts, h = p.beam_thickness, p.vem_thickness, p.pzt_offset
    # Beam and PZT are Timoshenko layers (the PZT's own bending and shear).
    Mb, Kb = _beam_layer(sh, p.beam_youngs_modulus, p.beam_shear_modulus, p.beam_density,
                         p.beam_area, p.beam_inertia, p.shear_correction)
    Mc, Kc = _beam_layer(sh, p.pzt_youngs_modulus, p.pzt_shear_modulus, p.pzt_density,
                         p.pzt_area, p.pzt_inertia, p.shear_correction)
    # The PZT's axial motion is u_c, not u: replace its axial terms accordingly.
    Mc = Mc - sh.integrate(lambda x: p.pzt_density * p.pzt_area * _outer(sh.N("u", x)))
    Kc = Kc - sh.integrate(lambda x: p.pzt_youngs_modulus * p.pzt_area * _outer(sh.dN("u")))

    def u_c(x):
        return sh.N("u", x) - h * sh.N("theta", x) + ts * sh.N("gamma", x)

    def du_c():
        return sh.dN("u") - h * sh.dN("theta") + ts * sh.dN("gamma")

    def u_s(x):
        return sh.N("u", x) - 0.5 * (tb + ts) * sh.N("theta", x) + 0.5 * ts * sh.N("gamma", x)

    def du_s():
        return sh.dN("u") - 0.5 * (tb + ts) * sh.dN("theta") + 0.5 * ts * sh.dN("gamma")

    Mc = Mc + sh.integrate(lambda x: p.pzt_density * p.pzt_area * _outer(u_c(x)))
    Kc = Kc + sh.integrate(lambda x: p.pzt_youngs_modulus * p.pzt_area * _outer(du_c()))
    # VEM: transverse/rotary and axial inertia; bending and extension with E_s;
    # shear with the GHM high-frequency modulus kappa (1 + alpha).
    As, Is = p.vem_area, p.vem_inertia
    Ms = sh.integrate(lambda x: p.vem_density * (As * _outer(sh.N("w", x))
                                                 + Is * _outer(sh.N("theta", x))
                                                 + As * _outer(u_s(x))))
    Ks = sh.integrate(lambda x: p.vem_youngs_modulus * (Is * _outer(sh.dN("theta"))
                                                        + As * _outer(du_s()))
                      + As * p.ghm_kappa * (1.0 + p.ghm_alpha) * _outer(sh.N("gamma", x)))
    Me = Mb + Mc + Ms
    Ke = Kb + Kc + Ks
    Ce = p.rayleigh_mass * Me + p.rayleigh_stiffness * Ke

    # GHM dissipation coordinates.
    def Nz(x):
        return np.array([1.0 - x / length, x / length])

    ak = As * p.ghm_alpha * p.ghm_kappa
    Kqz = sh.integrate(lambda x: ak * np.outer(sh.N("gamma", x), Nz(x)))
    Kz = sh.integrate(lambda x: ak * np.outer(Nz(x), Nz(x)))
    Mz = Kz / p.ghm_omega**2
    Cz = Kz * 2.0 * p.ghm_zeta / p.ghm_omega

    n = sh.n
    M = np.zeros((n + 2, n + 2))
    C = np.zeros_like(M)
    K = np.zeros_like(M)
    M[:n, :n], M[n:, n:] = Me, Mz
    C[:n, :n], C[n:, n:] = Ce, Cz
    K[:n, :n], K[n:, n:] = Ke, Kz
    K[:n, n:], K[n:, :n] = -Kqz, -Kqz.T
    Pc = np.zeros(n + 2)
    Pc[:n] = p.piezo_force_per_volt * sh.integrate(lambda x: du_c(), points=1)
    return ElementMatrices(M=M, C=C, K=K, Pc=Pc)
