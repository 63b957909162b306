"""Features of a critic on its own: quadratic forms of the (scaled) observation, for the
value of a linear policy on a cost (:data:`CRITIC_FEATURES`, the names a recipe's
``critic_features:`` takes). Used by the PPO policies (:mod:`train.core.ppo_policies`) and
the SAC critic (:mod:`train.core.sac_policies`)."""

from __future__ import annotations

import numpy as np
import torch
import torch.nn as nn
from gymnasium import spaces
from stable_baselines3.common.torch_layers import (
    BaseFeaturesExtractor,
    FlattenExtractor,
)

from ..features import DirectionFeatures

__all__ = [
    "QuadraticFeatures",
    "ScaledQuadraticFeatures",
    "NegativeScaledQuadraticFeature",
    "NegativeSquareForm",
    "scaled_state",
    "square_form_matrix",
    "square_norm",
    "CRITIC_FEATURES",
]


class QuadraticFeatures(BaseFeaturesExtractor):
    r"""Features :math:`[u,\ u u^T]` of the observation u (d + d^2 values, the outer
    product flattened): a linear value on them is a quadratic form plus a linear term, the
    shape of a linear-quadratic problem's value function. (The outer product holds each
    :math:`u_i u_j` twice, which a linear layer does not mind; it costs one broadcast
    product, where gathering the :math:`i \le j` entries costs an indexed gather and its
    scatter in the backward pass, 10x slower on a CPU.)"""

    def __init__(self, observation_space: spaces.Box):
        d = int(observation_space.shape[0])
        super().__init__(observation_space, features_dim=d + d * d)

    def forward(self, observations: torch.Tensor) -> torch.Tensor:
        outer = observations.unsqueeze(2) * observations.unsqueeze(1)
        return torch.cat([observations, outer.flatten(1)], dim=-1)


class ScaledQuadraticFeatures(QuadraticFeatures):
    r"""Quadratic features (:class:`QuadraticFeatures`) of :math:`u / \sqrt{c}`, where the
    observation is :math:`[u, \log c]` (``observe_reward_scale``). With the reward divided
    by the episode's passive cost c (``reward_scale: passive``), the value of a linear
    policy on a linear plant is :math:`V(u)/c` with V quadratic in u, hence exactly a
    quadratic form of :math:`u/\sqrt{c}`: one set of critic weights fits every load, where
    a quadratic form of u alone would have to span the six decades of c."""

    def __init__(self, observation_space: spaces.Box):
        d = int(observation_space.shape[0]) - 1
        super().__init__(spaces.Box(-np.inf, np.inf, (d,), np.float32))
        self._observation_space = observation_space

    def forward(self, observations: torch.Tensor) -> torch.Tensor:
        return super().forward(scaled_state(observations))


def scaled_state(observations: torch.Tensor, *extra: torch.Tensor) -> torch.Tensor:
    r""":math:`w = [u, \ldots] / \sqrt{c}` of observations :math:`[u, \log c]`
    (``observe_reward_scale``: log c last), the state the scaled critics are quadratic in;
    ``extra`` columns (SAC's applied action) join u before the scaling."""
    x = torch.cat([observations[:, :-1], *extra], dim=1) if extra else observations[:, :-1]
    return x * torch.exp(-0.5 * observations[:, -1:])


class NegativeScaledQuadraticFeature(BaseFeaturesExtractor):
    r"""The one feature :math:`q = \|M [w; 1]\|^2 \ge 0` of the observation
    :math:`[u, \log c]`, :math:`w = u/\sqrt{c}` (as :class:`ScaledQuadraticFeatures`), M a
    learned square matrix of size d + 1, started at 0.1 times a standard normal draw over
    :math:`\sqrt{d + 1}`. The critic on it is :math:`V = -q` (:attr:`output_weight`; its
    output layer is fixed, no bias): a quadratic form, a linear term and a constant that
    sum to at most 0 for every observation.

    Why: every reward of the env is a cost's negative, so every value is at most 0, and so
    is the value of a linear policy on a linear plant with noise, :math:`-(w^T P w + k)`
    with :math:`P \succeq 0`, :math:`k \ge 0`. A general quadratic form
    (:class:`ScaledQuadraticFeatures` with a linear output) can curve upwards, and in the
    PPO recipe's runs that ended in the +/-120 V limit cycle it did: on seed 8 its values
    reached +6e5 within the first rollouts after the whitening, the returns it bootstraps
    at each rollout's end turned positive, and the actor followed the critic's
    divergence (docs/training.md, "A critic that cannot be positive")."""

    #: The critic's value is this times the feature (the output layer fixed, no bias).
    output_weight = -1.0

    def __init__(self, observation_space: spaces.Box, init: float = 0.1):
        super().__init__(observation_space, features_dim=1)
        self.m = square_form_matrix(int(observation_space.shape[0]), init)  # d + 1: u, log c

    def forward(self, observations: torch.Tensor) -> torch.Tensor:
        w = scaled_state(observations)
        return square_norm(torch.cat([w, torch.ones_like(w[:, :1])], dim=-1), self.m)


def square_form_matrix(n: int, init: float = 0.1) -> nn.Parameter:
    r"""The learned n x n matrix M of a form :math:`\|M z\|^2`, started at ``init`` times a
    standard normal draw over :math:`\sqrt{n}`."""
    return nn.Parameter(torch.randn(n, n) * init / np.sqrt(n))


def square_norm(z: torch.Tensor, m: torch.Tensor) -> torch.Tensor:
    r""":math:`\|M z\|^2` of each row z of ``z``, as a column."""
    return (z @ m.T).square().sum(dim=-1, keepdim=True)


class NegativeSquareForm(nn.Module):
    r"""A critic head :math:`Q = -\|M z\|^2 \le 0` on features z (:func:`square_norm`,
    M from :func:`square_form_matrix`): SAC's never-positive twin of
    :class:`NegativeScaledQuadraticFeature`
    (:class:`train.core.sac_policies.ScaledQuadraticCritic` with ``negative=True``)."""

    def __init__(self, n: int, init: float = 0.1):
        super().__init__()
        self.m = square_form_matrix(n, init)

    def forward(self, z: torch.Tensor) -> torch.Tensor:
        return -square_norm(z, self.m)


#: ``critic_features`` of :class:`train.core.sb3_policies.SplitCriticPolicy` and their extractor
#: classes.
CRITIC_FEATURES = {
    "quadratic": QuadraticFeatures,
    "scaled_quadratic": ScaledQuadraticFeatures,
    "negative_scaled_quadratic": NegativeScaledQuadraticFeature,
    "direction": DirectionFeatures,
    "flatten": FlattenExtractor,
}
