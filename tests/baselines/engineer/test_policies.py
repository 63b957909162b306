"""The engineer's references on every level: finite volts within the limit on a tiny
episode, the SB3 protocol, and a stable small-signal loop."""

import numpy as np
import pytest

from acld_gym.test_sets import TEST_SETS
from baselines.engineer import engineer_policies, env_plant, spectral_radius

from .conftest import LEVELS


@pytest.mark.parametrize("env_id", LEVELS)
def test_tiny_episode_finite_within_the_limit(level_env, env_id):
    env = level_env(env_id, load_case="random")
    policies = engineer_policies(env)
    assert {"lqg", "mpc_rig"} <= set(policies)
    for name, pol in policies.items():
        obs, _ = env.reset(seed=3)
        state, start, volts = None, np.ones(1, bool), []
        done = False
        while not done:
            a, state = pol.predict(obs, state=state, episode_start=start)
            start = np.zeros(1, bool)
            assert a.shape == (1,) and a.dtype == np.float32, name
            volts.append(float(a[0]))
            obs, _, term, trunc, _ = env.step(a)
            done = term or trunc
        v = np.array(volts)
        assert np.all(np.isfinite(v)) and np.all(np.abs(v) <= 120.0), name
        assert np.abs(v).max() > 0.0, name


@pytest.mark.parametrize("env_id", ["ACLDBeamLab-v1", "ACLDBeamHard-v1"])
def test_batched_and_episode_start(level_env, env_id):
    """Two envs in a batch act as each alone; ``episode_start`` restarts one at rest."""
    env = level_env(env_id)
    pol = engineer_policies(env)["lqg"]
    rng = np.random.default_rng(0)
    obs = rng.normal(size=(6, env.observation_space.shape[0])).astype(np.float32)
    s_b, s_0, s_1 = None, None, None
    for k in range(6):
        pair = np.stack([obs[k], obs[5 - k]])
        a_b, s_b = pol.predict(pair, s_b, np.array([k == 0, k in (0, 3)]))
        a_0, s_0 = pol.predict(obs[k], s_0, np.array([k == 0]))
        a_1, s_1 = pol.predict(obs[5 - k], None if k == 3 else s_1, np.array([k == 0]))
        assert a_b.shape == (2, 1)
        np.testing.assert_array_equal(a_b[:, 0], np.r_[a_0, a_1])


@pytest.mark.parametrize("env_id", LEVELS)
def test_small_signal_loop_stable_on_the_nominal_plant(level_env, env_id):
    env = level_env(env_id)
    env.reset(seed=0)
    plant, c = env_plant(env)
    if env.unwrapped.config.randomized:  # the level's nominal plant: the design's own
        from acld_gym.envs.episode import fixed_plant

        plant = fixed_plant(env.unwrapped.nom, env.unwrapped.config)
    for name, pol in engineer_policies(env).items():
        rho = spectral_radius(pol, plant, c)
        assert rho < 1.0, (env_id, name, rho)


def _hard_test_set_radii(level_env, n):
    env = level_env("ACLDBeamHard-v1", load_case="random")
    policies = engineer_policies(env)
    worst = {name: 0.0 for name in policies}
    for seed in TEST_SETS["ACLDBeamHard-v1"].seeds[:n]:
        env.reset(seed=seed)
        plant, c = env_plant(env)
        for name, pol in policies.items():
            worst[name] = max(worst[name], spectral_radius(pol, plant, c))
    return worst


def test_hard_stable_on_test_set_plants(level_env):
    worst = _hard_test_set_radii(level_env, 6)
    assert all(r < 1.0 for r in worst.values()), worst


@pytest.mark.slow
def test_hard_stable_on_every_test_set_plant(level_env):
    worst = _hard_test_set_radii(level_env, 100)
    assert all(r < 1.0 for r in worst.values()), worst


def test_filter_fed_the_voltage_that_reaches_the_amplifier(level_env):
    """With a slew limit that binds (10 V per period) and a delay of 2, the voltage the
    policy feeds its filter is the one the env applies, period by period, and the MPC's
    commands respect the rate constraint."""
    env = level_env(
        "ACLDBeamLab-v1",
        load_case=1,
        actuator_delay=2,
        slew_rate=1e4,
        amplifier_bandwidth=None,
        sensor_noise=0.0,
    )
    step = env.unwrapped.config.slew_step
    for name, pol in engineer_policies(env).items():
        obs, _ = env.reset(seed=0)
        state, start, applied, fed, cmds = None, np.ones(1, bool), [], [], []
        for _ in range(20):
            a, state = pol.predict(obs, state=state, episode_start=start)
            start = np.zeros(1, bool)
            obs, _, _, _, info = env.step(a)
            cmds.append(float(a[0]))
            applied.append(float(info["voltage"]))
            fed.append(float(state[0, -1]))
        np.testing.assert_allclose(fed, applied, rtol=1e-12, atol=1e-9)
        assert np.abs(np.diff(applied)).max() <= step * (1 + 1e-9)
        assert np.abs(np.diff(applied)).max() > 0.5 * step, name  # the limit binds
        if name == "mpc_rig":
            assert np.abs(np.diff(cmds)).max() <= step * (1 + 1e-3) + 1e-3
