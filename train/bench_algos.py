r"""Algorithms of the teacher-free benchmark (``python -m train.benchmark``).

Every algorithm learns from the env's observation and reward only: no controller,
demonstration or controller-derived reward anywhere in training, and nothing read
from the env's internals. :func:`train_algo` trains one for a fixed env-step budget,
reports learning-curve points through a callback, and returns a policy with SB3's
``predict`` in volts.

* ``vrs`` (the recipe): vectorised random search (ARS, Mania et al. 2018, "V1-t") on
  the linear direction actor :class:`LinearDirectionActor`,
  :math:`V = 120\,\mathrm{clip}(w \cdot [u/|u|, \log|u|] + b, -1, 1)` (9 parameters
  for the 7-value observation z), :math:`u = T^T z` with T a whitening matrix the
  agent estimates from its own first round of episodes (:func:`whitening`). All
  2 x ``n_directions`` perturbed actors run side by side in the native batched env
  on the same episodes (common random numbers), and each episode's return R is
  scored as :math:`-\log(-R)` (``objective: log``), which makes loads whose returns
  differ by three decades weigh alike (reward normalisation per load).
* ``ars``: sb3-contrib's ``ARS`` (linear policy, clipped) on the direction features.
* ``ppo``, ``sac``, ``td3``, ``tqc``, ``crossq``: stable-baselines3 / sb3-contrib
  through :func:`make_sb3_env`: the native batched env (``SB3VecEnv``), actions in
  [-1, 1] (``train.vec.VecAgentEnv``, no residual, no shaping), optionally the
  direction features as the observation (:class:`VecDirectionFeatures`), and
  ``VecNormalize``. Options for them (fields of :class:`AlgoConfig`): ``whiten_steps``,
  a ZCA whitening of the observation estimated from the agent's own first rollouts
  (:class:`VecWhiten`, the steps counted in the budget); for PPO the policy
  ``SplitCriticPolicy`` (the critic on its own features, e.g. quadratic ones,
  :class:`SplitCriticPolicy`) and ``episode_scale``, advantages normalised per episode
  (:class:`EpisodeScaledRolloutBuffer`).
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import gymnasium as gym
import numpy as np
import torch
import torch.nn as nn
from gymnasium import spaces
from stable_baselines3.common.buffers import RolloutBuffer
from stable_baselines3.common.policies import ActorCriticPolicy
from stable_baselines3.common.torch_layers import (
    BaseFeaturesExtractor,
    FlattenExtractor,
    MlpExtractor,
)
from stable_baselines3.common.vec_env import VecEnv, VecEnvWrapper, VecNormalize

import acld_gym  # noqa: F401  (registers the env ids)

from .features import DirectionFeatures, direction_features

__all__ = ["ALGOS", "SB3_ALGOS", "AlgoConfig", "LinearDirectionActor", "whitening",
           "VecDirectionFeatures", "VecWhiten", "QuadraticFeatures", "SplitCriticPolicy",
           "EpisodeScaledRolloutBuffer",
           "ConcatVecEnv", "make_sb3_env", "SB3Policy", "RandomSearch", "train_algo"]

#: Algorithms from stable-baselines3 / sb3-contrib (module, class).
SB3_ALGOS = {"ppo": ("stable_baselines3", "PPO"), "sac": ("stable_baselines3", "SAC"),
             "td3": ("stable_baselines3", "TD3"), "tqc": ("sb3_contrib", "TQC"),
             "crossq": ("sb3_contrib", "CrossQ"), "ars": ("sb3_contrib", "ARS")}
ALGOS = ("vrs", *SB3_ALGOS)

#: Learning-curve callback: ``callback(env_steps, policy)``.
CurveCallback = Callable[[int, Any], None]


def parse_case(value) -> int | str:
    """A load case from YAML / CLI text: 1, 2, 3 or ``"random"``."""
    if value in (1, 2, 3, "random"):
        return value
    if str(value) in ("1", "2", "3"):
        return int(value)
    raise ValueError(f"load case must be 1, 2, 3 or 'random', got {value!r}")


@dataclass(frozen=True)
class AlgoConfig:
    """One algorithm's settings (a YAML file under ``train/benchmark/``).

    Attributes
    ----------
    algo : str
        One of :data:`ALGOS`.
    timesteps : int
        Env-step budget of a run (the same for every seed).
    n_envs : int
        Sub-envs of the native batched env (SB3 algorithms).
    loads : dict
        Training loads, ``{case: weight}`` with cases 1, 2, 3, ``random``. For ``vrs``
        the weights are episodes per candidate per iteration; for SB3 algorithms the
        sub-envs are split in proportion (:class:`ConcatVecEnv`).
    features : str or None
        ``"direction"``: the agent sees ``[z/|z|, log|z|]``; None: the raw observation.
    normalize : dict
        ``VecNormalize`` keyword arguments (SB3 algorithms).
    model : dict
        The algorithm's keyword arguments (SB3: ``policy`` included; ``vrs``: the
        fields of :class:`RandomSearch`).
    eval_points : int
        Learning-curve points (evaluations) over the budget, besides the one at step 0
        (log-spaced, :class:`eval_schedule`).
    whiten_steps : int
        SB3 algorithms: 0 (default) for none; else the agent first acts with its own
        initial (stochastic) policy for about this many env steps (whole vector steps,
        counted in the budget), and :func:`whitening` of the observation directions it
        saw becomes a fixed linear map of the observation, ``u = T^T z``
        (:class:`VecWhiten`), the network's input. Needs ``features: null`` and
        ``norm_obs: false``; the final actor takes T into its first layer.
    episode_scale : bool
        PPO only: the advantages of each episode in a rollout are divided by their
        root mean square (:class:`EpisodeScaledRolloutBuffer`; the critic's targets
        are unchanged): episodes whose returns differ by decades weigh alike in the
        policy gradient (normalisation per load). Use ``n_steps`` = the episode length.
    """

    algo: str
    timesteps: int
    n_envs: int = 16
    loads: dict = field(default_factory=lambda: {"random": 1})
    features: str | None = "direction"
    normalize: dict = field(default_factory=lambda: {"norm_obs": False, "norm_reward": True})
    model: dict = field(default_factory=dict)
    eval_points: int = 10
    whiten_steps: int = 0
    episode_scale: bool = False

    def __post_init__(self):
        if self.algo not in ALGOS:
            raise ValueError(f"algo must be one of {list(ALGOS)}, got {self.algo!r}")
        for name in ("timesteps", "n_envs", "eval_points"):
            value = getattr(self, name)
            if isinstance(value, bool) or not isinstance(value, int) or value < 1:
                raise ValueError(f"{name} must be a positive integer, got {value!r}")
        if not self.loads or any(not (isinstance(w, (int, float)) and w > 0)
                                 for w in self.loads.values()):
            raise ValueError(f"loads must map cases to positive weights, got {self.loads!r}")
        for case in self.loads:
            parse_case(case)
        if self.features not in (None, "direction"):
            raise ValueError(f"features must be 'direction' or null, got {self.features!r}")
        if self.algo != "vrs" and "policy" not in self.model:
            raise ValueError(f"{self.algo}: model must name the SB3 policy")
        if isinstance(self.whiten_steps, bool) or not isinstance(self.whiten_steps, int) \
                or self.whiten_steps < 0 or (self.whiten_steps and self.algo in ("vrs", "ars")):
            raise ValueError(f"whiten_steps must be a non-negative integer (SB3 algorithms "
                             f"other than ars; vrs: model.whiten), got {self.whiten_steps!r}")
        if self.whiten_steps and (self.features is not None
                                  or self.normalize.get("norm_obs", False)):
            raise ValueError("whiten_steps needs features: null and norm_obs: false (the "
                             "trained actor takes the whitening into its first layer)")
        if self.episode_scale and self.algo != "ppo":
            raise ValueError("episode_scale is for ppo only")

    @property
    def load_weights(self) -> dict:
        """``loads`` with parsed case keys."""
        return {parse_case(c): w for c, w in self.loads.items()}

    @classmethod
    def from_dict(cls, data: dict) -> AlgoConfig:
        known = set(cls.__dataclass_fields__)
        unknown = sorted(set(data) - known)
        if unknown:
            raise ValueError(f"unknown key(s) {unknown}; expected some of {sorted(known)}")
        return cls(**data)

    def as_dict(self) -> dict:
        return {k: getattr(self, k) for k in self.__dataclass_fields__}


class eval_schedule:  # noqa: N801  (used like a function)
    """Learning-curve evaluations: at step 0 and at ``points`` env-step counts spaced
    logarithmically from 1 % of ``budget`` to ``budget``; :meth:`due` is true once per
    threshold crossed."""

    def __init__(self, budget: int, points: int):
        self.thresholds = sorted({int(round(x)) for x in budget * np.logspace(-2, 0, points)})
        self.thresholds = [0] + [t for t in self.thresholds if t > 0]
        self._next = 0

    def due(self, steps: int) -> bool:
        if self._next >= len(self.thresholds) or steps < self.thresholds[self._next]:
            return False
        while self._next < len(self.thresholds) and steps >= self.thresholds[self._next]:
            self._next += 1
        return True


# --- the linear direction actor -------------------------------------------------
class LinearDirectionActor:
    r"""The switching actor :math:`V = V_{max}\,\mathrm{clip}(w \cdot f + b, -1, 1)` on
    :math:`f = [u/|u|, \log|u|]` of :math:`u = T^T z`, z the raw observation and T a fixed
    whitening matrix estimated from the agent's own observations (identity if None;
    ``theta = [w, b]``). ``features=None`` uses f = u instead (a saturated linear
    state feedback).

    ``predict`` follows SB3's protocol and returns volts, so
    :func:`baselines.evaluate.rollout` runs it like any baseline.
    """

    def __init__(self, theta: np.ndarray, v_max: float = 120.0,
                 features: str | None = "direction", transform: np.ndarray | None = None):
        self.theta = np.asarray(theta, dtype=np.float64).copy()
        self.v_max = float(v_max)
        self.features = features
        self.transform = None if transform is None else np.asarray(transform, np.float64)

    @staticmethod
    def actions(obs: np.ndarray, thetas: np.ndarray, features: str | None = "direction",
                transform: np.ndarray | None = None) -> np.ndarray:
        """Actions in [-1, 1], shape (n,), of one parameter row per observation row."""
        u = np.asarray(obs, np.float64)
        if transform is not None:
            u = u @ transform
        f = direction_features(u) if features == "direction" else u
        return np.clip(np.einsum("ni,ni->n", f, thetas[:, :-1]) + thetas[:, -1], -1.0, 1.0)

    def predict(self, observation, state=None, episode_start=None, deterministic: bool = True):
        """SB3 protocol: ``(voltages, state)``, shape (n, 1) for a batch or (1,)."""
        obs = np.asarray(observation, dtype=np.float64)
        batched = obs.ndim == 2
        obs2 = np.atleast_2d(obs)
        a = self.actions(obs2, np.broadcast_to(self.theta, (obs2.shape[0], self.theta.size)),
                         self.features, self.transform)
        v = (self.v_max * a)[:, None].astype(np.float32)
        return (v if batched else v[0]), state

    def as_dict(self) -> dict:
        return {"theta": self.theta.tolist(), "v_max": self.v_max, "features": self.features,
                "transform": None if self.transform is None else self.transform.tolist()}


def whitening(directions: np.ndarray, ridge: float = 1e-3) -> np.ndarray:
    r"""ZCA whitening matrix :math:`T = \Sigma^{-1/2}` (ridge-regularised, relative to the
    largest eigenvalue) of the second moment of the observation directions ``z/|z|``
    (rows), so that the direction features of ``z @ T`` are isotropic on average."""
    u = np.asarray(directions, dtype=np.float64)
    sigma = u.T @ u / max(u.shape[0], 1)
    lam, vec = np.linalg.eigh(sigma)
    lam = np.maximum(lam, 0.0) + ridge * lam.max()
    return (vec / np.sqrt(lam)) @ vec.T


@dataclass(frozen=True)
class RandomSearch:
    """Settings of ``vrs`` (the ``model:`` mapping of its YAML file).

    Attributes
    ----------
    n_directions : int
        Perturbation directions per iteration (2 x as many candidates).
    top_directions : int
        Directions used in the update (the best by max of their two scores).
    step_size : float
        ARS step size alpha (the update is divided by the scores' std).
    noise : float
        Perturbation std nu.
    relative : bool
        Scale step and perturbation by max(1, |theta| / sqrt(dim)): a step of the same
        relative size as the actor's gain grows (the boundary layer can thin out).
    objective : str
        Score of an episode with return R: ``"log"`` -log(-R) (per-load scale-free),
        ``"return"`` R itself.
    init_std : float
        Std of the random initial parameters (seeded).
    anneal : float
        Step size and noise fall linearly over the budget to this fraction of their
        initial values (1: constant), so the final actor jitters less.
    whiten : bool
        Estimate a whitening matrix (:func:`whitening`) from the observations of a first
        round of candidate episodes (counted in the budget) and search the actor on the
        whitened observation. The scaled observation's components are strongly
        correlated (up to 0.999), which makes an isotropic search in w ill-conditioned.
    common_episodes : bool
        Every candidate of an iteration runs on the same episodes (loads and sensor
        noise; common random numbers), so a direction's +/- scores differ by the
        perturbation, not by the loads. False: independent episodes per candidate.
    """

    n_directions: int = 16
    top_directions: int = 8
    step_size: float = 0.02
    noise: float = 0.03
    relative: bool = True
    objective: str = "log"
    init_std: float = 0.1
    anneal: float = 1.0
    whiten: bool = False
    common_episodes: bool = True

    def __post_init__(self):
        if not 1 <= self.top_directions <= self.n_directions:
            raise ValueError("need 1 <= top_directions <= n_directions")
        if self.objective not in ("log", "return"):
            raise ValueError(f"objective must be 'log' or 'return', got {self.objective!r}")


class _CandidateEnvs:
    """One native vector env per training load case, with ``per_candidate`` episodes of
    that case for each of ``n_candidates`` parameter rows (candidate-major)."""

    def __init__(self, env_id: str, loads: dict, n_candidates: int,
                 features: str | None = "direction"):
        self.envs = {}
        self.features = features
        self.n_candidates = n_candidates
        for case, n in loads.items():
            n = int(n)
            venv = gym.make_vec(env_id, num_envs=n_candidates * n, load_case=case).unwrapped
            self.envs[case] = (venv, n)
        first = next(iter(self.envs.values()))[0]
        self.v_max = float(first.single_action_space.high[0])
        self.horizon = int(first.horizon)
        self.n_obs = int(first.single_observation_space.shape[0])

    @property
    def steps_per_round(self) -> int:
        return sum(v.num_envs for v, _ in self.envs.values()) * self.horizon

    def returns(self, thetas: np.ndarray, seed: int, common: bool = True,
                transform: np.ndarray | None = None, collect: list | None = None) -> np.ndarray:
        """Returns, shape (n_candidates, episodes). ``common``: every candidate on the same
        episodes (episode j of a case seeded ``seed + j``; the cases' seeds are offset);
        else each candidate on its own episodes. ``collect``: a list that receives
        observation directions (every 10th step)."""
        out = []
        for c_idx, (venv, n) in enumerate(self.envs.values()):
            stride = 0 if common else n
            seeds = [seed + 100_000 * c_idx + stride * i + j
                     for i in range(self.n_candidates) for j in range(n)]
            obs, _ = venv.reset(seed=seeds)
            th = np.repeat(thetas, n, axis=0)
            ret = np.zeros(venv.num_envs)
            alive = np.ones(venv.num_envs, dtype=bool)
            for k in range(self.horizon):
                if collect is not None and k % 10 == 0:
                    z = np.asarray(obs, np.float64)
                    r = np.linalg.norm(z, axis=1, keepdims=True)
                    collect.append((z / np.maximum(r, 1e-12))[r[:, 0] > 0])
                v = self.v_max * LinearDirectionActor.actions(obs, th, self.features, transform)
                obs, r, term, trunc, _ = venv.step(v[:, None])
                ret += np.where(alive, r, 0.0)
                alive &= ~(term | trunc)
                if not alive.any():
                    break
            out.append(ret.reshape(self.n_candidates, n))
        return np.concatenate(out, axis=1)

    def close(self) -> None:
        for venv, _ in self.envs.values():
            venv.close()


def train_random_search(cfg: AlgoConfig, seed: int, env_id: str,
                        callback: CurveCallback | None = None,
                        ) -> tuple[LinearDirectionActor, dict]:
    """``vrs``: ARS on the linear direction actor for ``cfg.timesteps`` env steps.

    Returns the final actor and a record (iterations, steps, |theta|)."""
    rs = RandomSearch(**cfg.model)
    rng = np.random.default_rng(seed)
    envs = _CandidateEnvs(env_id, cfg.load_weights, 2 * rs.n_directions, cfg.features)
    n_obs = envs.n_obs
    dim = n_obs + 1 + (1 if cfg.features == "direction" else 0)  # features and a bias
    theta = rng.normal(0.0, rs.init_std, dim)
    transform = None
    steps, it = 0, 0
    schedule = eval_schedule(cfg.timesteps, cfg.eval_points)
    history = []

    def actor() -> LinearDirectionActor:
        return LinearDirectionActor(theta, envs.v_max, cfg.features, transform)

    def candidates(scale: float) -> tuple[np.ndarray, np.ndarray]:
        deltas = rng.normal(0.0, 1.0, (rs.n_directions, dim))
        return deltas, np.concatenate([theta + scale * rs.noise * deltas,
                                       theta - scale * rs.noise * deltas])

    def episode_seed() -> int:
        return int(rng.integers(1_000_000, 2**31 - 10_000_000))

    if rs.whiten and steps + envs.steps_per_round <= cfg.timesteps:
        if callback is not None and schedule.due(steps):
            callback(steps, actor())
        seen: list = []
        envs.returns(candidates(1.0)[1], episode_seed(), rs.common_episodes, None, seen)
        steps += envs.steps_per_round
        transform = whitening(np.concatenate(seen))
    while True:
        if callback is not None and schedule.due(steps):
            callback(steps, actor())
        if steps + envs.steps_per_round > cfg.timesteps:
            break
        scale = max(1.0, float(np.linalg.norm(theta)) / np.sqrt(dim)) if rs.relative else 1.0
        scale *= 1.0 - (1.0 - rs.anneal) * steps / cfg.timesteps
        deltas, cands = candidates(scale)
        R = envs.returns(cands, episode_seed(), rs.common_episodes, transform)
        steps += envs.steps_per_round
        score = (-np.log(np.maximum(-R, 1e-12)) if rs.objective == "log" else R).mean(axis=1)
        plus, minus = score[:rs.n_directions], score[rs.n_directions:]
        top = np.argsort(-np.maximum(plus, minus))[:rs.top_directions]
        std = float(np.concatenate([plus[top], minus[top]]).std()) + 1e-12
        theta = theta + scale * rs.step_size / (rs.top_directions * std) * (
            (plus[top] - minus[top]) @ deltas[top])
        it += 1
        history.append((steps, float(score.mean())))
    envs.close()
    final = actor()
    return final, {"iterations": it, "steps": steps, "actor": final.as_dict(),
                   "theta_norm": float(np.linalg.norm(theta)),
                   "score_history": history[-5:]}


# --- stable-baselines3 algorithms -------------------------------------------------
class VecDirectionFeatures(VecEnvWrapper):
    """Observation ``z`` -> ``[z/|z|, log|z|]`` (:func:`train.features.direction_features`),
    so that every SB3 algorithm (ARS included, whose policy takes no feature extractor)
    sees the same scale-free features."""

    def __init__(self, venv: VecEnv):
        d = venv.observation_space.shape[0] + 1
        super().__init__(venv, observation_space=spaces.Box(-np.inf, np.inf, (d,), np.float32))

    def _f(self, obs: np.ndarray) -> np.ndarray:
        return direction_features(obs).astype(np.float32)

    def reset(self) -> np.ndarray:
        return self._f(self.venv.reset())

    def step_wait(self):
        obs, rewards, dones, infos = self.venv.step_wait()
        for i in np.flatnonzero(dones):
            infos[i]["terminal_observation"] = self._f(infos[i]["terminal_observation"][None])[0]
        return self._f(obs), rewards, dones, infos


class VecWhiten(VecEnvWrapper):
    r"""Observation ``z`` -> ``u = T^T z`` with a fixed matrix T (identity until
    :meth:`set_transform`). While ``collect`` is a list, the raw observation directions
    ``z/|z|`` seen (every sub-env, every step) are appended to it, from which
    :func:`whitening` estimates T (:func:`train_sb3` with ``whiten_steps``)."""

    def __init__(self, venv: VecEnv):
        super().__init__(venv)
        self.transform = np.eye(venv.observation_space.shape[0])
        self.collect: list | None = None

    def set_transform(self, transform: np.ndarray) -> None:
        self.transform = np.asarray(transform, dtype=np.float64)

    def _u(self, obs: np.ndarray) -> np.ndarray:
        z = np.asarray(obs, dtype=np.float64)
        if self.collect is not None:
            r = np.linalg.norm(z, axis=-1, keepdims=True)
            self.collect.append((z / np.maximum(r, 1e-12))[r[:, 0] > 0])
        return (z @ self.transform).astype(np.float32)

    def reset(self) -> np.ndarray:
        return self._u(self.venv.reset())

    def step_wait(self):
        obs, rewards, dones, infos = self.venv.step_wait()
        for i in np.flatnonzero(dones):
            z = np.asarray(infos[i]["terminal_observation"], dtype=np.float64)
            infos[i]["terminal_observation"] = (z @ self.transform).astype(np.float32)
        return self._u(obs), rewards, dones, infos


class QuadraticFeatures(BaseFeaturesExtractor):
    r"""Features :math:`[u,\ u_i u_j\ (i \le j)]` of the observation u (d + d(d+1)/2
    values): a linear value on them is a quadratic form plus a linear term, the
    shape of a linear-quadratic problem's value function."""

    def __init__(self, observation_space: spaces.Box):
        d = int(observation_space.shape[0])
        super().__init__(observation_space, features_dim=d + d * (d + 1) // 2)
        i, j = np.triu_indices(d)
        self.register_buffer("_i", torch.as_tensor(i), persistent=False)
        self.register_buffer("_j", torch.as_tensor(j), persistent=False)

    def forward(self, observations: torch.Tensor) -> torch.Tensor:
        return torch.cat([observations, observations[:, self._i] * observations[:, self._j]],
                         dim=-1)


#: ``critic_features`` of :class:`SplitCriticPolicy` and their extractor classes.
CRITIC_FEATURES = {"quadratic": QuadraticFeatures, "direction": DirectionFeatures,
                   "flatten": FlattenExtractor}


class _SplitMlp(nn.Module):
    """``MlpExtractor``'s interface with actor and critic on inputs of their own size."""

    def __init__(self, pi_dim, vf_dim, net_arch, activation_fn, device):
        super().__init__()
        arch = net_arch if isinstance(net_arch, dict) else {"pi": net_arch, "vf": net_arch}
        pi = MlpExtractor(pi_dim, {"pi": list(arch.get("pi", [])), "vf": []},
                          activation_fn, device)
        vf = MlpExtractor(vf_dim, {"pi": [], "vf": list(arch.get("vf", []))},
                          activation_fn, device)
        self.policy_net, self.value_net = pi.policy_net, vf.value_net
        self.latent_dim_pi, self.latent_dim_vf = pi.latent_dim_pi, vf.latent_dim_vf

    def forward(self, features):
        return self.forward_actor(features), self.forward_critic(features)

    def forward_actor(self, features):
        return self.policy_net(features)

    def forward_critic(self, features):
        return self.value_net(features)


class SplitCriticPolicy(ActorCriticPolicy):
    """PPO's ``ActorCriticPolicy`` whose critic has features of its own,
    ``critic_features`` (a ``policy_kwargs`` key): ``"quadratic"``
    (:class:`QuadraticFeatures`; with ``net_arch: {vf: []}`` the value is a quadratic
    form of the observation, suited to a linear-quadratic problem), ``"direction"``
    (:class:`train.features.DirectionFeatures`) or ``"flatten"``. The actor sees the
    (flattened) observation, e.g. linear with ``net_arch: {pi: []}``."""

    def __init__(self, *args, critic_features: str = "quadratic", **kwargs):
        if critic_features not in CRITIC_FEATURES:
            raise ValueError(f"critic_features must be one of {list(CRITIC_FEATURES)}")
        self.critic_features = critic_features
        kwargs["share_features_extractor"] = False
        super().__init__(*args, **kwargs)

    def _build_mlp_extractor(self) -> None:
        self.vf_features_extractor = CRITIC_FEATURES[self.critic_features](
            self.observation_space)
        self.mlp_extractor = _SplitMlp(self.features_dim,
                                       self.vf_features_extractor.features_dim,
                                       self.net_arch, self.activation_fn, self.device)

    def _get_constructor_parameters(self) -> dict:
        data = super()._get_constructor_parameters()
        data["critic_features"] = self.critic_features
        return data


class EpisodeScaledRolloutBuffer(RolloutBuffer):
    """A ``RolloutBuffer`` that divides the GAE advantages of each episode segment (per
    sub-env, split at episode starts) by their root mean square, after the returns
    (the critic's targets, unchanged) are computed: advantage normalisation per
    episode (per load). Episodes whose returns differ by decades then weigh alike in
    the policy gradient, as in the random search's -log(-R) score."""

    def compute_returns_and_advantage(self, last_values, dones) -> None:
        super().compute_returns_and_advantage(last_values, dones)
        n = self.buffer_size
        for e in range(self.n_envs):
            starts = [0, *[int(t) for t in np.flatnonzero(self.episode_starts[1:, e]) + 1], n]
            for a, b in zip(starts[:-1], starts[1:], strict=True):
                rms = float(np.sqrt(np.mean(self.advantages[a:b, e] ** 2)))
                self.advantages[a:b, e] /= max(rms, 1e-12)


class ConcatVecEnv(VecEnv):
    """Several SB3 ``VecEnv`` with the same spaces side by side as one (sub-envs in order)."""

    def __init__(self, venvs: list[VecEnv]):
        self.venvs = list(venvs)
        self._sizes = [v.num_envs for v in self.venvs]
        self._splits = np.cumsum(self._sizes)[:-1]
        v0 = self.venvs[0]
        super().__init__(sum(self._sizes), v0.observation_space, v0.action_space)

    def reset(self):
        return np.concatenate([v.reset() for v in self.venvs])

    def step_async(self, actions) -> None:
        for v, a in zip(self.venvs, np.split(np.asarray(actions), self._splits), strict=True):
            v.step_async(a)

    def step_wait(self):
        parts = [v.step_wait() for v in self.venvs]
        return (np.concatenate([p[0] for p in parts]), np.concatenate([p[1] for p in parts]),
                np.concatenate([p[2] for p in parts]), [i for p in parts for i in p[3]])

    def close(self) -> None:
        for v in self.venvs:
            v.close()

    def seed(self, seed: int | None = None):
        out, offset = [], 0
        for v in self.venvs:
            out += v.seed(None if seed is None else seed + offset)
            offset += v.num_envs
        return out

    def _split_indices(self, indices):
        idx = range(self.num_envs) if indices is None else (
            [indices] if isinstance(indices, int) else indices)
        bounds = np.cumsum([0, *self._sizes])
        for i in idx:
            k = int(np.searchsorted(bounds, i, side="right") - 1)
            yield self.venvs[k], int(i - bounds[k])

    def get_attr(self, attr_name, indices=None):
        return [v.get_attr(attr_name, j)[0] for v, j in self._split_indices(indices)]

    def set_attr(self, attr_name, value, indices=None) -> None:
        for v in self.venvs:
            v.set_attr(attr_name, value)

    def env_method(self, method_name, *method_args, indices=None, **method_kwargs):
        return [v.env_method(method_name, *method_args, indices=j, **method_kwargs)[0]
                for v, j in self._split_indices(indices)]

    def env_is_wrapped(self, wrapper_class, indices=None):
        return [False for _ in self._split_indices(indices)]

    def get_images(self):
        return [None] * self.num_envs

    def set_options(self, options=None) -> None:
        for v in self.venvs:
            v.set_options(options)


def _split_envs(weights: dict, n_envs: int) -> dict:
    """Sub-envs per load case, in proportion to ``weights`` (at least one each)."""
    total = float(sum(weights.values()))
    counts = {c: max(1, int(round(n_envs * w / total))) for c, w in weights.items()}
    last = list(counts)[-1]
    counts[last] = max(1, n_envs - sum(v for c, v in counts.items() if c != last))
    return counts


def make_sb3_env(cfg: AlgoConfig, seed: int, env_id: str, gamma: float = 0.99) -> VecNormalize:
    """The SB3 training env: per training load case a native batched env
    (``SB3VecEnv`` over ``gym.make_vec(env_id)``) side by side, actions in [-1, 1]
    (``VecAgentEnv``: no residual, no shaping), :class:`VecWhiten` if
    ``cfg.whiten_steps`` (identity until :func:`train_sb3` sets it), optional direction
    features, and
    ``VecNormalize`` with ``cfg.normalize`` (seeded: sub-env i gets ``seed + i``)."""
    from acld_gym.envs.sb3 import SB3VecEnv

    from .vec import VecAgentEnv

    parts = []
    for case, n in _split_envs(cfg.load_weights, cfg.n_envs).items():
        parts.append(SB3VecEnv(venv=gym.make_vec(env_id, num_envs=n, load_case=case).unwrapped))
    venv: VecEnv = parts[0] if len(parts) == 1 else ConcatVecEnv(parts)
    venv.seed(seed)
    venv = VecAgentEnv(venv, residual=None, gamma=gamma, shaping=None)
    if cfg.whiten_steps:
        venv = VecWhiten(venv)
    if cfg.features == "direction":
        venv = VecDirectionFeatures(venv)
    return VecNormalize(venv, gamma=gamma, **cfg.normalize)


class SB3Policy:
    """A trained SB3 model with its frozen ``VecNormalize`` statistics as a policy on the
    env's raw observation, ``predict`` in volts (``V = v_max * clip(a, -1, 1)``);
    ``transform``: the agent's whitening matrix (:class:`VecWhiten`), or None."""

    def __init__(self, model, obs_norm: VecNormalize | None, features: str | None,
                 v_max: float = 120.0, transform: np.ndarray | None = None):
        self.model = model
        self.obs_norm = obs_norm
        self.features = features
        self.v_max = float(v_max)
        self.transform = None if transform is None else np.asarray(transform, np.float64)

    def predict(self, observation, state=None, episode_start=None, deterministic: bool = True):
        obs = np.asarray(observation, dtype=np.float32)
        batched = obs.ndim == 2
        x = np.atleast_2d(obs)
        if self.transform is not None:
            x = (x.astype(np.float64) @ self.transform).astype(np.float32)
        if self.features == "direction":
            x = direction_features(x).astype(np.float32)
        if self.obs_norm is not None:
            x = self.obs_norm.normalize_obs(x)
        import torch

        with torch.no_grad():  # the deterministic action of model.predict, without its checks
            a = self.model.policy._predict(torch.as_tensor(x), deterministic=True).numpy()
        v = (self.v_max * np.clip(np.asarray(a, dtype=np.float64).reshape(-1, 1), -1, 1))
        v = v.astype(np.float32)
        return (v if batched else v[0]), state


def _sb3_class(algo: str):
    import importlib

    module, name = SB3_ALGOS[algo]
    return getattr(importlib.import_module(module), name)


class _linear_schedule:  # noqa: N801  (an SB3 schedule: progress remaining 1 -> 0)
    def __init__(self, start: float, end: float):
        self.start, self.end = start, end

    def __call__(self, progress_remaining: float) -> float:
        return self.end + (self.start - self.end) * progress_remaining


def _resolve_policy_kwargs(kwargs: dict) -> dict:
    """YAML-friendly keyword arguments: ``policy_kwargs.activation_fn`` given by name
    (``"tanh"``); ``policy: SplitCriticPolicy`` names :class:`SplitCriticPolicy`;
    ``learning_rate`` / ``clip_range`` as ``{linear: [start, end]}``, a schedule linear in
    the progress from ``start`` to ``end``."""
    for key in ("learning_rate", "clip_range"):
        value = kwargs.get(key)
        if isinstance(value, dict):
            if set(value) != {"linear"} or len(value["linear"]) != 2:
                raise ValueError(f"{key}: a number or {{linear: [start, end]}}, got {value!r}")
            kwargs = {**kwargs, key: _linear_schedule(*map(float, value["linear"]))}

    if kwargs.get("policy") == "SplitCriticPolicy":
        kwargs = {**kwargs, "policy": SplitCriticPolicy}
    pk = dict(kwargs.get("policy_kwargs") or {})
    if isinstance(pk.get("activation_fn"), str):
        pk["activation_fn"] = {"tanh": nn.Tanh, "relu": nn.ReLU}[pk["activation_fn"].lower()]
    if pk:
        kwargs = {**kwargs, "policy_kwargs": pk}
    return kwargs


def _first_actor_layer(model) -> nn.Linear:
    """The first linear layer of an SB3 model's deterministic actor (as ``export_sb3``
    walks it)."""
    pol = model.policy
    actor = getattr(pol, "actor", None)
    if actor is not None and hasattr(actor, "latent_pi"):  # SAC, TQC
        layers = [*actor.latent_pi, *(actor.mu if isinstance(actor.mu, nn.Sequential)
                                      else [actor.mu])]
    elif actor is not None and hasattr(actor, "mu"):  # TD3
        layers = list(actor.mu)
    else:  # PPO
        layers = [*pol.mlp_extractor.policy_net, pol.action_net]
    return next(m for m in layers if isinstance(m, nn.Linear))


def _fold_transform(model, transform: np.ndarray) -> None:
    """Fold the whitening ``u = T^T z`` into the actor's first layer (``W u = (W T^T) z``),
    so that the trained actor takes the raw observation (and exports as a plain SB3
    actor). Only the deterministic actor stays meaningful afterwards (critic and gSDE
    noise still expect u): call it when training is over."""
    layer = _first_actor_layer(model)
    with torch.no_grad():
        t = torch.as_tensor(np.asarray(transform).T, dtype=layer.weight.dtype)
        layer.weight.copy_(layer.weight @ t)


def train_sb3(cfg: AlgoConfig, seed: int, env_id: str, callback: CurveCallback | None = None,
              ) -> tuple[SB3Policy, dict]:
    """Train an SB3 / sb3-contrib algorithm for ``cfg.timesteps`` env steps (with
    ``cfg.whiten_steps``: first that many steps of the initial policy, from which the
    whitening is estimated, then the rest of the budget of training)."""
    from stable_baselines3.common.callbacks import BaseCallback

    torch.set_num_threads(1)
    kwargs = _resolve_policy_kwargs(dict(cfg.model))
    policy = kwargs.pop("policy")
    gamma = float(kwargs.get("gamma", 0.99))
    if cfg.episode_scale:
        kwargs["rollout_buffer_class"] = EpisodeScaledRolloutBuffer
    venv = make_sb3_env(cfg, seed, env_id, gamma)
    v_max = 120.0
    model = _sb3_class(cfg.algo)(policy, venv, seed=seed, device="cpu", verbose=0, **kwargs)
    schedule = eval_schedule(cfg.timesteps, cfg.eval_points)
    white = venv.venv  # under VecNormalize (whiten_steps: no direction features)
    transform = None
    offset = 0

    def snapshot() -> SB3Policy:
        norm = None
        if cfg.normalize.get("norm_obs", False):
            import copy

            norm = copy.deepcopy(venv)
            norm.venv = None
            norm.training = False
        return SB3Policy(model, norm, cfg.features, v_max, transform)

    if cfg.whiten_steps:
        assert isinstance(white, VecWhiten)
        if callback is not None and schedule.due(0):
            callback(0, snapshot())
        white.collect = []
        obs = venv.reset()
        if getattr(model, "use_sde", False):
            model.policy.reset_noise(venv.num_envs)
        while offset < cfg.whiten_steps:
            action, _ = model.predict(obs, deterministic=False)
            obs, _, _, _ = venv.step(action)
            offset += venv.num_envs
        transform = whitening(np.concatenate(white.collect))
        white.collect = None
        white.set_transform(transform)

    class Curve(BaseCallback):
        def _on_step(self) -> bool:
            steps = offset + int(self.num_timesteps)
            if callback is not None and schedule.due(steps):
                callback(steps, snapshot())
            return True

        def _on_training_start(self) -> None:
            self._on_step()

    model.learn(max(cfg.timesteps - offset, 1), callback=Curve())
    record = {"steps": offset + int(model.num_timesteps), "whiten_steps": offset,
              "transform": None if transform is None else transform.tolist()}
    if transform is not None:  # u = T' z into the actor's first layer: a plain SB3 actor on z
        _fold_transform(model, transform)
        transform = None
    pol = snapshot()
    venv.close()
    return pol, record


def train_algo(cfg: AlgoConfig, seed: int, env_id: str, callback: CurveCallback | None = None,
               ) -> tuple[Any, dict]:
    """Train ``cfg`` with ``seed`` on ``env_id``; returns ``(policy, record)`` with
    ``record["train_seconds"]`` and ``record["train_cpu_seconds"]`` (wall and CPU time
    of training, evaluations excluded; on a shared machine the CPU time is the fairer
    measure)."""
    spent = [0.0, 0.0]
    last = [-1]

    def timed(steps, policy):  # evaluation time is not training time
        last[0] = steps
        t0, c0 = time.perf_counter(), time.process_time()
        if callback is not None:
            callback(steps, policy)
        spent[0] += time.perf_counter() - t0
        spent[1] += time.process_time() - c0

    t0, c0 = time.perf_counter(), time.process_time()
    if cfg.algo == "vrs":
        policy, record = train_random_search(cfg, seed, env_id, timed)
    else:
        policy, record = train_sb3(cfg, seed, env_id, timed)
    record["train_seconds"] = time.perf_counter() - t0 - spent[0]
    record["train_cpu_seconds"] = time.process_time() - c0 - spent[1]
    if callback is not None and record["steps"] > last[0]:
        callback(record["steps"], policy)  # the learning curve ends at the final policy
    return policy, record
