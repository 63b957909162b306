"""Tests of acld_gym.physics.elements: the Timoshenko and ACLD element matrices.

Reference matrices are typed in from the closed forms printed in the thesis
(/work/shared/seed/rodriguez-2006-acld-smc-lqr-thesis.txt, Appendix A):
``TimoshenkoFEM2.m`` (~line 1179) and ``BalamuruganNarayananFEM2.m`` (~line 1380),
and from eq. (32) of ch. 2 (piezo force vector). DOF orders:
beam ``[u1 w1 th1 u2 w2 th2]``, ACLD ``[u1 w1 th1 g1 u2 w2 th2 g2 z1 z2]``.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from numpy.testing import assert_allclose, assert_array_equal

from acld_gym.physics.elements import (
    acld_element,
    acld_terms,
    timoshenko_element,
    timoshenko_terms,
)
from acld_gym.physics.params import BeamParameters

P = BeamParameters()
LENGTHS = [0.03, 0.06, 0.09, 0.0075]
BEAM_W = [1, 4]  # w DOFs of the beam element
BEAM_U = [0, 3]
ACLD_W = [1, 5]
ACLD_U = [0, 4]
ACLD_G = [3, 7]  # gamma DOFs
Z = [8, 9]


def _assert_pd(A: np.ndarray) -> None:
    np.linalg.cholesky(A)  # raises LinAlgError if not positive definite
    assert np.linalg.eigvalsh(A).min() > 0


def _null_dim(K: np.ndarray, rtol: float = 1e-12) -> int:
    ev = np.linalg.eigvalsh(K)
    return int(np.sum(np.abs(ev) <= rtol * np.abs(ev).max()))


def _rigid_modes(n_node_dofs: int, le: float, n_extra: int = 0) -> np.ndarray:
    """Axial translation, transverse translation, rigid rotation (w = x*theta)."""
    n = 2 * n_node_dofs + n_extra
    r = np.zeros((n, 3))
    u1, w1, t1 = 0, 1, 2
    u2, w2, t2 = n_node_dofs, n_node_dofs + 1, n_node_dofs + 2
    r[[u1, u2], 0] = 1.0
    r[[w1, w2], 1] = 1.0
    r[[t1, t2], 2] = 1.0
    r[w2, 2] = le  # w(x) = x * theta0; node 1 at x = 0
    return r


# --- symmetry and definiteness ------------------------------------------------


@pytest.mark.parametrize("le", LENGTHS)
@pytest.mark.parametrize("make", [timoshenko_element, acld_element])
def test_symmetric(make, le):
    e = make(P, le)
    for A in (e.M, e.C, e.K):
        assert_allclose(A, A.T, rtol=0, atol=1e-14 * np.abs(A).max())


@pytest.mark.parametrize("le", LENGTHS)
@pytest.mark.parametrize("make", [timoshenko_element, acld_element])
def test_mass_positive_definite(make, le):
    e = make(P, le)
    _assert_pd(e.M)
    if make is acld_element:
        _assert_pd(e.M[8:, 8:])  # GHM (z) block on its own


@pytest.mark.parametrize("le", LENGTHS)
def test_beam_stiffness_psd_with_three_rigid_modes(le):
    # free-free 2-node Timoshenko element with one-point (reduced) shear integration:
    # rank 3 (extension, bending, shear), null space = 3 rigid-body modes
    K = timoshenko_element(P, le).K
    ev = np.linalg.eigvalsh(K)
    assert ev.min() >= -1e-12 * ev.max()
    assert _null_dim(K) == 3
    R = _rigid_modes(3, le)
    assert_allclose(K @ R, 0.0, atol=1e-12 * ev.max())
    # and the null space is exactly span(R)
    _, vecs = np.linalg.eigh(K)
    assert np.linalg.matrix_rank(np.column_stack([vecs[:, :3], R]), tol=1e-8) == 3


@pytest.mark.parametrize("le", [0.09, 0.0225])
@pytest.mark.parametrize("Es", [0.0, 14e6])
def test_acld_stiffness_psd_with_three_rigid_modes(le, Es):
    # the 10x10 ACLD element (incl. z): rigid modes have gamma = z = 0; the VEM shear
    # (kappa) and GHM terms make the gamma/z part positive definite
    p = dataclasses.replace(P, vem_youngs_modulus=Es)
    K = acld_element(p, le).K
    ev = np.linalg.eigvalsh(K)
    assert ev.min() >= -1e-12 * ev.max()
    assert _null_dim(K) == 3
    R = _rigid_modes(4, le, n_extra=2)
    assert_allclose(K @ R, 0.0, atol=1e-12 * ev.max())


def test_shear_uses_reduced_integration():
    # Reddy / Kwon & Bang (cited in TimoshenkoFEM2.m): one-point shear integration. The
    # antisymmetric rotation field theta = (-1 -> +1), w = 0 has zero shear strain at the
    # element centre, so its shear energy is zero; with exact (2-point) integration it
    # would be k G A Le / 3 > 0 (shear locking).
    K = timoshenko_terms(P, 0.06).units["beam.shear"]  # the shear term alone
    v = np.array([0, 0, -1.0, 0, 0, 1.0])
    assert abs(v @ K @ v) < 1e-20 * np.abs(K).max()


@pytest.mark.parametrize("le", LENGTHS)
@pytest.mark.parametrize(
    "make, terms", [(timoshenko_element, timoshenko_terms), (acld_element, acld_terms)]
)
def test_element_is_the_sum_of_its_terms(make, terms, le):
    # The parameter-affine form the randomized plants rely on: coefficients x unit matrices
    # reproduce the element, and scaling a material parameter scales its terms only.
    q = dataclasses.replace(P, beam_youngs_modulus=2 * P.beam_youngs_modulus)
    e, t = make(q, le), terms(P, le).combine(q)
    for a, b in ((e.M, t.M), (e.C, t.C), (e.K, t.K), (e.Pc, t.Pc)):
        np.testing.assert_allclose(b, a, rtol=1e-12, atol=1e-12 * np.abs(a).max())


# --- mass totals ----------------------------------------------------------------


@pytest.mark.parametrize("le", LENGTHS)
def test_beam_element_total_mass(le):
    # rho A Le from the translational DOFs (transverse and axial)
    M = timoshenko_element(P, le).M
    m = P.beam_density * P.beam_area * le
    one = np.ones(2)
    assert_allclose(one @ M[np.ix_(BEAM_W, BEAM_W)] @ one, m, rtol=1e-13)
    assert_allclose(one @ M[np.ix_(BEAM_U, BEAM_U)] @ one, m, rtol=1e-13)


@pytest.mark.parametrize("le", LENGTHS)
def test_acld_element_total_mass(le):
    # beam + VEM + PZT mass per unit length, times Le; axial rigid motion moves all layers
    M = acld_element(P, le).M
    m = (
        P.beam_density * P.beam_area + P.vem_density * P.vem_area + P.pzt_density * P.pzt_area
    ) * le
    one = np.ones(2)
    assert_allclose(one @ M[np.ix_(ACLD_W, ACLD_W)] @ one, m, rtol=1e-13)
    assert_allclose(one @ M[np.ix_(ACLD_U, ACLD_U)] @ one, m, rtol=1e-13)


# --- piezo force vector -----------------------------------------------------------


@pytest.mark.parametrize("le", LENGTHS)
def test_acld_piezo_vector_eq32(le):
    # thesis eq. (32): Pc_e = Ec d31 b [-1 0 h -ts 1 0 -h ts] (independent of Le), z rows 0
    h, ts = P.pzt_offset, P.vem_thickness
    expected = (
        P.pzt_youngs_modulus * P.d31 * P.width * np.array([-1, 0, h, -ts, 1, 0, -h, ts, 0, 0])
    )
    assert_allclose(acld_element(P, le).Pc, expected, rtol=1e-13, atol=0)
    assert_array_equal(timoshenko_element(P, le).Pc, np.zeros(6))


# --- comparison with the printed MATLAB closed forms --------------------------------


def _timoshenko_matlab(p: BeamParameters, Le: float):
    """TimoshenkoFEM2.m as printed in Appendix A."""
    Eb, Gb, rhob, k = (
        p.beam_youngs_modulus,
        p.beam_shear_modulus,
        p.beam_density,
        p.shear_correction,
    )
    Ab, Ib = p.width * p.beam_thickness, p.width * p.beam_thickness**3 / 12
    z = np.zeros(6)
    Kwbb = Eb * Ib / Le * np.array([z, z, [0, 0, 1, 0, 0, -1], z, z, [0, 0, -1, 0, 0, 1]])
    Kwbs = (
        Gb
        * Ab
        * k
        / 4
        / Le
        * np.array(
            [
                [0, 0, 0, 0, 0, 0],
                [0, 4, 2 * Le, 0, -4, 2 * Le],
                [0, 2 * Le, Le**2, 0, -2 * Le, Le**2],
                [0, 0, 0, 0, 0, 0],
                [0, -4, -2 * Le, 0, 4, -2 * Le],
                [0, 2 * Le, Le**2, 0, -2 * Le, Le**2],
            ]
        )
    )
    Kub = Eb * Ab / Le * np.array([[1, 0, 0, -1, 0, 0], z, z, [-1, 0, 0, 1, 0, 0], z, z])
    Mwb = (
        rhob
        * Le
        / 6
        * np.array(
            [
                [0, 0, 0, 0, 0, 0],
                [0, 2 * Ab, 0, 0, Ab, 0],
                [0, 0, 2 * Ib, 0, 0, Ib],
                [0, 0, 0, 0, 0, 0],
                [0, Ab, 0, 0, 2 * Ab, 0],
                [0, 0, Ib, 0, 0, 2 * Ib],
            ]
        )
    )
    Mub = rhob * Ab * Le / 6 * np.array([[2, 0, 0, 1, 0, 0], z, z, [1, 0, 0, 2, 0, 0], z, z])
    Me = Mwb + Mub
    Ke = Kwbb + Kwbs + Kub
    Ce = p.rayleigh_mass * Me + p.rayleigh_stiffness * Ke
    return Me, Ce, Ke


@pytest.mark.parametrize("le", LENGTHS)
def test_timoshenko_element_matches_matlab(le):
    Me, Ce, Ke = _timoshenko_matlab(P, le)
    e = timoshenko_element(P, le)
    assert_allclose(e.M, Me, rtol=1e-12, atol=1e-15 * np.abs(Me).max())
    assert_allclose(e.K, Ke, rtol=1e-12, atol=1e-15 * np.abs(Ke).max())
    assert_allclose(e.C, Ce, rtol=1e-12, atol=1e-15 * np.abs(Ce).max())


def _embed8(m6: np.ndarray) -> np.ndarray:
    """Beam-layer 6x6 [u w th]x2 into the ACLD 8x8 [u w th g]x2 (gamma rows zero)."""
    idx = [0, 1, 2, 4, 5, 6]
    out = np.zeros((8, 8))
    out[np.ix_(idx, idx)] = m6
    return out


def _acld_matlab(p: BeamParameters, Le: float):
    """BalamuruganNarayananFEM2.m as printed in Appendix A (10x10 M, C, K)."""
    tb, ts, tc, b = p.beam_thickness, p.vem_thickness, p.pzt_thickness, p.width
    As, Ac = b * ts, b * tc
    Is = b * ts**3 / 12
    h = ts + (tb + tc) / 2
    Ec, Es = p.pzt_youngs_modulus, p.vem_youngs_modulus
    rhoc, rhos = p.pzt_density, p.vem_density
    kappa, alpha, omega, chi = p.ghm_kappa, p.ghm_alpha, p.ghm_omega, p.ghm_zeta
    # Beam layer: same closed forms as TimoshenkoFEM2 (Kwbb, Kwbs, Kub, Mwb, Mub)
    Mb, _, Kb = _timoshenko_matlab(dataclasses.replace(p, rayleigh_mass=0.0), Le)
    # PZT bending/shear/transverse mass: same forms with Ec, Gc, rhoc, Ac, Ic
    pc = dataclasses.replace(
        p,
        beam_youngs_modulus=Ec,
        beam_shear_modulus=p.pzt_shear_modulus,
        beam_density=rhoc,
        beam_thickness=tc,
    )
    Mc6, _, Kc6 = _timoshenko_matlab(pc, Le)
    # drop the PZT's own axial terms (Kub/Mub pattern); Kuc/Muc below replace them
    Kc6[np.ix_([0, 3], [0, 3])] = 0.0
    Mc6[np.ix_([0, 3], [0, 3])] = 0.0
    z8 = np.zeros(8)
    Kuc = (
        Ec
        * Ac
        / Le
        * np.array(
            [
                [1, 0, -h, ts, -1, 0, h, -ts],
                z8,
                [-h, 0, h**2, -h * ts, h, 0, -(h**2), h * ts],
                [ts, 0, -h * ts, ts**2, -ts, 0, h * ts, -(ts**2)],
                [-1, 0, h, -ts, 1, 0, -h, ts],
                z8,
                [h, 0, -(h**2), h * ts, -h, 0, h**2, -h * ts],
                [-ts, 0, h * ts, -(ts**2), ts, 0, -h * ts, ts**2],
            ]
        )
    )
    Muc = (
        rhoc
        * Ac
        * Le
        * np.array(
            [
                [1 / 3, 0, -h / 3, ts / 3, 1 / 6, 0, -h / 6, ts / 6],
                z8,
                [-h / 3, 0, h**2 / 3, -h * ts / 3, -h / 6, 0, h**2 / 6, -h * ts / 6],
                [ts / 3, 0, -h * ts / 3, ts**2 / 3, ts / 6, 0, -h * ts / 6, ts**2 / 6],
                [1 / 6, 0, -h / 6, ts / 6, 1 / 3, 0, -h / 3, ts / 3],
                z8,
                [-h / 6, 0, h**2 / 6, -h * ts / 6, -h / 3, 0, h**2 / 3, -h * ts / 3],
                [ts / 6, 0, -h * ts / 6, ts**2 / 6, ts / 3, 0, -h * ts / 3, ts**2 / 3],
            ]
        )
    )
    # VEM
    c = (tb + ts) / 2
    Kwsb = (
        Es
        * Is
        / Le
        * np.array([z8, z8, [0, 0, 1, 0, 0, 0, -1, 0], z8, z8, z8, [0, 0, -1, 0, 0, 0, 1, 0], z8])
    )
    Kus = (
        Es
        * As
        / Le
        * np.array(
            [
                [1, 0, -c, ts / 2, -1, 0, c, -ts / 2],
                z8,
                [-c, 0, c**2, -c * ts / 2, c, 0, -(c**2), c * ts / 2],
                [ts / 2, 0, -c * ts / 2, ts**2 / 4, -ts / 2, 0, c * ts / 2, -(ts**2) / 4],
                [-1, 0, c, -ts / 2, 1, 0, -c, ts / 2],
                z8,
                [c, 0, -(c**2), c * ts / 2, -c, 0, c**2, -c * ts / 2],
                [-ts / 2, 0, c * ts / 2, -(ts**2) / 4, ts / 2, 0, -c * ts / 2, ts**2 / 4],
            ]
        )
    )
    Ks = (
        As
        * (kappa + alpha * kappa)
        * Le
        * np.array(
            [
                z8,
                z8,
                z8,
                [0, 0, 0, 1 / 3, 0, 0, 0, 1 / 6],
                z8,
                z8,
                z8,
                [0, 0, 0, 1 / 6, 0, 0, 0, 1 / 3],
            ]
        )
    )
    Mws = (
        rhos
        * Le
        * np.array(
            [
                z8,
                [0, As / 3, 0, 0, 0, As / 6, 0, 0],
                [0, 0, Is / 3, 0, 0, 0, Is / 6, 0],
                z8,
                z8,
                [0, As / 6, 0, 0, 0, As / 3, 0, 0],
                [0, 0, Is / 6, 0, 0, 0, Is / 3, 0],
                z8,
            ]
        )
    )
    tbs = tb + ts
    Mus = (
        rhos
        * As
        * Le
        * np.array(
            [
                [1 / 3, 0, -tbs / 6, ts / 6, 1 / 6, 0, -tbs / 12, ts / 12],
                z8,
                [
                    -tbs / 6,
                    0,
                    tbs**2 / 12,
                    -tbs * ts / 12,
                    -tbs / 12,
                    0,
                    tbs**2 / 24,
                    -tbs * ts / 24,
                ],
                [ts / 6, 0, -tbs * ts / 12, ts**2 / 12, ts / 12, 0, -tbs * ts / 24, ts**2 / 24],
                [1 / 6, 0, -tbs / 12, ts / 12, 1 / 3, 0, -tbs / 6, ts / 6],
                z8,
                [
                    -tbs / 12,
                    0,
                    tbs**2 / 24,
                    -tbs * ts / 24,
                    -tbs / 6,
                    0,
                    tbs**2 / 12,
                    -tbs * ts / 12,
                ],
                [ts / 12, 0, -tbs * ts / 24, ts**2 / 24, ts / 6, 0, -tbs * ts / 12, ts**2 / 12],
            ]
        )
    )
    Kqz = (
        As
        * alpha
        * kappa
        * Le
        * np.array([[0, 0], [0, 0], [0, 0], [1 / 3, 1 / 6], [0, 0], [0, 0], [0, 0], [1 / 6, 1 / 3]])
    )
    Kz = As * alpha * kappa * Le * np.array([[1 / 3, 1 / 6], [1 / 6, 1 / 3]])
    # printed Mz has [1/3 1/3; 1/6 1/3] (a typesetting slip); the eq. (28) form is
    # Kz / omega^2, symmetric
    Mz = Kz / omega**2
    Cz = 2 * As * alpha * kappa * Le * chi / omega * np.array([[1 / 3, 1 / 6], [1 / 6, 1 / 3]])

    Me = _embed8(Mb) + _embed8(Mc6) + Mws + Muc + Mus
    Ke = _embed8(Kb) + _embed8(Kc6) + Kuc + Kwsb + Kus + Ks
    M = np.block([[Me, np.zeros((8, 2))], [np.zeros((2, 8)), Mz]])
    C = np.block(
        [
            [p.rayleigh_mass * Me + p.rayleigh_stiffness * Ke, np.zeros((8, 2))],
            [np.zeros((2, 8)), Cz],
        ]
    )
    K = np.block([[Ke, -Kqz], [-Kqz.T, Kz]])
    return M, C, K


@pytest.mark.parametrize("le", [0.09, 0.03])
@pytest.mark.parametrize("Es", [0.0, 14e6])  # MATLAB: Es = 0*14e6
def test_acld_element_matches_matlab(le, Es):
    p = dataclasses.replace(P, vem_youngs_modulus=Es)
    M, C, K = _acld_matlab(p, le)
    e = acld_element(p, le)
    for got, want in ((e.M, M), (e.C, C), (e.K, K)):
        assert_allclose(got, want, rtol=1e-10, atol=1e-13 * np.abs(want).max())


# --- GHM ------------------------------------------------------------------------


def _condensed(K: np.ndarray) -> np.ndarray:
    """Static condensation of the z DOFs: K_qq - K_qz K_zz^-1 K_zq."""
    return K[:8, :8] - K[:8, 8:] @ np.linalg.solve(K[8:, 8:], K[8:, :8])


@pytest.mark.parametrize("le", [0.09, 0.03])
def test_ghm_static_limit_is_equilibrium_modulus(le):
    # GHM, thesis eq. (20): s G(s) -> kappa as s -> 0; the high-frequency modulus is
    # kappa (1 + alpha). Statically condensing z must leave As * kappa * int(Ng^T Ng).
    base = acld_element(P, le).K
    Kc = _condensed(base)
    # 1) independent of alpha (the mini-oscillator strength drops out at DC)
    for alpha in (0.5, 3.0):
        K_alpha = acld_element(dataclasses.replace(P, ghm_alpha=alpha), le).K
        assert_allclose(_condensed(K_alpha), Kc, rtol=1e-10, atol=1e-12 * np.abs(Kc).max())
        assert not np.allclose(K_alpha[:8, :8], base[:8, :8])  # unlike the uncondensed one
    # 2) the condensed VEM shear stiffness is kappa * As * Le/6 [[2, 1], [1, 2]] on gamma
    k2 = 2.5 * P.ghm_kappa
    Kc2 = _condensed(acld_element(dataclasses.replace(P, ghm_kappa=k2), le).K)
    diff = Kc2 - Kc
    expected = np.zeros((8, 8))
    expected[np.ix_(ACLD_G, ACLD_G)] = (
        (k2 - P.ghm_kappa) * P.vem_area * le / 6 * np.array([[2, 1], [1, 2]])
    )
    assert_allclose(diff, expected, rtol=1e-9, atol=1e-9 * np.abs(expected).max())
    # 3) the uncondensed (instantaneous) stiffness carries kappa (1 + alpha)
    Kq2 = acld_element(dataclasses.replace(P, ghm_kappa=k2), le).K[:8, :8]
    expected_hf = expected * (1 + P.ghm_alpha)
    assert_allclose(
        Kq2 - base[:8, :8], expected_hf, rtol=1e-9, atol=1e-9 * np.abs(expected_hf).max()
    )


@pytest.mark.parametrize("le", [0.09, 0.03])
def test_damping_rayleigh_and_ghm_blocks(le):
    # thesis MATLAB: Cea = [a_hat*Me + b_hat*Ke, 0; 0, Cz], Cz = 2 chi/omega Kz,
    # Mz = Kz/omega^2 (eqs. 27-29), no mass/damping coupling between q and z
    e = acld_element(P, le)
    a, b = P.rayleigh_mass, P.rayleigh_stiffness
    assert_allclose(
        e.C[:8, :8], a * e.M[:8, :8] + b * e.K[:8, :8], rtol=1e-13, atol=1e-16 * np.abs(e.C).max()
    )
    Kz = e.K[8:, 8:]
    assert_allclose(
        Kz, P.vem_area * P.ghm_alpha * P.ghm_kappa * le / 6 * np.array([[2, 1], [1, 2]]), rtol=1e-13
    )
    assert_allclose(e.C[8:, 8:], 2 * P.ghm_zeta / P.ghm_omega * Kz, rtol=1e-13)
    assert_allclose(e.M[8:, 8:], Kz / P.ghm_omega**2, rtol=1e-13)
    for A in (e.M, e.C):
        assert_array_equal(A[:8, 8:], 0.0)
        assert_array_equal(A[8:, :8], 0.0)
    # z couples to gamma only (stiffness): K_qz nonzero only in gamma rows
    rows = np.flatnonzero(np.any(e.K[:8, 8:] != 0, axis=1))
    assert_array_equal(rows, ACLD_G)


@pytest.mark.parametrize("le", LENGTHS)
def test_beam_rayleigh_damping(le):
    e = timoshenko_element(P, le)
    assert_allclose(
        e.C,
        P.rayleigh_mass * e.M + P.rayleigh_stiffness * e.K,
        rtol=1e-13,
        atol=1e-16 * np.abs(e.C).max(),
    )
    # and the coefficients actually act (not both zero)
    e0 = timoshenko_element(dataclasses.replace(P, rayleigh_mass=0.0, rayleigh_stiffness=0.0), le)
    assert_array_equal(e0.C, 0.0)
    assert np.abs(e.C).max() > 0
