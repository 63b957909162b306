"""The engineer's references: designs for each level's known actuator and sensor.

What a level's engineer knows -- its datasheet (:mod:`acld_gym.envs.presets`: the
computation delay, the amplifier's bandwidth and slew rate, the sensor's noise, what the
env observes) and the package's public nominal design -- goes into the designs; what they
cannot know (the episode's load, temperature and parameters) stays out.

* :class:`DelayLQGPolicy` (``"lqg"``): output-feedback LQG on the env's reward, its model
  augmented with the commands in flight and the amplifier's lag, its Kalman filter fed the
  voltage that reaches the amplifier;
* :class:`ActuatorMPCPolicy` (``"mpc_rig"``): the MPC of the env's reward with the delay by
  prediction, the slew limit as a rate constraint, the lag in its model and the LQR's
  cost-to-go as its tail (about rest it is the LQG's law; saturated it plans the limit);

Both keep their own filter on the tip measurement (SB3's ``state``): the ``"estimate"``
observation's tip or the ``"measurement"`` observation's newest sample. Their small-signal
loop on a plant: :func:`spectral_radius` (:mod:`baselines.engineer.loop`).

:func:`engineer_policies` returns a level's references by name, with the level's design
(:data:`DESIGNS`, chosen offline on training episodes: :mod:`baselines.engineer.tuning`).
"""

from __future__ import annotations

from .base import RigPolicy
from .designs import DESIGNS, design_kwargs
from .level import engineer_policies
from .loop import closed_loop, env_plant, spectral_radius
from .lqg import DelayLQGPolicy
from .model import RigModel, rig_model
from .mpc import ActuatorMPCPolicy

__all__ = [
    "RigPolicy",
    "DelayLQGPolicy",
    "ActuatorMPCPolicy",
    "RigModel",
    "rig_model",
    "closed_loop",
    "spectral_radius",
    "env_plant",
    "engineer_policies",
    "DESIGNS",
    "design_kwargs",
]
