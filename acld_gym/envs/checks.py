"""Validation of the environments' arguments: every check raises ``ValueError`` naming the
argument and what was expected, before any state changes (the generic checks are in
:mod:`acld_gym.util.validate`).

The numeric ranges of the environment's arguments (:data:`ENV_RANGES`) are physical or
practical limits, stated here once and printed in the env's docstring and the README:
beyond them a result would be meaningless (a tip sensor with 1 m of noise), overflow
(a deflection scale of 1e-300 m makes the reward infinite) or exhaust memory (the
episode's loads and noise are tabulated at reset).
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from acld_gym.envs.episode import (
    LOAD_CASES,
    OBS_MODES,
    OBSERVERS,
    PARAM_NOISE_MAX,
    nominal,
)
from acld_gym.physics.truth import MESHES
from acld_gym.thesis.table2 import V_LIMIT
from acld_gym.util.validate import check_choice, check_real

__all__ = ["configure", "check_config", "episode_spec", "check_actions", "check_episode_size",
           "ENV_RANGES", "MAX_EPISODE_STEPS", "MAX_TABLE_STEPS"]


#: Accepted ranges of the env's numeric arguments: (low, high, unit, why).
ENV_RANGES: dict[str, tuple[float, float, str, str]] = {
    "dt": (1e-4, 1e-2, "s", "control period of a piezo rig; the plant is built for 2 pi/dt"),
    "episode_length": (1e-4, 1e3, "s", "and at most MAX_EPISODE_STEPS steps"),
    "sensor_noise": (0.0, 1e-3, "m", "std of the tip sensor; 0 for none"),
    "y_ref": (1e-9, 1.0, "m", "deflection scale of the reward"),
    "lam": (0.0, 1e6, "-", "voltage weight of the reward"),
    "deflection_limit": (1e-6, 1.0, "m", "termination limit"),
}


#: Largest episode of a single env, in steps: its loads and sensor noise are tabulated at
#: reset, about 350 bytes per step (350 MB at the limit).
MAX_EPISODE_STEPS = 1_000_000


#: Largest number of tabulated env-steps of a vector env (num_envs x steps per episode),
#: about 170 bytes each (680 MB at the limit).
MAX_TABLE_STEPS = 4_000_000


def check_episode_size(episode_length: float, dt: float, num_envs: int = 1) -> int:
    """The episode's step count, ``round(episode_length / dt)``; ``ValueError`` beyond
    :data:`MAX_EPISODE_STEPS` (or :data:`MAX_TABLE_STEPS` over ``num_envs``)."""
    steps = int(round(episode_length / dt))
    if steps < 1:
        raise ValueError(f"episode_length must be at least dt, got {episode_length!r}")
    if steps > MAX_EPISODE_STEPS:
        raise ValueError(f"episode_length / dt = {steps} steps exceeds {MAX_EPISODE_STEPS} "
                         "(an episode's loads and noise are tabulated at reset, ~350 bytes "
                         "per step)")
    if num_envs * steps > MAX_TABLE_STEPS:
        raise ValueError(f"num_envs x episode steps = {num_envs * steps} exceeds "
                         f"{MAX_TABLE_STEPS} (the vector env tabulates every sub-env's "
                         "episode, ~170 bytes per step)")
    return steps


def check_actions(action, n: int, v_max: float, vector: bool = False):
    """``n`` requested voltages as float64 and their clipped values.

    A single env takes real numbers of shape (1,); a vector env shape (n,) or (n, 1).
    Anything else -- strings, bytes, bools, complex numbers, other shapes, NaN or
    inf -- raises ``ValueError`` before any state changes.
    """
    a = np.asarray(action)
    if a.dtype.kind not in "iuf":
        raise ValueError(f"action must be real numbers (volts), got {action!r} "
                         f"(dtype {a.dtype})")
    shapes = ((n,), (n, 1)) if vector else ((1,),)
    if a.shape not in shapes:
        want = " or ".join(str(s) for s in shapes)
        raise ValueError(f"action must have shape {want} (voltages [V]), got shape {a.shape}")
    a = a.astype(np.float64).reshape(-1)
    if not np.isfinite(a).all():
        raise ValueError(f"action must be finite, got {a[~np.isfinite(a)][0]!r}")
    return a, np.clip(a, -v_max, v_max)


# --- pieces shared by ACLDBeamEnv and ACLDBeamVectorEnv ------------------------
def configure(env, *, load_case, mesh, dt, episode_length, observer, obs_mode, sensor_noise,
              y_ref, lam, param_noise, deflection_limit, render_mode, num_envs: int = 1) -> None:
    """Validate the keyword arguments shared by the single and the vector env
    (``ValueError`` naming a bad one) and set them, with the nominal design, on ``env``."""
    check_config(load_case=load_case, mesh=mesh, dt=dt, episode_length=episode_length,
                 observer=observer, obs_mode=obs_mode, sensor_noise=sensor_noise, y_ref=y_ref,
                 lam=lam, param_noise=param_noise, deflection_limit=deflection_limit,
                 render_mode=render_mode, render_modes=env.metadata["render_modes"],
                 param_noise_max=env._param_noise_max, num_envs=num_envs)
    env.load_case = load_case
    env.mesh = mesh
    env.dt = float(dt)
    env.episode_length = float(episode_length)
    env.observer_kind = observer
    env.obs_mode = obs_mode
    env.sensor_noise = float(sensor_noise)
    env.y_ref = float(y_ref)
    env.lam = float(lam)
    env.param_noise = float(param_noise)
    env.deflection_limit = float(deflection_limit)
    env.render_mode = render_mode
    env.v_max = V_LIMIT
    env.obs_hist = 8
    env.nom = nominal(env.dt, 10, max(env.sensor_noise, 1e-9), mesh=mesh,
                      model_std=env._model_std)
    env.harmonic_modes = (env._harmonic_modes if env._harmonic_modes is not None
                          else tuple(float(w) for w in env.nom.modes[:2]))


def check_config(*, load_case, mesh, dt, episode_length, observer, obs_mode, sensor_noise, y_ref,
                 lam, param_noise, deflection_limit, render_mode, render_modes,
                 param_noise_max: float | None = None, num_envs: int = 1) -> None:
    """Validate the environment's keyword arguments (``ValueError`` naming a bad one):
    choices, the ranges of :data:`acld_gym.envs.checks.ENV_RANGES`, the ``param_noise`` bound
    of the mesh and the episode's size (:func:`acld_gym.envs.checks.check_episode_size`)."""
    check_choice("load_case", load_case, LOAD_CASES)
    check_choice("mesh", mesh, MESHES)
    check_choice("observer", observer, OBSERVERS)
    check_choice("obs_mode", obs_mode, OBS_MODES)
    values = {"dt": dt, "episode_length": episode_length, "sensor_noise": sensor_noise,
              "y_ref": y_ref, "lam": lam, "deflection_limit": deflection_limit}
    for name, value in values.items():
        low, high, unit, _ = ENV_RANGES[name]
        check_real(name, value, low, high, unit=unit)
    limit = param_noise_max if param_noise_max is not None else PARAM_NOISE_MAX.get(mesh, 0.0)
    check_real("param_noise", param_noise, 0.0)
    if param_noise > limit:
        raise ValueError(f"param_noise must be at most {limit} for mesh={mesh!r} (relative std; "
                         f"beyond it the nominal observer and baselines are not validated), got "
                         f"{param_noise!r}")
    check_episode_size(float(episode_length), float(dt), num_envs)
    if render_mode is not None and render_mode not in render_modes:
        raise ValueError(f"render_mode must be one of {list(render_modes)} or "
                         f"None, got {render_mode!r}")


def episode_spec(spec, steps: int):
    """``spec`` with ``max_episode_steps`` set to the env's ``steps`` when it has none (the
    env truncates itself there) or a larger one (the env still ends at ``steps``)."""
    if spec is None:
        return None
    limit = spec.max_episode_steps
    if limit is None or limit > steps:
        spec = replace(spec, max_episode_steps=int(steps))
    return spec
