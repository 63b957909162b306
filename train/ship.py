"""``python -m train.ship RUN NAME``: copy a training run's best checkpoint into
``train/agents/NAME/`` (``model.zip``, ``vecnormalize.pkl``, ``learning_curve.csv``
and ``metadata.json`` with the command, seed and versions of the run)."""

from __future__ import annotations

import argparse
import json
import shutil
import sys
from pathlib import Path

from .agent import META_FILE, MODEL_FILE, STATS_FILE
from .compare import AGENTS_DIR

__all__ = ["ship", "main"]


def ship(run: str | Path, name: str, agents_dir: str | Path = AGENTS_DIR) -> Path:
    """Copy ``run``'s ``best/`` checkpoint (the ``EvalCallback`` best on the thesis
    cases) and its records to ``agents_dir/name``; returns that directory."""
    run = Path(run)
    needed = [run / "best" / "best_model.zip", run / "best" / STATS_FILE, run / META_FILE,
              run / "learning_curve.csv"]
    for f in needed:
        if not f.is_file():
            raise FileNotFoundError(f"run directory {str(run)!r} lacks {f.relative_to(run)}")
    dst = Path(agents_dir) / name
    dst.mkdir(parents=True, exist_ok=True)
    shutil.copy(needed[0], dst / MODEL_FILE)
    shutil.copy(needed[1], dst / STATS_FILE)
    shutil.copy(needed[3], dst / "learning_curve.csv")
    meta = json.loads(needed[2].read_text())
    meta["checkpoint"] = "best on the thesis cases (EvalCallback)"
    (dst / META_FILE).write_text(json.dumps(meta, indent=2) + "\n")
    return dst


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(prog="python -m train.ship", description=__doc__)
    p.add_argument("run", help="a run directory written by python -m train")
    p.add_argument("name", help="agent name, e.g. ppo, sac, ppo_robust")
    p.add_argument("--agents", default=str(AGENTS_DIR), help="destination (default: shipped)")
    args = p.parse_args(argv)
    if not args.name.replace("_", "").isalnum():
        p.error(f"name must be letters, digits and underscores, got {args.name!r}")
    try:
        dst = ship(args.run, args.name, args.agents)
    except OSError as exc:
        p.error(str(exc))
    print(f"shipped {dst}/")
    return 0


if __name__ == "__main__":
    sys.exit(main())
