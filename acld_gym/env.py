"""Deprecated path of :mod:`acld_gym.envs.beam_env` (acld-gym 0.1); removed in 0.3."""

from acld_gym._shim import moved
from acld_gym.design.nominal import NominalDesign as Nominal
from acld_gym.design.nominal import nominal_design as nominal
from acld_gym.envs.beam_env import COMPILED_STEP, ACLDBeamEnv
from acld_gym.physics.loads import random_load

moved("acld_gym.env", "acld_gym.envs.beam_env (ACLDBeamEnv), acld_gym.design.nominal "
      "(nominal_design)")

__all__ = ["ACLDBeamEnv", "COMPILED_STEP", "Nominal", "nominal", "random_load"]
