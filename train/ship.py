"""``python -m train.ship RUN NAME``: copy a trained agent into ``train/agents/NAME/``
(``policy.npz``, ``metadata.json`` with the command, seed, versions, how it was trained
and the observation fingerprint of the run, and ``learning_curve.csv``)."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from acld_gym.util.atomic import write_text

from .agent import CURVE_FILE, META_FILE, MODEL_FILE, POLICY_FILE, STATS_FILE, TrainedAgent
from .compare import AGENTS_DIR

__all__ = ["ship", "main"]


def ship(run: str | Path, name: str, agents_dir: str | Path = AGENTS_DIR) -> Path:
    """Copy an agent directory (``python -m train`` writes one in its ``--out``,
    ``python -m train.benchmark`` one per trial in ``<out>/agents/<config>-s<seed>``: the
    run's final policy, ``policy.npz`` + ``metadata.json``, nothing pickled) and its
    learning curve to ``agents_dir/name``, atomically per file; returns that directory.
    The agent is validated (:meth:`train.agent.TrainedAgent.load`) before it is copied."""
    run = Path(run)
    for f in (run / POLICY_FILE, run / META_FILE):
        if not f.is_file():
            raise FileNotFoundError(f"agent directory {str(run)!r} lacks {f.name}")
    agent = TrainedAgent.load(run, check=False)
    agent.metadata["checkpoint"] = "final policy"
    dst = Path(agents_dir) / name
    agent.save(dst)
    if (run / CURVE_FILE).is_file():
        write_text(dst / CURVE_FILE, (run / CURVE_FILE).read_text())
    for stale in (MODEL_FILE, STATS_FILE):  # pickled files of an older format
        (dst / stale).unlink(missing_ok=True)
    return dst


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(prog="python -m train.ship", description=__doc__)
    p.add_argument("run", help="an agent directory: the --out of python -m train, or "
                              "<out>/agents/<config>-s<seed> of python -m train.benchmark")
    p.add_argument("name", help="agent name, e.g. ppo, sac, ppo_robust")
    p.add_argument("--agents", default=str(AGENTS_DIR), help="destination (default: shipped)")
    args = p.parse_args(argv)
    if not args.name.replace("_", "").isalnum():
        p.error(f"name must be letters, digits and underscores, got {args.name!r}")
    try:
        dst = ship(args.run, args.name, args.agents)
    except (OSError, ValueError) as exc:
        p.error(str(exc))
    print(f"shipped {dst}/")
    return 0


if __name__ == "__main__":
    from acld_gym.util.validate import run_main

    sys.exit(run_main(main))
