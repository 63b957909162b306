"""A probe of the PPO recipe with a critic that knows how much of the episode is left.

The evaluation measures a finite episode: ISE over the 1 s of an episode. The random search
optimises that too (each episode's return). PPO, as the recipe runs it, optimises a
discounted return that is bootstrapped at the 1 s time limit (SB3 adds gamma V(s_T) where
the env reports a truncation), so the cost of a deflection left at 1 s counts in training
and not in the evaluation, and the recipe's critic, a quadratic form of the whitened
observation, cannot tell a state early in an episode from the same state late in it
(Pardo et al. 2018, "Time limits in reinforcement learning").

This probe gives the critic (only) the episode's remaining time: the training env appends
``r = 1 - k / 1000`` to the observation (:class:`VecRemainingTime`, privileged, after log c),
the actor drops both (``DropLast`` with ``n=2``: the same linear law on the whitened
observation, deployable on the plain env), and the critic is

    V(u, c, r) = sum_k b_k(r) [1, w, w w'] . theta_k,   w = u / sqrt(c),
    b_k(r) = 1 - exp(-r T / tau_k),  tau_k in {0.03, 0.1, 0.3, 1} s,  T = 1 s,

with no constant: V = 0 when the episode is over (r = 0), so the bootstrap at the time
limit adds nothing and the training objective is the finite episode's discounted return.
Everything else is the recipe's (``--gamma``, default the recipe's 0.999; one run per seed).

It prints one JSON line per seed: the run's validation cost and ISE / LQR on cases 1, 2, 3
and the held-out random loads (``studies/probes/probe.py``). Not a test; about 1 min per seed
on one core::

    python studies/probes/time_critic.py --seeds 0 1 2 3 4
    python studies/probes/time_critic.py --seeds 0 1 2 3 4 --gamma 1.0

Its numbers are in docs/training.md ("Reinforcement learning from scratch", the probes
table).
"""

from __future__ import annotations

import dataclasses
import sys

import numpy as np
import torch
from gymnasium import spaces
from probe import EPISODE_STEPS, one_run, run_recipe, seeds_main  # studies/probes/probe.py
from stable_baselines3.common.torch_layers import BaseFeaturesExtractor
from stable_baselines3.common.vec_env import VecEnvWrapper, VecNormalize

from train.core.sb3_policies import DropLast, QuadraticFeatures, SplitCriticPolicy
from train.vec import VecWhiten, make_vec_env

#: Time constants [s] of the critic's time basis b_k(r) = 1 - exp(-r T / tau_k).
TAUS = (0.03, 0.1, 0.3, 1.0)


class VecRemainingTime(VecEnvWrapper):
    """Appends each sub-env's remaining episode time ``r = 1 - k / steps`` (k env steps
    taken in the episode) to its observation; the final observation of an episode that
    ran its ``steps`` gets r = 0."""

    def __init__(self, venv, steps: int = EPISODE_STEPS):
        lo = np.append(venv.observation_space.low, 0.0).astype(np.float32)
        hi = np.append(venv.observation_space.high, 1.0).astype(np.float32)
        super().__init__(venv, observation_space=spaces.Box(lo, hi, dtype=np.float32))
        self.steps = steps
        self.k = np.zeros(venv.num_envs, dtype=np.int64)

    def _append(self, obs: np.ndarray) -> np.ndarray:
        r = np.maximum(1.0 - self.k / self.steps, 0.0).astype(np.float32)
        return np.concatenate([obs, r[:, None]], axis=-1).astype(np.float32)

    def reset(self) -> np.ndarray:
        self.k[:] = 0
        return self._append(self.venv.reset())

    def step_wait(self):
        obs, rewards, dones, infos = self.venv.step_wait()
        self.k += 1
        for i in np.flatnonzero(dones):
            if infos[i].get("TimeLimit.truncated") and self.k[i] != self.steps:
                raise RuntimeError(f"sub-env {i} truncated after {self.k[i]} steps")
            r = max(1.0 - self.k[i] / self.steps, 0.0)
            infos[i]["terminal_observation"] = np.append(
                infos[i]["terminal_observation"], np.float32(r)
            ).astype(np.float32)
        self.k[dones] = 0
        return self._append(obs), rewards, dones, infos


def make_time_vec_env(cfg, seed: int, env_id: str):
    """:func:`train.vec.make_vec_env`'s training env with :class:`VecRemainingTime` under
    the whitening (which passes log c and r through)."""
    plain = make_vec_env(dataclasses.replace(cfg, whiten_steps=0), seed, env_id)
    inner = plain.venv  # VecAgentEnv, under a VecNormalize that changes nothing here
    if cfg.normalize.get("norm_obs") or cfg.normalize.get("norm_reward"):
        raise ValueError("the probe expects normalize: {norm_obs: false, norm_reward: false}")
    white = VecWhiten(VecRemainingTime(inner), passthrough=2)
    return VecNormalize(white, gamma=cfg.gamma, **cfg.normalize)


class TimeScaledQuadraticFeatures(BaseFeaturesExtractor):
    r"""Features :math:`b_k(r)\,[1, w, w w^T]` of the observation ``[u, log c, r]``,
    :math:`w = u/\sqrt{c}` (``[w, w w^T]``: :class:`train.core.sb3_policies.QuadraticFeatures`),
    for every k (:data:`TAUS`): each vanishes at r = 0."""

    def __init__(self, observation_space: spaces.Box):
        self.d = int(observation_space.shape[0]) - 2
        quadratic = QuadraticFeatures(spaces.Box(-np.inf, np.inf, (self.d,), np.float32))
        super().__init__(observation_space, features_dim=(1 + quadratic.features_dim) * len(TAUS))
        self.quadratic = quadratic
        self.register_buffer("tau", torch.tensor(TAUS, dtype=torch.float32))

    def forward(self, obs: torch.Tensor) -> torch.Tensor:
        d = self.d
        w = obs[:, :d] * torch.exp(-0.5 * obs[:, d : d + 1])
        q = torch.cat([torch.ones_like(w[:, :1]), self.quadratic(w)], dim=-1)
        b = 1.0 - torch.exp(-obs[:, d + 1 : d + 2] / self.tau)  # r T / tau with T = 1 s
        return (q.unsqueeze(2) * b.unsqueeze(1)).flatten(1)


class TimeCriticPolicy(SplitCriticPolicy):
    """The recipe's asymmetric actor-critic on ``[u, log c, r]``: the actor the linear law
    on u, the critic :class:`TimeScaledQuadraticFeatures` with no bias (V = 0 at r = 0)."""

    def __init__(self, *args, **kwargs):
        kwargs.setdefault("features_extractor_class", DropLast)
        kwargs.setdefault("features_extractor_kwargs", {"n": 2})
        super().__init__(*args, **kwargs)
        with torch.no_grad():
            self.value_net.bias.zero_()
        self.value_net.bias.requires_grad_(False)

    def make_critic_extractor(self) -> TimeScaledQuadraticFeatures:
        return TimeScaledQuadraticFeatures(self.observation_space)


def config(gamma: float | None = None):
    """``train/recipes/ppo.yaml``'s config with :class:`TimeCriticPolicy`, one run."""
    model = {} if gamma is None else {"gamma": gamma}
    return one_run(TimeCriticPolicy, drop=("critic_features",), **model)


def run(seed: int, gamma: float | None = None, env_id: str = "ACLDBeam-v1") -> dict:
    """Train one run of seed ``seed`` and evaluate it."""
    cfg = config(gamma)
    return run_recipe(cfg, seed, env_id, make_env=make_time_vec_env, gamma=cfg.gamma)


def main(argv: list[str] | None = None) -> int:
    def add_arguments(p):
        p.add_argument("--gamma", type=float, default=None, help="discount (recipe: 0.999)")

    return seeds_main(__doc__, lambda seed, a: run(seed, a.gamma), argv, add_arguments)


if __name__ == "__main__":
    sys.exit(main())
