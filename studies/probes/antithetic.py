"""A probe of the PPO recipe with the random search's common random numbers: sub-envs in
pairs on the same loads, with opposite gain noise.

The random search compares each perturbation of its gains with its mirror image on the same
loads (common random numbers, antithetic pairs); without that it ends at 1.29x LQR on case 1
instead of 0.84x (docs/training.md, ``vrs_no_crn``). The recipe's PPO draws gSDE's noise
on the actor's gains independently per sub-env, each on a load of its own, and relies on
its critic to take the load-to-load variation out of the advantages.

This probe seeds sub-envs ``2i`` and ``2i + 1`` alike (``seed + i``; ``paired_loads`` of
:class:`train.config.TrainConfig`), so the pair draws the same loads and sensor noise
episode after episode (the native batched env restarts every sub-env after its 1000
steps), and gives the pair opposite gain noise, ``E`` and ``-E``, per rollout
(``antithetic_noise`` of :class:`train.core.sb3_policies.SplitCriticPolicy`). To first
order the pair's policy-gradient terms add up to ``(A+ - A-) (E u) u / sigma^2``: what the
load does to both advantages cancels, as in the random search's difference of returns.
Everything else is the recipe's, one run per seed (``studies/ablations/
ablation_ppo_antithetic*.yaml`` are the same settings with the recipe's retry).

It prints one JSON line per seed: the run's validation cost and ISE / LQR on cases 1, 2, 3
and the held-out random loads (``studies/probes/probe.py``). Not a test; about 1 min per seed
on one core::

    python studies/probes/antithetic.py --seeds 0 1 2 3 4
    python studies/probes/antithetic.py --seeds 0 1 2 3 4 --no-pairs      # the noise only
    python studies/probes/antithetic.py --seeds 0 1 2 3 4 --no-antithetic # the loads only

Its numbers are in docs/training.md ("Reinforcement learning from scratch", the probes
table).
"""

from __future__ import annotations

import dataclasses
import sys

from probe import one_run, run_recipe, seeds_main  # studies/probes/probe.py, beside this script

from train.core.sb3_policies import AsymmetricCriticPolicy

#: PPO keyword arguments the command line may change (``--gamma`` etc.).
MODEL_OPTIONS = ("gamma", "ent_coef", "clip_range")


def config(pairs: bool = True, antithetic: bool = True, reward_scale: str = "passive", **model):
    """``train/recipes/ppo.yaml``'s config with the sub-envs seeded in pairs (``pairs``)
    and antithetic gain noise (``antithetic``), one run; ``model`` replaces PPO keyword
    arguments, ``reward_scale`` the training env's (the recipe's ``"passive"``, or
    ``"lqr"``)."""
    cfg = one_run(AsymmetricCriticPolicy, {"antithetic_noise": antithetic}, **model)
    env_kwargs = {**cfg.env_kwargs, "reward_scale": reward_scale}
    return dataclasses.replace(cfg, paired_loads=pairs, env_kwargs=env_kwargs)


def run(
    seed: int,
    pairs: bool = True,
    antithetic: bool = True,
    reward_scale: str = "passive",
    env_id="ACLDBeam-v1",
    **model,
) -> dict:
    """Train one run of seed ``seed`` and evaluate it."""
    cfg = config(pairs, antithetic, reward_scale, **model)
    settings = {"pairs": pairs, "antithetic": antithetic, "reward_scale": reward_scale}
    return run_recipe(cfg, seed, env_id, **settings, **model)


def main(argv: list[str] | None = None) -> int:
    def add_arguments(p):
        p.add_argument("--no-pairs", action="store_true", help="every sub-env its own loads")
        p.add_argument("--no-antithetic", action="store_true", help="independent gain noise")
        p.add_argument("--reward-scale", default="passive", choices=("passive", "lqr"))
        for key in MODEL_OPTIONS:
            p.add_argument("--" + key.replace("_", "-"), type=float, help="recipe's if omitted")

    def one(seed, a):
        model = {k: getattr(a, k) for k in MODEL_OPTIONS if getattr(a, k) is not None}
        return run(seed, not a.no_pairs, not a.no_antithetic, a.reward_scale, **model)

    return seeds_main(__doc__, one, argv, add_arguments)


if __name__ == "__main__":
    sys.exit(main())
