"""A built env refuses a setting assigned afterwards (issue 65, a second probe:
``env.unwrapped.harmonic_modes = (1e6, 1e6)`` bypassed the sub-step Nyquist check, and
``config``, ``temperature``, ``max_episode_steps`` assignments were ignored in silence)."""

import gymnasium as gym
import numpy as np
import pytest

import acld_gym  # noqa: F401
from acld_gym.envs.config import EnvConfig
from acld_gym.envs.fixed import fixed_names
from acld_gym.envs.sb3 import SB3VecEnv

SETTINGS = [
    ("harmonic_modes", (1e6, 1e6)),
    ("config", EnvConfig(dt=2e-3)),
    ("temperature", 99.0),
    ("max_episode_steps", 5000),
    ("nom", None),
]


@pytest.mark.parametrize("name, value", SETTINGS)
def test_single_and_vector_env_refuse_an_assigned_setting(name, value):
    env = gym.make("ACLDBeam-v1").unwrapped
    before = env.harmonic_modes
    with pytest.raises(AttributeError, match=rf"ACLDBeamEnv\.{name} is fixed at construction"):
        setattr(env, name, value)
    assert env.harmonic_modes == before and env.config == EnvConfig()
    venv = gym.make_vec("ACLDBeam-v1", num_envs=2).unwrapped
    with pytest.raises(AttributeError, match=rf"ACLDBeamVectorEnv\.{name} is fixed"):
        setattr(venv, name, value)
    if hasattr(env, name):  # (gymnasium's set_attr puts a name the env lacks on a wrapper)
        sync = gym.make_vec("ACLDBeam-v1", num_envs=2, vectorization_mode="sync")
        with pytest.raises(AttributeError, match=rf"ACLDBeamEnv\.{name} is fixed"):
            sync.set_attr(name, value)


def test_what_stays_settable():
    env = gym.make("ACLDBeam-v1")
    env.unwrapped.compiled_step = False  # documented: the numpy reference step
    env.reset(seed=0)
    assert np.isfinite(env.step(np.zeros(1, np.float32))[1])
    sb3 = SB3VecEnv(num_envs=2)
    sb3.set_attr("load_case", 2)
    assert sb3.venv.load_case == 2
    names = fixed_names(EnvConfig)
    assert "load_case" not in names and {"dt", "config"} <= names
    assert type(env.unwrapped).FIXED_NAMES == type(sb3.venv).FIXED_NAMES == names
