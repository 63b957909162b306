"""Actuator realism (issue 21): delay, amplifier lag and slew limit, each checked as physics,
each off by default (v1 unchanged), through single, vector and compiled steps alike."""

from __future__ import annotations

import numpy as np
import pytest

from acld_gym.design.discrete import discretize
from acld_gym.envs.beam_env import COMPILED_STEP, ACLDBeamEnv
from acld_gym.physics.actuator import V_LIMIT, with_amplifier
from acld_gym.physics.loads import TipLoad

PATHS = [True, False] if COMPILED_STEP else [False]
QUIET = TipLoad(())  # no load: the response is the voltage's alone


def _run(commands, compiled=True, **kw):
    env = ACLDBeamEnv(load_case=QUIET, sensor_noise=0.0, **kw)
    env.compiled_step = compiled
    env.reset(seed=0)
    rows = []
    for u in commands:
        _, r, _, _, info = env.step(np.array([u], np.float32))
        rows.append((info["tip_deflection"], info["voltage"], info["requested_voltage"], r))
    return np.array(rows)


def _pulse(n=120):
    u = np.zeros(n)
    u[3:40] = 90.0
    u[60:70] = -150.0  # clipped to -120
    return u


@pytest.mark.parametrize("compiled", PATHS)
@pytest.mark.parametrize("delay", [1, 2, 5])
def test_a_delay_of_k_periods_shifts_the_response_exactly_k_steps(delay, compiled):
    u = _pulse()
    ref = _run(u, compiled)
    got = _run(u, compiled, actuator_delay=delay)
    # the voltage on the patch is the command k periods late, exactly
    np.testing.assert_array_equal(got[delay:, 1], ref[:-delay, 1])
    np.testing.assert_array_equal(got[:delay, 1], 0.0)
    # ... and so is the tip (same dynamics, summed in another order: to rounding)
    scale = np.abs(ref[:, 0]).max()
    np.testing.assert_allclose(got[delay:, 0], ref[:-delay, 0], rtol=1e-10, atol=1e-12 * scale)
    assert np.abs(got[: delay + 1, 0]).max() == 0.0
    np.testing.assert_array_equal(got[:, 2], np.float32(u))  # the action, as requested


@pytest.mark.parametrize("compiled", PATHS)
@pytest.mark.parametrize("bandwidth", [50.0, 300.0, 2000.0])
def test_the_lag_step_response_has_its_time_constant(bandwidth, compiled):
    k = np.arange(1, 41)
    got = _run(np.full(40, 100.0), compiled, amplifier_bandwidth=bandwidth)
    tau = 1.0 / (2 * np.pi * bandwidth)
    np.testing.assert_allclose(got[:, 1], 100.0 * (1.0 - np.exp(-k * 1e-3 / tau)), rtol=1e-12)


def test_the_lag_drives_the_beam_continuously_within_the_period():
    # A finer reference: the same amplifier and beam sampled at dt / 20 (independent
    # exponentials), stepped 20 times per period with the command held.
    bandwidth, u = 150.0, _pulse(80)
    got = _run(u, amplifier_bandwidth=bandwidth)
    env = ACLDBeamEnv()
    A, B, E, _ = env.nom.design.plant
    fine = discretize(*with_amplifier(A, B, E, bandwidth), 1e-3 / 20, 1)
    x = np.zeros(A.shape[0] + 1)
    y = []
    for uk in np.clip(u, -V_LIMIT, V_LIMIT):
        for _ in range(20):
            x = fine.Ad @ x + fine.Bd[:, 0] * uk
        y.append(env.nom.output @ x[:-1])
    np.testing.assert_allclose(got[:, 0], y, rtol=1e-8, atol=1e-10 * np.abs(y).max())
    # without the lag the beam responds faster: the lag is really in the plant
    assert np.abs(_run(u)[:, 0] - got[:, 0]).max() > 0.05 * np.abs(y).max()


@pytest.mark.parametrize("compiled", PATHS)
def test_the_slew_limited_voltage_ramps_at_the_rate_given(compiled):
    rate = 2.5e4  # V/s: 25 V per 1 ms period
    u = np.r_[np.full(10, 100.0), np.full(10, -30.0), np.full(5, 200.0)]
    got = _run(u, compiled, slew_rate=rate)[:, 1]
    want, v = [], 0.0
    for uk in np.clip(u, -V_LIMIT, V_LIMIT):
        v += np.clip(uk - v, -25.0, 25.0)
        want.append(v)
    np.testing.assert_allclose(got, want, rtol=1e-12)
    assert got[:4].tolist() == pytest.approx([25.0, 50.0, 75.0, 100.0])
    assert np.diff(got[:4]).max() / 1e-3 == pytest.approx(rate)


@pytest.mark.parametrize("compiled", PATHS)
def test_options_compose_in_the_amplifier_order(compiled):
    # the command, delayed, moves the amplifier at the slew rate, which the lag follows
    got = _run(
        np.full(12, 100.0), compiled, actuator_delay=2, slew_rate=5e4, amplifier_bandwidth=500.0
    )[:, 1]
    a = np.exp(-2 * np.pi * 500.0 * 1e-3)
    want, vp = [], 0.0
    for amp in [0.0, 0.0, 50.0] + [100.0] * 9:
        vp = a * vp + (1 - a) * amp
        want.append(vp)
    np.testing.assert_allclose(got, want, rtol=1e-10)


def test_the_reward_charges_the_patch_voltage_and_the_observer_sees_the_command():
    env = ACLDBeamEnv(
        load_case=QUIET, sensor_noise=0.0, actuator_delay=1, lam=0.5, obs_mode="measurement"
    )
    env.reset(seed=0)
    obs, r, *_, info = env.step(np.array([60.0], np.float32))
    assert info["voltage"] == 0.0 and r == 0.0  # nothing on the patch yet
    assert obs[-1] == pytest.approx(0.5)  # the observation's last voltage: the command
    obs, r, *_, info = env.step(np.array([0.0], np.float32))
    assert info["voltage"] == 60.0
    assert info["reward_voltage"] == -(0.5 * (60.0 / 120.0) ** 2)


def test_options_are_off_by_default_and_v1_is_unchanged():
    u = _pulse()
    ref = _run(u)
    for kw in (dict(actuator_delay=0), dict(amplifier_bandwidth=None), dict(slew_rate=None)):
        assert _run(u, **kw).tobytes() == ref.tobytes()
    env = ACLDBeamEnv()
    assert env.batch.layout.z_size == 67 and env.batch.layout.out_voltage is None


@pytest.mark.parametrize(
    "kw, name",
    [
        ({"actuator_delay": -1}, "actuator_delay"),
        ({"actuator_delay": 1.5}, "actuator_delay"),
        ({"actuator_delay": 101}, "actuator_delay"),
        ({"amplifier_bandwidth": 0.0}, "amplifier_bandwidth"),
        ({"slew_rate": -5.0}, "slew_rate"),
        ({"slew_rate": float("inf")}, "slew_rate"),
    ],
)
def test_bad_actuator_settings_name_themselves(kw, name):
    with pytest.raises(ValueError, match=name):
        ACLDBeamEnv(**kw)
