"""Policy pieces for the SB3 algorithms, by job in their own modules and importable from here
(recipes and saved models name ``train.core.sb3_policies.<Class>``):

* :mod:`train.core.critic_features`: a critic's own features (quadratic forms,
  :data:`CRITIC_FEATURES`);
* :mod:`train.core.ppo_policies`: PPO's :class:`SplitCriticPolicy` and
  :class:`AsymmetricCriticPolicy`;
* :mod:`train.core.sac_policies`: SAC's :class:`ScaledQuadraticCritic` and
  :class:`AsymmetricSACPolicy`;
* :mod:`train.core.sb3_inference`: a trained model as a ``predict`` policy in volts
  (:class:`SB3Policy`).

The rollout buffer of the off-policy algorithms is :mod:`train.core.buffers`.
"""

from __future__ import annotations

import acld_gym  # noqa: F401  (registers the env ids)

from ..features import DropLast
from .critic_features import (
    CRITIC_FEATURES,
    NegativeScaledQuadraticFeature,
    NegativeSquareForm,
    QuadraticFeatures,
    ScaledQuadraticFeatures,
    scaled_state,
    square_form_matrix,
    square_norm,
)
from .ppo_policies import AsymmetricCriticPolicy, SplitCriticPolicy, antithetic_pairs
from .sac_policies import AsymmetricSACPolicy, ScaledQuadraticCritic
from .sb3_inference import SB3Policy

__all__ = [
    "QuadraticFeatures",
    "CRITIC_FEATURES",
    "SplitCriticPolicy",
    "AsymmetricCriticPolicy",
    "AsymmetricSACPolicy",
    "ScaledQuadraticCritic",
    "DropLast",
    "ScaledQuadraticFeatures",
    "NegativeScaledQuadraticFeature",
    "NegativeSquareForm",
    "SB3Policy",
    "antithetic_pairs",
    "scaled_state",
    "square_form_matrix",
    "square_norm",
]
