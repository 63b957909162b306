"""What the PPO probes of ``studies/probes/`` share (``residual_actor.py``, ``episode_noise.py``,
``beta_actor.py``, ``time_critic.py``, ``antithetic.py``, ``paired_minibatches.py``,
``actor_steps.py``, ``phase_weights.py``): the PPO recipe they were measured against,
acld-gym 0.8.0-0.14.0's (:data:`BASE`; the recipe since 0.15.0 is ``antithetic.py``'s
pairs with the entropy coefficient 0.05, the ``--recipe ppo`` of two probes,
:data:`RECIPES`, and the ``base`` of ``actor_steps.py``, ``paired_minibatches.py`` and
``phase_weights.py``), with another policy, one run per seed (:func:`one_run`), trained
and evaluated as the benchmark does (:func:`run_recipe`), and a command line printing one
JSON line per seed (:func:`seeds_main`).

A run's line: its settings, its training wall time, its cost on 256 validation loads (the
recipe's own check at the run's end, :func:`train.core.evaluate.validation_cost`; LQR
0.535, the shipped random search 0.5129, the +/-120 V limit cycle ~1.94) and ISE / LQR on
cases 1, 2, 3 and the held-out random loads (:func:`train.core.evaluate.ise_rel_lqr`).
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import time
from collections.abc import Callable, Iterable
from pathlib import Path

#: Env steps per episode of ACLDBeam-v1 (1 s at 1 ms).
EPISODE_STEPS = 1000

#: The config the probes change: acld-gym 0.8.0-0.14.0's PPO recipe
#: (``studies/ablations/ablation_ppo_independent.yaml``), on which their numbers were measured.
BASE = "ablation_ppo_independent"

#: The configs a probe's ``--recipe`` may change: :data:`BASE`, or ``"ppo"``, acld-gym
#: 0.15.0's recipe (``train/recipes/ppo.yaml``).
RECIPES = (BASE, "ppo")

#: The ablation configs: ``studies/ablations/``.
ABLATIONS = Path(__file__).resolve().parents[1] / "ablations"


def load_study_config(name: str):
    """The :class:`train.config.TrainConfig` of ``name``: ``studies/ablations/<name>.yaml``
    if there is one, else a recipe name or a YAML path (:func:`train.config.load_config`)."""
    from train.config import load_config

    path = ABLATIONS / f"{name}.yaml"
    return load_config(path if path.is_file() else name)


def one_run(
    policy,
    policy_kwargs: dict | None = None,
    drop: Iterable[str] = (),
    base: str = BASE,
    **model,
):
    """The config ``base`` (:data:`BASE` unless given) with ``policy`` (None: the base's; its
    ``policy_kwargs`` added to the base's) and one run per seed, its failures reported
    rather than retried; the keys in ``drop`` are removed from the base's model and policy
    keyword arguments, and ``model`` replaces model keyword arguments."""
    cfg = load_study_config(base)
    drop = set(drop)
    kept = {k: v for k, v in cfg.model.items() if k not in drop}
    kwargs = {k: v for k, v in kept.get("policy_kwargs", {}).items() if k not in drop}
    kwargs.update(policy_kwargs or {})
    policy = kept["policy"] if policy is None else policy
    new = {**kept, **model, "policy": policy, "policy_kwargs": kwargs}
    return dataclasses.replace(cfg, model=new, restarts=1, restart_above=None)


def run_recipe(
    cfg, seed: int, env_id: str = "ACLDBeam-v1", make_env: Callable | None = None, **settings
) -> dict:
    """Train one run of ``cfg`` (a :class:`train.config.TrainConfig`) for ``seed`` and
    evaluate it; ``make_env`` is the training env's factory if not the recipe's
    (:func:`train.core.sb3_train.train_sb3`); ``settings`` are reported after the seed."""
    from train.core.evaluate import ise_rel_lqr
    from train.core.sb3_train import train_sb3

    t0 = time.perf_counter()
    factory = {} if make_env is None else {"make_env": make_env}
    policy, record = train_sb3(cfg, seed, env_id, **factory)
    wall = time.perf_counter() - t0
    rel = ise_rel_lqr(policy, env_id)
    return {
        "seed": seed,
        **settings,
        "train_wall_s": round(wall),
        "validation_cost_256": round(record["select"]["cost"], 4),
        "ise_rel_lqr": {str(k): round(float(v), 3) for k, v in rel.items()},
    }


def seeds_main(
    doc: str,
    run: Callable[[int, argparse.Namespace], dict],
    argv: list[str] | None = None,
    add_arguments: Callable[[argparse.ArgumentParser], None] | None = None,
) -> int:
    """The probe's command line: ``--seeds`` (default 0) and the probe's own arguments
    (``add_arguments``); prints ``run(seed, args)`` as a JSON line per seed."""
    p = argparse.ArgumentParser(description=doc.split("\n\n")[0])
    p.add_argument("--seeds", type=int, nargs="+", default=[0])
    if add_arguments is not None:
        add_arguments(p)
    args = p.parse_args(argv)
    for seed in args.seeds:
        print(json.dumps(run(seed, args)), flush=True)
    return 0


def train_and_score(cfg, seed: int, env_id: str):
    """Train one run of ``cfg`` for ``seed`` on ``env_id`` and score it as every agent is:
    ``(policy, score, training wall time [s])``, the score a
    :class:`train.scoring.PolicyScore` (score v2 on the level's test set, ISE / thesis LQR)."""
    from train.core.sb3_train import train_sb3
    from train.scoring import score

    t0 = time.perf_counter()
    policy, _ = train_sb3(cfg, seed, env_id)
    wall = time.perf_counter() - t0
    return policy, score(policy, env_id), wall
