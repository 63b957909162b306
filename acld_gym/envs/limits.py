"""The limits of the configuration that other modules check against as well: the certified
``param_noise`` bound per mesh, the largest actuator delay and the largest episodes, with
their checks. :class:`acld_gym.envs.config.EnvConfig` validates its fields with them (and
re-exports them); :mod:`acld_gym.envs.conflicts` and the training configs read them without
importing the configuration."""

from __future__ import annotations

from acld_gym.util.validate import check_real

__all__ = [
    "PARAM_NOISE_MAX",
    "MAX_DELAY",
    "MAX_EPISODE_STEPS",
    "MAX_TABLE_STEPS",
    "check_param_noise",
    "check_episode_size",
]

#: Largest accepted ``param_noise`` per mesh (relative std of the log-normal factors,
#: which are truncated at 3 std). Every drawn plant is a physical beam, hence stable;
#: within these bounds the nominal Kalman observer with LQR, SMC and MPC also stays
#: stable on every plant: checked at all 1024 corners of the box of +/-3 std
#: (tests/baselines/test_robustness.py). At 0.1 on the thesis mesh 512 corners are unstable.
PARAM_NOISE_MAX = {"converged": 0.1, "thesis": 0.05}

#: Largest actuator delay [control periods].
MAX_DELAY = 100

#: Largest episode of a single env, in steps: its sensor noise (and, in the numpy reference
#: step, its loads) are tabulated at reset, up to about 180 bytes per step.
MAX_EPISODE_STEPS = 1_000_000

#: Largest number of tabulated env-steps of a vector env (num_envs x steps per episode):
#: 8 bytes each of sensor noise, 170 more in the numpy reference step (680 MB at the limit).
MAX_TABLE_STEPS = 4_000_000


def check_param_noise(value, mesh: str, bound: float | None = None) -> float:
    """``param_noise`` as a float in [0, bound] (default bound :data:`PARAM_NOISE_MAX` of
    ``mesh``); ``ValueError`` naming it. The one check of ``param_noise`` (the env's config,
    the training configs)."""
    limit = bound if bound is not None else PARAM_NOISE_MAX.get(mesh, 0.0)
    v = check_real("param_noise", value, 0.0)
    if v > limit:
        raise ValueError(
            f"param_noise must be at most {limit} for mesh={mesh!r} (relative std; "
            f"beyond it the nominal observer and baselines are not validated), got "
            f"{value!r}"
        )
    return v


def check_episode_size(episode_length: float, dt: float, num_envs: int = 1) -> int:
    """The episode's step count, ``round(episode_length / dt)``; ``ValueError`` beyond
    :data:`MAX_EPISODE_STEPS` (or :data:`MAX_TABLE_STEPS` over ``num_envs``)."""
    steps = int(round(episode_length / dt))
    if steps < 1:
        raise ValueError(f"episode_length must be at least dt, got {episode_length!r}")
    if steps > MAX_EPISODE_STEPS:
        raise ValueError(
            f"episode_length / dt = {steps} steps exceeds {MAX_EPISODE_STEPS} "
            "(an episode's noise is tabulated at reset, ~350 bytes per step)"
        )
    if num_envs * steps > MAX_TABLE_STEPS:
        raise ValueError(
            f"num_envs x episode steps = {num_envs * steps} exceeds "
            f"{MAX_TABLE_STEPS} (the vector env tabulates every sub-env's "
            "episode, ~170 bytes per step)"
        )
    return steps
