"""SAC's policy with a critic on its own features: :class:`ScaledQuadraticCritic` (Q as a
quadratic form of the scaled state and action) and :class:`AsymmetricSACPolicy` (the actor
drops the privileged last entry; a headroom on the action)."""

from __future__ import annotations

import numpy as np
import torch
import torch.nn as nn
from gymnasium import spaces
from stable_baselines3.common.policies import ContinuousCritic
from stable_baselines3.common.torch_layers import (
    create_mlp,
)
from stable_baselines3.sac.policies import SACPolicy

from acld_gym.util.validate import check_real
from acld_gym.wrappers import check_headroom

from ..features import DropLast
from .critic_features import (
    NegativeSquareForm,
    QuadraticFeatures,
    scaled_state,
)

__all__ = ["ScaledQuadraticCritic", "AsymmetricSACPolicy"]


class ScaledQuadraticCritic(ContinuousCritic):
    r"""SAC's twin critic on the quadratic features (and linear terms and a constant) of
    :math:`w = [u, a] / \sqrt{c}`, the observation being ``[u, log c]`` of an env with
    ``reward_scale: passive`` and ``observe_reward_scale: true``. With ``net_arch: {qf: []}``
    each critic is a quadratic form of w: the shape of the state-action value of a linear
    policy on a linear plant with a quadratic reward, divided by the episode's passive cost
    c (:class:`train.core.critic_features.ScaledQuadraticFeatures` for the state value).
    With hidden layers
    (``qf: [64, 64]``) an MLP on those features, which can also represent what the
    saturation at +/-120 V does to the value.

    The action entering w is the one the actuator applies, :math:`\mathrm{clip}(k a, -1,
    1)` (V / 120 V) for the ``action_headroom`` k of the training env
    (:class:`train.voltage.VoltageMap`). With k > 1 an action beyond 1/k changes nothing,
    and the critic says so (its gradient in a is zero there): a quadratic form of the raw
    a would extrapolate its slope past the limit and drive the tanh actor into tanh's flat
    tail, where the entropy term then fights it (measured: the temperature grows 30x and
    the policy degrades after 1M steps).

    ``offset_scale``: None (no extra feature; the layer's bias is the constant), or a
    constant feature of that value. In the scaled units of ``reward_scale: passive`` the
    value's constant is about -70 at gamma 0.995 (the cost of the loads still to come;
    fitted by least squares on the random search's data, against quadratic coefficients of
    0.003-3): with Adam's steps of about 1e-3 a bias takes some 70,000 updates to get
    there, and meanwhile the quadratic terms make up for it; a feature of 100 brings it
    within 700.

    ``negative``: each critic is :math:`Q = -\|M [w; s]\|^2` instead
    (:class:`NegativeSquareForm`; s the ``offset_scale``, or 1), a quadratic form, a linear
    term and a constant that sum to at most 0, as every value of the env's costs is: the
    PPO recipe's never-positive critic
    (:class:`train.core.critic_features.NegativeScaledQuadraticFeature`) for SAC.
    It takes ``net_arch: []`` only."""

    def __init__(
        self,
        observation_space,
        action_space,
        net_arch,
        *args,
        n_critics: int = 2,
        activation_fn=nn.ReLU,
        action_headroom: float = 1.0,
        offset_scale: float | None = None,
        negative: bool = False,
        **kwargs,
    ):
        super().__init__(
            observation_space,
            action_space,
            net_arch,
            *args,
            n_critics=n_critics,
            activation_fn=activation_fn,
            **kwargs,
        )
        self.action_headroom = check_headroom(action_headroom)
        self.offset_scale = (
            None
            if offset_scale is None
            else check_real("offset_scale", offset_scale, 0.0, low_open=True)
        )
        if not isinstance(negative, bool) or (negative and list(net_arch)):
            raise ValueError(
                f"negative (SAC's policy_kwargs negative_critic) must be true or false, and "
                f"true with net_arch qf: [] only; got {negative!r} with qf: {list(net_arch)!r}"
            )
        self.negative = negative
        d = int(observation_space.shape[0]) - 1 + int(np.prod(action_space.shape))
        # negative: each critic on [w, s]; else on the quadratic features of w and the
        # constant offset_scale, if any
        self.quadratic = (
            None if negative else QuadraticFeatures(spaces.Box(-np.inf, np.inf, (d,), np.float32))
        )
        n_feat = None if negative else self.quadratic.features_dim + (offset_scale is not None)
        self.q_networks = []
        for idx in range(n_critics):
            if negative:
                q_net = NegativeSquareForm(d + 1)
            else:
                q_net = nn.Sequential(*create_mlp(n_feat, 1, list(net_arch), activation_fn))
            self.add_module(f"qf{idx}", q_net)  # replaces the MLP of the same name
            self.q_networks.append(q_net)

    def _features(self, obs: torch.Tensor, actions: torch.Tensor) -> torch.Tensor:
        applied = torch.clamp(self.action_headroom * actions, -1.0, 1.0)
        w = scaled_state(obs, applied)
        if self.negative:
            s = 1.0 if self.offset_scale is None else self.offset_scale
            return torch.cat([w, torch.full_like(w[:, :1], s)], dim=1)
        f = self.quadratic(w)
        if self.offset_scale is None:
            return f
        return torch.cat([f, torch.full_like(f[:, :1], self.offset_scale)], dim=1)

    def forward(self, obs: torch.Tensor, actions: torch.Tensor) -> tuple[torch.Tensor, ...]:
        f = self._features(obs, actions)
        return tuple(q(f) for q in self.q_networks)

    def q1_forward(self, obs: torch.Tensor, actions: torch.Tensor) -> torch.Tensor:
        return self.q_networks[0](self._features(obs, actions))


class AsymmetricSACPolicy(SACPolicy):
    """SAC's policy on the observation ``[u, log c]``: the (squashed Gaussian) actor reads u
    only (:class:`DropLast`; ``net_arch: {pi: []}`` a linear law, deployable on the plain
    env), the twin critic is :class:`ScaledQuadraticCritic` of the applied action, for the
    ``action_headroom`` of the env's action map (:func:`train.core.sb3_train.make_model`
    passes the config's), with its ``offset_scale``, never positive with ``negative_critic``
    (:class:`NegativeSquareForm`).

    Two bounds on the actor, for an exploration floor: ``mean_clip`` m limits the
    pre-tanh mean to [-m, m] (a ``Hardtanh``, exported as a ``clip``; with m = 1 and
    headroom 3 the limit is still reached, tanh(1) = 0.76 > 1/3, and the entropy's
    tanh correction stays bounded), and ``log_std_min`` bounds the (state-dependent) log
    standard deviation from below (SB3's own bound is -20). With SAC's temperature tuned
    to its target entropy the noise shrank to about 5 V on the applied voltage; the
    critic then saw too little of the action's effect to tell its slope in a, and the
    actor's gain drifted up until the policy degraded."""

    #: The policy takes the env's ``action_headroom`` as a keyword (its critic reads the
    #: applied action): :func:`train.core.sb3_train.make_model` passes the config's.
    takes_action_headroom = True

    def __init__(
        self,
        *args,
        action_headroom: float = 1.0,
        offset_scale: float | None = None,
        mean_clip: float | None = None,
        log_std_min: float | None = None,
        negative_critic: bool = False,
        **kwargs,
    ):
        self.action_headroom = check_headroom(action_headroom)
        if mean_clip is not None:
            check_real("mean_clip", mean_clip, 0.0, low_open=True)
        if log_std_min is not None and not -20.0 <= check_real("log_std_min", log_std_min) < 2.0:
            raise ValueError(
                f"log_std_min must be in [-20, 2) (SAC's log std range), got {log_std_min!r}"
            )
        self.offset_scale = offset_scale
        self.negative_critic = negative_critic
        self.mean_clip = mean_clip
        self.log_std_min = log_std_min
        kwargs.setdefault("features_extractor_class", DropLast)
        kwargs["share_features_extractor"] = False
        super().__init__(*args, **kwargs)

    def make_actor(self, features_extractor=None):
        actor = super().make_actor(features_extractor)
        if self.mean_clip is not None:
            actor.mu = nn.Sequential(actor.mu, nn.Hardtanh(-self.mean_clip, self.mean_clip))
        if self.log_std_min is not None:
            actor.log_std = nn.Sequential(actor.log_std, nn.Hardtanh(self.log_std_min, 2.0))
        return actor

    def make_critic(self, features_extractor=None) -> ScaledQuadraticCritic:
        critic_kwargs = self._update_features_extractor(self.critic_kwargs, features_extractor)
        return ScaledQuadraticCritic(
            **critic_kwargs,
            action_headroom=self.action_headroom,
            offset_scale=self.offset_scale,
            negative=self.negative_critic,
        ).to(self.device)

    def _get_constructor_parameters(self) -> dict:
        data = super()._get_constructor_parameters()
        data.update(
            action_headroom=self.action_headroom,
            offset_scale=self.offset_scale,
            negative_critic=self.negative_critic,
            mean_clip=self.mean_clip,
            log_std_min=self.log_std_min,
        )
        return data
