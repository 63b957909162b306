"""PulseSuperposition drives any per-period load through the env's public step exactly."""

import gymnasium as gym
import numpy as np
import pytest

from baselines.analysis.excitation import PulseSuperposition, causal_convolution
from baselines.evaluate import rollout
from baselines.policies import LQRPolicy, MPCPolicy, PassivePolicy


@pytest.fixture(scope="module")
def quiet_rig():
    """Without sensor noise, where the superposed loop must equal the env's own cases."""
    return PulseSuperposition(n_steps=1000, sensor_noise=0.0, basis_seeds=1)


@pytest.mark.parametrize("cls", [LQRPolicy, MPCPolicy])
def test_two_superposed_pulses_are_load_case_2_under_a_saturating_policy(quiet_rig, cls):
    f = np.zeros(1000)
    f[0] = f[100] = 1.0  # case 2: 1 N over [0, 1 ms) and over [100 ms, 101 ms)
    pol = cls()
    sup = quiet_rig.run(pol, f)
    ep = rollout(pol, gym.make("ACLDBeam-v1", load_case=2, sensor_noise=0.0), seed=0)
    assert np.mean(np.abs(ep.voltage) >= 120.0) > 0.1  # saturation: the policy is nonlinear
    np.testing.assert_allclose(sup.y[1:], ep.y, rtol=0, atol=1e-7 * np.abs(ep.y).max())
    np.testing.assert_allclose(sup.voltage, ep.voltage, rtol=0, atol=1e-3)


def test_the_own_pulse_reproduces_a_noisy_episode_exactly():
    rig = PulseSuperposition(n_steps=500, basis_seeds=1, seed=7)  # default sensor noise
    f = np.zeros(500)
    f[0] = 1.0
    pol = LQRPolicy()
    sup = rig.run(pol, f)
    ep = rollout(pol, gym.make("ACLDBeam-v1", load_case=1, episode_length=0.5), seed=7)
    np.testing.assert_allclose(sup.y[1:], ep.y, rtol=0, atol=1e-7 * np.abs(ep.y).max())


def test_no_load_is_rest_and_loads_add_up(rig):
    pol = LQRPolicy()
    rest = rig.run(pol, np.zeros(300))
    assert np.all(rest.y == 0) and np.all(rest.voltage == 0)  # the own noise cancels exactly
    rng = np.random.default_rng(0)
    f1, f2 = 1e-3 * rng.normal(size=(2, 300))
    a, b, ab = rig.run(pol, f1), rig.run(pol, f2), rig.run(pol, f1 + f2)
    assert np.abs(ab.voltage).max() < 120  # below saturation: the loop is linear
    # (to the float32 rounding of the observation the policy is given, as the env's)
    np.testing.assert_allclose(ab.y, a.y + b.y, atol=1e-5 * np.abs(ab.y).max())


def test_passive_run_is_the_convolution_and_equals_the_passive_policy(rig):
    f = np.zeros(400)
    f[[0, 50, 51]] = (0.3, -0.2, 0.5)
    np.testing.assert_allclose(
        rig.passive(f).y, rig.run(PassivePolicy(), f).y, atol=1e-12 * np.abs(rig.passive(f).y).max()
    )


def test_causal_convolution_by_hand():
    g = np.array([9.0, 1.0, 2.0, 3.0])  # g[0] is never used
    np.testing.assert_allclose(
        causal_convolution([1.0, 10.0, 0.0], g), [0.0, 1.0, 2.0 + 10.0, 3.0 + 20.0]
    )


def test_refusals_are_named(rig):
    with pytest.raises(ValueError, match="deflection limit"):
        rig.passive(np.full(2000, 10.0))  # 10 N held: 36 mm static (the limit: 20 mm)
    with pytest.raises(ValueError, match="load must be"):
        rig.run(LQRPolicy(), np.zeros(2001))
    with pytest.raises(ValueError, match="dt"):
        PulseSuperposition(n_steps=10, dt=5e-4)
    with pytest.raises(ValueError, match="load_case"):
        PulseSuperposition(n_steps=10, load_case=2)
    with pytest.raises(ValueError, match="param_noise"):
        PulseSuperposition(n_steps=10, param_noise=0.05, basis_seeds=2)


def test_a_policy_with_a_state_keeps_it_through_the_superposed_run():
    """Through the measurement observation a reference policy runs its own observer
    (MeasurementFeedback, SB3's state): the superposed run hands the state back each step,
    as rollout does, and equals the env's own case 2."""
    kw = dict(sensor_noise=0.0, obs_mode="measurement")
    rig = PulseSuperposition(n_steps=600, basis_seeds=1, **kw)
    pol = LQRPolicy.for_env(rig.env)
    assert pol.predict(rig.env.observation_space.sample())[1] is not None  # it has a state
    f = np.zeros(600)
    f[0] = f[100] = 1.0
    sup = rig.run(pol, f)
    ep = rollout(pol, gym.make("ACLDBeam-v1", load_case=2, episode_length=0.6, **kw), seed=0)
    np.testing.assert_allclose(sup.y[1:], ep.y, rtol=0, atol=1e-7 * np.abs(ep.y).max())
    np.testing.assert_allclose(sup.voltage, ep.voltage, rtol=0, atol=1e-3)
