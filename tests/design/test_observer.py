"""Tests of acld_gym.design.observer: the thesis observer (sec. 3.2, CARE with Q = I, R = 1
on (A^T, C^T), ``MixedBeamModel.m``) and the steady-state Kalman alternative.

Provenance: thesis = /work/shared/seed/rodriguez-2006-acld-smc-lqr-thesis.txt sec. 3.2;
the Kalman filter is the package's own documented design (module docstring).
"""

from __future__ import annotations

import numpy as np
import pytest
from numpy.testing import assert_allclose, assert_array_equal

from acld_gym.design.observer import kalman_observer
from acld_gym.design.pipeline import design


@pytest.fixture(scope="module")
def d():
    return design()


@pytest.mark.parametrize("kind", ["thesis", "thesis-unfed"])
def test_thesis_observer_stable(d, kind):
    obs = d.observer(kind)
    A, B, E, Cy = d.plant
    assert obs.n == A.shape[0]
    assert_array_equal(obs.C, Cy)
    assert_array_equal(obs.T, d.reduced.SL.T)
    assert np.max(np.linalg.eigvals(obs.A - obs.L @ obs.C).real) < 0


def test_kalman_observer_stable(d):
    obs = d.observer("kalman")
    r = d.reduced
    assert obs.n == r.order
    assert_array_equal(obs.T, np.eye(r.order))
    assert np.max(np.linalg.eigvals(r.A - obs.L @ r.C).real) < 0
    assert not obs.fed_load


def test_fed_and_unfed_load_input(d):
    E = d.plant[2]
    fed = d.observer("thesis")
    unfed = d.observer("thesis-unfed")
    assert_array_equal(fed.E, E)
    assert fed.fed_load
    assert not np.any(unfed.E)
    assert unfed.E.shape == E.shape
    assert not unfed.fed_load
    # Same gain either way.
    assert_allclose(fed.L, unfed.L)


def test_thesis_gain_solves_filter_riccati(d):
    # L = X C^T with X the stabilizing solution of A X + X A^T - X C^T C X + I = 0.
    from acld_gym.design.numerics import care_gain

    A, _, _, Cy = d.plant
    Lt, X = care_gain(A.T, Cy.T, np.eye(A.shape[0]), np.eye(1))
    assert_allclose(d.observer("thesis").L, Lt.T)
    assert_allclose(Lt.T, X @ Cy.T, rtol=1e-8, atol=1e-14 * np.abs(Lt).max())


@pytest.mark.parametrize(
    "kw,name",
    [
        ({"load_std": 0.0}, "load_std"),
        ({"load_std": -1.0}, "load_std"),
        ({"sensor_std": 0.0}, "sensor_std"),
        ({"sensor_std": -1e-6}, "sensor_std"),
    ],
)
def test_kalman_bad_noise_raises(d, kw, name):
    with pytest.raises(ValueError, match=name):
        kalman_observer(d.reduced, **kw)


def test_design_bad_observer_kind(d):
    with pytest.raises(ValueError, match="observer"):
        d.observer("luenberger")
