"""ISE / LQR of an rl-zoo3-trained agent (``train/zoo/*.yml``) through the plain env.

Loads ``RUN/ACLDBeam-v1.zip`` (an rl-zoo3 log directory, e.g. ``logs/ppo/ACLDBeam-v1_1``; with
``--best``, ``RUN/best_model.zip``, the best of rl-zoo3's evaluations) and
evaluates its deterministic actor on ``ACLDBeam-v1`` as registered (+/-120 V; the actor of
the asymmetric policies never reads the training env's appended log reward scale): thesis
cases 1, 2, 3 (seed 0) and the held-out random set, divided by LQR's ISE
(:mod:`train.core.evaluate`). With ``--validation N``, also its cost on the first ``N``
validation loads (:func:`train.core.evaluate.validation_cost`, disjoint from the held-out
set) and LQR's there, by which the recipes' ``restarts`` choose between runs. Not a test::

    python -m rl_zoo3.train --algo ppo --env ACLDBeam-v1 --gym-packages acld_gym \\
        --conf-file train/zoo/ppo.yml -f logs --seed 0 --eval-freq -1 --num-threads 1
    python benchmarks/zoo_eval.py ppo logs/ppo/ACLDBeam-v1_1 --validation 256
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("algo", choices=("ppo", "sac"))
    p.add_argument("run", type=Path, help="the rl-zoo3 run directory")
    p.add_argument(
        "--best",
        action="store_true",
        help="the best model of rl-zoo3's evaluations (best_model.zip)",
    )
    p.add_argument(
        "--validation",
        type=int,
        default=0,
        metavar="N",
        help="also the cost on the first N validation loads (default 0: not computed)",
    )
    args = p.parse_args(argv)
    import torch
    from stable_baselines3 import PPO, SAC

    torch.set_num_threads(1)  # torch's default threads make small policies slow on few cores

    from train.core.evaluate import (
        ise_rel_lqr,
        lqr_validation_cost,
        validation_cost,
        validation_seeds,
    )
    from train.core.sb3_policies import SB3Policy

    path = args.run / ("best_model.zip" if args.best else "ACLDBeam-v1.zip")
    if not path.is_file():
        p.error(f"run: no {path}")
    if args.validation < 0:
        p.error(f"--validation: expected a number of loads >= 0, got {args.validation}")
    model = {"ppo": PPO, "sac": SAC}[args.algo].load(path, device="cpu")
    from train.voltage import VoltageMap

    # the recipe's action headroom (AsymmetricSACPolicy records it; 1 for the others)
    headroom = getattr(model.policy, "action_headroom", 1.0)
    policy = SB3Policy(model, None, None, voltage_map=VoltageMap(headroom=headroom))
    rel = {str(k): round(float(v), 4) for k, v in ise_rel_lqr(policy, "ACLDBeam-v1").items()}
    out = {"run": str(args.run), "algo": args.algo, "model": path.name, "ise_rel_lqr": rel}
    if args.validation:
        seeds = validation_seeds(args.validation)
        out["validation_cost"] = validation_cost(policy, "ACLDBeam-v1", seeds)
        out["lqr_validation_cost"] = lqr_validation_cost("ACLDBeam-v1", seeds)
    print(json.dumps(out, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
