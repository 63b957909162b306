"""A probe of the PPO recipe's limit-cycle failures: the critic learns first, the actor waits.

The recipe's runs that fail (about one in six: docs/training.md) fall into the +/-120 V limit
cycle within their first ~10 rollouts after the whitening (case 1 at 4-5.5x LQR by 0.4M env
steps, never left), while the critic, a quadratic form that starts at zero, has seen only
those few rollouts: the first updates of the actor follow advantages that are mostly the
critic's error. A warmed-up learning rate (``ablation_ppo_warmup.yaml``) slows the critic
as much as the actor.

This probe freezes the actor (the linear law's gains and gSDE's log std: no gradient, so
Adam leaves them) for the updates of the first ``--frozen-rollouts`` rollouts (default 10,
164k env steps), while the critic trains as in the recipe; then everything trains as in
the recipe, to the end of the same budget (one run per seed; ``--candidate``: with the
paired loads, antithetic gain noise and entropy coefficient 0.05 of
``ablation_ppo_antithetic_ent_05.yaml``).

It prints one JSON line per seed: the run's validation cost and ISE / LQR on cases 1, 2, 3
and the held-out random loads (``studies/probes/probe.py``). Not a test; about 0.5-1 min per
seed on one core::

    python studies/probes/critic_first.py --seeds 0 1 2 3 4
    python studies/probes/critic_first.py --seeds 0 1 2 3 4 --candidate

Its numbers are in docs/training.md ("Reinforcement learning from scratch", the probes
table).
"""

from __future__ import annotations

import dataclasses
import sys

from probe import one_run, run_recipe, seeds_main  # studies/probes/probe.py, beside this script

from train.core.sb3_policies import AsymmetricCriticPolicy


class CriticFirstPolicy(AsymmetricCriticPolicy):
    """The recipe's policy whose actor (``action_net`` and ``log_std``) takes no gradient
    until ``frozen_rollouts`` rollouts have been trained on. gSDE draws its noise once per
    rollout (``sde_sample_freq: -1``), at the rollout's start, with one matrix per sub-env:
    the draws with more than one matrix count the rollouts (the first is the whitening's,
    before any rollout)."""

    def __init__(self, *args, frozen_rollouts: int = 10, **kwargs):
        if not isinstance(frozen_rollouts, int) or frozen_rollouts < 0:
            raise ValueError(f"frozen_rollouts: a whole number >= 0, got {frozen_rollouts!r}")
        super().__init__(*args, **kwargs)
        self.frozen_rollouts = frozen_rollouts
        self.draws = 0
        self._set_actor_trainable(frozen_rollouts == 0)

    def actor_parameters(self) -> list:
        """The actor's parameters: the linear law's and gSDE's log std."""
        return [*self.action_net.parameters(), self.log_std]

    def _set_actor_trainable(self, on: bool) -> None:
        for p in self.actor_parameters():
            p.requires_grad_(on)

    def reset_noise(self, n_envs: int = 1) -> None:
        if n_envs > 1:
            self.draws += 1
            # draw 1: the whitening's; draw j + 1 starts rollout j, whose update follows
            self._set_actor_trainable(self.draws > self.frozen_rollouts + 1)
        super().reset_noise(n_envs)


def config(frozen_rollouts: int = 10, candidate: bool = False):
    """``train/recipes/ppo.yaml``'s config with :class:`CriticFirstPolicy`, one run
    (``candidate``: with ``ablation_ppo_antithetic_ent_05.yaml``'s three changes)."""
    kwargs = {"frozen_rollouts": frozen_rollouts}
    if not candidate:
        return one_run(CriticFirstPolicy, kwargs)
    cfg = one_run(CriticFirstPolicy, {**kwargs, "antithetic_noise": True}, ent_coef=0.05)
    return dataclasses.replace(cfg, paired_loads=True)


def run(seed: int, frozen_rollouts: int = 10, candidate: bool = False, env_id="ACLDBeam-v1"):
    """Train one run of seed ``seed`` and evaluate it."""
    cfg = config(frozen_rollouts, candidate)
    return run_recipe(cfg, seed, env_id, frozen_rollouts=frozen_rollouts, candidate=candidate)


def main(argv: list[str] | None = None) -> int:
    def add_arguments(p):
        p.add_argument("--frozen-rollouts", type=int, default=10, help="rollouts (default 10)")
        p.add_argument("--candidate", action="store_true", help="paired, antithetic, ent 0.05")

    return seeds_main(
        __doc__, lambda seed, a: run(seed, a.frozen_rollouts, a.candidate), argv, add_arguments
    )


if __name__ == "__main__":
    sys.exit(main())
