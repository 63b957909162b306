r"""A probe of the PPO recipe with a Beta policy (Chou et al. 2017) in place of its gSDE
Gaussian: a distribution bounded to the actuator's range, for an optimum that saturates.

The recipe's Gaussian is clipped to +/-120 V, so once its mean is far beyond the limit
every sample is clipped alike and the policy gradient vanishes: the +/-120 V limit cycle
that ends 6 of 51 of its runs. A Beta distribution has no mass outside the range. Here the
action is ``a = 2 x - 1`` with ``x ~ Beta(alpha, beta)``, ``alpha = 1 + softplus(w_a' u +
b_a)`` and ``beta = 1 + softplus(w_b' u + b_b)`` on the whitened observation ``u`` (both
above 1: unimodal), the deterministic action its mean ``(alpha - beta) / (alpha + beta)``
(:class:`BetaDistribution`, :class:`BetaActorPolicy`). The noise is drawn per step: a Beta
has no counterpart of gSDE's noise on the gains. Everything else is the recipe's
(``train/recipes/ppo.yaml``: the asymmetric quadratic critic, whitening, reward per
load, entropy bonus, schedule), one run per seed.

It prints one JSON line per seed: the run's validation cost and ISE / LQR on cases 1, 2, 3
and the held-out random loads (``studies/probes/probe.py``). Not a test; about 1 min per seed
on one core::

    python studies/probes/beta_actor.py --seeds 0 1 2 3 4
    python studies/probes/beta_actor.py --seeds 0 1 2 3 4 --ent-coef 0

Its numbers are in docs/training.md ("Reinforcement learning from scratch", the probes
table). The actor is not exported as an agent (:class:`train.agent.ActorProgram` has no
Beta mean); the policy is evaluated through SB3, on the raw observation once the whitening
is folded into its first layer.
"""

from __future__ import annotations

import math
import sys
from functools import partial

import torch
import torch.nn as nn
import torch.nn.functional as F
from probe import one_run, run_recipe, seeds_main  # studies/probes/probe.py, beside this script
from stable_baselines3.common.distributions import Distribution

from train.core.sb3_policies import AsymmetricCriticPolicy

#: How far from 0 and 1 a sample of x is kept, so that its log-density stays finite.
EDGE = 1e-6


class BetaDistribution(Distribution):
    """Actions ``a = 2 x - 1`` in [-1, 1] with ``x ~ Beta(alpha, beta)`` per action
    dimension, ``alpha, beta = 1 + softplus(net output)``."""

    def __init__(self, action_dim: int):
        super().__init__()
        self.action_dim = action_dim

    def proba_distribution_net(self, latent_dim: int) -> nn.Module:
        return nn.Linear(latent_dim, 2 * self.action_dim)

    def proba_distribution(self, params: torch.Tensor) -> BetaDistribution:
        conc = 1.0 + F.softplus(params)
        alpha, beta = conc[..., : self.action_dim], conc[..., self.action_dim :]
        self.distribution = torch.distributions.Beta(alpha, beta)
        return self

    def log_prob(self, actions: torch.Tensor) -> torch.Tensor:
        x = ((actions + 1.0) / 2.0).clamp(EDGE, 1.0 - EDGE)
        return (self.distribution.log_prob(x) - math.log(2.0)).sum(dim=-1)

    def entropy(self) -> torch.Tensor:
        return (self.distribution.entropy() + math.log(2.0)).sum(dim=-1)

    def sample(self) -> torch.Tensor:
        return 2.0 * self.distribution.rsample().clamp(EDGE, 1.0 - EDGE) - 1.0

    def mode(self) -> torch.Tensor:  # the mean: the deterministic action
        return 2.0 * self.distribution.mean - 1.0

    def actions_from_params(self, params: torch.Tensor, deterministic: bool = False):
        return self.proba_distribution(params).get_actions(deterministic=deterministic)

    def log_prob_from_params(self, params: torch.Tensor):
        actions = self.actions_from_params(params)
        return actions, self.log_prob(actions)


class BetaActorPolicy(AsymmetricCriticPolicy):
    """The recipe's asymmetric actor-critic with :class:`BetaDistribution` as the actor's
    distribution (``use_sde`` off), its parameters linear in the whitened observation."""

    def _build(self, lr_schedule) -> None:
        super()._build(lr_schedule)
        self.action_dist = BetaDistribution(int(self.action_space.shape[0]))
        self.action_net = self.action_dist.proba_distribution_net(self.mlp_extractor.latent_dim_pi)
        if self.ortho_init:  # SB3's initialisation of an action head: gain 0.01
            self.action_net.apply(partial(self.init_weights, gain=0.01))
        self.optimizer = self.optimizer_class(
            self.parameters(), lr=lr_schedule(1), **self.optimizer_kwargs
        )

    def _get_action_dist_from_latent(self, latent_pi: torch.Tensor):
        return self.action_dist.proba_distribution(self.action_net(latent_pi))


def config(ent_coef: float | None = None):
    """``train/recipes/ppo.yaml``'s config with :class:`BetaActorPolicy` and without gSDE,
    one run (``ent_coef``: the entropy coefficient, if not the recipe's)."""
    model = {} if ent_coef is None else {"ent_coef": float(ent_coef)}
    return one_run(BetaActorPolicy, drop=("use_sde", "sde_sample_freq", "log_std_init"), **model)


def run(seed: int, ent_coef: float | None = None, env_id: str = "ACLDBeam-v1") -> dict:
    """Train one run of seed ``seed`` and evaluate it."""
    cfg = config(ent_coef)
    return run_recipe(cfg, seed, env_id, ent_coef=cfg.model["ent_coef"])


def main(argv: list[str] | None = None) -> int:
    def add_arguments(p):
        p.add_argument("--ent-coef", type=float, default=None, help="default: the recipe's")

    return seeds_main(__doc__, lambda seed, a: run(seed, a.ent_coef), argv, add_arguments)


if __name__ == "__main__":
    sys.exit(main())
