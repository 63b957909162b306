"""``observe_commands``: the commands still in flight appended to the observation (the
oldest first, in units of 120 V, before log c), what a delay-aware controller knows. Checked
against the actions sent: after step k the last ``actuator_delay`` clipped actions are the
appended entries (one fewer in the ``"measurement"`` observation, which ends with the
newest); nothing is appended without a delay; the dynamics and rewards are the plain env's.
Step-for-step parity of the single, vector, compiled and numpy paths:
tests/envs/test_batch.py (options "commands", "commands-measurement")."""

from __future__ import annotations

import gymnasium as gym
import numpy as np
import pytest

import acld_gym  # noqa: F401
from acld_gym.envs.beam_env import ACLDBeamEnv
from acld_gym.envs.step import commands_in_flight
from acld_gym.physics.actuator import V_LIMIT
from acld_gym.wrappers import ObserveModes


def _actions(n, seed=0):
    return np.random.default_rng(seed).uniform(-2 * V_LIMIT, 2 * V_LIMIT, size=(n, 1))


@pytest.mark.parametrize(
    "kw, appended",
    [
        ({"actuator_delay": 3}, 3),
        ({"actuator_delay": 3, "obs_mode": "full"}, 3),
        ({"actuator_delay": 3, "obs_mode": "measurement"}, 2),
        ({"actuator_delay": 1, "obs_mode": "measurement"}, 0),
        ({}, 0),
    ],
)
def test_the_last_commands_are_appended_oldest_first(kw, appended):
    plain = ACLDBeamEnv(load_case="random", **kw)
    env = ACLDBeamEnv(load_case="random", observe_commands=True, **kw)
    n = plain.observation_space.shape[0]
    assert env.observation_space.shape == (n + appended,)
    assert appended == commands_in_flight(env.config.obs_mode, env.config.actuator_delay)
    o, _ = env.reset(seed=3)
    p, _ = plain.reset(seed=3)
    np.testing.assert_array_equal(o[:n], p)
    np.testing.assert_array_equal(o[n:], 0.0)  # at rest: nothing in flight
    sent = []
    for a in _actions(12):
        o, r, *_ = env.step(a)
        p, rp, *_ = plain.step(a)
        sent.append(np.clip(a[0], -V_LIMIT, V_LIMIT) / V_LIMIT)
        assert r == rp  # the same plant and reward: only the observation grows
        np.testing.assert_array_equal(o[:n], p)
        delay = env.config.actuator_delay
        want = ([0.0] * delay + sent)[-delay:][:appended] if appended else []
        np.testing.assert_array_equal(o[n:], np.float32(want))


def test_vector_env_and_log_c_order():
    kw = dict(load_case="random", observe_commands=True, reward_scale="passive")
    venv = gym.make_vec("ACLDBeamLab-v1", num_envs=3, observe_reward_scale=True, **kw)
    single = gym.make("ACLDBeamLab-v1", observe_reward_scale=True, **kw)
    assert venv.single_observation_space.shape == single.observation_space.shape == (11,)
    obs, info = venv.reset(seed=[5, 6, 7])
    acts = np.array([[50.0], [-300.0], [10.0]])
    obs, *_, info = venv.step(acts)
    np.testing.assert_allclose(obs[:, -2], np.clip(acts[:, 0], -120, 120) / 120, rtol=1e-7)
    np.testing.assert_array_equal(obs[:, -1], np.log(info["reward_scale"]).astype(np.float32))
    for compiled in (True, False):  # the single env, compiled step or not, the same row
        single.unwrapped.compiled_step = compiled
        single.reset(seed=5)
        o, *_ = single.step(acts[0])
        np.testing.assert_allclose(o, obs[0], rtol=1e-6, atol=1e-9)


def test_observe_modes_keeps_the_appended_commands():
    env = ObserveModes(ACLDBeamEnv(load_case=1, actuator_delay=2, observe_commands=True), modes=1)
    assert env.observation_space.shape == (5,)  # 2 mode entries, the tip, 2 commands
    env.reset(seed=0)
    env.step(np.array([60.0]))
    o, *_ = env.step(np.array([-30.0]))
    np.testing.assert_allclose(o[-2:], [0.5, -0.25])


@pytest.mark.parametrize("bad", ["yes", 1, None])
def test_a_bad_value_is_one_line(bad):
    with pytest.raises(ValueError, match=r"^observe_commands must be True or False, got"):
        ACLDBeamEnv(observe_commands=bad)
