"""``python -m train.leaderboard``: the leaderboard of every level, from committed data.

``collect --env-id ID [--references] [--benchmark DIR [--algos NAME ...]]`` measures a
level's references (every reference and mark that ``python -m baselines.evaluate --env-id
ID`` reports, and the clairvoyant bound) and the trained agents of a ``python -m
train.benchmark --env-id ID --out DIR`` folder (every seed: score v2 on the test set by
``train.scoring.score``, ISE relative to the thesis LQR on cases 1, 2, 3 and the held-out
random loads, effort after settling, training time, runs and retries; per algorithm the IQM
over the seeds with 95 % stratified-bootstrap intervals) and merges them into
``results/<env id>.json``: the references and each algorithm are replaced independently,
the rest of the file is kept. ``--score-episodes N``: a reduced run on the first N test
episodes (not the published score; the file says so).

``guide-run -- COMMAND ...`` runs the command of a script of the guide "Train on any level
with any library" (``python docs/examples/sb3_ppo.py ACLDBeamLab-v1 --seed 101``, the SB3
SAC script, or CleanRL's patched ``ppo_continuous_action.py``), shows its output, times it
and keeps the score it prints in ``results/guide/runs.json`` (:mod:`train.leaderboard.guide`).

``render [--check]`` writes ``docs/leaderboard.md``, the README's block (between
``<!-- leaderboard:start -->`` and ``<!-- leaderboard:end -->``) and the guide's block of
``docs/any-library.md`` (between ``<!-- guide-runs:start -->`` and ``<!-- guide-runs:end
-->``) from ``results/`` alone, computing nothing; ``--check`` writes nothing and exits 1
with one line if any of them differs from what the data give.

Examples::

    python -m train.leaderboard collect --env-id ACLDBeamLab-v1 --references
    python -m train.leaderboard collect --env-id ACLDBeamLab-v1 \\
        --benchmark runs/ACLDBeamLab-v1/benchmark --algos ppo
    python -m train.leaderboard guide-run -- python docs/examples/sb3_ppo.py \\
        ACLDBeam-v1 --seed 101
    python -m train.leaderboard render
"""

from __future__ import annotations

import argparse
import shlex
import sys
from pathlib import Path

from acld_gym.util.atomic import check_directory, check_writable, write_texts
from acld_gym.util.text import command_names, plain, prog
from acld_gym.util.validate import arg_type, run_main

__all__ = ["main", "build_parser", "collect", "guide_run", "render"]

NAME = "python -m train.leaderboard"


def build_parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(
        prog=prog(NAME),
        description=plain(__doc__),
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    sub = p.add_subparsers(dest="command", required=True, metavar="{collect,guide-run,render}")
    c = sub.add_parser("collect", help="measure a level's references and agents into results/")
    c.add_argument("--env-id", required=True, help="a registered id of this package")
    c.add_argument("--references", action="store_true", help="the level's references and marks")
    c.add_argument(
        "--benchmark",
        metavar="DIR",
        help=command_names("the output folder of python -m train.benchmark"),
    )
    c.add_argument("--algos", nargs="+", metavar="NAME", help="only these configs of DIR")
    c.add_argument(
        "--score-episodes",
        type=arg_type(int, 1, 100_000),
        default=None,
        help="a reduced run on the first N test episodes (default: the whole test set)",
    )
    c.add_argument("--results", default="results", help="the data folder (default results)")
    c.add_argument("--quiet", action="store_true", help="no progress lines")
    g = sub.add_parser(
        "guide-run", help="run a guide script's command and keep its score in results/guide/"
    )
    g.add_argument("--results", default="results", help="the data folder (default results)")
    g.add_argument("argv", nargs=argparse.REMAINDER, metavar="-- COMMAND ...")
    r = sub.add_parser("render", help="write the pages and the README block from results/")
    r.add_argument("--results", default="results", help="the data folder (default results)")
    r.add_argument("--page", default="docs/leaderboard.md", help="default docs/leaderboard.md")
    r.add_argument("--readme", default="README.md", help="default README.md")
    r.add_argument("--guide", default="docs/any-library.md", help="default docs/any-library.md")
    r.add_argument("--check", action="store_true", help="write nothing; exit 1 on a difference")
    return p


def collect(args, parser: argparse.ArgumentParser, argv: list[str]) -> int:
    """The ``collect`` subcommand (arguments checked before anything is computed)."""
    from acld_gym.envs.presets import check_env_id
    from acld_gym.test_sets import evaluation_set

    from .collect import (
        collect_benchmark,
        collect_references,
        level_path,
        load_or_empty,
        merge,
        write_level,
    )

    try:
        env_id = check_env_id(args.env_id, "--env-id")
        if not (args.references or args.benchmark):
            raise ValueError("collect needs --references, --benchmark DIR or both")
        if args.algos and not args.benchmark:
            raise ValueError("--algos needs --benchmark DIR")
        size = len(evaluation_set(env_id).seeds)
        if args.score_episodes is not None and args.score_episodes > size:
            raise ValueError(f"--score-episodes: the test set of {env_id} has {size} episodes")
        if args.benchmark and not Path(args.benchmark).is_dir():
            raise ValueError(f"--benchmark: {args.benchmark} is not a folder")
        check_directory(args.results, "--results")
        path = level_path(args.results, env_id)
        check_writable(path, "--results")
    except ValueError as exc:
        parser.error(str(exc))
    level = load_or_empty(path, env_id)  # a damaged file: one line, nothing computed
    command = shlex.join([*NAME.split(), *argv])
    say = None if args.quiet else print
    refs = agents = None
    if args.benchmark:  # the trials are read and checked before the references' minutes
        agents = collect_benchmark(
            args.benchmark, env_id, command, args.algos, args.score_episodes, say
        )
    if args.references:
        if say:
            say(f"  references of {env_id}: scoring every reference on its test set")
        refs = collect_references(env_id, command, args.score_episodes, quiet=args.quiet)
    write_level(path, merge(level, refs, agents))
    parts = (["references"] if refs else []) + sorted(agents or {})
    print(f"wrote {path} ({', '.join(parts)})")
    return 0


def guide_run(args, parser: argparse.ArgumentParser) -> int:
    """The ``guide-run`` subcommand (the command and the folder checked before it runs)."""
    from .guide import GUIDE_FILE, guide_run, parse_command

    argv = args.argv[1:] if args.argv[:1] == ["--"] else args.argv
    try:
        if not argv:
            raise ValueError("guide-run needs a command after --")
        parse_command(argv)
        check_directory(args.results, "--results")
        check_writable(Path(args.results) / GUIDE_FILE, "--results")
    except ValueError as exc:
        parser.error(str(exc))
    try:
        rec = guide_run(argv, args.results)
    except (RuntimeError, ValueError) as exc:
        print(f"{NAME} guide-run: {exc}", file=sys.stderr)
        return 1
    print(
        f"kept in {Path(args.results) / GUIDE_FILE}: {rec['client']} on {rec['env_id']}, "
        f"seed {rec['seed']}: score {rec['score']['iqm']:.4f}, {rec['wall_seconds']:.0f} s"
    )
    return 0


def render(args) -> int:
    """The ``render`` subcommand."""
    from .guide import GUIDE_FILE, read_runs
    from .guide_page import END as GUIDE_END
    from .guide_page import START as GUIDE_START
    from .guide_page import guide_block
    from .readme import readme_block, replace_block
    from .render import page, read_levels

    levels = read_levels(args.results)
    runs_file = Path(args.results) / GUIDE_FILE
    runs = read_runs(runs_file) if runs_file.is_file() else []
    page_path, readme, guide = Path(args.page), Path(args.readme), Path(args.guide)
    texts = {page_path: page(levels)}
    olds = {page_path: page_path.read_text(encoding="utf-8") if page_path.is_file() else None}
    for path, block, markers in (
        (readme, readme_block(levels), {}),
        (guide, guide_block(runs, levels), {"start": GUIDE_START, "end": GUIDE_END}),
    ):
        olds[path] = path.read_text(encoding="utf-8")
        texts[path] = replace_block(olds[path], block, path, **markers)
    if args.check:
        stale = [str(p) for p, text in texts.items() if olds[p] != text]
        if stale:
            print(
                f"{' and '.join(stale)} differ from what {args.results}/ gives: run {NAME} render",
                file=sys.stderr,
            )
            return 1
        print(f"{', '.join(map(str, texts))} are what {args.results}/ gives")
        return 0
    write_texts(texts)
    print(
        f"wrote {page_path}, the block of {readme} and the block of {guide} "
        f"({len(levels)} levels, {len(runs)} guide runs)"
    )
    return 0


def main(argv: list[str] | None = None) -> int:
    argv = sys.argv[1:] if argv is None else list(argv)
    parser = build_parser()
    args = parser.parse_args(argv)
    if args.command == "collect":
        return collect(args, parser, argv)
    if args.command == "guide-run":
        return guide_run(args, parser)
    return render(args)


if __name__ == "__main__":
    sys.exit(run_main(main))
