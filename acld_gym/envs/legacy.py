"""``ACLDBeam-v0``: the thesis configuration, registered under the id the package was first
published with.

v0 simulates the thesis's own model: its 1 + 1 + 3-element mesh (38 states), its 6-state
balanced-truncation design model and its observer choices, with the same dynamics,
reward, spaces and episode as ever. Since acld-gym 0.3.0 its observation is the design
model's state in the canonical real modal form that v1 uses
(:func:`acld_gym.design.reduction.modal_form`), so a v0 episode is the same on every
machine; before, it was the Schur method's own coordinates, whose signs depend on the
CPU's BLAS kernels (issue 19).

What v0 still does differently from ``gym.make("ACLDBeam-v1", mesh="thesis")``
(:data:`V0_SETTINGS`; the env's Version History says the same):

* random-load harmonics aim at 179 and 1115 rad/s (the thesis's rounded modes 1 and 2)
  instead of the plant's own 178.64 and 1115.40 rad/s;
* its Kalman filter is driven by the tip load alone (``model_std=0``; v1 adds a
  model-error noise of 0.1, :data:`acld_gym.design.observer.MODEL_STD`);
* ``param_noise`` may go up to 0.5 (v1: 0.05 on the thesis mesh, within which the
  baselines are certified stable).
"""

from __future__ import annotations

from acld_gym.envs.beam_env import ACLDBeamEnv
from acld_gym.envs.vector_env import ACLDBeamVectorEnv

__all__ = ["ACLDBeamEnvV0", "ACLDBeamVectorEnvV0", "V0_SETTINGS"]

#: What v0 sets differently from v1 on the thesis mesh (module docstring). ``param_noise``
#: up to 0.5 is a physical beam (v0 made no promise that the baselines stay stable on it,
#: and they do not beyond a few percent).
V0_SETTINGS = {"_harmonic_modes": (179.0, 1115.0), "_model_std": 0.0, "_param_noise_max": 0.5}


def _no_mesh(kwargs: dict) -> dict:
    if "mesh" in kwargs:
        raise TypeError("ACLDBeam-v0 has no mesh argument (it is the thesis mesh); use "
                        "ACLDBeam-v1 with mesh='thesis' or 'converged'")
    return kwargs


class ACLDBeamEnvV0(ACLDBeamEnv):
    """``ACLDBeam-v0``: :class:`acld_gym.envs.beam_env.ACLDBeamEnv` on the thesis mesh, in the
    canonical observation basis, with random-load harmonics at 179 and 1115 rad/s, the
    Kalman filter driven by the load alone (``model_std=0``) and ``param_noise`` up to 0.5
    (:data:`V0_SETTINGS`). Same keyword arguments as v1, without ``mesh``."""

    env_id = "ACLDBeam-v0"
    _harmonic_modes = V0_SETTINGS["_harmonic_modes"]
    _model_std = V0_SETTINGS["_model_std"]
    _param_noise_max = V0_SETTINGS["_param_noise_max"]

    def __init__(self, **kwargs):
        super().__init__(mesh="thesis", **_no_mesh(kwargs))


class ACLDBeamVectorEnvV0(ACLDBeamVectorEnv):
    """The batched ``ACLDBeam-v0`` (see :class:`ACLDBeamEnvV0`)."""

    env_id = "ACLDBeam-v0"
    _harmonic_modes = V0_SETTINGS["_harmonic_modes"]
    _model_std = V0_SETTINGS["_model_std"]
    _param_noise_max = V0_SETTINGS["_param_noise_max"]

    def __init__(self, num_envs: int = 1, max_episode_steps: int | None = None, **kwargs):
        super().__init__(num_envs=num_envs, max_episode_steps=max_episode_steps, mesh="thesis",
                         **_no_mesh(kwargs))
