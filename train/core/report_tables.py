"""The benchmark's tables as Markdown (:func:`markdown`), the README's headline
(:func:`headline`) and the comparison lines against the random search
(:func:`stretch_lines`), from a :func:`train.core.report_stats.summarize` summary."""

from __future__ import annotations

from .evaluate import CASES, OBJECTIVE_LOADS
from .report_stats import GOALS, seeds_beating_references

__all__ = ["budget", "markdown", "headline", "stretch_lines", "LABELS", "KINDS", "STRETCH_BASE"]


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
    # the checks of this version that the record holds (an older record's other goals: not shown)
    checks = [k for k in next(iter(summary["algorithms"].values()))["goals"] if k in GOALS]
    lines += [
        "",
        "Checks (on every seed, relative to the level's thesis LQR and SMC):",
        "",
        "| algorithm | " + " | ".join(checks) + " |",
        "|---" * (1 + len(checks)) + "|",
    ]
    for name, a in summary["algorithms"].items():
        lines.append(
            f"| {name} | " + " | ".join("yes" if a["goals"][k] else "no" for k in checks) + " |"
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


#: The algorithm the deep-RL agents are compared with, case by case.
STRETCH_BASE = "vrs"


def stretch_lines(summary: dict) -> list[str]:
    """The comparison with the random search, read off the summary: for each algorithm but
    :data:`STRETCH_BASE`, the cases whose IQM of ISE / LQR is below the random search's
    (five decimals: the two can be that close) and, where both have it, the IQM of the
    validation cost against the search's. No lines without the search."""
    algos = summary["algorithms"]
    base = algos.get(STRETCH_BASE)
    if base is None or len(algos) < 2:
        return []
    out = [
        "",
        f"Against {STRETCH_BASE}: is the IQM below {STRETCH_BASE}'s on every case "
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
