"""Deprecated path of :mod:`acld_gym.physics.model` (acld-gym 0.1); removed in 0.3."""

from acld_gym._shim import moved
from acld_gym.physics.model import BeamModel, ParametricModel, build_model, parametric_model

moved("acld_gym.model", "acld_gym.physics.model")

__all__ = ["BeamModel", "ParametricModel", "build_model", "parametric_model"]
