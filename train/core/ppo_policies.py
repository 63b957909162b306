"""PPO's actor-critic policies with a critic on its own features: :class:`SplitCriticPolicy`
(actor and critic read different features; antithetic gSDE noise) and
:class:`AsymmetricCriticPolicy` (the actor drops the privileged last entry, the critic reads
it)."""

from __future__ import annotations

import torch
import torch.nn as nn
from stable_baselines3.common.policies import ActorCriticPolicy
from stable_baselines3.common.torch_layers import (
    BaseFeaturesExtractor,
    MlpExtractor,
)

from ..features import DropLast
from .critic_features import CRITIC_FEATURES

__all__ = ["SplitCriticPolicy", "AsymmetricCriticPolicy", "antithetic_pairs"]


class _SplitMlp(nn.Module):
    """``MlpExtractor``'s interface with actor and critic on inputs of their own size."""

    def __init__(self, pi_dim, vf_dim, net_arch, activation_fn, device):
        super().__init__()
        arch = net_arch if isinstance(net_arch, dict) else {"pi": net_arch, "vf": net_arch}
        pi = MlpExtractor(pi_dim, {"pi": list(arch.get("pi", [])), "vf": []}, activation_fn, device)
        vf = MlpExtractor(vf_dim, {"pi": [], "vf": list(arch.get("vf", []))}, activation_fn, device)
        self.policy_net, self.value_net = pi.policy_net, vf.value_net
        self.latent_dim_pi, self.latent_dim_vf = pi.latent_dim_pi, vf.latent_dim_vf

    def forward(self, features):
        return self.forward_actor(features), self.forward_critic(features)

    def forward_actor(self, features):
        return self.policy_net(features)

    def forward_critic(self, features):
        return self.value_net(features)


def antithetic_pairs(draws: torch.Tensor) -> torch.Tensor:
    """A copy of ``draws`` (one per sub-env, first axis) with sub-env ``2i + 1``'s the
    negative of ``2i``'s: the pair layout of ``paired_loads`` and ``antithetic_noise``."""
    out = draws.clone()
    out[1::2] = -out[0::2]
    return out


class SplitCriticPolicy(ActorCriticPolicy):
    """PPO's ``ActorCriticPolicy`` whose critic has features of its own,
    ``critic_features`` (a ``policy_kwargs`` key): ``"quadratic"``
    (:class:`train.core.critic_features.QuadraticFeatures`; with ``net_arch: {vf: []}``
    the value is a quadratic form of the observation, suited to a linear-quadratic
    problem), ``"scaled_quadratic"``
    (:class:`train.core.critic_features.ScaledQuadraticFeatures`),
    ``"negative_scaled_quadratic"``
    (:class:`train.core.critic_features.NegativeScaledQuadraticFeature`: the value
    itself, never positive; its output
    layer fixed, with ``net_arch: {vf: []}`` only), ``"direction"``
    (:class:`train.features.DirectionFeatures`) or ``"flatten"``. The actor sees the
    (flattened) observation, e.g. linear with ``net_arch: {pi: []}``.
    ``antithetic_noise`` (a ``policy_kwargs`` key, with ``use_sde``): gSDE's noise in
    antithetic pairs of sub-envs (:meth:`reset_noise`)."""

    def __init__(
        self, *args, critic_features: str = "quadratic", antithetic_noise: bool = False, **kwargs
    ):
        if critic_features not in CRITIC_FEATURES:
            raise ValueError(f"critic_features must be one of {list(CRITIC_FEATURES)}")
        if not isinstance(antithetic_noise, bool) or (
            antithetic_noise and not kwargs.get("use_sde", False)
        ):
            raise ValueError(
                f"antithetic_noise must be true or false, and true with use_sde only; "
                f"got {antithetic_noise!r}"
            )
        self.critic_features = critic_features
        self.antithetic_noise = antithetic_noise
        kwargs["share_features_extractor"] = False
        super().__init__(*args, **kwargs)
        weight = getattr(self.vf_features_extractor, "output_weight", None)
        if weight is not None:  # the critic's sign is its features': output layer fixed
            if self.mlp_extractor.latent_dim_vf != 1:
                raise ValueError(
                    f"critic_features {critic_features!r} is the value itself: it takes "
                    f"net_arch vf: [], got a critic of {self.mlp_extractor.latent_dim_vf} outputs"
                )
            with torch.no_grad():
                self.value_net.weight.fill_(weight)
                self.value_net.bias.zero_()
            self.value_net.requires_grad_(False)

    def reset_noise(self, n_envs: int = 1) -> None:
        """gSDE's new noise on the actor's gains, one matrix E per sub-env; with
        ``antithetic_noise`` in pairs, sub-env ``2i + 1`` acting with ``-E`` where ``2i``
        acts with ``E`` (with sub-envs seeded in pairs, ``paired_loads`` of
        :class:`train.config.TrainConfig`, the pair's load-driven returns cancel in the
        policy gradient, as in the random search's antithetic differences). A single draw
        (``n_envs=1``: SB3's ``PPO.load`` and a one-env rollout) has no pair and is gSDE's
        own; any other odd number is a ``ValueError``, before a draw, so the policy's noise
        is left as it was."""
        if self.antithetic_noise and n_envs % 2 and n_envs != 1:
            raise ValueError(
                f"antithetic_noise needs 1 or an even number of noise draws (n_envs: sub-envs, "
                f"or PPO's batch_size), got {n_envs}"
            )
        super().reset_noise(n_envs)
        if not self.antithetic_noise or n_envs == 1:
            return
        dist = self.action_dist
        dist.exploration_matrices = antithetic_pairs(dist.exploration_matrices.detach())

    def make_critic_extractor(self) -> BaseFeaturesExtractor:
        """The critic's features extractor on the observation space: ``critic_features``'
        class (:data:`CRITIC_FEATURES`); a subclass may build another."""
        return CRITIC_FEATURES[self.critic_features](self.observation_space)

    def _build_mlp_extractor(self) -> None:
        self.vf_features_extractor = self.make_critic_extractor()
        self.mlp_extractor = _SplitMlp(
            self.features_dim,
            self.vf_features_extractor.features_dim,
            self.net_arch,
            self.activation_fn,
            self.device,
        )

    def _get_constructor_parameters(self) -> dict:
        data = super()._get_constructor_parameters()
        data["critic_features"] = self.critic_features
        data["antithetic_noise"] = self.antithetic_noise
        return data


class AsymmetricCriticPolicy(SplitCriticPolicy):
    r"""An asymmetric actor-critic on the observation ``[u, log c]`` of an env with
    ``reward_scale: passive`` and ``observe_reward_scale: true``: the actor reads u only
    (:class:`DropLast`; with ``net_arch: {pi: []}`` a linear law, deployable on the plain
    env), the critic the quadratic features of :math:`u/\sqrt{c}`
    (:class:`train.core.critic_features.ScaledQuadraticFeatures`)."""

    def __init__(self, *args, critic_features: str = "scaled_quadratic", **kwargs):
        kwargs.setdefault("features_extractor_class", DropLast)
        super().__init__(*args, critic_features=critic_features, **kwargs)
