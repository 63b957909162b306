"""ISE / LQR of an rl-zoo3-trained agent (``train/zoo/*.yml``) through the plain env.

Loads ``RUN/ACLDBeam-v1.zip`` (an rl-zoo3 log directory, e.g. ``logs/ppo/ACLDBeam-v1_1``; with
``--best``, ``RUN/best_model.zip``, the best of rl-zoo3's evaluations) and
evaluates its deterministic actor on ``ACLDBeam-v1`` as registered (+/-120 V; the actor of
the asymmetric policies never reads the training env's appended log reward scale): thesis
cases 1, 2, 3 (seed 0) and the held-out random set, divided by LQR's ISE
(:mod:`train.bench.evaluate`). Not a test::

    python -m rl_zoo3.train --algo ppo --env ACLDBeam-v1 --gym-packages acld_gym \\
        --conf-file train/zoo/ppo.yml -f logs --seed 0 --eval-freq -1
    python benchmarks/zoo_eval.py ppo logs/ppo/ACLDBeam-v1_1
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
    args = p.parse_args(argv)
    from stable_baselines3 import PPO, SAC

    from train.bench.evaluate import ise_rel_lqr
    from train.bench.sb3_policies import SB3Policy

    path = args.run / ("best_model.zip" if args.best else "ACLDBeam-v1.zip")
    if not path.is_file():
        p.error(f"run: no {path}")
    model = {"ppo": PPO, "sac": SAC}[args.algo].load(path, device="cpu")
    from train.voltage import VoltageMap

    # the recipe's action headroom (AsymmetricSACPolicy records it; 1 for the others)
    headroom = getattr(model.policy, "action_headroom", 1.0)
    policy = SB3Policy(model, None, None, voltage_map=VoltageMap(headroom=headroom))
    rel = {str(k): round(float(v), 4) for k, v in ise_rel_lqr(policy, "ACLDBeam-v1").items()}
    print(
        json.dumps(
            {"run": str(args.run), "algo": args.algo, "model": path.name, "ise_rel_lqr": rel},
            indent=1,
        )
    )
    return 0


if __name__ == "__main__":
    sys.exit(main())
