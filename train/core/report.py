"""The benchmark's report: IQM of ISE / LQR with 95 % bootstrap intervals per algorithm
and case (:func:`summarize`), its markdown table, and the learning-curve figure."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from acld_gym.util.atomic import save_figure, write_texts
from acld_gym.util.text import plain, prog
from acld_gym.util.validate import check_figure_path, os_error_line, run_main

from .evaluate import CASES, OBJECTIVE_LOADS
from .records import DataFileError, read_results
from .trials import REFERENCES

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
]


#: The goals (issue 20), each a function of every seed's ISE / LQR ``rel`` (seeds x
#: :data:`CASES`), their IQM ``stats``, the references (ISE / LQR) and the runs.
GOALS = {
    "every_seed_beats_lqr_and_smc": lambda rel, stats, refs, runs: bool(
        seeds_beating_references(rel, refs).all()
    ),
    "every_seed_case3_within_2pct": lambda rel, stats, refs, runs: bool((rel[:, 2] <= 1.02).all()),
    "iqm_cases_1_2_at_most_0.90": lambda rel, stats, refs, runs: all(
        stats[c]["iqm"] <= 0.90 for c in ("1", "2")
    ),
    "iqm_random_at_most_0.97": lambda rel, stats, refs, runs: stats["random"]["iqm"] <= 0.97,
    "train_wall_within_15_min": lambda rel, stats, refs, runs: (
        max(r["train_seconds"] for r in runs) <= 900.0
    ),
}


def seeds_beating_references(rel: np.ndarray, refs: dict) -> np.ndarray:
    """Per seed (a row of ``rel``, ISE / LQR on :data:`CASES`), whether it is below LQR
    and SMC (``refs["smc"]``, ISE / LQR per case) on cases 1, 2 and the random loads: the
    first goal's rule, per seed."""
    rel = np.atleast_2d(np.asarray(rel, dtype=float))
    cols = [(CASES.index(c), str(c)) for c in (1, 2, "random")]
    return np.all(
        [rel[:, j] < min(1.0, refs.get("smc", {}).get(c, np.inf)) for j, c in cols], axis=0
    )


def goals_of(rel: np.ndarray, stats: dict, refs: dict, runs: list[dict]) -> dict:
    """Which of :data:`GOALS` a config meets."""
    return {name: bool(goal(rel, stats, refs, runs)) for name, goal in GOALS.items()}


def summarize(records: list[dict], refs: dict) -> dict:
    """Per config: IQM and 95 % stratified-bootstrap CI of ISE / LQR per case over the
    seeds, the per-seed values, wall time, and the goals (:data:`GOALS`)."""
    from .stats import iqm, iqm_with_ci

    lqr = refs["lqr"]
    out: dict = {
        "env_id": refs["env_id"],
        "episodes": refs["episodes"],
        "algorithms": {},
        "references": {
            k: {c: refs[k][c] / lqr[c] for c in lqr} for k in ("passive", *REFERENCES) if k in refs
        },
    }
    if "validation_cost" in refs:
        out["reference_validation_cost"] = dict(refs["validation_cost"])
    for name in dict.fromkeys(r["name"] for r in records):
        runs = sorted((r for r in records if r["name"] == name), key=lambda r: r["seed"])
        costs = [r.get("validation_cost") for r in runs]
        rel = np.array([[r["final_ise"][str(c)] / lqr[str(c)] for c in CASES] for r in runs])
        stats = {str(c): iqm_with_ci(rel[:, j]) for j, c in enumerate(CASES)}
        goals = goals_of(rel, stats, out["references"], runs)
        curve_steps = [p["steps"] for p in runs[0]["curve"]]
        n_pts = min(len(r["curve"]) for r in runs)
        curve = []
        for k in range(n_pts):
            pt = {"steps": curve_steps[k]}
            for c in CASES:
                vals = np.array([r["curve"][k]["ise"][str(c)] / lqr[str(c)] for r in runs])
                pt[str(c)] = iqm_with_ci(vals, reps=500)
            curve.append(pt)
        out["algorithms"][name] = {
            "algo": runs[0]["algo"],
            "budget": runs[0]["budget"],
            "restarts": int(runs[0]["config"].get("restarts", 1)),  # runs per seed (at most)
            "restart_above": runs[0]["config"].get("restart_above"),
            "seeds": [r["seed"] for r in runs],
            "ise_rel_lqr": stats,
            # the env's own objective (train.core.evaluate.OBJECTIVE_LOADS validation
            # loads); None for trials recorded before it was (acld-gym < 0.19)
            "validation_cost": (
                None if None in costs else iqm_with_ci(np.array(costs, dtype=float))
            ),
            "goals": goals,
            "train_seconds": {
                "iqm": iqm([r["train_seconds"] for r in runs]),
                "max": max(r["train_seconds"] for r in runs),
            },
            "train_cpu_seconds": {
                "iqm": iqm([r.get("train_cpu_seconds", np.nan) for r in runs]),
                "max": max(r.get("train_cpu_seconds", np.nan) for r in runs),
            },
            "per_seed": [
                {
                    "seed": r["seed"],
                    "train_seconds": r["train_seconds"],
                    "train_cpu_seconds": r.get("train_cpu_seconds", np.nan),
                    "runs": len(r.get("record", {}).get("restarts", {}).get("runs", [None])),
                    **{str(c): float(rel[i, j]) for j, c in enumerate(CASES)},
                    "validation_cost": costs[i],
                }
                for i, r in enumerate(runs)
            ],
            "curve": curve,
        }
    return out


def budget(a: dict) -> str:
    """An algorithm's budget per seed as the table prints it: ``4,000,000 (2 runs)`` when
    each seed is several runs (``restarts:``), ``15,000,000 (up to 3 runs)`` when a run
    is followed by another only if it failed (``restart_above:``)."""
    runs = a.get("restarts", 1)
    if runs == 1:
        return f"{a['budget']:,}"
    return f"{a['budget']:,} ({'up to ' if a.get('restart_above') else ''}{runs} runs)"


def markdown(summary: dict) -> str:
    """The summary as markdown: the IQM table (ISE / LQR and the validation cost), the
    goals, the stretch goal (:func:`stretch_lines`) and the per-seed table."""

    def cell(s, fmt=".3f"):
        return f"{s['iqm']:{fmt}} [{s['ci_low']:{fmt}}, {s['ci_high']:{fmt}}]"

    def cost(x, fmt=".4f"):
        return "-" if x is None else (cell(x, fmt) if isinstance(x, dict) else f"{x:{fmt}}")

    n_rand = len(summary["episodes"]["random"])
    ref_costs = summary.get("reference_validation_cost", {})
    lines = [
        f"ISE / ISE_LQR on `{summary['env_id']}` (+/-120 V, 1 ms, Kalman observer, "
        f"deterministic policy): IQM over seeds [95 % stratified-bootstrap CI]; thesis "
        f"cases seed 0, `random` = mean ISE over {n_rand} held-out episodes / LQR's. "
        f"*Validation cost*: the env's own objective, which the agents are trained on and "
        f"which charges for the voltage: the step cost on each of {OBJECTIVE_LOADS} "
        "validation loads divided by the passive beam's, averaged (passive 1, lower is "
        "better; `train.core.evaluate.validation_cost`).",
        "",
        "| algorithm | budget [env steps] | seeds | case 1 | case 2 | case 3 | random "
        "| validation cost | train wall / CPU time per seed [s] (IQM; max) |",
        "|---|---|---|---|---|---|---|---|---|",
    ]
    for name, a in summary["algorithms"].items():
        t, cpu = a["train_seconds"], a["train_cpu_seconds"]
        lines.append(
            f"| {name} ({a['algo']}) | {budget(a)} | {len(a['seeds'])} | "
            + " | ".join(cell(a["ise_rel_lqr"][str(c)]) for c in CASES)
            + f" | {cost(a.get('validation_cost'))}"
            + f" | {t['iqm']:.0f} / {cpu['iqm']:.0f}; {t['max']:.0f} / {cpu['max']:.0f} |"
        )
    for ref, vals in summary["references"].items():
        lines.append(
            f"| {ref} (reference) | - | - | "
            + " | ".join(f"{vals[str(c)]:.3f}" for c in CASES)
            + f" | {cost(ref_costs.get(ref))} | - |"
        )
    lines += [
        "",
        "Goals (issue 20; every seed, or the IQM over seeds, as named):",
        "",
        "| algorithm | " + " | ".join(next(iter(summary["algorithms"].values()))["goals"]) + " |",
        "|---" * (1 + len(next(iter(summary["algorithms"].values()))["goals"])) + "|",
    ]
    for name, a in summary["algorithms"].items():
        lines.append(
            f"| {name} | " + " | ".join("yes" if v else "no" for v in a["goals"].values()) + " |"
        )
    lines += stretch_lines(summary)
    lines += [
        "",
        "Per seed (ISE / LQR; validation cost):",
        "",
        "| algorithm | seed | case 1 | case 2 | case 3 | random | validation cost "
        "| train wall / CPU [s] |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for name, a in summary["algorithms"].items():
        for s in a["per_seed"]:
            vals = " | ".join(f"{s[str(c)]:.3f}" for c in CASES)
            seed = s["seed"]
            if a.get("restart_above"):  # how many runs this seed took
                seed = f"{seed} ({s['runs']} run{'s' if s['runs'] > 1 else ''})"
            lines.append(
                f"| {name} | {seed} | {vals} | {cost(s.get('validation_cost'), '.5f')} "
                f"| {s['train_seconds']:.0f} / {s['train_cpu_seconds']:.0f} |"
            )
    return "\n".join(lines) + "\n"


#: How :func:`headline` names the benchmark's algorithms (any other: its own name).
LABELS = {"vrs": "random search", "ppo": "SB3 PPO", "sac": "SB3 SAC"}
#: What :func:`headline` says a reference row is (any other: "designed").
KINDS = {"passive": "no control", "bound": "clairvoyant"}


def headline(summary: dict) -> str:
    r"""The README's headline table: per algorithm the IQM over the seeds of ISE / LQR per
    case and of the validation cost, how many seeds are below LQR and SMC on cases 1, 2
    and the random loads (:func:`seeds_beating_references`) and the training time per
    seed (IQM; the longest), then the reference rows; the full tables are
    :func:`markdown`'s."""
    refs, ref_costs = summary["references"], summary.get("reference_validation_cost", {})
    lines = [
        "| trained from scratch | case 1 | case 2 | case 3 | random | validation cost "
        "| seeds better than LQR and SMC (cases 1, 2, random) | training per seed [min] "
        "(IQM; longest) |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for name, a in summary["algorithms"].items():
        rel = [[s[str(c)] for c in CASES] for s in a["per_seed"]]
        wins = int(seeds_beating_references(rel, refs).sum())
        cost = a.get("validation_cost")
        t = a["train_seconds"]
        lines.append(
            f"| {LABELS.get(name, name)} (`{name}`) | "
            + " | ".join(f"{a['ise_rel_lqr'][str(c)]['iqm']:.3f}" for c in CASES)
            + f" | {'-' if cost is None else format(cost['iqm'], '.4f')}"
            + f" | {wins} of {len(a['per_seed'])} | {t['iqm'] / 60:.1f}; {t['max'] / 60:.1f} |"
        )
    for ref, vals in refs.items():
        cost = ref_costs.get(ref)
        lines.append(
            f"| {ref} ({KINDS.get(ref, 'designed')}) | "
            + " | ".join(f"{vals[str(c)]:.3f}" for c in CASES)
            + f" | {'-' if cost is None else format(cost, '.4f')} | - | - |"
        )
    n_rand = len(summary["episodes"]["random"])
    lines += [
        "",
        f"ISE / LQR on `{summary['env_id']}` (IQM over the seeds; lower is better; `random` "
        f"is {n_rand} held-out loads). Validation cost: the env's own reward, which charges "
        f"for the voltage, on {OBJECTIVE_LOADS} validation loads, divided by the passive "
        "beam's (passive 1, lower is better).",
    ]
    if summary.get("command"):  # the command, then what the run recorded of it
        command, _, note = summary["command"].partition(" (")
        notes = [note.removesuffix(")")] if note else []
        if summary.get("wall_seconds") is not None:
            notes.append(f"{summary['wall_seconds'] / 60:.0f} min in all")
        lines.append(f"Run: `{command}`" + (f" ({'; '.join(notes)})" if notes else "") + ".")
    return "\n".join(lines) + "\n"


#: The algorithm issue 20's stretch goal measures the deep-RL agents against.
STRETCH_BASE = "vrs"


def stretch_lines(summary: dict) -> list[str]:
    """Issue 20's stretch goal, read off the summary: for each algorithm but
    :data:`STRETCH_BASE`, the cases whose IQM of ISE / LQR is below the random search's
    (five decimals: the two can be that close) and, where both have it, the IQM of the
    validation cost against the search's. No lines without the search."""
    algos = summary["algorithms"]
    base = algos.get(STRETCH_BASE)
    if base is None or len(algos) < 2:
        return []
    out = [
        "",
        f"Stretch (issue 20): the IQM below {STRETCH_BASE}'s on every case "
        "(ISE / LQR, and the validation cost, lower is better):",
        "",
    ]
    for name, a in algos.items():
        if name == STRETCH_BASE:
            continue
        cells, wins = [], 0
        for c in CASES:
            x, y = a["ise_rel_lqr"][str(c)]["iqm"], base["ise_rel_lqr"][str(c)]["iqm"]
            wins += x < y
            cells.append(f"{'random' if c == 'random' else f'case {c}'} {_versus(x, y)}")
        line = f"- {name}: below on {wins} of {len(CASES)} cases ({'; '.join(cells)})"
        va, vb = a.get("validation_cost"), base.get("validation_cost")
        if va is not None and vb is not None:
            line += f"; validation cost {_versus(va['iqm'], vb['iqm'])}"
        out.append(line + ".")
    return out


def _versus(x: float, y: float) -> str:
    """``x < y`` or ``x >= y``, both to five decimals."""
    return f"{x:.5f} {'<' if x < y else '>='} {y:.5f}"


def plot_curves(summary: dict, path: Path) -> Path:
    """The figure of :func:`curves_figure`, written to ``path`` (atomically)."""
    import matplotlib.pyplot as plt

    fig = curves_figure(summary)
    try:
        return save_figure(fig, path, dpi=110)
    finally:
        plt.close(fig)


def ratio_log_axis(ax, subs: tuple[float, ...] | None = None) -> None:
    """A logarithmic y axis of ratios (ISE / LQR) labelled in plain numbers (0.9, 2, 3)
    on its major and minor ticks; ``subs``: the minor ticks' multiples of each decade
    (matplotlib's default if None)."""
    from matplotlib.ticker import FuncFormatter, LogLocator

    ax.set_yscale("log")
    if subs is not None:
        ax.yaxis.set_minor_locator(LogLocator(subs=subs))
    for axis_fmt in (ax.yaxis.set_major_formatter, ax.yaxis.set_minor_formatter):
        axis_fmt(FuncFormatter(lambda v, _: f"{v:g}"))


#: Colour and line style of each reference level in the learning-curve figure.
_REF_STYLES = {
    "lqr": ("k", "--"),
    "smc": ("tab:gray", ":"),
    "mpc": ("tab:purple", "-."),
    "bound": ("tab:brown", "--"),
}


def _draw_case(ax, summary: dict, key: str, zoom_from: float) -> list[float]:
    """One case's curves, 95 % bands, reported diamonds and reference levels on ``ax``; returns
    the values the zoom must hold (curve points from ``zoom_from`` env steps on, the reported
    CIs, LQR's and SMC's levels)."""
    near = []
    for name, a in summary["algorithms"].items():
        steps = np.array([p["steps"] for p in a["curve"]], dtype=float)
        mid = np.array([p[key]["iqm"] for p in a["curve"]])
        lo = np.array([p[key]["ci_low"] for p in a["curve"]])
        hi = np.array([p[key]["ci_high"] for p in a["curve"]])
        (line,) = ax.plot(steps, mid, marker=".", lw=1.2, label=name)
        ax.fill_between(steps, lo, hi, color=line.get_color(), alpha=0.2, lw=0)
        # the reported result: the final policy, or the selected checkpoint (select:)
        rep = a["ise_rel_lqr"][key]
        ax.plot(
            [a["budget"]],
            [rep["iqm"]],
            marker="D",
            ms=6,
            mfc="none",
            color=line.get_color(),
            ls="none",
        )
        near += [*mid[steps >= zoom_from], rep["ci_low"], rep["ci_high"]]
    for ref, (color, ls) in _REF_STYLES.items():
        if ref in summary["references"]:
            level = summary["references"][ref][key]
            ax.axhline(
                level, color=color, ls=ls, lw=1, label=ref.upper() if ref != "bound" else "bound"
            )
            if ref in ("lqr", "smc"):
                near.append(level)
    return near


def curves_figure(summary: dict):
    """IQM ISE / LQR vs env steps per case with 95 % bands and the reference levels; a
    hollow diamond at the budget marks the reported IQM, which is the selected checkpoint's
    when the config selects one (``select:``), not the last point of the curve. With
    ``restarts:`` the curve is the returned run's (steps of that run) and the budget, where
    the diamond sits, counts every run.

    The top row shows whole runs on a log ISE axis (the passive beam is ~4x LQR); the bottom
    row zooms on the end of training, from a tenth of the smallest budget on, where the
    algorithms differ by a few per cent of LQR."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.ticker import FuncFormatter, LogLocator

    fig, grid = plt.subplots(2, 4, figsize=(17, 7.6))
    algos = summary["algorithms"]
    zoom_from = 0.1 * min(a["budget"] for a in algos.values())
    for row, axes in enumerate(grid):
        for ax, case in zip(axes, CASES, strict=True):
            key = str(case)
            near = _draw_case(ax, summary, key, zoom_from)
            ax.grid(alpha=0.3, which="both")
            if row == 0:
                ax.set_xscale("symlog", linthresh=1e4)  # step 0 (the initial actor) included
                ax.set_xlim(left=0)
                ratio_log_axis(ax, subs=(2, 3, 5))
                ax.set_title(f"load case {case}" if case != "random" else "held-out random loads")
            else:
                ax.set_xscale("log")
                ax.set_xlim(zoom_from, 1.3 * max(a["budget"] for a in algos.values()))
                ax.xaxis.set_minor_locator(LogLocator(subs=(2, 5)))
                for axis_fmt in (ax.xaxis.set_major_formatter, ax.xaxis.set_minor_formatter):
                    axis_fmt(FuncFormatter(lambda v, _: f"{v / 1e6:g}M"))
                lo_y = min(near)
                hi_y = min(max(near), max(1.1, 1.1 * lo_y))  # > lo_y even when all exceed 1.1
                pad = 0.08 * (hi_y - lo_y)
                ax.set_ylim(lo_y - pad, hi_y + pad)
                bound = summary["references"].get("bound", {}).get(key)
                if bound is not None and bound < lo_y - pad:
                    ax.set_title(f"zoom (bound {bound:.3f}, below)", fontsize=9)
                else:
                    ax.set_title("zoom on the end of training", fontsize=9)
                ax.set_xlabel("env steps")
    grid[0][0].set_ylabel("ISE / ISE$_{LQR}$ (IQM over seeds, 95 % CI)")
    grid[1][0].set_ylabel("ISE / ISE$_{LQR}$, zoomed")
    grid[0][0].plot(
        [],
        [],
        marker="D",
        mfc="none",
        color="k",
        ls="none",
        label="reported (final or selected checkpoint)",
    )
    grid[0][0].legend(fontsize=7)
    fig.suptitle(f"Teacher-free RL on {summary['env_id']}", fontsize=10)
    fig.tight_layout()
    return fig


#: The generated blocks a Markdown page may hold (``--write``), by kind: the full tables
#: (:func:`markdown`, the training page) and the headline (:func:`headline`, the README).
BLOCKS = {"tables": markdown, "headline": headline}

#: The markers around a generated block (``kind`` one of :data:`BLOCKS`).
MARK_BEGIN = "<!-- benchmark-{kind}:begin (python -m train.core.report {src} --write {dst}) -->"
MARK_END = "<!-- benchmark-{kind}:end -->"


def replace_block(text: str, tables: str, src: str, dst: str, kind: str = "tables") -> str:
    """``text`` with the part between the markers of ``kind`` (:data:`MARK_BEGIN`,
    :data:`MARK_END`) replaced by ``tables``; ``ValueError`` if the markers are missing."""
    begin, end = MARK_BEGIN.format(kind=kind, src=src, dst=dst), MARK_END.format(kind=kind)
    if text.count(begin) != 1 or text.count(end) != 1 or text.index(begin) > text.index(end):
        raise ValueError(f"{dst}: expected one {begin!r} ... {end!r} block")
    head, rest = text.split(begin)
    _, tail = rest.split(end)
    return f"{head}{begin}\n\n{tables}\n{end}{tail}"


def render_blocks(summary: dict) -> dict[str, str]:
    """Every generated block (:data:`BLOCKS`) of ``summary``, by kind."""
    return {kind: render(summary) for kind, render in BLOCKS.items()}


def write_blocks(text: str, blocks: dict[str, str], src: str, dst: str) -> str:
    """``text`` with every generated block it holds (each once) replaced by its rendered
    ``blocks`` (:func:`render_blocks`); ``ValueError`` if it holds none."""
    kinds = [k for k in blocks if MARK_END.format(kind=k) in text]
    if not kinds:
        begins = " or ".join(repr(MARK_BEGIN.format(kind=k, src=src, dst=dst)) for k in blocks)
        raise ValueError(f"{dst}: expected one {begins} block")
    for kind in kinds:
        text = replace_block(text, blocks[kind], src, dst, kind)
    return text


def main(argv: list[str] | None = None) -> int:
    """``python -m train.core.report RESULTS.json [--write PAGE.md ...] [--plot FIG.png]``:
    the benchmark's tables (:func:`markdown`) from a committed results file, printed, or
    written into the generated blocks of each page (:func:`write_blocks`: the tables, the
    headline; atomically, every page checked before any is written); ``--plot`` also draws
    its learning curves (:func:`plot_curves`)."""
    import argparse

    p = argparse.ArgumentParser(
        prog=prog("python -m train.core.report"),
        description=plain(main.__doc__),
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument("results", type=Path, help="a results.json of python -m train.benchmark")
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
    import sys

    sys.exit(run_main(main))
