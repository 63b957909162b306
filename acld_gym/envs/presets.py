"""The registered configurations: every id is a set of :class:`acld_gym.envs.config.EnvConfig`
fields, registered as the spec's ``kwargs`` (``gym.spec(id).kwargs`` shows them; keyword
arguments of ``gym.make`` replace them, and a keyword that one of them would silently
override is refused: :mod:`acld_gym.envs.conflicts`), with its episode's step count as
``gym.spec(id).max_episode_steps``. This module imports nothing heavy, so that
``import acld_gym`` stays light.

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

ENTRY_POINT = "acld_gym.envs.beam_env:ACLDBeamEnv"
VECTOR_ENTRY_POINT = "acld_gym.envs.vector_env:ACLDBeamVectorEnv"

#: The lab rig's actuator and sensor (module docstring, with the sources).
LAB = {
    "actuator_delay": 1,
    "slew_rate": 4.18e6,
    "amplifier_bandwidth": 60e3,
    "sensor_noise": 1.8e-7,
}
#: The hard level: the lab rig, the temperature, parameter noise and partial observation.
HARD = {**LAB, "temperature_range": (18.0, 28.0), "param_noise": 0.05, "obs_mode": "measurement"}

#: id -> the EnvConfig fields it sets (JSON-able; the rest are EnvConfig's defaults).
PRESETS: dict[str, dict] = {
    "ACLDBeam-v1": {},
    "ACLDBeam-v0": {
        "mesh": "thesis",
        "harmonic_modes": (179.0, 1115.0),
        "model_std": 0.0,
        "param_noise_max": 0.5,
        "env_id": "ACLDBeam-v0",
    },
    "ACLDBeamLab-v1": {**LAB, "env_id": "ACLDBeamLab-v1"},
    "ACLDBeamHard-v1": {**HARD, "env_id": "ACLDBeamHard-v1"},
}


def check_env_id(value, name: str = "env_id") -> str:
    """``value`` if it is one of this package's registered ids (:data:`PRESETS`), matched as
    a plain string; else ``ValueError`` naming ``name`` and the ids. Never passed to an
    importer first: Gymnasium's ``"module:Env"`` form would import ``module``, so an id
    read from a file or a command line is checked here before ``gym.make`` sees it."""
    if not isinstance(value, str) or value not in PRESETS:
        raise ValueError(f"{name} must be one of this package's ids {list(PRESETS)}, got {value!r}")
    return value


def preset(env_id: str, **changes):
    """The :class:`acld_gym.envs.config.EnvConfig` of a registered id (with ``changes``)."""
    from acld_gym.envs.config import make_config

    check_env_id(env_id)
    return make_config(**{**PRESETS[env_id], **changes})


def episode_steps(env_id: str) -> int:
    """The step count of an id's episodes (:func:`kwargs_steps` of its settings)."""
    return kwargs_steps(PRESETS[check_env_id(env_id)])


def kwargs_steps(kwargs: dict, limit: int | None = None) -> int | None:
    """The step count of the episodes of an env made with ``kwargs``: ``round(episode_length
    / dt)`` of its keywords, else of its ``config``, else EnvConfig's defaults (1 s, 1 ms;
    mirrored here to keep this module light: tests/envs/test_conflicts.py checks them),
    shortened to ``kwargs["max_episode_steps"]`` or ``limit`` if given; ``limit`` where the
    keywords are not numbers (the env refuses them)."""
    config = kwargs.get("config")
    length = kwargs.get("episode_length", getattr(config, "episode_length", 1.0))
    dt = kwargs.get("dt", getattr(config, "dt", 1e-3))
    try:
        steps = int(round(length / dt))
    except (TypeError, ValueError, ZeroDivisionError, OverflowError):
        return limit
    for cap in (kwargs.get("max_episode_steps"), limit):
        if type(cap) is int and cap > 0:
            steps = min(steps, cap)
    return steps


def register_presets() -> None:
    """Register every id of :data:`PRESETS` with gymnasium (once), with its episode's step
    count as ``gym.spec(id).max_episode_steps`` for the tools that read the registry. The
    env truncates itself after ``episode_length / dt`` steps, so gymnasium's ``make`` and
    ``make_vec`` add no ``TimeLimit`` of that count
    (:class:`acld_gym.envs.registration.RegisteredSpec`): ``gym.make``, ``make_vec`` and
    the SB3 adapter all follow ``episode_length`` and ``dt``; ``max_episode_steps=`` can
    still shorten an episode (a longer one is refused)."""
    from gymnasium.envs.registration import registry

    from acld_gym.envs.registration import RegisteredSpec

    for env_id, kwargs in PRESETS.items():
        if env_id not in registry:
            registry[env_id] = RegisteredSpec(
                id=env_id,
                entry_point=ENTRY_POINT,
                vector_entry_point=VECTOR_ENTRY_POINT,
                kwargs=dict(kwargs),
            )
