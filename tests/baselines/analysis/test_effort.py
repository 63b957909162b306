"""The effort measures on synthetic voltages whose RMS, total variation and reactive power
are known in closed form, and on the thesis cases."""

import math

import numpy as np
import pytest

from acld_gym.physics.actuator import patch_capacitance
from baselines.analysis.effort import AT_LIMIT_RTOL, SETTLE_DELAY, at_limit, effort, settled_from

DT = 1e-3


def test_triangle_wave_has_its_rms_and_total_variation():
    # a triangle between -A and A with period 40 steps: 4 A of variation per period
    A, period, n = 50.0, 40, 2000
    k = np.arange(n)
    v = A * (1 - 4 * np.abs(((k + period / 4) / period) % 1 - 0.5))
    e = effort(v, np.zeros(n), DT, settle_s=0.5)
    # sampled at 20 steps per ramp: RMS^2 = (A^2 / 3)(1 + 2 / 20^2) (continuous: A^2 / 3)
    assert e.rms_voltage_V == pytest.approx(A / math.sqrt(3) * math.sqrt(1 + 2 / 20**2), rel=1e-9)
    assert e.total_variation_V_per_s == pytest.approx(4 * A / (period * DT), rel=1e-9)
    assert e.limit_fraction == 0.0 and e.settled_from_s == 0.5


def test_sine_reactive_power_is_omega_c_v_rms_squared():
    w, A, n = 2 * np.pi * 50.0, 30.0, 4000
    v = A * np.sin(w * DT * np.arange(n))
    c = 1e-8
    e = effort(v, np.zeros(n), DT, settle_s=float("nan"), capacitance=c)
    v_rms = A / math.sqrt(2)
    assert e.rms_voltage_V == pytest.approx(v_rms, rel=1e-9)
    # I_k = C (V_k - V_k-1) / dt: 2 sin(w dt / 2) / dt instead of w, to O((w dt)^2)
    exact = c * v_rms**2 * 2 * math.sin(w * DT / 2) / DT
    assert e.reactive_power_var == pytest.approx(exact, rel=1e-3)
    assert e.reactive_power_var == pytest.approx(w * c * v_rms**2, rel=1e-2)
    assert math.isnan(e.total_variation_V_per_s) and math.isnan(e.limit_fraction)


def test_time_at_the_limit_and_residual_tip_in_the_settled_window():
    v = np.concatenate([np.zeros(500), np.tile([120.0, -120.0, 120.0, 3.0], 125)])
    y = np.concatenate([np.ones(500), np.full(500, 2e-6)])
    e = effort(v, y, DT, settle_s=0.5)
    assert e.limit_fraction == pytest.approx(0.75)
    assert e.residual_tip_rms_m == pytest.approx(2e-6)
    assert e.settled_rms_voltage_V == pytest.approx(math.sqrt((3 * 120.0**2 + 9.0) / 4))
    assert effort(v, y, DT, 0.5).reactive_power_var == pytest.approx(
        effort(v, y, DT, 0.5, capacitance=patch_capacitance()).reactive_power_var
    )


def test_the_limit_within_a_solver_tolerance():
    """A QP's saturated voltage, 1e-7 short of the bound by a CPU-dependent round-off
    (the MPC's OSQP tolerance), is at the limit; 10 mV short is not."""
    assert AT_LIMIT_RTOL >= 100 * 1e-7
    v = np.array([120.0, -120.0 * (1 - 1e-7), 120.0 * (1 - 3e-7), 119.99, 0.0, 150.0])
    assert at_limit(v).tolist() == [True, True, True, False, False, True]
    assert at_limit(v, v_max=150.0).tolist() == [False] * 5 + [True]
    w = np.concatenate([np.zeros(500), np.tile([120.0 * (1 - 1e-7), 3.0], 250)])
    assert effort(w, np.zeros(1000), DT, settle_s=0.5).limit_fraction == pytest.approx(0.5)


def test_settled_windows_of_the_thesis_cases():
    assert settled_from(1) == pytest.approx(0.001 + SETTLE_DELAY)
    assert settled_from(2) == pytest.approx(0.101 + SETTLE_DELAY)
    assert settled_from(3) == pytest.approx(0.193 + SETTLE_DELAY)
    assert math.isnan(settled_from("random")) and math.isnan(settled_from(True))


def test_bad_input_is_named():
    with pytest.raises(ValueError, match="same length"):
        effort(np.zeros(10), np.zeros(9), DT, 0.0)
    with pytest.raises(ValueError, match="dt"):
        effort(np.zeros(10), np.zeros(10), 0.0, 0.0)


def test_the_issue_measurement_of_lqr_on_case_1():
    """Issue 22 measured LQR on case 1 (seed 0) after 0.5 s: 4.4 V RMS, 3.5 kV/s, 17.7 um."""
    from acld_gym.envs.beam_env import ACLDBeamEnv
    from baselines.evaluate import metrics_row, rollout
    from baselines.policies import LQRPolicy

    ep = rollout(LQRPolicy(), ACLDBeamEnv(load_case=1), seed=0)
    e = effort(ep.voltage, ep.y, DT, settled_from(1))
    assert e.settled_rms_voltage_V == pytest.approx(4.4, abs=0.05)
    assert e.total_variation_V_per_s == pytest.approx(3.5e3, abs=50)
    assert e.residual_tip_rms_m == pytest.approx(17.7e-6, abs=0.15e-6)
    row = metrics_row(1, "lqr", ep)
    assert row.total_variation_V_per_s == e.total_variation_V_per_s
    assert row.as_dict()["limit_fraction"] == 0.0
    assert metrics_row("random", "lqr", ep).as_dict()["limit_fraction"] is None
