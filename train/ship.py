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

__all__ = ["ship", "best_timesteps", "main"]


def best_timesteps(curve: str | Path) -> int:
    """Training steps of the best evaluation in a ``learning_curve.csv``: the lowest
    mean ISE relative to LQR over the thesis cases (the ``EvalCallback``'s ranking;
    the first of equal ones)."""
    import csv

    with Path(curve).open() as fh:
        rows = list(csv.DictReader(fh))
    if not rows:
        raise ValueError(f"{curve}: empty learning curve")
    steps = sorted({int(r["timesteps"]) for r in rows})
    score = {t: sum(float(r["ise_rel_lqr"]) for r in rows if int(r["timesteps"]) == t)
             for t in steps}
    return min(steps, key=lambda t: (score[t], t))


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
    meta["best_timesteps"] = best_timesteps(needed[3])
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
