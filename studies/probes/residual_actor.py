"""A probe of the PPO recipe with a nonlinear actor that keeps the linear law: a residual MLP.

The recipe's actor is linear on the whitened observation ``u = T' z``; its Gaussian mean is
``w' u + b``. This probe widens the actor's latent to ``[u, h(u)]`` with ``h`` a tanh MLP
(``--hidden``, default one layer of 64), so the mean is ``w' u + v' h(u) + b``: the linear
law plus a learned nonlinear correction, both from SB3's usual initialisation (the output
layer's gain 0.01). Everything else is ``train/recipes/ppo.yaml``'s (one run per seed: the
probe reports each run, failed ones too). gSDE draws its noise on the gains of the whole
latent, ``[u, h]``, as it does on the recipe's ``u`` (``--noise latent``), or on the linear
law's gains alone, the correction deterministic (``--noise linear``).

It prints one JSON line per seed: the run's validation cost and ISE / LQR on cases 1, 2, 3
and the held-out random loads (``studies/probes/probe.py``). Not a test; about 1 min per seed
on one core::

    python studies/probes/residual_actor.py --seeds 0 1 2 3 4
    python studies/probes/residual_actor.py --seeds 0 1 2 3 4 --noise linear
    python studies/probes/residual_actor.py --seeds 0 1 2 3 4 --recipe ppo   # on 0.15.0's recipe

Its numbers are in docs/training.md ("Reinforcement learning from scratch", the probes
table). The actor is not exported as an agent (:class:`train.agent.ActorProgram` has no
concatenation); the policy is evaluated through SB3, on the raw observation once the
whitening is folded into the residual module (:meth:`ResidualActorPolicy.fold_whitening`).
"""

from __future__ import annotations

import sys

import numpy as np
import torch
import torch.nn as nn
from probe import (  # studies/probes/probe.py, beside this script
    BASE,
    RECIPES,
    one_run,
    run_recipe,
    seeds_main,
)
from stable_baselines3.common.distributions import StateDependentNoiseDistribution

from train.core.sb3_policies import AsymmetricCriticPolicy


class Residual(nn.Module):
    """The actor's latent ``[u, h(u)]`` of an input ``x`` with ``u = T' x``: ``T`` is the
    identity while training (the env whitens), the whitening once it is folded in."""

    def __init__(self, dim: int, hidden: list[int]):
        super().__init__()
        layers: list[nn.Module] = []
        width = dim
        for h in hidden:
            layers += [nn.Linear(width, h), nn.Tanh()]
            width = h
        self.mlp = nn.Sequential(*layers)
        self.register_buffer("T", torch.eye(dim))
        self.latent_dim = dim + width

    def forward(self, x: torch.Tensor) -> torch.Tensor:
        u = x @ self.T
        return torch.cat([u, self.mlp(u)], dim=-1)


NOISES = ("latent", "linear")


class ResidualActorPolicy(AsymmetricCriticPolicy):
    """The recipe's asymmetric actor-critic with :class:`Residual` as the actor's latent
    (``policy_kwargs``: ``hidden``, the MLP's widths; ``noise``, what gSDE's noise acts on:
    ``"latent"``, all of ``[u, h]``, or ``"linear"``, ``u`` alone). The critic is the
    recipe's."""

    def __init__(
        self, *args, hidden: list[int] | tuple[int, ...] = (64,), noise: str = "latent", **kwargs
    ):
        if not hidden or any(int(h) < 1 for h in hidden):
            raise ValueError(f"hidden: expected one or more positive widths, got {hidden!r}")
        if noise not in NOISES:
            raise ValueError(f"noise: expected one of {list(NOISES)}, got {noise!r}")
        self.hidden = [int(h) for h in hidden]
        self.noise = noise
        super().__init__(*args, **kwargs)

    def _get_action_dist_from_latent(self, latent_pi: torch.Tensor):
        if self.noise == "linear" and isinstance(self.action_dist, StateDependentNoiseDistribution):
            d = self.features_dim  # gSDE's noise on the gains of u only: h's entries zeroed
            sde = torch.cat([latent_pi[..., :d], torch.zeros_like(latent_pi[..., d:])], dim=-1)
            mean = self.action_net(latent_pi)
            return self.action_dist.proba_distribution(mean, self.log_std, sde)
        return super()._get_action_dist_from_latent(latent_pi)

    def _build_mlp_extractor(self) -> None:
        super()._build_mlp_extractor()
        net = Residual(self.features_dim, self.hidden)
        self.mlp_extractor.policy_net = net
        self.mlp_extractor.latent_dim_pi = net.latent_dim

    def fold_whitening(self, transform: np.ndarray) -> None:
        """Fold ``u = T' z`` into the residual module, so that the actor takes the raw
        observation (:func:`train.core.sb3_train.fold_whitening` calls it, in place of its
        fold into a linear actor's first layer)."""
        net = self.mlp_extractor.policy_net
        with torch.no_grad():
            net.T.copy_(torch.as_tensor(transform, dtype=net.T.dtype))

    def _get_constructor_parameters(self) -> dict:
        return {**super()._get_constructor_parameters(), "hidden": self.hidden, "noise": self.noise}


def config(hidden: list[int], noise: str = "latent", recipe: str = BASE):
    """The PPO config ``recipe`` (:data:`probe.BASE`, or ``"ppo"``: acld-gym 0.15.0's
    recipe, whose critic cannot be positive and whose gSDE draws come in antithetic pairs
    of paired sub-envs) with the residual actor, one run."""
    return one_run(ResidualActorPolicy, {"hidden": list(hidden), "noise": noise}, base=recipe)


def run(
    seed: int,
    hidden: list[int],
    noise: str = "latent",
    env_id: str = "ACLDBeam-v1",
    recipe: str = BASE,
) -> dict:
    """Train one run of seed ``seed`` and evaluate it."""
    cfg = config(hidden, noise, recipe)
    return run_recipe(cfg, seed, env_id, hidden=hidden, noise=noise, recipe=recipe)


def main(argv: list[str] | None = None) -> int:
    def add_arguments(p):
        p.add_argument("--hidden", type=int, nargs="+", default=[64], help="the MLP's widths")
        p.add_argument(
            "--noise", choices=NOISES, default="latent", help="what gSDE's noise acts on"
        )
        p.add_argument("--recipe", default=BASE, choices=RECIPES, help="config changed")

    def one(seed, a):
        return run(seed, a.hidden, a.noise, recipe=a.recipe)

    return seeds_main(__doc__, one, argv, add_arguments)


if __name__ == "__main__":
    sys.exit(main())
