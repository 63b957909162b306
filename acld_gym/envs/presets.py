"""The registered configurations: every id is a set of :class:`acld_gym.envs.config.EnvConfig`
fields, registered as the spec's ``kwargs`` (``gym.spec(id).kwargs`` shows them; keyword
arguments of ``gym.make`` replace them, and a keyword that one of them would silently
override is refused: :mod:`acld_gym.envs.conflicts`), with its episode's step count as
``gym.spec(id).max_episode_steps``. The ids' data live in :mod:`acld_gym.envs.ids` (plain
data, imported by ``import acld_gym``, which registers them:
:func:`acld_gym.envs.registration.register_presets`); this module is their public face and
builds an id's configuration (:func:`preset`).

* ``ACLDBeam-v1``: the defaults (the mesh-converged beam).
* ``ACLDBeam-v0``: the thesis configuration -- the thesis mesh, its random-load harmonics at
  179 and 1115 rad/s, a Kalman filter driven by the load alone and ``param_noise`` up to 0.5
  (the env's Version History).
* ``ACLDBeamLab-v1``: v1 with the actuator and sensor of a laboratory rig (:data:`LAB`):

  - ``actuator_delay=1``: the controller samples the tip, computes and writes the voltage at
    the next sampling instant, a one-period computation delay (the usual implementation on
    a real-time target; Franklin, Powell & Workman, *Digital Control of Dynamic Systems*,
    3rd ed., 1998, on computation delay);
  - ``slew_rate=4.18e6`` V/s: a +/-150 V bender driver's peak current, 95 mA (PiezoDrive
    BD150), on the patch's 22.7 nF (:data:`acld_gym.physics.actuator.REFERENCE_SLEW_RATE`);
  - ``amplifier_bandwidth=60e3`` Hz: the signal bandwidth of PiezoDrive's miniature bender
    driver PDu100B (60 kHz unloaded; its datasheet); the BD150's is not stated in the data
    cited;
  - ``sensor_noise=1.8e-7`` m: a laser triangulation sensor's digital output, Micro-Epsilon
    optoNCDT 1700-10 (10 mm range, 14-bit values: one step is 6.23167e-5 of the range, 0.623
    um, manual sec. 7.3), whose quantization has a standard deviation of a step / sqrt(12).

  At 1 kHz the amplifier barely matters (a 240 V swing takes 57 us, the lag is 2.7 us); the
  delay does.
* ``ACLDBeamHard-v1``: the lab rig (:data:`HARD`) plus a polymer temperature drawn per episode
  in 18-28 °C (an unconditioned laboratory; its transition, :mod:`acld_gym.physics.
  temperature`), parameter noise 0.05 and partial observation: ``obs_mode="measurement"``
  (the last 8 tip measurements and the last command, no state estimate).
"""

from __future__ import annotations

from acld_gym.envs.config import EnvConfig, make_config
from acld_gym.envs.ids import (
    ENTRY_POINT,
    HARD,
    LAB,
    PRESETS,
    VECTOR_ENTRY_POINT,
    check_env_id,
    episode_steps,
    kwargs_steps,
)
from acld_gym.envs.registration import register_presets

__all__ = [
    "PRESETS",
    "LAB",
    "HARD",
    "ENTRY_POINT",
    "VECTOR_ENTRY_POINT",
    "preset",
    "check_env_id",
    "episode_steps",
    "kwargs_steps",
    "register_presets",
]


def preset(env_id: str, **changes) -> EnvConfig:
    """The :class:`acld_gym.envs.config.EnvConfig` of a registered id (with ``changes``)."""
    check_env_id(env_id)
    return make_config(**{**PRESETS[env_id], **changes})
