"""A level's engineer's references by name (:func:`engineer_policies`), each built with the
level's design (:data:`baselines.engineer.designs.DESIGNS`)."""

from __future__ import annotations

from baselines import arguments
from baselines.policies import mpc_available

from .lqg import DelayLQGPolicy
from .mpc import ActuatorMPCPolicy

__all__ = ["engineer_policies"]


def engineer_policies(env) -> dict:
    """The engineer's references of ``env``'s level (any wrapper of an ``ACLDBeamEnv``),
    name -> policy with SB3's ``predict``: ``"lqg"`` (:class:`DelayLQGPolicy`) and, where
    the QP solver osqp is installed, ``"mpc_rig"`` (:class:`ActuatorMPCPolicy`), both with
    the level's design (:data:`baselines.engineer.designs.DESIGNS`). ``env`` may be one of
    this package's ids."""
    env = arguments.acld_env(env)
    out = {"lqg": DelayLQGPolicy.for_env(env)}
    if mpc_available():
        out["mpc_rig"] = ActuatorMPCPolicy.for_env(env)
    return out
