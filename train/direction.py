r"""The direction features :math:`[z/|z|, \log|z|]` in numpy (the trained agent's actor,
:class:`train.agent.ActorProgram`); :class:`train.features.DirectionFeatures` is their torch
twin for training."""

from __future__ import annotations

import numpy as np

__all__ = ["EPS", "direction_features"]

#: Amplitude floor of the norm (the observation's scales are of order one).
EPS = 1e-12


def direction_features(obs: np.ndarray) -> np.ndarray:
    r"""numpy twin of :class:`train.features.DirectionFeatures`: ``[z / |z|, log |z|]``,
    shape (n, d + 1)."""
    z = np.asarray(obs, dtype=np.float64)
    r = np.sqrt(np.sum(z * z, axis=-1, keepdims=True) + EPS**2)
    return np.concatenate([z / r, np.log(r)], axis=-1)
