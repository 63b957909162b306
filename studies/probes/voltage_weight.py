"""A probe of the training reward's voltage weight: the PPO recipe (one run per seed, no
retry) trained with the env option ``lam`` (the reward's voltage weight, 0.01 by default)
set to ``--lam``, and scored as every agent is, on the level's own reward-free score
(score v2 on the test set, ISE only) and its validation cost with the default weight.

Why: the score is ISE only; the training reward adds ``lam (V / 120)^2`` per step, and the
reward per load (``reward_scale: passive``) divides it by the passive cost of the load, so
on the small random loads, where the sensor noise drives the voltage, that term dominates
and the cheapest law is a timid one. The random search optimizes the log of each episode's
cost instead, which weighs those loads less (by 1 / its own cost, not 1 / passive).

One JSON line per seed. Not a test; ~2 min per seed on one core::

    python studies/probes/voltage_weight.py --env-id ACLDBeamLab-v1 --lam 0.001 --seeds 0 1
"""

from __future__ import annotations

import dataclasses
import sys

from probe import one_run, seeds_main, train_and_score  # studies/probes/probe.py


def config(lam: float, recipe: str = "ppo"):
    """The recipe's config, one run per seed, with the env option ``lam`` in its training
    env (the evaluation's env keeps the level's own reward)."""
    cfg = one_run(None, base=recipe)
    return dataclasses.replace(cfg, env_kwargs={**cfg.env_kwargs, "lam": lam})


def run(seed: int, args) -> dict:
    from train.core.evaluate import validation_cost

    cfg = config(args.lam, args.recipe)
    policy, got, wall = train_and_score(cfg, seed, args.env_id)
    return {
        "seed": seed,
        "env_id": args.env_id,
        "recipe": args.recipe,
        "lam": args.lam,
        "train_wall_s": round(wall),
        "score_v2": round(got.iqm, 4),
        "ci": [round(x, 4) for x in got.ci],
        "ise_rel_lqr": {str(k): round(float(v), 3) for k, v in got.ise_rel_lqr.items()},
        "validation_cost_lam_0.01": round(validation_cost(policy, args.env_id), 4),
    }


def add_arguments(p) -> None:
    p.add_argument("--env-id", default="ACLDBeamLab-v1")
    p.add_argument("--lam", type=float, default=0.01, help="the reward's voltage weight")
    p.add_argument("--recipe", default="ppo")


if __name__ == "__main__":
    sys.exit(seeds_main(__doc__, run, add_arguments=add_arguments))
