"""This package's env ids as plain data: the :class:`acld_gym.envs.config.EnvConfig` fields
each id sets (:data:`PRESETS`; the ids and the sources of their settings are described in
:mod:`acld_gym.envs.presets`), the entry points, the check of an id and the step count of
an id's episodes. It imports nothing, so that registering the ids (``import acld_gym``)
stays light and every module of :mod:`acld_gym.envs` can read the ids without importing
the configuration."""

from __future__ import annotations

__all__ = [
    "PRESETS",
    "LAB",
    "HARD",
    "ENTRY_POINT",
    "VECTOR_ENTRY_POINT",
    "check_env_id",
    "episode_steps",
    "kwargs_steps",
]

ENTRY_POINT = "acld_gym.envs.beam_env:ACLDBeamEnv"
VECTOR_ENTRY_POINT = "acld_gym.envs.vector_env:ACLDBeamVectorEnv"

#: The lab rig's actuator and sensor (:mod:`acld_gym.envs.presets`, with the sources).
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
