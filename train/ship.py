"""``python -m train.ship RUN NAME``: copy a training run's best checkpoint into
``train/agents/NAME/`` (``policy.npz``, ``metadata.json`` with the command, seed,
versions, teacher and observation fingerprint of the run, and ``learning_curve.csv``)."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from acld_gym.util.atomic import write_text

from .agent import META_FILE, MODEL_FILE, POLICY_FILE, STATS_FILE, TrainedAgent
from .callbacks import CURVE_FILE
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
    """Copy ``run``'s ``best/`` agent (the ``EvalCallback`` best on the thesis cases:
    ``policy.npz`` and ``metadata.json``, nothing pickled) and its learning curve to
    ``agents_dir/name``, atomically per file; returns that directory. ``run`` may also be
    an agent directory itself (``python -m train.benchmark`` saves one per trial, its
    final policy, in ``<out>/agents/<config>-s<seed>``): it is copied as it is."""
    run = Path(run)
    if (run / POLICY_FILE).is_file() and (run / META_FILE).is_file() and not (
            run / "best").is_dir():
        agent = TrainedAgent.load(run, check=False)
        agent.metadata["checkpoint"] = "final policy"
        dst = Path(agents_dir) / name
        agent.save(dst)
        if (run / CURVE_FILE).is_file():
            write_text(dst / CURVE_FILE, (run / CURVE_FILE).read_text())
        return dst
    needed = [run / "best" / POLICY_FILE, run / "best" / META_FILE, run / CURVE_FILE]
    for f in needed:
        if not f.is_file():
            raise FileNotFoundError(f"run directory {str(run)!r} lacks {f.relative_to(run)}")
    agent = TrainedAgent.load(run / "best", check=False)
    agent.metadata["checkpoint"] = "best on the thesis cases (EvalCallback)"
    agent.metadata["best_timesteps"] = best_timesteps(needed[2])
    dst = Path(agents_dir) / name
    agent.save(dst)
    write_text(dst / CURVE_FILE, needed[2].read_text())
    for stale in (MODEL_FILE, STATS_FILE):  # pickled files of an older format
        (dst / stale).unlink(missing_ok=True)
    return dst


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(prog="python -m train.ship", description=__doc__)
    p.add_argument("run", help="a run directory written by python -m train, or an agent "
                              "directory written by python -m train.benchmark")
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
    from acld_gym.util.validate import run_main

    sys.exit(run_main(main))
