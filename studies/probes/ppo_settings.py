"""A probe of PPO's settings on one level: the PPO recipe (one run per seed, no retry) with
some of its model keyword arguments replaced (``--model``, JSON; its policy's:
``--policy-kwargs``; ``--recipe sac``: SAC's recipe, its checkpoint selection kept),
scored as every agent is (score v2 on the level's test set, ISE / thesis LQR) beside its
validation cost (the env's
reward per load on the validation loads of :func:`train.core.evaluate.validation_cost`'s
default seeds, 64 loads: not the recipe's 256, so its values sit ~0.012 above the retry
messages' on the lab rig).

Why: the lab rig's PPO seeds score 0.716-0.730 where the random search's are 0.736-0.739,
and over 20 single runs there the validation cost orders the test score (Spearman -0.92):
the gap is PPO's optimization, not its objective. The probe asks whether a learning rate,
epoch count, minibatch size or GAE lambda moves it (studies/README.md, "PPO's settings on
the lab rig").

One JSON line per seed. Not a test; ~1-2 min per seed on one core::

    python studies/probes/ppo_settings.py --env-id ACLDBeamLab-v1 --seeds 0 2 3 \\
        --model '{"learning_rate": {"linear": [1.5e-3, 0.0]}}'
"""

from __future__ import annotations

import dataclasses
import json
import sys

from probe import one_run, seeds_main, train_and_score  # studies/probes/probe.py


def config(model: dict, recipe: str = "ppo", policy_kwargs: dict | None = None):
    """The recipe's config, one run per seed, its model keyword arguments updated by
    ``model`` and its policy's by ``policy_kwargs``."""
    cfg = one_run(None, base=recipe)
    new = {**cfg.model, **model}
    if policy_kwargs:
        new["policy_kwargs"] = {**cfg.model.get("policy_kwargs", {}), **policy_kwargs}
    return dataclasses.replace(cfg, model=new)


def run(seed: int, args) -> dict:
    from train.core.evaluate import validation_cost

    model = json.loads(args.model)
    policy_kwargs = json.loads(args.policy_kwargs)
    cfg = config(model, args.recipe, policy_kwargs)
    policy, got, wall = train_and_score(cfg, seed, args.env_id)
    return {
        "seed": seed,
        "env_id": args.env_id,
        "recipe": args.recipe,
        "model": model,
        "policy_kwargs": policy_kwargs,
        "train_wall_s": round(wall),
        "score_v2": round(got.iqm, 4),
        "ise_rel_lqr": {str(k): round(float(v), 3) for k, v in got.ise_rel_lqr.items()},
        "validation_cost": round(validation_cost(policy, args.env_id), 4),
    }


def add_arguments(p) -> None:
    p.add_argument("--env-id", default="ACLDBeamLab-v1")
    p.add_argument("--model", default="{}", help="PPO keyword arguments to replace (JSON)")
    p.add_argument("--policy-kwargs", default="{}", help="policy keyword arguments (JSON)")
    p.add_argument("--recipe", default="ppo", help="the recipe changed (ppo or sac)")


if __name__ == "__main__":
    sys.exit(seeds_main(__doc__, run, add_arguments=add_arguments))
