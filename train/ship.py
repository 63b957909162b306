"""``python -m train.ship RUN NAME``: copy a trained agent into ``train/agents/NAME/``
(``policy.npz``, ``metadata.json`` with the command, seed, versions, how it was trained
and the observation fingerprint of the run, and ``learning_curve.csv``).
``python -m train.ship OUT NAME --best CONFIG``: the same for the seed of a benchmark
config best on the thesis cases (:func:`best_seed`)."""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

from acld_gym.physics.loads import THESIS_CASES
from acld_gym.util.atomic import write_text

from .agent import CURVE_FILE, META_FILE, MODEL_FILE, POLICY_FILE, STATS_FILE, TrainedAgent
from .compare import AGENTS_DIR

__all__ = ["best_seed", "ship", "main"]

#: The cases the shipping rule looks at, as results.json keys them: the thesis's (the held-out
#: random loads take no part).
RULE_CASES = tuple(str(c) for c in THESIS_CASES)


def best_seed(out: str | Path, config: str) -> int:
    """The seed of benchmark config ``config`` best on the thesis cases: the lowest mean
    ISE / LQR over cases 1-3 in ``out/results.json`` (``python -m train.benchmark --out
    out``); the first of equal means. The held-out random loads take no part."""
    path = Path(out) / "results.json"
    if not path.is_file():
        raise FileNotFoundError(
            f"no benchmark results {str(path)!r} (the --out of python -m train.benchmark)"
        )
    algos = json.loads(path.read_text()).get("algorithms", {})
    if config not in algos:
        raise ValueError(f"config {config!r} is not in {str(path)!r}; it has {sorted(algos)}")
    per_seed = algos[config].get("per_seed")
    keys = ("seed", *RULE_CASES)
    if not per_seed or not all(isinstance(r, dict) and all(k in r for k in keys) for r in per_seed):
        raise ValueError(f"{str(path)!r}: config {config!r} needs per_seed rows with {list(keys)}")
    means = [sum(float(r[c]) for c in RULE_CASES) / len(RULE_CASES) for r in per_seed]
    return int(per_seed[means.index(min(means))]["seed"])


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
    p.add_argument(
        "run",
        help="an agent directory: the --out of python -m train, or "
        "<out>/agents/<config>-s<seed> of python -m train.benchmark; "
        "with --best, that <out>",
    )
    p.add_argument(
        "--best",
        metavar="CONFIG",
        help="ship the seed of benchmark config CONFIG "
        "best on the thesis cases (mean ISE / LQR over cases 1-3)",
    )
    p.add_argument("name", help="agent name, e.g. ppo, sac, ppo_robust")
    p.add_argument("--agents", default=str(AGENTS_DIR), help="destination (default: shipped)")
    args = p.parse_args(argv)
    if not args.name.replace("_", "").isalnum():
        p.error(f"name must be letters, digits and underscores, got {args.name!r}")
    try:
        run = args.run
        if args.best is not None:
            from .bench.trials import agent_dir

            seed = best_seed(run, args.best)
            run = agent_dir(run, args.best, seed)
            print(f"{args.best}: seed {seed} is best on cases 1-3")
        dst = ship(run, args.name, args.agents)
    except (OSError, ValueError) as exc:
        p.error(str(exc))
    print(f"shipped {dst}/")
    return 0


if __name__ == "__main__":
    from acld_gym.util.validate import run_main

    sys.exit(run_main(main))
