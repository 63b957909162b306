"""The canonical reduced realization (issue 15): the same observation on every machine.

Other CPUs' BLAS kernels return Schur and singular vectors with other signs and
round-off. These tests perturb the *inputs* of the Schur and SVD steps the same way --
renumbering, sign-flipping or rotating the full model's coordinates -- and require the
reduced model, the observation scales, the observer gains and a whole episode's
observations to come out the same to 1e-9 (relative to each quantity's largest entry).
They never touch the BLAS settings (``benchmarks/check_kernels.py`` compares kernels by
hand).
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
import scipy.linalg as sla

import acld_gym.envs.episode as env_module
from acld_gym.design.reduction import modal_form, schur_balanced_truncation
from acld_gym.envs.beam_env import ACLDBeamEnv
from acld_gym.envs.episode import nominal
from acld_gym.physics.plant import Plant
from acld_gym.physics.truth import plant
from baselines.policies import LQRPolicy

RTOL = 1e-9


def _rel(a, b) -> float:
    a, b = np.asarray(a), np.asarray(b)
    return float(np.max(np.abs(a - b)) / np.max(np.abs(b)))


def _transformed(p: Plant, T: np.ndarray) -> Plant:
    """The same plant in coordinates q' = T q (T orthogonal): M' = T M T^T, ..."""
    return dataclasses.replace(
        p, units={k: T @ U @ T.T for k, U in p.units.items()}, piezo=T @ p.piezo,
        Fd=T @ p.Fd, c=T @ p.c, physical=p.physical @ T.T, node_w=p.node_w @ T.T)


def _signed_permutation(n: int, rng) -> np.ndarray:
    return np.eye(n)[rng.permutation(n)] * rng.choice([-1.0, 1.0], n)[:, None]


def _transforms(mesh: str):
    rng = np.random.default_rng(1)
    n = plant(mesh).n_coordinates
    out = [("signed permutation", _signed_permutation(n, rng))]
    if mesh == "converged":  # mass-normalized coordinates: any rotation is well posed
        out.append(("rotation", np.linalg.qr(rng.normal(size=(n, n)))[0]))
    return out


@pytest.fixture
def transformed_nominal(monkeypatch):
    """nominal() of a transformed plant, with the nominal cache isolated."""
    original = env_module.nominal_plant

    def build(mesh: str, T: np.ndarray):
        monkeypatch.setattr(env_module, "nominal_plant",
                            lambda m, dt: _transformed(original(m, dt), T))
        nominal.cache_clear()
        return nominal(mesh=mesh)

    yield build
    nominal.cache_clear()


@pytest.mark.parametrize("mesh", ["thesis", "converged"])
def test_design_is_invariant_under_renumbering_and_rotation(mesh, transformed_nominal):
    ref = nominal(mesh=mesh)
    r0 = ref.design.reduced
    for label, T in _transforms(mesh):
        T2 = sla.block_diag(T, T)
        nom = transformed_nominal(mesh, T)
        r = nom.design.reduced
        for name in ("A", "B", "C", "E"):
            assert _rel(getattr(r, name), getattr(r0, name)) < RTOL, (label, name)
        assert _rel(r.SL, T2 @ r0.SL) < RTOL and _rel(r.SR, T2 @ r0.SR) < RTOL, label
        assert _rel(r.hsv[:10], r0.hsv[:10]) < RTOL, label
        assert _rel(nom.xr_scale, ref.xr_scale) < RTOL, label
        assert _rel(nom.kalman.Lc, ref.kalman.Lc) < RTOL, label
        assert _rel(nom.kalman.Lp, ref.kalman.Lp) < RTOL, label
        # The LQR gains solve Riccati equations with Q = 1e11 S_R^T W S_R: conditioning of
        # ~1e7 x eps, so they agree to 1e-8 rather than 1e-9.
        assert _rel(nom.design.lqr.a, ref.design.lqr.a) < 1e-8, label
        k0, k1 = (LQRPolicy(nom=x).small_signal_gain() for x in (ref, nom))
        assert _rel(k1, k0) < 1e-8, label


def _episode(seed=0, **kw):
    env = ACLDBeamEnv(load_case="random", **kw)
    obs, _ = env.reset(seed=seed)
    rows = [obs]
    rng = np.random.default_rng(5)
    for _ in range(300):
        obs, *_ = env.step(rng.uniform(-150, 150, 1).astype(np.float32))
        rows.append(obs)
    return np.array(rows, dtype=np.float64)


@pytest.mark.parametrize("mesh", ["thesis", "converged"])
def test_episode_observations_are_invariant(mesh, transformed_nominal):
    ref = _episode(mesh=mesh)
    for label, T in _transforms(mesh):
        transformed_nominal(mesh, T)
        obs = _episode(mesh=mesh)
        # float32 observations: compare to the float32 resolution of their largest entry
        assert _rel(obs, ref) < max(RTOL, 2 * np.finfo(np.float32).eps), label


def test_modal_form_is_the_documented_convention():
    r = nominal().design.reduced
    mf = modal_form(r.A, r.B, r.C)
    lam = mf.eigenvalues
    assert np.all(np.diff(np.abs(lam)) > 0)  # ordered by |lambda|
    assert np.allclose(r.A, mf.A)  # already canonical: T = I up to round-off
    for blk in mf.blocks:
        b, c = r.B[blk, 0], r.C[0, blk]
        assert b[0] > 0 and (b.size == 1 or b[1] == 0.0)
        assert np.linalg.norm(b) == pytest.approx(np.linalg.norm(c), rel=1e-9)


def test_modal_form_refuses_ambiguous_bases():
    A = np.diag([-1.0, -1.0 - 1e-9, -3.0])
    with pytest.raises(np.linalg.LinAlgError, match="closer"):
        modal_form(A, np.ones((3, 1)), np.ones((1, 3)))
    with pytest.raises(np.linalg.LinAlgError, match="no voltage input"):
        modal_form(np.diag([-1.0, -2.0]), np.array([[1.0], [0.0]]), np.ones((1, 2)))


def test_truncation_refuses_a_split_pair_of_hankel_values():
    # A mode with damping ratio 1e-7 has two Hankel values equal to ~1e-7 (relative):
    # cutting between them (order 1) leaves the kept direction undetermined.
    def mode(w, z):
        return np.array([[-z * w, w], [-w, -z * w]])

    A = sla.block_diag(mode(1.0, 1e-7), mode(10.0, 0.1))
    B = np.array([[1.0], [0.0], [1.0], [0.0]])
    C = np.array([[0.0, 1.0, 0.0, 1.0]])
    with pytest.raises(np.linalg.LinAlgError, match="nearly equal"):
        schur_balanced_truncation(A, B, C, 1)
    assert schur_balanced_truncation(A, B, C, 2).order == 2


def test_schur_basis_is_kept_for_v0_and_differs_from_modal():
    A, B, E, C = plant("thesis").state_space()
    legacy = schur_balanced_truncation(A, B, C, 6, E=E, basis="schur")
    canon = schur_balanced_truncation(A, B, C, 6, E=E)
    assert legacy.basis == "schur" and canon.basis == "modal"
    assert _rel(legacy.hsv, canon.hsv) == 0.0
    # same transfer function: equal Markov parameters C A^k B
    for k in range(4):
        m0 = legacy.C @ np.linalg.matrix_power(legacy.A, k) @ legacy.B
        m1 = canon.C @ np.linalg.matrix_power(canon.A, k) @ canon.B
        assert m1 == pytest.approx(m0, rel=1e-8)
