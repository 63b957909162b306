"""Deprecated path of :mod:`acld_gym.envs.vector_env` (acld-gym 0.1); removed in 0.3."""

from acld_gym._shim import moved
from acld_gym.envs.vector_env import ACLDBeamVectorEnv

moved("acld_gym.vector_env", "acld_gym.envs.vector_env")

__all__ = ["ACLDBeamVectorEnv"]
