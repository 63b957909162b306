"""Sampled-data (ZOH) model of acld_gym.design.discrete, against the exact continuous simulator."""

import numpy as np
import pytest
import scipy.linalg as sla

from acld_gym.design.discrete import discretize
from acld_gym.design.pipeline import design
from acld_gym.design.simulate import simulate
from acld_gym.physics.loads import Pulse, TipLoad, thesis_load


@pytest.fixture(scope="module")
def d():
    return design()


def _run_sampled(sd, load, n_steps, voltage=0.0):
    x = np.zeros(sd.Ad.shape[0])
    ys = [0.0]
    for k in range(n_steps):
        f0, f1 = sd.load_samples(load, k * sd.dt)
        x = sd.Ad @ x + sd.Bd[:, 0] * voltage + sd.load_increment(f0, f1)
        ys.append(x[17])
    return np.array(ys)


@pytest.mark.parametrize("case, tol", [(1, 1e-8), (2, 1e-8), (3, 1e-4)])
def test_sampled_passive_matches_exact_simulation(d, case, tol):
    # Reference: the exact piecewise-affine simulator sampled at the same instants.
    A, B, E, Cy = d.plant
    sd = discretize(A, B, E, 1e-3, substeps=10)
    load = thesis_load(case)
    y = _run_sampled(sd, load, 250)
    ref = simulate(
        A, B, E, Cy, d.observer("thesis"), d.passive, load, t_end=0.25, v_max=None, dt=1e-3
    )
    assert np.abs(y - ref.y).max() / np.abs(ref.y).max() < tol


def test_pulse_edges_inside_a_period_are_exact(d):
    # Edges at 0.3 ms and 1.7 ms: inside control periods, on the 0.1 ms sub-step grid.
    A, B, E, Cy = d.plant
    sd = discretize(A, B, E, 1e-3, substeps=10)
    load = TipLoad((Pulse(3e-4, 1.4e-3, 0.7),))
    y = _run_sampled(sd, load, 100)
    ref = simulate(
        A, B, E, Cy, d.observer("thesis"), d.passive, load, t_end=0.1, v_max=None, dt=1e-3
    )
    # The simulator adds the edges to its output grid; compare at the period instants.
    at_periods = np.isclose(ref.t / 1e-3, np.round(ref.t / 1e-3), atol=1e-6)
    yref = ref.y[at_periods]
    assert yref.size == y.size
    assert np.abs(y - yref).max() / np.abs(yref).max() < 1e-8


def test_zoh_matrices(d):
    A, B, E, _ = d.plant
    sd = discretize(A, B, E, 1e-3, substeps=4)
    # Ad = e^{A dt}, against scipy's expm of the balanced matrix D^-1 A D (A's entries span
    # 1e-3 .. 1e12; the raw expm is off by about 1e-6 relative, depending on the CPU's BLAS);
    # a constant voltage held forever reaches the DC response -A^-1 B.
    Ab, (sc, _) = sla.matrix_balance(A * 1e-3, permute=False, separate=True)
    ref = (sc[:, None] * sla.expm(Ab)) / sc[None, :]
    assert np.allclose(sd.Ad, ref, rtol=1e-7, atol=1e-9)
    x = np.zeros(A.shape[0])
    for _ in range(5000):
        x = sd.Ad @ x + sd.Bd[:, 0]
    xdc = -np.linalg.solve(A, B[:, 0])
    assert abs(x[17] - xdc[17]) < 1e-3 * abs(xdc[17])
    # The held-load response equals the sum of both hold weights.
    assert np.allclose(sd.Ed[:, 0], sd.W0.sum(1) + sd.W1.sum(1))
    assert sd.substeps == 4 and np.isclose(sd.times[-1], 1e-3)


@pytest.mark.parametrize(
    "kw, name",
    [
        ({"dt": 0.0}, "dt"),
        ({"dt": -1e-3}, "dt"),
        ({"dt": float("nan")}, "dt"),
        ({"substeps": 0}, "substeps"),
        ({"substeps": 2.5}, "substeps"),
    ],
)
def test_bad_arguments(d, kw, name):
    A, B, E, _ = d.plant
    args = {"dt": 1e-3, "substeps": 10, **kw}
    with pytest.raises(ValueError, match=name):
        discretize(A, B, E, **args)
