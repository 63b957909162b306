"""The clairvoyant bound's certificates (baselines/bound_certificate.py) on small random
problems: the KKT check's duality gap bounds the excess cost over the optimum, and the
slew certificate's lower bound lies below the cost of every feasible point, for any
multipliers."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.optimize import lsq_linear

from acld_gym.design.discrete import convolution_matrix
from baselines.bound_certificate import kkt_check, slew_certificate
from baselines.bound_slew import _feasible


def _problem(seed: int, n: int):
    rng = np.random.default_rng(seed)
    h = rng.normal(size=n) * np.exp(-0.3 * np.arange(n))  # a decaying impulse response
    y = rng.normal(size=n) * 3.0
    return rng, h, y


def _cost(h, y, v):
    r = y + convolution_matrix(h) @ v
    return 0.5 * float(r @ r)


@settings(max_examples=40, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), n=st.integers(1, 12))
def test_the_gap_bounds_the_excess_over_the_optimum(seed, n):
    rng, h, y = _problem(seed, n)
    best = lsq_linear(convolution_matrix(h), -y, bounds=(-1.0, 1.0), method="bvls", tol=1e-14).x
    optimum = _cost(h, y, best)
    v = rng.uniform(-1.0, 1.0, n)
    # unit limit and unit scales: kkt_check works in mm and units of v_max
    check = kkt_check(h * 1e-3, y * 1e-3, v, v_max=1.0)
    assert check.feasible and check.objective == pytest.approx(_cost(h, y, v), rel=1e-12)
    assert check.objective - optimum <= check.gap * (1 + 1e-9) + 1e-12
    at_optimum = kkt_check(h * 1e-3, y * 1e-3, best, v_max=1.0)
    assert at_optimum.gap <= 1e-6 * max(at_optimum.objective, 1e-12) + 1e-9
    assert not kkt_check(h * 1e-3, y * 1e-3, np.full(n, 1.5), v_max=1.0).feasible


@settings(max_examples=40, deadline=None)
@given(
    seed=st.integers(0, 2**32 - 1),
    n=st.integers(1, 12),
    rho=st.floats(0.01, 2.0),
)
def test_the_slew_lower_bound_holds_for_any_multipliers(seed, n, rho):
    rng, h, y = _problem(seed, n)
    w = _feasible(rng.uniform(-1.0, 1.0, n), rho)
    cert = slew_certificate(h, y, w, rng.normal(size=n) * 10.0, rho)
    assert cert.feasible and cert.objective >= cert.lower
    for _ in range(20):  # every feasible point costs at least the lower bound
        u = _feasible(rng.uniform(-1.0, 1.0, n), rho)
        assert _cost(h, y, u) >= cert.lower - 1e-9 * max(1.0, abs(cert.lower))
    if rho < 0.9:  # a first step beyond the slew limit (from w_{-1} = 0) is not feasible
        steep = np.zeros(n)
        steep[0] = 1.1 * rho
        assert not slew_certificate(h, y, steep, np.zeros(n), rho).feasible
