"""``python -m train.ship RUN NAME``: copy a trained agent into ``agents/NAME/`` of the
current directory, or ``DIR/NAME/`` with ``--agents DIR`` (``policy.npz``,
``metadata.json`` with the command, seed, versions, how it was trained and the observation
fingerprint of the run, and ``learning_curve.csv``).
``python -m train.ship OUT NAME --best CONFIG``: the same for the seed of a benchmark
config best on the thesis cases (:func:`best_seed`).

The run's files are read as :meth:`train.agent.TrainedAgent.load` reads them (no link
followed out of the run's folder, every field checked); the shipped folder is written
whole, swapped in with one rename (:meth:`train.agent.TrainedAgent.save`), so a reader or
a full disk sees the old agent or the new one. An existing ``NAME`` is replaced only with
``--force``.

Nothing is written into the installed package: the agents that ship with it
(``train/agents/``, :data:`train.compare.AGENTS_DIR`) are read by ``python -m
train.compare`` and the figures, and a user's agents go where the user works
(``./agents``, or ``--agents DIR``); ``python -m train.compare --agents agents`` compares
them."""

from __future__ import annotations

import argparse
import os
import sys
from pathlib import Path

from acld_gym.physics.loads import THESIS_CASES
from acld_gym.util.atomic import check_directory
from acld_gym.util.text import command_names, plain, prog
from acld_gym.util.validate import os_error_line

from .agent import CURVE_FILE, TrainedAgent
from .agent_files import check_replaceable, curve_rows
from .agent_schema import is_real

__all__ = ["DEFAULT_AGENTS", "best_seed", "ship", "build_parser", "main"]

#: The cases the shipping rule looks at, as results.json keys them: the thesis's (the held-out
#: random loads take no part).
RULE_CASES = tuple(str(c) for c in THESIS_CASES)

#: Where agents are shipped by default: ``agents/`` in the current working directory (never
#: the installed package's ``train/agents/``).
DEFAULT_AGENTS = "agents"


def best_seed(out: str | Path, config: str) -> int:
    """The seed of benchmark config ``config`` best on the thesis cases: the lowest mean
    ISE / LQR over cases 1-3 in ``out/results.json`` (``python -m train.benchmark --out
    out``); the first of equal means. The held-out random loads take no part."""
    path = Path(out) / "results.json"
    if not path.is_file():
        raise FileNotFoundError(
            f"no benchmark results {str(path)!r} (the --out of python -m train.benchmark)"
        )
    from .core.records import read_json

    data = read_json(path)  # (a DataFileError, a ValueError, naming it; at most 64 MiB read)
    algos = data.get("algorithms") if isinstance(data, dict) else None
    if not isinstance(algos, dict):
        raise ValueError(f"{str(path)!r}: expected an object with 'algorithms'")
    if config not in algos:
        raise ValueError(f"config {config!r} is not in {str(path)!r}; it has {sorted(algos)}")
    per_seed = algos[config].get("per_seed") if isinstance(algos[config], dict) else None
    keys = ("seed", *RULE_CASES)
    if not isinstance(per_seed, list) or not per_seed or not all(_rule_row(r) for r in per_seed):
        raise ValueError(
            f"{str(path)!r}: config {config!r} needs per_seed rows with {list(keys)} "
            "(an integer seed >= 0 and finite ratios)"
        )
    means = [sum(float(r[c]) for c in RULE_CASES) / len(RULE_CASES) for r in per_seed]
    return int(per_seed[means.index(min(means))]["seed"])


def _rule_row(row) -> bool:
    """Whether a per-seed row has a seed (an integer >= 0) and a finite ratio per case."""
    if not isinstance(row, dict) or not all(k in row for k in ("seed", *RULE_CASES)):
        return False
    seed = row["seed"]
    ok_seed = isinstance(seed, int) and not isinstance(seed, bool) and seed >= 0
    return ok_seed and all(is_real(row[c]) for c in RULE_CASES)


def check_name(name) -> str:
    """``name`` if it can name a shipped agent: letters, digits and underscores (a folder
    name, never a path); ``ValueError`` otherwise."""
    if not isinstance(name, str) or not name.replace("_", "").isalnum() or not name.isascii():
        raise ValueError(f"name must be letters, digits and underscores, got {name!r}")
    return name


def ship(
    run: str | Path, name: str, agents_dir: str | Path = DEFAULT_AGENTS, force: bool = False
) -> Path:
    """Copy an agent directory (``python -m train`` writes one in its ``--out``,
    ``python -m train.benchmark`` one per trial in ``<out>/agents/<config>-s<seed>``: the
    run's final policy, ``policy.npz`` + ``metadata.json``, nothing pickled) and its
    learning curve to ``agents_dir/name`` (default ``agents/name`` in the current
    directory), the folder written whole (module docstring);
    returns that directory. The agent is read and validated by
    :meth:`train.agent.TrainedAgent.load` (its observation fingerprint included: a shipped
    agent loads) before anything is written; ``FileExistsError`` if ``agents_dir/name``
    exists and not ``force``."""
    check_name(name)
    agent = TrainedAgent.load(run)  # checked against its env: a shipped agent loads
    curve = agent.learning_curve()
    if curve is not None:
        curve_rows(curve, str(Path(run) / CURVE_FILE))
    dst = Path(agents_dir) / name
    if os.path.lexists(dst) and not force:
        raise FileExistsError(
            f"agent {name!r} exists in {str(Path(agents_dir))!r}; pass --force to replace it"
        )
    check_replaceable(dst)
    agent.metadata["checkpoint"] = "final policy"
    return agent.save(dst, {CURVE_FILE: curve} if curve is not None else None)


def build_parser() -> argparse.ArgumentParser:
    """The command line of ``python -m train.ship`` (``acld-gym ship``)."""
    p = argparse.ArgumentParser(
        prog=prog("python -m train.ship"),
        description=plain(__doc__),
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument(
        "run",
        help=command_names(
            "an agent directory: the --out of python -m train, or "
            "<out>/agents/<config>-s<seed> of python -m train.benchmark; with --best, that <out>"
        ),
    )
    p.add_argument(
        "--best",
        metavar="CONFIG",
        help="ship the seed of benchmark config CONFIG "
        "best on the thesis cases (mean ISE / LQR over cases 1-3)",
    )
    p.add_argument("name", help="agent name, e.g. ppo, sac, ppo_robust")
    p.add_argument(
        "--agents",
        metavar="DIR",
        default=DEFAULT_AGENTS,
        help="destination folder of agents (default: ./agents, in the current directory)",
    )
    p.add_argument("--force", action="store_true", help="replace an existing agent of that name")
    return p


def main(argv: list[str] | None = None) -> int:
    p = build_parser()
    args = p.parse_args(argv)
    try:
        check_name(args.name)
        check_directory(args.agents, "--agents")  # before anything is read or written
    except ValueError as exc:
        p.error(str(exc))
    try:
        run = args.run
        if args.best is not None:
            from .core.trials import agent_dir

            seed = best_seed(run, args.best)
            run = agent_dir(run, args.best, seed)
            print(f"{args.best}: seed {seed} is best on cases 1-3")
        dst = ship(run, args.name, args.agents, force=args.force)
    except OSError as exc:  # a full disk names the file: the agent folder is left as it was
        p.error(str(exc) if exc.errno is None else os_error_line(exc))
    except ValueError as exc:
        p.error(str(exc))
    print(f"shipped {dst}/")
    return 0


if __name__ == "__main__":
    from acld_gym.util.validate import run_main

    sys.exit(run_main(main))
