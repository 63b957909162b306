"""Policy pieces for the SB3 algorithms: a critic on its own (e.g. quadratic) features
(:class:`train.core.sb3_policies.SplitCriticPolicy`), and a trained model as a
``predict`` policy in volts (:class:`SB3Policy`)."""

from __future__ import annotations

import pickle

import numpy as np
import torch
import torch.nn as nn
from gymnasium import spaces
from stable_baselines3.common.policies import ActorCriticPolicy, ContinuousCritic
from stable_baselines3.common.torch_layers import (
    BaseFeaturesExtractor,
    FlattenExtractor,
    MlpExtractor,
)
from stable_baselines3.common.vec_env import VecNormalize
from stable_baselines3.sac.policies import SACPolicy

import acld_gym  # noqa: F401  (registers the env ids)
from acld_gym.util.validate import check_real

from ..agent import actor_extractor
from ..features import DirectionFeatures, DropLast, direction_features  # DropLast re-exported

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
    "SB3Policy",
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
    :class:`NegativeScaledQuadraticFeature` (:class:`ScaledQuadraticCritic` with
    ``negative=True``)."""

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
    (:class:`QuadraticFeatures`; with ``net_arch: {vf: []}`` the value is a quadratic
    form of the observation, suited to a linear-quadratic problem),
    ``"scaled_quadratic"`` (:class:`ScaledQuadraticFeatures`), ``"negative_scaled_quadratic"``
    (:class:`NegativeScaledQuadraticFeature`: the value itself, never positive; its output
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
    (:class:`ScaledQuadraticFeatures`)."""

    def __init__(self, *args, critic_features: str = "scaled_quadratic", **kwargs):
        kwargs.setdefault("features_extractor_class", DropLast)
        super().__init__(*args, critic_features=critic_features, **kwargs)


class _PolicyOnly:
    """What :class:`SB3Policy` and :func:`train.agent.export_sb3` read of an SB3 model:
    its ``policy`` (the torch module). Pickles the module as plain bytes: a process pool
    sends results with torch's tensor reductions (shared memory), which refuse the tensors
    a training step leaves attached to autograd (gSDE's last noise draw)."""

    def __init__(self, policy):
        self.policy = policy

    def __getstate__(self) -> dict:
        return {"policy": pickle.dumps(self.policy, protocol=pickle.HIGHEST_PROTOCOL)}

    def __setstate__(self, state: dict) -> None:
        self.policy = pickle.loads(state["policy"])


class SB3Policy:
    """A trained SB3 model with its frozen ``VecNormalize`` statistics as a policy on the
    env's raw observation, ``predict`` in volts (``voltage_map``: the training env's
    :class:`train.voltage.VoltageMap`, default ``V = 120 clip(a, -1, 1)``);
    ``transform``: the agent's whitening matrix (:class:`train.vec.VecWhiten`), or None."""

    def __init__(
        self,
        model,
        obs_norm: VecNormalize | None,
        features: str | None,
        transform: np.ndarray | None = None,
        voltage_map=None,
    ):
        from ..voltage import VoltageMap

        self.model = model
        self.obs_norm = obs_norm
        self.features = features
        self.transform = None if transform is None else np.asarray(transform, np.float64)
        self.voltage_map = VoltageMap() if voltage_map is None else voltage_map
        extractor = actor_extractor(model)  # an asymmetric agent's actor drops the
        # privileged entries (log c, ...) the plain env does not have: predict pads them
        self.privileged = extractor.n if isinstance(extractor, DropLast) else 0

    @property
    def residual(self) -> str | None:
        """The voltage map's residual (None or ``"lqr"``)."""
        return self.voltage_map.residual

    def portable(self) -> SB3Policy:
        """This policy without its model's training state (env, replay buffer, logger,
        schedules): the same ``predict`` and export, small enough to send between
        processes (a SAC model with its buffer pickles to ~1 GB)."""
        return SB3Policy(
            _PolicyOnly(self.model.policy),
            self.obs_norm,
            self.features,
            self.transform,
            self.voltage_map,
        )

    def predict(self, observation, state=None, episode_start=None, deterministic: bool = True):
        obs = np.asarray(observation, dtype=np.float32)
        batched = obs.ndim == 2
        raw = np.atleast_2d(obs)
        x = raw
        if self.transform is not None:
            x = (x.astype(np.float64) @ self.transform).astype(np.float32)
        if self.features == "direction":
            x = direction_features(x).astype(np.float32)
        if self.obs_norm is not None:
            x = self.obs_norm.normalize_obs(x)
        if self.privileged:
            x = np.concatenate([x, np.zeros((len(x), self.privileged), np.float32)], axis=1)
        import torch

        with torch.no_grad():  # the deterministic action of model.predict, without its checks
            a = self.model.policy._predict(torch.as_tensor(x), deterministic=True).numpy()
        v = self.voltage_map(a, raw)
        return (v if batched else v[0]), state


class ScaledQuadraticCritic(ContinuousCritic):
    r"""SAC's twin critic on the quadratic features (and linear terms and a constant) of
    :math:`w = [u, a] / \sqrt{c}`, the observation being ``[u, log c]`` of an env with
    ``reward_scale: passive`` and ``observe_reward_scale: true``. With ``net_arch: {qf: []}``
    each critic is a quadratic form of w: the shape of the state-action value of a linear
    policy on a linear plant with a quadratic reward, divided by the episode's passive cost
    c (:class:`ScaledQuadraticFeatures` for the state value). With hidden layers
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
    PPO recipe's never-positive critic (:class:`NegativeScaledQuadraticFeature`) for SAC.
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
        from stable_baselines3.common.torch_layers import create_mlp

        from acld_gym.wrappers import check_headroom

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
        from acld_gym.wrappers import check_headroom

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
