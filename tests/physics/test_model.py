"""Tests of acld_gym.physics.model: the clamped ACLD beam, its spectrum and state space.

Provenance:
* "thesis" = /work/shared/seed/rodriguez-2006-acld-smc-lqr-thesis.txt, sec. 2.7
  (38 states, 19 DOFs, output = 18th state) and ch. 5 load case 3 (the 179 rad/s
  harmonic load "corresponded to a natural frequency of the full order model").
* "Euler-Bernoulli" = classical cantilever, omega_n = (beta_n L)^2 sqrt(EI/(rho A L^4)),
  beta_n L = 1.87510407, 4.69409113, 7.85475744.
* "Timoshenko statics" = tip deflection of a cantilever under a tip load,
  P L^3/(3 E I) + P L/(k G A) (exact for Timoshenko beam theory).
"""

from __future__ import annotations

import numpy as np
import pytest
import scipy.linalg as sla
from numpy.testing import assert_allclose, assert_array_equal

from acld_gym.physics.model import build_model
from acld_gym.physics.params import BeamParameters, Mesh, table1

P = BeamParameters()
BETA_L = np.array([1.87510407, 4.69409113, 7.85475744])
EI = P.beam_youngs_modulus * P.beam_inertia
RHO_A = P.beam_density * P.beam_area
OMEGA_EB = BETA_L**2 * np.sqrt(EI / (RHO_A * P.length**4))  # ~172.3, 1079.6, 3022.9 rad/s

# A bare aluminium beam: the PZT and VEM layers are kept in the geometry but made
# mechanically negligible (moduli and densities scaled by 1e-6), so the ACLD section
# carries only the beam. The remaining gamma/z DOFs decouple (to O(1e-6)); their
# modes (~omega/sqrt(1+alpha) = 707 rad/s) stay in the spectrum and are filtered
# out below by their mode shapes (no transverse kinetic energy).
EPS = 1e-6
BARE = {
    "pzt_youngs_modulus": P.pzt_youngs_modulus * EPS,
    "pzt_shear_modulus": P.pzt_shear_modulus * EPS,
    "pzt_density": P.pzt_density * EPS,
    "vem_density": P.vem_density * EPS,
}


@pytest.fixture(scope="module")
def model():
    return build_model()


def _bending_frequencies(m, omega_max: float) -> np.ndarray:
    """Undamped frequencies below omega_max of modes whose kinetic energy is mostly
    in the transverse (w) DOFs."""
    w2, V = sla.eigh(m.K, m.M, subset_by_value=(-np.inf, omega_max**2))
    free = list(m.dofs.free)
    wd = [free.index(nd["w"]) for nd in m.dofs.node_dofs if nd["w"] in free]
    MV = m.M @ V
    frac = (V[wd] * MV[wd]).sum(axis=0) / (V * MV).sum(axis=0)
    # the classification must be clear-cut (no mode in between)
    assert np.all((frac > 0.95) | (frac < 0.05)), frac
    return np.sqrt(w2[frac > 0.5])


# --- matrices -----------------------------------------------------------------


def test_shapes_and_tip_index(model):
    assert model.M.shape == model.C.shape == model.K.shape == (19, 19)  # thesis sec. 2.7
    assert model.Pc.shape == model.Fd.shape == (19,)
    assert model.tip_index == 17
    assert model.n_dofs == 19 and model.n_states == 38
    assert_array_equal(np.flatnonzero(model.Fd), [17])
    assert model.Fd[17] == 1.0


def test_symmetric_and_definite(model):
    for A in (model.M, model.C, model.K):
        assert_allclose(A, A.T, rtol=0, atol=1e-14 * np.abs(A).max())
    np.linalg.cholesky(model.M)  # M positive definite
    np.linalg.cholesky(model.K)  # K positive definite after the clamp
    assert np.linalg.eigvalsh(model.C).min() > 0  # Rayleigh + GHM damping: C > 0 too


def test_all_poles_stable(model):
    p = model.poles
    assert p.shape == (38,)
    assert np.all(p.real < 0)
    assert_allclose(np.sort(p), np.sort(np.linalg.eigvals(model.state_space()[0])), rtol=1e-8)


def test_first_natural_frequency_179(model):
    # thesis ch. 5, load case 3: 179 rad/s is a natural frequency of the full-order model
    w = model.natural_frequencies()
    assert np.all(np.diff(w) >= 0)
    assert w[0] == pytest.approx(179.0, rel=0.01)  # actual: 178.63 rad/s
    # sqrt(eig(K, M)) (C = 0, z DOFs kept as undamped oscillators) is a different
    # quantity (176.5 rad/s) but must be in the same neighbourhood
    assert model.undamped_frequencies()[0] == pytest.approx(w[0], rel=0.03)


def test_table1_preset_differs():
    m1 = build_model(preset="table1")
    assert m1.params == table1()
    assert m1.params != build_model().params
    f0 = build_model().natural_frequencies()[0]
    f1 = m1.natural_frequencies()[0]
    assert abs(f1 - f0) / f0 > 0.01  # 174.8 vs 178.6 rad/s
    assert not np.allclose(m1.K, build_model().K)


def test_preset_errors():
    with pytest.raises(ValueError, match="nope"):
        build_model(preset="nope")
    with pytest.raises(ValueError):
        build_model(params=BeamParameters(), preset="table1")
    # "matlab" is the default
    assert_allclose(build_model(preset="matlab").K, build_model().K)


def test_overrides_reach_params_and_mesh():
    m = build_model(n_after=6, patch_length=0.1)
    assert m.mesh == Mesh(1, 1, 6)
    assert m.params.patch_length == 0.1
    assert m.n_dofs == 19 + 3 * 3
    m2 = build_model(mesh=Mesh(2, 2, 6))
    assert m2.n_dofs == 37


# --- state space --------------------------------------------------------------


def test_state_space_shapes_and_structure(model):
    A, B, E, Cy = model.state_space()
    assert A.shape == (38, 38) and B.shape == (38, 1) and E.shape == (38, 1)
    assert Cy.shape == (1, 38)
    assert_array_equal(np.flatnonzero(Cy), [17])  # thesis: 18th state = tip deflection
    assert Cy[0, 17] == 1.0
    n = 19
    assert_array_equal(A[:n, :n], 0.0)
    assert_array_equal(A[:n, n:], np.eye(n))
    assert_array_equal(B[:n], 0.0)
    assert_array_equal(E[:n], 0.0)
    # A = [0 I; -M^-1 K, -M^-1 C], B = [0; M^-1 Pc], E = [0; M^-1 Fd]  (thesis eqs. 47-49)
    M, C, K = model.M, model.C, model.K
    assert_allclose(M @ A[n:, :n], -K, rtol=1e-9, atol=1e-9 * np.abs(K).max())
    assert_allclose(M @ A[n:, n:], -C, rtol=1e-9, atol=1e-9 * np.abs(C).max())
    assert_allclose(M @ B[n:, 0], model.Pc, rtol=1e-9, atol=1e-9 * np.abs(model.Pc).max())
    assert_allclose(M @ E[n:, 0], model.Fd, rtol=1e-9, atol=1e-9)


def test_dc_gain_equals_static_tip_deflection(model):
    A, _, E, Cy = model.state_space()
    dc = -(Cy @ np.linalg.solve(A, E))[0, 0]
    static = model.static_tip_deflection(1.0)
    assert dc == pytest.approx(static, rel=1e-8)
    assert static > 0
    assert model.static_tip_deflection(0.1) == pytest.approx(0.1 * static, rel=1e-12)


# --- bare beam against beam theory ----------------------------------------------


def test_bare_beam_matches_euler_bernoulli():
    # uniform 40-element mesh (7.5 mm elements everywhere)
    m = build_model(mesh=Mesh(4, 12, 24), **BARE)
    w = _bending_frequencies(m, 1.3 * OMEGA_EB[2])
    assert len(w) == 3
    assert_allclose(w, OMEGA_EB, rtol=0.01)  # actual: +0.0004 %, +0.10 %, +0.30 %
    # the fundamental is converged far beyond the 1 % requirement
    assert w[0] == pytest.approx(OMEGA_EB[0], rel=1e-3)


def test_bare_beam_static_tip_deflection():
    m = build_model(mesh=Mesh(4, 12, 24), **BARE)
    k = P.shear_correction
    exact = P.length**3 / (3 * EI) + P.length / (k * P.beam_shear_modulus * P.beam_area)
    assert m.static_tip_deflection(1.0) == pytest.approx(exact, rel=0.01)
    # linear reduced-integration elements converge to it: 40 elements are within 0.1 %
    assert m.static_tip_deflection(1.0) == pytest.approx(exact, rel=1e-3)


def test_bare_beam_convergence_rate():
    # first bending frequency vs. mesh size h ~ 1/factor (factor x the 1+1+3 mesh).
    # Rate from successive differences (no reference solution needed):
    # w(h) - w(h/2) ~ c h^r.
    factors = np.array([1, 2, 4, 8, 16])
    w1 = np.array(
        [
            _bending_frequencies(
                build_model(mesh=Mesh().refined(int(f)), **BARE), 1.5 * OMEGA_EB[0]
            )[0]
            for f in factors
        ]
    )
    diffs = w1[:-1] - w1[1:]
    assert np.all(diffs > 0)  # monotone convergence from above (stiffness-type error)
    rate = np.polyfit(np.log(1.0 / factors[:-1]), np.log(diffs), 1)[0]
    assert 1.5 < rate < 2.5  # actual: ~1.99 (linear elements, O(h^2) eigenvalue error)
    # extrapolated (converged) value vs. Euler-Bernoulli (t/L = 1 %: shear and rotary
    # inertia lower it by < 0.1 %)
    w_inf = w1[-1] - diffs[-1] / (2**rate - 1)
    assert w_inf == pytest.approx(OMEGA_EB[0], rel=1e-3)
    assert w_inf < OMEGA_EB[0]


def test_default_acld_model_mesh_convergence():
    # the thesis's coarse 1+1+3 mesh vs. a 4x refined one (4+4+12):
    # actual 178.63 -> 177.50 rad/s, a 0.63 % change
    w_coarse = build_model().natural_frequencies()[0]
    w_fine = build_model(mesh=Mesh().refined(4)).natural_frequencies()[0]
    change = abs(w_coarse - w_fine) / w_fine
    assert change < 0.01
    assert w_fine < w_coarse  # stiffness-type discretization error: coarse mesh is stiffer
