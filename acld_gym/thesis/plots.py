"""Figures of the reproduction (thesis Figs. 5, 9-24 and 20). Each function writes its
figure to ``path`` atomically, or with ``out`` (a dict) puts its bytes in ``out[path]``
for :func:`acld_gym.util.atomic.write_files` (a command's outputs all or none)."""

from __future__ import annotations

from pathlib import Path

import matplotlib

from acld_gym.util.atomic import save_figure

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from acld_gym.design.pipeline import Design  # noqa: E402
from acld_gym.design.reduction import frequency_response  # noqa: E402

__all__ = ["plot_response", "plot_hankel", "plot_frequency_response"]


def plot_response(path: Path, t, y, v, title: str, load=None, out: dict | None = None) -> None:
    """Tip deflection [mm] and voltage [V] vs time, as in thesis Figs. 9-24."""
    fig, ax = plt.subplots(2 if load is None else 3, 1, sharex=True, figsize=(7, 5.5))
    ax[0].plot(t, np.asarray(y) * 1e3, lw=0.9)
    ax[0].set_ylabel("tip deflection [mm]")
    ax[1].plot(t, v, lw=0.9, color="C3")
    ax[1].set_ylabel("voltage [V]")
    if load is not None:
        ax[2].plot(t, load, lw=0.9, color="C2")
        ax[2].set_ylabel("tip load [N]")
    ax[-1].set_xlabel("time [s]")
    ax[0].set_title(title)
    for a in ax:
        a.grid(alpha=0.3)
    fig.tight_layout()
    save_figure(fig, path, out, dpi=110)
    plt.close(fig)


def plot_hankel(path: Path, d: Design, out: dict | None = None) -> None:
    """Hankel singular values of the full model (thesis Fig. 5)."""
    hsv = d.reduced.hsv
    k = d.reduced.order
    fig, ax = plt.subplots(figsize=(7, 4))
    idx = np.arange(1, hsv.size + 1)
    ax.semilogy(idx[:k], hsv[:k], "o", color="C0", label=f"kept ({k})")
    ax.semilogy(idx[k:], np.maximum(hsv[k:], 1e-20), "o", mfc="none", color="C7", label="discarded")
    ax.set_xlabel("state")
    ax.set_ylabel("Hankel singular value")
    ax.set_title("Hankel singular values, voltage -> tip deflection (thesis Fig. 5)")
    ax.grid(alpha=0.3, which="both")
    ax.legend()
    fig.tight_layout()
    save_figure(fig, path, out, dpi=110)
    plt.close(fig)


def plot_frequency_response(path: Path, d: Design, out: dict | None = None) -> None:
    """Voltage and tip-load to tip deflection, full vs reduced (thesis Fig. 20)."""
    A, B, E, Cy = d.plant
    r = d.reduced
    w = np.logspace(1, 5.5, 1500)
    fig, ax = plt.subplots(2, 1, sharex=True, figsize=(7, 6))
    channels = ((B, r.B, "voltage [m/V]"), (E, r.E, "tip load [m/N]"))
    for a, (bf, br, lab) in zip(ax, channels, strict=True):
        a.loglog(w, np.abs(frequency_response(A, bf, Cy, w)), label="full (38 states)")
        a.loglog(
            w,
            np.abs(frequency_response(r.A, br, r.C, w)),
            "--",
            label=f"reduced ({r.order} states)",
        )
        a.set_ylabel(f"|y / {lab.split()[0]}| {lab.split()[-1]}")
        a.grid(alpha=0.3, which="both")
        a.legend()
    ax[-1].set_xlabel("frequency [rad/s]")
    ax[0].set_title("Frequency response to the tip deflection (thesis Fig. 20)")
    fig.tight_layout()
    save_figure(fig, path, out, dpi=110)
    plt.close(fig)
