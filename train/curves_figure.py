"""The learning-curve figure of ``python -m train.compare --plots``: ISE / LQR on the thesis
cases against training env steps for each agent (:func:`learning_curves_figure`,
:func:`plot_learning_curves`), and :func:`sparse_ratio_labels`, the labels of a ratio log
axis that the figures share. Re-exported by :mod:`train.compare` and
:mod:`train.figures`."""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

from acld_gym.util.atomic import save_figure

from .agent import AgentFileError
from .agent_files import read_curve
from .core.evaluate import lqr_ise
from .core.report_plots import ratio_log_axis

__all__ = ["learning_curves_figure", "plot_learning_curves", "sparse_ratio_labels"]


def sparse_ratio_labels(ax) -> None:
    """Label only the minor ticks 2, 3, 5, 8 of each decade of ``ax``'s log y axis (0.8,
    2, 3, 5, ...): 0.9 and 1 lie 0.05 decade apart and their labels overlap."""
    from matplotlib.ticker import FuncFormatter  # matplotlib is slow to import (plots only)

    def label(v: float, _pos) -> str:
        lead = round(v / 10 ** np.floor(np.log10(v) + 1e-9), 6)
        return f"{v:g}" if lead in (2, 3, 5, 8) else ""

    ax.yaxis.set_minor_formatter(FuncFormatter(label))


def learning_curves_figure(agents: dict):
    """ISE / LQR on the three thesis cases against training env steps for each agent (from
    its ``learning_curve.csv``), both axes logarithmic: the curves span four decades of
    steps (SAC's 2M to the random search's 100M) and fall from the passive level (~3.7x)
    to within a few per cent of one another. The untrained point (step 0) has no place on
    a log axis and is left out. ``None`` if no agent has a curve."""
    # matplotlib is slow to import (and sets its backend): only a figure needs it
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    curves = {}
    for name, agent in agents.items():  # read as the agent was: no link, rows checked
        try:
            rows = None if agent.directory is None else read_curve(agent.directory)
        except AgentFileError as exc:  # one line; the comparison stands
            print(f"{name}: no learning curve ({exc})", file=sys.stderr)
            rows = None
        if rows:
            curves[name] = rows
    if not curves:
        return None
    lqr = lqr_ise(episodes={c: (0,) for c in (1, 2, 3)})
    fig, axes = plt.subplots(1, 3, figsize=(12, 3.6))
    for ax, case in zip(axes, (1, 2, 3), strict=True):
        for name, rows in curves.items():
            sub = [r for r in rows if r["case"] == str(case) and int(r["timesteps"]) > 0]
            ax.plot(
                [int(r["timesteps"]) for r in sub],
                [float(r["ise"]) / lqr[case] for r in sub],
                marker=".",
                lw=1,
                label=name,
            )
        ax.axhline(1.0, color="k", ls="--", lw=1, label="LQR")
        ax.set_xscale("log")
        ratio_log_axis(ax)
        sparse_ratio_labels(ax)  # 0.9 beside 1 overlapped
        ax.set_title(f"load case {case}")
        ax.set_xlabel("training env steps")
        ax.grid(alpha=0.3, which="both")
    axes[0].set_ylabel("ISE / LQR")
    axes[0].legend(fontsize=8)
    fig.tight_layout()
    return fig


def plot_learning_curves(agents: dict, directory: Path) -> Path | None:
    """Write :func:`learning_curves_figure` to ``directory/learning_curves.png``; ``None``
    (and no file) if no agent has a curve."""
    import matplotlib.pyplot as plt  # slow to import: only a figure needs it

    fig = learning_curves_figure(agents)
    if fig is None:
        return None
    directory.mkdir(parents=True, exist_ok=True)
    out = directory / "learning_curves.png"
    save_figure(fig, out, dpi=110)
    plt.close(fig)
    return out
