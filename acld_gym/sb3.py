"""Deprecated path of :mod:`acld_gym.envs.sb3` (acld-gym 0.1); removed in 0.3."""

from acld_gym._shim import moved
from acld_gym.envs.sb3 import SB3VecEnv

moved("acld_gym.sb3", "acld_gym.envs.sb3")

__all__ = ["SB3VecEnv"]
