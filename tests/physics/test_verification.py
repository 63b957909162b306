"""Independent verification of the finite-element model against closed-form results
(GitHub issue 13, item 2).

Provenance: every reference number is computed by ``tests/physics/closed_form.py`` (no code
shared with acld_gym; its docstrings give author, year and equation of each formula)
from the parameters of :class:`acld_gym.physics.params.BeamParameters` (the thesis's MATLAB
values): aluminium beam 300 x 15 x 3 mm, E = 70 GPa, G = 26 GPa, rho = 2700 kg/m^3,
k = 5/6; PZT 1 mm (E = 64.9 GPa, rho = 7600); VEM 0.25 mm (rho = 1250, GHM kappa =
1e6 Pa, alpha = 1, omega = 1000 rad/s, zeta = 4, no extensional modulus). Rayleigh
damping is switched off everywhere (``rayleigh_mass = rayleigh_stiffness = 0``).
Numbers quoted as "measured" in comments were measured with this code (numpy 2.4,
scipy 1.17) and are documentation, the asserted tolerances are justified next to them.

1. Bare beam (``patch_length = 0``, no ACLD element): frequencies of modes 1-3 against
   the clamped-free Timoshenko frequency equation, the Euler-Bernoulli values for
   contrast, O(h^2) mesh convergence, and the static tip deflection.
2. Fully covered passive sandwich beam: complex poles (frequencies and modal loss
   factors) of modes 1-3 against the Mead-Markus sandwich theory solved exactly for
   the cantilever, and against RKU with the "equivalent wavelength" of the cantilever
   (which turns out to be a poor approximation here, see
   :func:`test_rku_equivalent_wavelength_is_crude_for_this_cantilever`).
"""

from __future__ import annotations

import numpy as np
import pytest
import scipy.sparse.linalg as spla
from closed_form import (
    Sandwich,
    cantilever_beta_l,
    euler_bernoulli_cantilever,
    ghm_modulus,
    loss_factor,
    mead_markus_flexural_rigidity,
    mead_markus_pole,
    reduced_integration_tip_deflection,
    rku_flexural_rigidity,
    rku_pole,
    timoshenko_cantilever_frequencies,
    timoshenko_tip_deflection,
)
from numpy.testing import assert_allclose

from acld_gym.physics.model import build_model, parametric_model
from acld_gym.physics.params import BeamParameters, Mesh

P = BeamParameters()
L = P.length
NO_RAYLEIGH = {"rayleigh_mass": 0.0, "rayleigh_stiffness": 0.0}
BARE = {"patch_start": 0.0, "patch_length": 0.0, "n_before": 0, "n_patch": 0, **NO_RAYLEIGH}
FULL = {"patch_start": 0.0, "patch_length": L, "n_before": 0, "n_after": 0, **NO_RAYLEIGH}

# beam section properties for the closed forms
E, G, KS, RHO = P.beam_youngs_modulus, P.beam_shear_modulus, P.shear_correction, P.beam_density
A, I = P.beam_area, P.beam_inertia
# closed_form: Timoshenko clamped-free frequency equation -> 172.2544, 1078.972,
# 3018.770 rad/s; Euler-Bernoulli (beta_n L = 1.8751, 4.6941, 7.8548) -> 172.2686,
# 1079.589, 3022.879 rad/s, i.e. Timoshenko lower by 0.008 %, 0.057 %, 0.136 %.
OMEGA_T = timoshenko_cantilever_frequencies(E, G, KS, RHO, A, I, L)
OMEGA_EB = euler_bernoulli_cantilever(E, I, RHO, A, L)


def bare_beam(n: int, **overrides):
    """A plain aluminium cantilever of ``n`` equal Timoshenko elements, no damping."""
    return build_model(n_after=n, **{**BARE, **overrides})


# --- the patch-free beam can be built ---------------------------------------------


def test_bare_beam_has_no_acld_element():
    m = bare_beam(10)
    assert [kind for kind, _, _ in m.dofs.elements] == ["beam"] * 10
    assert m.dofs.z_dofs == ()
    assert all(set(nd) == {"u", "w", "theta"} for nd in m.dofs.node_dofs)
    assert m.n_dofs == 3 * 10  # 11 nodes x (u, w, theta) minus the clamped node
    assert_allclose(m.dofs.node_x, np.linspace(0.0, L, 11), atol=1e-15)
    assert not np.any(m.Pc)  # no actuator
    assert not np.any(m.C)  # Rayleigh off and no VEM: undamped
    # 3 beam elements of the thesis mesh can be reused as-is for a bare beam too
    assert bare_beam(3).n_states == 18


@pytest.mark.parametrize(
    "overrides,field",
    [
        # a zero-length patch must not carry ACLD elements ...
        ({"patch_start": 0.0, "patch_length": 0.0, "n_before": 0, "n_patch": 1}, "n_patch"),
        # ... and a real patch needs at least one
        ({"patch_start": 0.0, "n_before": 0, "n_patch": 0}, "n_patch"),
        ({"n_patch": 0}, "n_patch"),  # the thesis's patch with n_patch = 0
        # n_patch = 0 is for the bare beam, whose elements are all counted in n_after
        ({"patch_start": 0.0, "patch_length": 0.0, "n_before": 1, "n_patch": 0}, "n_patch"),
        # a bare beam has no patch position
        ({"patch_start": 0.03, "patch_length": 0.0, "n_before": 0, "n_patch": 0}, "patch_start"),
        ({"patch_length": -0.01}, "patch_length"),
    ],
)
def test_zero_patch_validation(overrides, field):
    with pytest.raises(ValueError, match=rf"\b{field}\b"):
        build_model(**overrides)


def test_mesh_zero_patch_only_without_elements_before():
    assert Mesh(0, 0, 5).n_patch == 0
    with pytest.raises(ValueError, match="n_patch"):
        Mesh(1, 0, 3)
    with pytest.raises(ValueError, match="n_patch"):
        Mesh(0, -1, 3)


# --- the closed forms themselves ------------------------------------------------------


def test_reference_beam_closed_forms():
    # tabulated clamped-free roots (Thomson, App. D.3; Rayleigh): 1.8751, 4.6941, 7.8548
    assert_allclose(cantilever_beta_l(3), [1.87510407, 4.69409113, 7.85475744], atol=1e-8)
    # Timoshenko < Euler-Bernoulli, by an amount growing with the mode number ...
    rel = OMEGA_T / OMEGA_EB - 1.0
    assert np.all(rel < 0) and np.all(np.diff(rel) < 0)
    # ... which scales with (t/L)^2 (rotary inertia and shear ~ (beta r)^2) and vanishes
    # in the slender limit: the frequency equation reduces to 1 + cos(bL) cosh(bL) = 0
    for scale in (10.0, 100.0):
        rel_s = (
            timoshenko_cantilever_frequencies(E, G, KS, RHO, A, I, scale * L)
            / euler_bernoulli_cantilever(E, I, RHO, A, scale * L)
            - 1.0
        )
        assert_allclose(rel_s, rel / scale**2, rtol=5e-3)  # to O((t/L)^2), measured 2e-3


def test_reference_static_closed_forms():
    exact = timoshenko_tip_deflection(1.0, E, G, KS, A, I, L)
    # P L^3/(3EI) = 3.8095e-3 m, P L/(kGA) = 3.077e-7 m
    assert exact == pytest.approx(L**3 / (3 * E * I) + L / (KS * G * A), rel=1e-15)
    for n in (1, 4, 100):
        fe = reduced_integration_tip_deflection(1.0, E, G, KS, A, I, L, n)
        assert exact - fe == pytest.approx(L**3 / (12 * E * I * n**2), rel=1e-9)


# --- 1. bare beam: frequencies ------------------------------------------------------

MESHES = (25, 50, 100, 200)


def lowest_frequencies(n: int) -> np.ndarray:
    """Lowest three undamped frequencies [rad/s] of the bare beam on ``n`` elements, from
    the model's sparse K and M (shift-invert Lanczos: cheap and insensitive to BLAS
    threading on a busy machine, unlike the dense ``undamped_frequencies``, which
    gives the same values, see below). The axial modes start at ~26 600 rad/s, far
    above bending mode 3."""
    M, _, K, _ = parametric_model(n_after=n, **BARE).combine()
    w2 = spla.eigsh(K.tocsc(), k=3, M=M.tocsc(), sigma=0.0, return_eigenvectors=False)
    return np.sqrt(np.sort(w2))


@pytest.fixture(scope="module")
def bare_frequencies():
    """Lowest three frequencies on 25, 50, 100, 200 elements."""
    return {n: lowest_frequencies(n) for n in MESHES}


def test_sparse_and_dense_bare_frequencies_agree(bare_frequencies):
    # the dense solver loses ~1e-8 on mode 1 (eigenvalue spread: the axial and shear
    # modes of 6 mm elements are ~1e8 x omega_1^2, so eps x 1e8 ~ 2e-8 on omega_1^2);
    # measured 7e-9, 2e-10, 8e-11 with this machine's kernels, 5.6e-8 on mode 1 with
    # OpenBLAS's Sandybridge kernels
    assert_allclose(bare_beam(50).undamped_frequencies()[:3], bare_frequencies[50], rtol=2e-7)


def test_bare_beam_frequencies_match_timoshenko(bare_frequencies):
    fe = bare_frequencies[200]
    err_t = fe / OMEGA_T - 1.0
    err_eb = fe / OMEGA_EB - 1.0
    # requirement: within 0.1 % of the Timoshenko closed form.
    # measured (200 elements): +0.0003 %, +0.006 %, +0.018 %
    assert np.all(np.abs(err_t) < 1e-3), err_t
    # and much closer to Timoshenko than to Euler-Bernoulli (measured: |err_eb| =
    # 0.008 %, 0.051 %, 0.118 %, i.e. 26x, 8x, 7x the Timoshenko error)
    assert np.all(np.abs(err_t) < np.abs(err_eb) / 5), (err_t, err_eb)
    # Richardson extrapolation of the O(h^2) error from 100 and 200 elements removes the
    # discretisation error: then the FE reproduces Timoshenko theory to ~1e-7
    # (measured: 7e-10, 8e-9, 8e-8); the tolerance is 80x below the Timoshenko/EB
    # difference of mode 1
    extrap = (4 * fe - bare_frequencies[100]) / 3
    assert_allclose(extrap, OMEGA_T, rtol=1e-6)


def test_bare_beam_frequency_convergence_rate(bare_frequencies):
    n = np.array(MESHES, dtype=float)
    err = np.array([bare_frequencies[k] / OMEGA_T - 1.0 for k in MESHES])  # (mesh, mode)
    # consistent mass + stiff (not locked) element: convergence from above
    assert np.all(err > 0)
    slopes = [np.polyfit(np.log(n), np.log(err[:, j]), 1)[0] for j in range(3)]
    # linear elements: eigenvalue error O(h^2). measured: -1.999, -2.001, -2.003
    assert_allclose(slopes, -2.0, atol=0.05)


# --- 1. bare beam: statics -----------------------------------------------------------


@pytest.mark.parametrize("shear_modulus", [G, G * 1e-4])  # the second makes shear ~ bending
@pytest.mark.parametrize("n", [1, 2, 3, 10, 40])
def test_bare_beam_static_tip_deflection(n, shear_modulus):
    """Finding: the tip deflection of this element (linear w and theta, one-point shear
    integration) is *not* exact on every mesh. The shear part P L/(kGA) and the nodal
    rotations are exact, but the bending part is short by exactly P L^3/(12 E I N^2),
    a relative error -1/(4 N^2) of P L^3/(3EI) (the trapezoidal rule of the quadratic
    rotation, see closed_form.reduced_integration_tip_deflection): 25 % on one element,
    0.016 % on 40. The FE reproduces that closed form to round-off."""
    m = bare_beam(n, beam_shear_modulus=shear_modulus)
    fe = m.static_tip_deflection(1.0)
    exact = timoshenko_tip_deflection(1.0, E, shear_modulus, KS, A, I, L)
    predicted = reduced_integration_tip_deflection(1.0, E, shear_modulus, KS, A, I, L, n)
    assert fe == pytest.approx(predicted, rel=1e-9)  # measured: <= 3e-10
    bending = L**3 / (3 * E * I)
    assert (fe - exact) / bending == pytest.approx(-0.25 / n**2, abs=1e-9)


# --- 2. fully covered sandwich beam ---------------------------------------------------

SANDWICH = Sandwich(
    b=P.width,
    L=L,
    E1=P.beam_youngs_modulus,
    t1=P.beam_thickness,
    rho1=P.beam_density,
    t2=P.vem_thickness,
    rho2=P.vem_density,
    E3=P.pzt_youngs_modulus,
    t3=P.pzt_thickness,
    rho3=P.pzt_density,
    E2=P.vem_youngs_modulus,
)


def ghm(s: complex) -> complex:
    """The VEM's GHM shear modulus G(s) [Pa] (thesis eq. (20), default parameters)."""
    return ghm_modulus(s, P.ghm_kappa, P.ghm_alpha, P.ghm_omega, P.ghm_zeta)


#: "equivalent wavelength" of the cantilever's modes: k_n = beta_n / L
K_CANTILEVER = cantilever_beta_l(3) / L


@pytest.fixture(scope="module")
def reference_poles():
    """Closed-form complex eigenvalues [1/s] of modes 1-3 (closed_form):
    RKU with k_n = beta_n/L, and Mead-Markus solved for the cantilever; each with the
    GHM modulus at the pole, G(lambda), or at the real frequency, G(j omega_n)."""
    out = {}
    for at in ("pole", "real"):
        rku = [rku_pole(SANDWICH, k, ghm, evaluate_at=at) for k in K_CANTILEVER]
        out["rku", at] = np.array(rku)
        out["mm", at] = np.array(
            [mead_markus_pole(SANDWICH, ghm, lam, evaluate_at=at) for lam in rku]
        )
    return out


def sandwich_poles(n: int) -> np.ndarray:
    """The three lowest oscillatory poles (Im > 0) of the fully covered FE model on ``n``
    ACLD elements. The other poles are the overdamped (real) GHM poles and the higher
    bending, axial and shear modes."""
    p = build_model(n_patch=n, **FULL).poles
    osc = p[p.imag > 1e-6 * np.abs(p)]
    return osc[np.argsort(np.abs(osc))][:3]


def extrapolated(coarse: np.ndarray, fine: np.ndarray) -> np.ndarray:
    """Richardson extrapolation of an O(h^2) quantity from meshes h and h/2."""
    return (4 * fine - coarse) / 3


@pytest.fixture(scope="module")
def fe_poles():
    """Poles on 20 and 40 ACLD elements (242 and 482 states, well under a second) and
    their Richardson extrapolation "ext"."""
    out = {n: sandwich_poles(n) for n in (20, 40)}
    out["ext"] = extrapolated(out[20], out[40])
    return out


def test_reference_sandwich_closed_forms_agree_with_each_other():
    for G2 in (ghm(0.0), ghm(1000j), 3.0e6 + 2.0e6j):
        for k in K_CANTILEVER:
            # RKU with a shear-only core (E2 = 0) is Mead-Markus' D_t (1 + Y g/(g + k^2))
            assert rku_flexural_rigidity(SANDWICH, G2, k) == pytest.approx(
                mead_markus_flexural_rigidity(SANDWICH, G2, k), rel=1e-12
            )
    # the transfer-matrix solution reproduces RKU exactly where RKU is exact (pinned
    # ends, sinusoidal modes k = n pi / L)
    for n in (1, 2, 3):
        k = n * np.pi / L
        lam = rku_pole(SANDWICH, k, ghm)
        assert mead_markus_pole(
            SANDWICH, ghm, 1.05 * lam, supports="pinned-pinned"
        ) == pytest.approx(lam, rel=1e-10)
    # and with a vanishing core modulus the cantilever is two uncoupled EB faces,
    # omega_n = (beta_n L)^2 sqrt((E1 I1 + E3 I3)/(m L^4))
    eb = cantilever_beta_l(3) ** 2 * np.sqrt(SANDWICH.D_faces / (SANDWICH.mass * L**4))
    lam = [mead_markus_pole(SANDWICH, lambda s: 1e-6, 1.02j * w) for w in eb]
    assert_allclose(np.imag(lam), eb, rtol=1e-10)


def test_full_cover_model_damping_is_only_the_vem(fe_poles):
    m = build_model(n_patch=4, **FULL)
    assert [kind for kind, _, _ in m.dofs.elements] == ["acld"] * 4
    z = [m.dofs.reduced_of(g) for g in m.dofs.z_dofs]
    nodal = np.setdiff1d(np.arange(m.n_dofs), z)
    assert not np.any(m.C[np.ix_(nodal, np.arange(m.n_dofs))])  # Rayleigh off
    assert np.all(np.diag(m.C)[z] > 0)  # GHM dissipation coordinates only
    # a passive, dissipative model: every pole is stable
    assert np.all(m.poles.real < 0)
    assert np.all(fe_poles[40].real < 0)


def test_sandwich_loss_factors_match_mead_markus_cantilever(fe_poles, reference_poles):
    """Modal loss factors of the FE model against Mead-Markus, same physics otherwise.

    Loss factor of a pole: eta = Im(-lambda^2)/Re(-lambda^2) (closed_form.loss_factor),
    the exact counterpart of the sandwich's Im(EI*)/Re(EI*). The FE realizes G(s) with
    the GHM coordinates exactly, so its poles solve det(lambda^2 M + K(G(lambda))) = 0:
    the reference is therefore Mead-Markus with G evaluated at the pole, not at the real
    frequency (that choice changes eta of mode 1 by 2 %, see the next test).

    Mead-Markus (closed_form): lambda = -3.395 + 147.76j, -4.950 + 972.41j,
    -4.939 + 2500.08j 1/s, eta = 0.04598, 0.01018, 0.003951.
    measured, 40 elements: eta +0.21 %, -0.15 %, -0.65 %; frequency (Im lambda)
    +0.018 %, +0.086 %, +0.29 %. Extrapolated from 20 and 40 elements: eta -0.003 %,
    -0.10 %, -0.12 %; frequency -0.013 %, -0.067 %, -0.13 %.

    Tolerances. 40 elements: 1 % on eta, 0.5 % on the frequency, covering the mesh error
    (O(h^2); the extrapolated values from 20/40 and from 80/160 elements differ by
    < 0.01 %, so extrapolation removes it). Extrapolated: 0.3 % on eta,
    0.2 % on the frequency, covering what the FE has and Mead-Markus neglects:
    rotary inertia and shear of the faces (lower the frequencies by about the bare
    beam's Timoshenko correction, 0.008 %, 0.06 %, 0.14 % for modes 1-3), longitudinal
    inertia of the faces (estimated by adding it to the transfer-matrix solution:
    -0.01 % on the frequencies, +0.006 %, -0.06 %, -0.08 % on eta), and the face shear
    strain missing from the FE's VEM shear strain (gamma only); all <~ 0.2 %, in line
    with the -0.1 % that remain for modes 2-3 at 160 elements (slow test).
    """
    ref = reference_poles["mm", "pole"]
    eta_ref = np.array([loss_factor(lam) for lam in ref])
    fe = fe_poles[40]
    eta_fe = np.array([loss_factor(lam) for lam in fe])
    assert_allclose(fe.imag, ref.imag, rtol=5e-3)
    assert_allclose(eta_fe, eta_ref, rtol=1e-2)
    ext = fe_poles["ext"]
    assert_allclose(ext.imag, ref.imag, rtol=2e-3)
    assert_allclose([loss_factor(lam) for lam in ext], eta_ref, rtol=3e-3)
    # the modes really are damped by the VEM, mode 1 most: 4.6 %, 1.0 %, 0.39 %
    assert np.all(np.diff(eta_fe) < 0) and eta_fe[2] > 1e-3
    # light damping: the choice of definition hardly matters, eta = 2 zeta of the pole
    # to 0.1 % (2 zeta/eta = 1 - 1.5 zeta^2 + ...; measured -0.08 %, -0.004 %, -0.0006 %)
    zeta = -fe.real / np.abs(fe)
    assert_allclose(2 * zeta, eta_fe, rtol=2e-3)


def test_ghm_modulus_at_pole_not_real_frequency(fe_poles, reference_poles):
    """With G(j omega_n) instead of G(lambda) (the classical complex-modulus recipe),
    eta of mode 1 drops by 2.0 % (modes 2, 3: 0.09 %, 0.005 %): the difference is
    first order in eta times d ln G/d ln omega. The FE poles follow G(lambda)."""
    fe = loss_factor(fe_poles["ext"][0])
    at_pole = loss_factor(reference_poles["mm", "pole"][0])
    at_real = loss_factor(reference_poles["mm", "real"][0])
    assert 0.01 < at_pole / at_real - 1.0 < 0.04
    assert abs(fe / at_pole - 1.0) < abs(fe / at_real - 1.0) / 5


def test_rku_equivalent_wavelength_is_crude_for_this_cantilever(fe_poles, reference_poles):
    """RKU assumes sinusoidal modes (exact for pinned ends); for the cantilever the usual
    assumption k_n = beta_n/L (beta_n L = 1.875, 4.694, 7.855) ignores that the
    constraining layer's ends are free, where its force and the core shear must
    vanish. With this soft, thin core the shear-lag length 1/sqrt|g| ~ 90 mm is 30 % of
    the beam (sqrt|g| L ~ 3.5), so those end zones dominate mode 1: RKU puts mode 1's
    frequency 25 % too high and its eta 29 % low, eta of mode 2 42 % high and of mode 3
    9 % high
    (measured; Mead-Markus solved for the cantilever as the reference). Only for
    sqrt|g| L >> 1 or short wavelengths (higher modes) does RKU become adequate, so it
    is not used as the acceptance reference; the FE agrees with the exact sandwich
    solution (40 elements) more than 10x better than RKU does."""
    rku, mm, fe = reference_poles["rku", "pole"], reference_poles["mm", "pole"], fe_poles[40]
    eta = {
        name: np.array([loss_factor(lam) for lam in poles])
        for name, poles in (("rku", rku), ("mm", mm), ("fe", fe))
    }
    rku_err = eta["rku"] / eta["mm"] - 1.0  # measured -0.293, +0.417, +0.090
    fe_err = eta["fe"] / eta["mm"] - 1.0
    assert np.all(np.abs(rku_err) > 0.05), rku_err
    assert np.all(np.abs(fe_err) < np.abs(rku_err) / 10), (fe_err, rku_err)
    assert rku[0].imag / mm[0].imag - 1.0 > 0.2  # measured +25.5 %
    # the shear parameter: sqrt|g*| L at mode 1's pole
    assert 3.0 < abs(np.sqrt(SANDWICH.g(ghm(mm[0])))) * L < 4.0


@pytest.mark.slow
def test_sandwich_fine_mesh(reference_poles):
    """80 and 160 elements (962 and 1922 states; ~3 s with a single-threaded BLAS, but
    10-30 s with a multi-threaded one on a busy 2-core machine): the mesh error is
    nearly gone; what remains is the physics Mead-Markus neglects (see above).
    measured, 160 elements: eta +0.008 %, -0.10 %, -0.15 %, frequency -0.011 %,
    -0.057 %, -0.10 %; extrapolated from 80 and 160 elements: eta -0.005 %, -0.10 %,
    -0.12 %, frequency -0.013 %, -0.067 %, -0.13 %."""
    ref = reference_poles["mm", "pole"]
    eta_ref = [loss_factor(lam) for lam in ref]
    coarse, fine = sandwich_poles(80), sandwich_poles(160)
    for fe in (fine, extrapolated(coarse, fine)):
        assert_allclose([loss_factor(lam) for lam in fe], eta_ref, rtol=3e-3)
        assert_allclose(fe.imag, ref.imag, rtol=2e-3)
