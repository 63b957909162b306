"""The benchmark's report: IQM of ISE / LQR with 95 % bootstrap intervals per algorithm
and case (:func:`summarize`), its markdown table, and the learning-curve figure.

``python -m train.core.report`` (:func:`main`); the pieces live by job and are importable
from here: the statistics (:mod:`train.core.report_stats`), the tables and headline
(:mod:`train.core.report_tables`), the figure (:mod:`train.core.report_plots`) and the
pages' generated blocks (:mod:`train.core.report_pages`)."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from acld_gym.util.atomic import write_texts
from acld_gym.util.text import command_names, plain, prog
from acld_gym.util.validate import check_figure_path, os_error_line, run_main

from .records import DataFileError, read_results
from .report_pages import BLOCKS, MARK_BEGIN, MARK_END, render_blocks, replace_block, write_blocks
from .report_plots import curves_figure, plot_curves, ratio_log_axis
from .report_stats import GOALS, goals_of, seeds_beating_references, summarize
from .report_tables import KINDS, LABELS, STRETCH_BASE, budget, headline, markdown, stretch_lines

__all__ = [
    "GOALS",
    "goals_of",
    "summarize",
    "markdown",
    "headline",
    "stretch_lines",
    "seeds_beating_references",
    "render_blocks",
    "write_blocks",
    "ratio_log_axis",
    "curves_figure",
    "plot_curves",
    "budget",
    "LABELS",
    "KINDS",
    "STRETCH_BASE",
    "BLOCKS",
    "MARK_BEGIN",
    "MARK_END",
    "replace_block",
]


def main(argv: list[str] | None = None) -> int:
    """``python -m train.core.report RESULTS.json [--write PAGE.md ...] [--plot FIG.png]``:
    the benchmark's tables (Markdown) from a committed results file, printed, or with
    ``--write`` put into each page between its generated-block markers (the tables and the
    headline; every page is checked before any is written, and each is replaced
    atomically); ``--plot`` also draws its learning curves (ISE / LQR against env steps)
    to an image."""
    p = argparse.ArgumentParser(
        prog=prog("python -m train.core.report"),
        description=plain(main.__doc__),
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument(
        "results", type=Path, help=command_names("a results.json of python -m train.benchmark")
    )
    p.add_argument(
        "--write",
        type=Path,
        nargs="+",
        default=None,
        metavar="PAGE",
        help="replace the generated blocks of these Markdown pages",
    )
    p.add_argument(
        "--plot",
        type=Path,
        default=None,
        metavar="FIG",
        help="also write the learning curves to this image",
    )
    args = p.parse_args(argv)
    try:  # every field the tables and the figure read, checked (DataFileError names it)
        summary = read_results(args.results)
    except (OSError, DataFileError) as exc:
        p.error(os_error_line(exc) if isinstance(exc, OSError) else f"not a results file: {exc}")
    blocks = render_blocks(summary)
    if args.plot is not None:
        try:
            check_figure_path(args.plot, "--plot")
        except (OSError, ValueError) as exc:
            p.error(str(exc))
        plot_curves(summary, args.plot)
        print(f"wrote the learning curves of {args.results} to {args.plot}")
    if args.write is None:
        if args.plot is None:
            print(blocks["tables"], end="")
        return 0
    texts = {}
    for page in args.write:
        try:
            texts[page] = write_blocks(page.read_text(), blocks, str(args.results), str(page))
        except (OSError, ValueError) as exc:  # an undecodable page: name it
            p.error(str(exc) if str(page) in str(exc) else f"{page}: {exc}")
    write_texts(texts)  # every page or none (a full disk fails before any is replaced)
    for page in texts:
        print(f"wrote the tables of {args.results} into {page}")
    return 0


if __name__ == "__main__":
    sys.exit(run_main(main))
