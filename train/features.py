r"""Observation features for the agents' actors: the scale-free direction features
(:class:`DirectionFeatures`) and the asymmetric actor's view without the privileged entries
(:class:`DropLast`).

Near the +/-120 V limit the best voltage is close to bang-bang: the constrained
MPC saturates in 86 % of the steps of random-load episodes, and the sign of its
voltage is a linear function of the *direction* of the scaled estimate (a linear
classifier on :math:`z/|z|` agrees with it in 98 % of the steps). The decision
does not depend on the vibration's amplitude, which spans three decades in an
episode; a network on the raw observation must resolve it at every amplitude.
"""

from __future__ import annotations

import torch
from gymnasium import spaces
from stable_baselines3.common.torch_layers import BaseFeaturesExtractor

from .direction import EPS, direction_features

__all__ = ["DirectionFeatures", "DropLast", "direction_features", "FEATURES"]


class DirectionFeatures(BaseFeaturesExtractor):
    r"""Features :math:`[z / |z|,\ \log |z|]` of the observation z (d + 1 values).

    A linear actor on these features is a switching surface through the origin,
    :math:`V = 120\,\mathrm{clip}(w^T z/|z| + c \log|z| + b)`, with a boundary
    layer of angular width about :math:`1/|w|` that is the same at every
    amplitude; the critic gets the amplitude from :math:`\log |z|`. Use it on
    observations that are not mean-shifted (``VecNormalize(norm_obs=False)``:
    the env's observation is already scaled to order one).
    """

    def __init__(self, observation_space: spaces.Box):
        if len(observation_space.shape) != 1:
            raise ValueError(
                f"observation_space: DirectionFeatures needs a flat Box, "
                f"got shape {observation_space.shape}"
            )
        super().__init__(observation_space, features_dim=observation_space.shape[0] + 1)

    def forward(self, observations: torch.Tensor) -> torch.Tensor:
        r = torch.sqrt(torch.sum(observations * observations, dim=-1, keepdim=True) + EPS**2)
        return torch.cat([observations / r, torch.log(r)], dim=-1)


class DropLast(BaseFeaturesExtractor):
    """The observation without its last ``n`` entries (default 1): the actor of an
    asymmetric actor-critic, which must not read the privileged entries the training env
    appends, the log(reward scale) (``observe_reward_scale``, :mod:`acld_gym.envs.scale`)
    and any after it."""

    def __init__(self, observation_space: spaces.Box, n: int = 1):
        dim = int(observation_space.shape[0])
        if not (isinstance(n, int) and 1 <= n < dim):
            raise ValueError(f"n: expected an integer in [1, {dim - 1}], got {n!r}")
        self.n = n
        super().__init__(observation_space, features_dim=dim - n)

    def forward(self, observations: torch.Tensor) -> torch.Tensor:
        return observations[:, : -self.n]


#: ``features`` values of a training config and their extractor classes.
FEATURES = {"direction": DirectionFeatures}
