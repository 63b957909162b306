"""The truth plant (issue 13): the mesh-converged beam the env simulates.

Provenance of the references:
* "converged model": Richardson extrapolation of the damped modes on meshes refined
  32, 64 and 128 times (fitted rate 2.00), and pointwise Richardson extrapolation of the
  frequency responses of the 64x and 128x meshes (acld_gym.physics.convergence);
* the thesis mesh's errors: the issue's table (mode 2 +14 %, mode 3 +50 %).
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from acld_gym.design.reduction import frequency_response
from acld_gym.envs.config import PARAM_NOISE_MAX
from acld_gym.physics import plant_cache as plant_cache
from acld_gym.physics.convergence import (
    converged_responses,
    mode_study,
    relative_hinf,
    response_grid,
)
from acld_gym.physics.krylov import build_converged_plant
from acld_gym.physics.model import build_model, parametric_model
from acld_gym.physics.params import BeamParameters, Mesh
from acld_gym.physics.plant import band_of
from acld_gym.physics.truth import plant
from acld_gym.physics.uncertainty import randomized_parameters

BAND = band_of(1e-3)  # twice the 1 kHz control's Nyquist frequency, 6283 rad/s


@pytest.fixture(scope="module")
def study():
    return mode_study(refinements=(32, 64, 128))


def _modes_in_band(p):
    lam = p.modes()
    return lam[lam.imag < BAND]


def test_convergence_rate_is_two(study):
    # Linear elements, reduced-integration shear: O(h^2) in frequency and damping.
    assert study.rate == pytest.approx(2.0, abs=0.05)
    assert study.damping_rate[[0, 1, 3]] == pytest.approx(2.0, abs=0.05)


def test_converged_plant_modes_match_the_limit(study):
    # Every mode below twice the Nyquist frequency: 0.5 % in frequency, 2 % in damping.
    lam = _modes_in_band(plant("converged"))
    assert lam.size == 4 == int(np.sum(study.limit < BAND))
    zeta = -lam.real / np.abs(lam)
    assert np.abs(lam.imag / study.limit - 1).max() < 0.005
    assert np.abs(zeta / study.damping_limit - 1).max() < 0.02


def test_thesis_mesh_errors_are_the_issues(study):
    f = plant("thesis").natural_frequencies()[:3]
    err = f / study.limit[:3] - 1
    assert err == pytest.approx([0.0071, 0.1426, 0.4963], abs=0.002)


def test_converged_plant_responses_match_the_converged_model():
    lam = _modes_in_band(plant("converged"))
    w = response_grid(lam, BAND)
    ref = converged_responses(w)
    A, B, E, C = plant("converged").state_space()
    g = np.column_stack([frequency_response(A, B, C, w), frequency_response(A, E, C, w)])
    err = relative_hinf(g, ref)
    assert np.all(err < 0.01), err  # issue 13: within 1 %; measured 0.30 % and 0.16 %
    A, B, E, C = plant("thesis").state_space()
    g = np.column_stack([frequency_response(A, B, C, w), frequency_response(A, E, C, w)])
    assert np.all(relative_hinf(g, ref) > 0.5)  # the thesis mesh is 66-69 % off


def test_shipped_plant_is_current_and_equals_a_fresh_build():
    # The shipped file's key is that of today's defaults (a stale file fails here), and a
    # rebuild on this machine agrees with it to the accuracy of the fine-mesh solves
    # (~1e-6, the reason the file is shipped).
    key = plant_cache.key(BeamParameters(), 1e-3, 128)
    assert (plant_cache.SHIPPED_DIR / f"plant-converged-{key}.npz").is_file()
    shipped = plant("converged")
    fresh = build_converged_plant(1e-3, BeamParameters(), 128)
    assert fresh.n_states == shipped.n_states == 36
    w = response_grid(_modes_in_band(shipped), BAND, points=100)
    for i in (1, 2):  # voltage and load
        a = frequency_response(
            *(m for j, m in enumerate(shipped.state_space()) if j in (0, i, 3)), w
        )
        b = frequency_response(*(m for j, m in enumerate(fresh.state_space()) if j in (0, i, 3)), w)
        assert np.max(np.abs(a - b)) / np.max(np.abs(b)) < 1e-5


def test_cache_key_follows_every_parameter(tmp_path, monkeypatch):
    base = plant_cache.key(BeamParameters(), 1e-3, 128)
    for f in dataclasses.fields(BeamParameters):
        value = getattr(BeamParameters(), f.name)
        changed = dataclasses.replace(BeamParameters(), **{f.name: value * 1.01 or 1e3})
        assert plant_cache.key(changed, 1e-3, 128) != base, f.name
    assert plant_cache.key(BeamParameters(), 5e-4, 128) != base
    assert plant_cache.key(BeamParameters(), 1e-3, 64) != base
    # A built plant goes to the user cache atomically and is read back from it.
    monkeypatch.setenv("ACLD_GYM_CACHE_DIR", str(tmp_path))
    calls = []
    params = dataclasses.replace(BeamParameters(), ghm_zeta=4.5)
    p = dataclasses.replace(plant("thesis"), params=params)  # a file holds its key's params

    def build():
        calls.append(1)
        return p

    got = plant_cache.cached(params, 1e-3, 128, build)
    again = plant_cache.cached(params, 1e-3, 128, build)
    assert calls == [1] and got is p and again.n_states == p.n_states
    assert [f.name for f in tmp_path.iterdir()] == [
        f"plant-converged-{plant_cache.key(params, 1e-3, 128)}.npz"
    ]
    # A damaged file is ignored (rebuilt), never half-read.
    (tmp_path / f"plant-converged-{plant_cache.key(params, 1e-3, 128)}.npz").write_bytes(b"x")
    plant_cache.cached(params, 1e-3, 128, build)
    assert calls == [1, 1]


def test_parameter_terms_equal_a_direct_assembly():
    # The randomized plant is the unit matrices with new coefficients; that must be the
    # model assembled with the new parameters.
    rng = np.random.default_rng(4)
    p0 = BeamParameters()
    p1 = randomized_parameters(rng, 0.3, p0)
    pm = parametric_model(p0, Mesh().refined(2))
    direct = parametric_model(p1, Mesh().refined(2)).combine()
    for a, b in zip(pm.combine(p1), direct, strict=True):
        a, b = (x.toarray() if hasattr(x, "toarray") else x for x in (a, b))
        assert np.max(np.abs(a - b)) <= 1e-12 * np.max(np.abs(b))
    # ... and, for the thesis plant, build_model's state space.
    A1 = plant("thesis").state_space(p1)[0]
    assert np.max(np.abs(A1 - build_model(p1).state_space()[0])) <= 1e-9 * np.abs(A1).max()


@pytest.mark.parametrize("mesh", ["converged", "thesis"])
def test_randomized_plants_are_stable_physical_beams(mesh):
    # The energy argument of acld_gym.physics.truth: M, K symmetric positive definite, C positive
    # definite, whatever the draw; so every pole is in the left half plane.
    p = plant(mesh)
    rng = np.random.default_rng(0)
    for _ in range(50):
        params = randomized_parameters(rng, PARAM_NOISE_MAX[mesh], p.params)
        M, C, K, _ = p.matrices(params)
        for X in (M, C, K):
            assert np.allclose(X, X.T, rtol=0, atol=1e-12 * np.abs(X).max())
            assert np.linalg.eigvalsh(X).min() > 0
        assert np.linalg.eigvals(p.state_space(params)[0]).real.max() < 0
