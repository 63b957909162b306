r"""Parameter uncertainty of the beam: which material parameters are uncertain and how a
perturbed set is drawn.

``param_noise`` multiplies each of :data:`RANDOMIZED` by :math:`e^z`,
:math:`z \sim N(0, \sigma^2)` truncated to :math:`\pm` :data:`PARAM_NOISE_CLIP`
:math:`\sigma`: a log-normal factor, so every drawn value keeps its sign and every drawn
beam is a physical one (its Galerkin projection is stable, :mod:`acld_gym.physics.truth`).
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from acld_gym.physics.params import BeamParameters

__all__ = ["RANDOMIZED", "PARAM_NOISE_CLIP", "randomized_parameters"]

#: Parameters perturbed by ``param_noise`` (multiplicative, log-normal, per episode).
RANDOMIZED = (
    "ghm_kappa",
    "ghm_alpha",
    "ghm_omega",
    "ghm_zeta",
    "vem_density",
    "beam_youngs_modulus",
    "pzt_youngs_modulus",
    "d31",
    "rayleigh_mass",
    "rayleigh_stiffness",
)

#: Truncation of the log-normal parameter factors, in standard deviations.
PARAM_NOISE_CLIP = 3.0


def randomized_parameters(
    rng: np.random.Generator, param_noise: float, params: BeamParameters
) -> BeamParameters:
    """``params`` with each of :data:`RANDOMIZED` times :math:`e^z`,
    :math:`z \\sim N(0, \\sigma^2)` truncated to :math:`\\pm 3\\sigma`
    (:data:`PARAM_NOISE_CLIP`); ``sigma = param_noise``."""
    z = np.clip(
        rng.normal(0.0, param_noise, len(RANDOMIZED)),
        -PARAM_NOISE_CLIP * param_noise,
        PARAM_NOISE_CLIP * param_noise,
    )
    return replace(
        params,
        **{
            name: getattr(params, name) * float(np.exp(zi))
            for name, zi in zip(RANDOMIZED, z, strict=True)
        },
    )
