"""Shared fixtures of the engineer's references' tests: one env per level."""

import gymnasium as gym
import pytest

import acld_gym  # noqa: F401  (registers the ids)

LEVELS = ("ACLDBeam-v0", "ACLDBeam-v1", "ACLDBeamLab-v1", "ACLDBeamHard-v1")


@pytest.fixture(scope="session")
def level_env():
    """``level_env(env_id, **kwargs)``: a cached env of a level (an episode of 20 ms)."""
    cache = {}

    def make(env_id, **kwargs):
        key = (env_id, tuple(sorted(kwargs.items())))
        if key not in cache:
            cache[key] = gym.make(env_id, episode_length=0.02, **kwargs)
        return cache[key]

    return make
