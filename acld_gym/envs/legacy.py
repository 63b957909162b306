"""``ACLDBeam-v0``, kept registered with its original behaviour.

v0 simulates the thesis's 38-state mesh and observes the reduced state in the
coordinates that the Schur balanced truncation happens to return. Those depend on
the signs of Schur and singular vectors, which differ between the BLAS kernels
that OpenBLAS picks for each CPU: the same agent sees different observations on
different machines (issue 15). Use ``ACLDBeam-v1`` (:class:`acld_gym.envs.beam_env.ACLDBeamEnv`);
v0 exists to rerun v0-era results. ``ACLDBeam-v1`` with ``mesh="thesis"`` has v0's
physics in canonical coordinates.
"""

from __future__ import annotations

from acld_gym.envs.beam_env import ACLDBeamEnv
from acld_gym.envs.vector_env import ACLDBeamVectorEnv

__all__ = ["ACLDBeamEnvV0", "ACLDBeamVectorEnvV0"]

#: v0's settings; ``param_noise`` up to 0.5 is a physical beam (v0 made no promise that the
#: baselines stay stable on it, and they do not beyond a few percent).
_V0 = {"_basis": "schur", "_harmonic_modes": (179.0, 1115.0), "_model_std": 0.0,
       "_param_noise_max": 0.5}


def _no_mesh(kwargs: dict) -> dict:
    if "mesh" in kwargs:
        raise TypeError("ACLDBeam-v0 has no mesh argument (it is the thesis mesh); use "
                        "ACLDBeam-v1 with mesh='thesis' or 'converged'")
    return kwargs


class ACLDBeamEnvV0(ACLDBeamEnv):
    """``ACLDBeam-v0``: :class:`acld_gym.envs.beam_env.ACLDBeamEnv` on the thesis mesh with the
    Schur coordinates (machine-dependent), random-load harmonics at 179 and 1115 rad/s and
    the Kalman filter driven by the load alone (``model_std=0``).
    Same keyword arguments as v1, without ``mesh``."""

    env_id = "ACLDBeam-v0"
    _basis = _V0["_basis"]
    _harmonic_modes = _V0["_harmonic_modes"]
    _model_std = _V0["_model_std"]
    _param_noise_max = _V0["_param_noise_max"]

    def __init__(self, **kwargs):
        super().__init__(mesh="thesis", **_no_mesh(kwargs))


class ACLDBeamVectorEnvV0(ACLDBeamVectorEnv):
    """The batched ``ACLDBeam-v0`` (see :class:`ACLDBeamEnvV0`)."""

    env_id = "ACLDBeam-v0"
    _basis = _V0["_basis"]
    _harmonic_modes = _V0["_harmonic_modes"]
    _model_std = _V0["_model_std"]
    _param_noise_max = _V0["_param_noise_max"]

    def __init__(self, num_envs: int = 1, max_episode_steps: int | None = None, **kwargs):
        super().__init__(num_envs=num_envs, max_episode_steps=max_episode_steps, mesh="thesis",
                         **_no_mesh(kwargs))
