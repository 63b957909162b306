"""The nominal design's sampled LQR gain (``NominalDesign.lqr_gain``): the discrete
Riccati solution of python-control, a stable closed loop, and the weight it is given."""

from __future__ import annotations

import numpy as np
import pytest
from numpy.testing import assert_allclose

from acld_gym.design.feedback import THESIS_LQR_WEIGHT
from acld_gym.design.nominal import nominal_design


@pytest.fixture(scope="module")
def nom():
    return nominal_design()


def test_lqr_gain_is_python_controls_dlqr(nom):
    control = pytest.importorskip("control")
    sr = nom.reduced
    Q = nom.design.state_weight(THESIS_LQR_WEIGHT)
    K_ref, _, _ = control.dlqr(sr.Ad, sr.Bd, 0.5 * (Q + Q.T), np.eye(1))
    K = nom.lqr_gain()
    assert K.shape == (1, sr.Ad.shape[0])
    assert_allclose(K, np.asarray(K_ref), rtol=1e-6)


def test_lqr_gain_stabilizes_and_follows_its_weight(nom):
    sr = nom.reduced
    rho = [
        np.max(np.abs(np.linalg.eigvals(sr.Ad - sr.Bd @ nom.lqr_gain(w))))
        for w in (THESIS_LQR_WEIGHT / 100, THESIS_LQR_WEIGHT)
    ]
    assert max(rho) < 1.0
    assert np.linalg.norm(nom.lqr_gain(THESIS_LQR_WEIGHT / 100)) < np.linalg.norm(nom.lqr_gain())


def test_the_design_is_the_same_whatever_the_callers_blas_threads():
    """The design is cached, so the call that builds it first sets the env's observer and
    scales for the whole process: it is built on one BLAS thread whatever the caller's
    setting. On an AMD EPYC with OpenBLAS's Haswell kernels, one thread and two give
    scales one ulp apart; here the public builder under two threads must equal the same
    build under one, bit for bit (on kernels that never differ this holds trivially)."""
    from threadpoolctl import threadpool_limits

    from acld_gym.design import nominal

    build = nominal.nominal_design.__wrapped__  # the builder behind the cache
    with threadpool_limits(limits=1, user_api="blas"):
        one = build(mesh="thesis")
    with threadpool_limits(limits=2, user_api="blas"):
        two = build(mesh="thesis")

    def arrays(d):
        return [d.plant.Ad, d.reduced.Ad, d.reduced.Bd, d.kalman.Lc, d.kalman.Lp]

    for a, b in zip(arrays(one), arrays(two), strict=True):
        assert np.array_equal(a, b)
    assert np.array_equal(one.thesis.Lp, two.thesis.Lp)  # the two that differed there
    assert np.array_equal(one.xr_scale, two.xr_scale)
