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

``render [--check]`` writes ``docs/leaderboard.md`` and the README's block (between
``<!-- leaderboard:start -->`` and ``<!-- leaderboard:end -->``) from ``results/*.json``
alone, computing nothing; ``--check`` writes nothing and exits 1 with one line if either
differs from what the data give.

Examples::

    python -m train.leaderboard collect --env-id ACLDBeamLab-v1 --references
    python -m train.leaderboard collect --env-id ACLDBeamLab-v1 \\
        --benchmark runs/ACLDBeamLab-v1/benchmark --algos ppo
    python -m train.leaderboard render
"""

from __future__ import annotations

import argparse
import shlex
import sys
from pathlib import Path

from acld_gym.util.atomic import check_directory, check_writable, write_texts
from acld_gym.util.text import plain, prog
from acld_gym.util.validate import arg_type, run_main

__all__ = ["main", "build_parser", "collect", "render"]

NAME = "python -m train.leaderboard"


def build_parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(
        prog=prog(NAME),
        description=plain(__doc__),
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    sub = p.add_subparsers(dest="command", required=True, metavar="{collect,render}")
    c = sub.add_parser("collect", help="measure a level's references and agents into results/")
    c.add_argument("--env-id", required=True, help="a registered id of this package")
    c.add_argument("--references", action="store_true", help="the level's references and marks")
    c.add_argument("--benchmark", metavar="DIR", help="a python -m train.benchmark folder")
    c.add_argument("--algos", nargs="+", metavar="NAME", help="only these configs of DIR")
    c.add_argument(
        "--score-episodes",
        type=arg_type(int, 1, 100_000),
        default=None,
        help="a reduced run on the first N test episodes (default: the whole test set)",
    )
    c.add_argument("--results", default="results", help="the data folder (default results)")
    c.add_argument("--quiet", action="store_true", help="no progress lines")
    r = sub.add_parser("render", help="write the page and the README block from results/")
    r.add_argument("--results", default="results", help="the data folder (default results)")
    r.add_argument("--page", default="docs/leaderboard.md", help="default docs/leaderboard.md")
    r.add_argument("--readme", default="README.md", help="default README.md")
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


def render(args) -> int:
    """The ``render`` subcommand."""
    from .readme import readme_block, replace_block
    from .render import page, read_levels

    levels = read_levels(args.results)
    page_path, readme = Path(args.page), Path(args.readme)
    text = page(levels)
    readme_text = readme.read_text(encoding="utf-8")
    new_readme = replace_block(readme_text, readme_block(levels), readme)
    if args.check:
        old = page_path.read_text(encoding="utf-8") if page_path.is_file() else None
        stale = [
            str(p)
            for p, a, b in ((page_path, old, text), (readme, readme_text, new_readme))
            if a != b
        ]
        if stale:
            print(
                f"{' and '.join(stale)} differ from what {args.results}/*.json give: "
                f"run {NAME} render",
                file=sys.stderr,
            )
            return 1
        print(f"{page_path} and the README block are what {args.results}/*.json give")
        return 0
    write_texts({page_path: text, readme: new_readme})
    print(f"wrote {page_path} and the block of {readme} ({len(levels)} levels with data)")
    return 0


def main(argv: list[str] | None = None) -> int:
    argv = sys.argv[1:] if argv is None else list(argv)
    parser = build_parser()
    args = parser.parse_args(argv)
    if args.command == "collect":
        return collect(args, parser, argv)
    return render(args)


if __name__ == "__main__":
    sys.exit(run_main(main))
