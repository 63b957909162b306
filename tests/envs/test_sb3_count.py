"""SB3VecEnv's sub-env count with ``venv=``: omitted or the env's own, never silently
another (issue 65, a second probe)."""

import gymnasium as gym
import pytest

import acld_gym  # noqa: F401
from acld_gym.envs.sb3 import SB3VecEnv


def test_num_envs_other_than_venvs_is_refused_naming_both():
    venv = gym.make_vec("ACLDBeam-v1", num_envs=2)
    with pytest.raises(ValueError, match=r"num_envs=8 differs from venv's 2 sub-envs"):
        SB3VecEnv(num_envs=8, venv=venv)
    assert SB3VecEnv(venv=venv).num_envs == 2
    assert SB3VecEnv(num_envs=2, venv=venv).num_envs == 2


def test_num_envs_builds_the_env_default_one():
    assert SB3VecEnv().num_envs == 1
    assert SB3VecEnv(3).num_envs == 3
    with pytest.raises(ValueError, match="num_envs"):
        SB3VecEnv(num_envs=0)
