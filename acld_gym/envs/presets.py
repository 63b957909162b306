"""The registered configurations: every id is a set of :class:`acld_gym.envs.config.EnvConfig`
fields, registered as the spec's ``kwargs`` (``gym.spec(id).kwargs`` shows them; keyword
arguments of ``gym.make`` replace them). This module imports nothing heavy, so that
``import acld_gym`` stays light.

* ``ACLDBeam-v1``: the defaults (the mesh-converged beam).
* ``ACLDBeam-v0``: the thesis configuration -- the thesis mesh, its random-load harmonics at
  179 and 1115 rad/s, a Kalman filter driven by the load alone and ``param_noise`` up to 0.5
  (the env's Version History).
"""

from __future__ import annotations

__all__ = ["PRESETS", "ENTRY_POINT", "VECTOR_ENTRY_POINT", "preset", "register_presets"]

ENTRY_POINT = "acld_gym.envs.beam_env:ACLDBeamEnv"
VECTOR_ENTRY_POINT = "acld_gym.envs.vector_env:ACLDBeamVectorEnv"

#: id -> the EnvConfig fields it sets (JSON-able; the rest are EnvConfig's defaults).
PRESETS: dict[str, dict] = {
    "ACLDBeam-v1": {},
    "ACLDBeam-v0": {"mesh": "thesis", "harmonic_modes": (179.0, 1115.0), "model_std": 0.0,
                    "param_noise_max": 0.5, "env_id": "ACLDBeam-v0"},
}


def preset(env_id: str, **changes):
    """The :class:`acld_gym.envs.config.EnvConfig` of a registered id (with ``changes``)."""
    from acld_gym.envs.config import make_config

    if env_id not in PRESETS:
        raise ValueError(f"env_id must be one of {list(PRESETS)}, got {env_id!r}")
    return make_config(**{**PRESETS[env_id], **changes})


def register_presets() -> None:
    """Register every id of :data:`PRESETS` with gymnasium (once). No ``max_episode_steps``:
    the env truncates itself after ``episode_length / dt`` steps (its spec reports that
    count), so ``gym.make``, ``make_vec`` and the SB3 adapter all follow ``episode_length``
    and ``dt``; ``max_episode_steps=`` can still shorten an episode."""
    from gymnasium.envs.registration import register, registry

    for env_id, kwargs in PRESETS.items():
        if env_id not in registry:
            register(id=env_id, entry_point=ENTRY_POINT, vector_entry_point=VECTOR_ENTRY_POINT,
                     kwargs=dict(kwargs))
