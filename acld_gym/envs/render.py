"""Rendering of :class:`acld_gym.envs.beam_env.ACLDBeamEnv`: deflected beam, tip history,
voltage."""

from __future__ import annotations

import numpy as np

__all__ = ["render_frame", "show", "close", "FigureOwner"]


def _beam_shape(env) -> tuple[np.ndarray, np.ndarray]:
    """Node positions [m] and transverse displacements [m] of the plant's mesh."""
    truth = env.nom.truth
    return truth.node_x, truth.node_w @ np.asarray(env.x)[: truth.n_coordinates]


def render_frame(env, fig=None):
    """Draw the current state; returns ``(rgb array (H, W, 3) uint8, figure)``."""
    import matplotlib  # (matplotlib here and below: ~0.3 s to import, only rendering needs it)

    if fig is None:
        if env.render_mode != "human":
            matplotlib.use("Agg", force=False)
        import matplotlib.pyplot as plt  # (rendering only)

        fig = plt.figure(figsize=(6.4, 4.8), dpi=80)
    fig.clf()
    ax0, ax1, ax2 = fig.subplots(3, 1, gridspec_kw={"height_ratios": [2, 1, 1]})
    p = env.nom.truth.params
    xs, w = _beam_shape(env)
    ax0.plot(
        xs * 1e3,
        w * 1e3,
        "-",
        marker="o" if xs.size < 40 else None,
        ms=3,
        color="0.3",
        label="beam",
    )
    ax0.axvspan(
        p.patch_start * 1e3,
        (p.patch_start + p.patch_length) * 1e3,
        color="C1",
        alpha=0.3,
        label="ACLD patch",
    )
    lim = max(1.0, 1.2 * float(np.max(np.abs(w))) * 1e3)
    ax0.set_ylim(-lim, lim)
    ax0.set_xlim(0, p.length * 1e3)
    ax0.set_xlabel("x [mm]")
    ax0.set_ylabel("w [mm]")
    ax0.set_title(
        f"t = {env.k * env.dt:.3f} s   V = {env.v:+.0f} V   load = "
        f"{float(env.load(env.k * env.dt)):+.2f} N",
        fontsize=9,
    )
    ax0.legend(loc="upper left", fontsize=7)
    if env.history:
        t, y, v = (np.array(c) for c in zip(*env.history, strict=True))
        ax1.plot(t, y * 1e3, lw=0.8)
        ax2.plot(t, v, lw=0.8, color="C3")
    ax1.set_ylabel("tip [mm]")
    ax2.set_ylabel("V [V]")
    ax2.set_ylim(-1.1 * env.v_max, 1.1 * env.v_max)
    ax2.set_xlabel("time [s]")
    fig.tight_layout()
    fig.canvas.draw()
    frame = np.asarray(fig.canvas.buffer_rgba())[..., :3].copy()
    return frame, fig


def show(fig) -> None:
    """Display the figure for ``render_mode="human"`` (no-op without a display)."""
    import matplotlib.pyplot as plt  # (rendering only)

    plt.pause(1e-3) if plt.get_backend().lower() != "agg" else None


def close(fig) -> None:
    import matplotlib.pyplot as plt  # (rendering only)

    plt.close(fig)


class FigureOwner:
    """Mixin for envs that keep a matplotlib figure: closes it once and leaves it
    out of pickles (figures do not pickle; a new one is made on the next render)."""

    _fig = None

    def _close_figure(self) -> None:
        if self._fig is not None:
            close(self._fig)
            self._fig = None

    def __getstate__(self):
        state = self.__dict__.copy()
        state["_fig"] = None
        return state
