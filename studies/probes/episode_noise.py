"""A probe of the PPO recipe with gSDE's noise held for a whole episode (or any number of
steps), as the random search holds each perturbation of its gains for whole episodes.

The recipe (``train/recipes/ppo.yaml``) draws gSDE's noise on the actor's gains, a matrix
``E ~ N(0, sigma^2)`` per sub-env, once per 64-step rollout, so a 1000-step episode sees
about 16 draws. This probe draws ``eps ~ N(0, 1)`` per sub-env once per episode and acts
with ``E = eps * sigma`` (``sigma`` the current one, so a PPO update still changes the noise
mid-episode by its scale). The native batched env starts its sub-envs together and every
episode runs its 1000 steps unless it leaves the deflection limit, so the probe redraws
``eps`` every 1000 rollout steps (:class:`EpisodeNoisePolicy`; ``--hold N``: every N steps);
everything else is the recipe's, one run per seed.

It prints one JSON line per seed: the run's validation cost and ISE / LQR on cases 1, 2, 3
and the held-out random loads (``studies/probes/probe.py``). Not a test; about 1 min per seed
on one core::

    python studies/probes/episode_noise.py --seeds 0 1 2 3 4
    python studies/probes/episode_noise.py --seeds 0 1 2 3 4 --hold 128
    python studies/probes/episode_noise.py --seeds 0 1 2 3 4 --recipe ppo   # on 0.15.0's recipe

Its numbers are in docs/training.md ("Reinforcement learning from scratch", the probes
table).
"""

from __future__ import annotations

import sys

import torch
from probe import (  # studies/probes/probe.py
    BASE,
    EPISODE_STEPS,
    RECIPES,
    one_run,
    run_recipe,
    seeds_main,
)
from torch.distributions import Normal

from train.core.sb3_policies import AsymmetricCriticPolicy, antithetic_pairs


class EpisodeNoisePolicy(AsymmetricCriticPolicy):
    """The recipe's actor-critic with gSDE's standard-normal draw held per sub-env for
    ``hold`` calls of :meth:`forward` (one per env step of a rollout; default
    :data:`EPISODE_STEPS`) and scaled by the current ``sigma`` whenever SB3 asks for new
    noise (each rollout)."""

    def __init__(self, *args, hold: int = EPISODE_STEPS, **kwargs):
        if not (isinstance(hold, int) and hold >= 1):
            raise ValueError(f"hold: expected a positive number of steps, got {hold!r}")
        self.hold = hold
        super().__init__(*args, **kwargs)
        self.eps: torch.Tensor | None = None
        self.steps = 0

    def _act_with_eps(self) -> None:
        dist = self.action_dist
        std = dist.get_std(self.log_std)
        dist.weights_dist = Normal(torch.zeros_like(std), std)
        dist.exploration_mat = dist.weights_dist.rsample()
        dist.exploration_matrices = self.eps * std

    def _draw(self, shape) -> torch.Tensor:
        """A standard-normal draw per sub-env; with ``antithetic_noise`` sub-env ``2i + 1``
        gets the negative of ``2i``'s, as the recipe's gSDE noise (0.15.0)."""
        eps = torch.randn(shape)
        return antithetic_pairs(eps) if self.antithetic_noise and shape[0] > 1 else eps

    def reset_noise(self, n_envs: int = 1) -> None:
        std = self.action_dist.get_std(self.log_std)
        if self.eps is None or self.eps.shape[0] != n_envs:
            self.eps = self._draw((n_envs, *std.shape))
            self.steps = 0
        self._act_with_eps()

    def forward(self, obs: torch.Tensor, deterministic: bool = False):
        if self.eps is not None and self.steps and self.steps % self.hold == 0:
            self.eps = self._draw(self.eps.shape)  # e.g. the sub-envs' next episodes
            self._act_with_eps()
        self.steps += 1
        return super().forward(obs, deterministic)

    def _get_constructor_parameters(self) -> dict:
        return {**super()._get_constructor_parameters(), "hold": self.hold}


def config(hold: int = EPISODE_STEPS, recipe: str = BASE):
    """The PPO config ``recipe`` (:data:`probe.BASE`, or ``"ppo"``: acld-gym 0.15.0's
    recipe, its sub-envs in pairs with antithetic draws) with :class:`EpisodeNoisePolicy`,
    one run."""
    return one_run(EpisodeNoisePolicy, {"hold": hold}, base=recipe)


def run(
    seed: int, hold: int = EPISODE_STEPS, env_id: str = "ACLDBeam-v1", recipe: str = BASE
) -> dict:
    """Train one run of seed ``seed`` and evaluate it."""
    return run_recipe(config(hold, recipe), seed, env_id, hold=hold, recipe=recipe)


def main(argv: list[str] | None = None) -> int:
    def add_arguments(p):
        p.add_argument("--hold", type=int, default=EPISODE_STEPS, help="steps per noise draw")
        p.add_argument("--recipe", default=BASE, choices=RECIPES, help="config changed")

    return seeds_main(
        __doc__, lambda seed, a: run(seed, a.hold, recipe=a.recipe), argv, add_arguments
    )


if __name__ == "__main__":
    sys.exit(main())
