"""The benchmark's learning-curve figure (:func:`curves_figure`, :func:`plot_curves`) and
:func:`ratio_log_axis`, a log axis of ratios labelled in plain numbers."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from acld_gym.util.atomic import save_figure

from .evaluate import CASES

__all__ = ["ratio_log_axis", "curves_figure", "plot_curves"]


def plot_curves(summary: dict, path: Path) -> Path:
    """The figure of :func:`curves_figure`, written to ``path`` (atomically)."""
    import matplotlib.pyplot as plt  # slow to import: only a figure needs it

    fig = curves_figure(summary)
    try:
        return save_figure(fig, path, dpi=110)
    finally:
        plt.close(fig)


def ratio_log_axis(ax, subs: tuple[float, ...] | None = None) -> None:
    """A logarithmic y axis of ratios (ISE / LQR) labelled in plain numbers (0.9, 2, 3)
    on its major and minor ticks; ``subs``: the minor ticks' multiples of each decade
    (matplotlib's default if None)."""
    from matplotlib.ticker import FuncFormatter, LogLocator  # slow to import: plots only

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
    # matplotlib is slow to import (and sets its backend): only a figure needs it
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
