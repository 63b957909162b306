"""The documentation's pictures: the hero figure and the beam's animation.

``python -m train.figures hero PATH`` writes the README's and docs home's figure: the four
policies that matter on ``ACLDBeam-v1`` -- the passive beam, the thesis's LQR, the
engineer's design (``mpc_rig``; ``lqg`` without osqp) and the shipped PPO agent -- with the
clairvoyant bound as the reference: (a) the tip's envelope on load case 1 on a log axis,
where the policies part after the first 0.2 s, (b) each one's ISE relative to the thesis
LQR on the thesis cases and the held-out random loads.

``python -m train.figures animation PATH`` writes the environment page's animation:
``render()`` frames (``render_mode="rgb_array"``: the beam's shape, the tip and the
voltage) of an episode, as an animated GIF or WebP (pillow, which matplotlib brings).

Both are written atomically (:mod:`acld_gym.util.atomic`). :func:`sparse_ratio_labels`
labels a ratio log axis's minor ticks without overlap (the learning curves).
"""

from __future__ import annotations

import argparse
import io
import sys
from pathlib import Path

import gymnasium as gym
import numpy as np
from numpy.lib.stride_tricks import sliding_window_view

from acld_gym.envs.beam_env import ACLDBeamEnv
from acld_gym.envs.presets import check_env_id
from acld_gym.util.atomic import check_writable, save_figure, write_atomic
from acld_gym.util.text import plain, prog
from acld_gym.util.validate import arg_type, run_main
from baselines.evaluate import episode_rows
from baselines.evaluation.rollout import check_compatible
from baselines.marks import level_references

from .agent_dirs import AGENTS_DIR, load_agents
from .core.evaluate import HELDOUT_SEEDS
from .curves_figure import sparse_ratio_labels

__all__ = [
    "HERO_CASES",
    "hero_policies",
    "hero_data",
    "hero_figure",
    "beam_frames",
    "save_animation",
    "sparse_ratio_labels",
    "main",
]

#: The rows of the hero's right panel: the thesis cases and the held-out random loads.
HERO_CASES = (1, 2, 3, "random")
#: Colour, label of each policy of the hero (the bound is drawn in black).
_STYLE = {
    "passive": ("0.55", "passive beam"),
    "lqr": ("C0", "thesis LQR"),
    "mpc_rig": ("C1", "engineer's MPC (mpc_rig)"),
    "lqg": ("C1", "engineer's LQG (lqg)"),
    "ppo": ("C2", "PPO agent (ppo)"),
    "bound": ("k", "clairvoyant bound"),
}


def hero_policies(agents_dir: str | Path | None = None) -> dict:
    """Name -> policy: passive, the thesis's LQR and the engineer's design of
    ``ACLDBeam-v1`` (:func:`baselines.marks.level_references`), and the shipped ``ppo``
    agent (``agents_dir``, default :data:`train.agent_dirs.AGENTS_DIR`)."""
    refs = level_references(ACLDBeamEnv())
    engineer = "mpc_rig" if "mpc_rig" in refs else "lqg"
    out = {name: refs[name] for name in ("passive", "lqr", engineer)}
    return out | load_agents(AGENTS_DIR if agents_dir is None else agents_dir, ["ppo"])


def hero_data(policies: dict, random_episodes: int = 20, env_kwargs: dict | None = None):
    """``(case-1 episodes by name, {case: {name: ISE / thesis LQR}})`` for ``policies``
    and the bound: episode seed 0 of each thesis case (as ``train.compare``), the mean ISE
    over the first ``random_episodes`` held-out random loads."""
    episodes: dict = {}
    ratios = {}
    for case in HERO_CASES:
        seeds = (0,) if case != "random" else HELDOUT_SEEDS[:random_episodes]
        if not seeds:
            continue
        rows = [r for s in seeds for r in episode_rows(policies, case, s, env_kwargs, episodes)]
        ise = {n: np.mean([r.ise for r in rows if r.policy == n]) for n in [*policies, "bound"]}
        ratios[case] = {n: float(v / ise["lqr"]) for n, v in ise.items()}
    return {n: ep for (c, n), ep in episodes.items() if c == 1}, ratios


def _envelope(y: np.ndarray, window: int) -> np.ndarray:
    """The running maximum of ``|y|`` over the last ``window`` samples."""
    a = np.abs(np.concatenate([np.zeros(window - 1), np.asarray(y)]))
    return sliding_window_view(a, window).max(axis=1)


def hero_figure(episodes: dict, ratios: dict):
    """The hero figure of :func:`hero_data`'s output (a matplotlib figure)."""
    # matplotlib is slow to import (and sets its backend): only a figure needs it
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (ax, bx) = plt.subplots(1, 2, figsize=(10, 3.9), gridspec_kw={"width_ratios": [1.45, 1]})
    for name, ep in episodes.items():
        colour, label = _STYLE[name]
        dt = float(ep.t[1] - ep.t[0]) if ep.t.size > 1 else 1e-3
        env = np.maximum(_envelope(ep.y * 1e3, max(1, round(0.035 / dt))), 1e-5)
        style = {"ls": "--", "lw": 1.4} if name == "bound" else {"lw": 1.8}
        ax.semilogy(ep.t, env, color=colour, label=label, **style)
    ax.set_xlabel("time [s]")
    ax.set_ylabel("tip deflection, envelope [mm]")
    ax.set_title("(a) Load case 1: how fast the beam comes to rest", fontsize=10, loc="left")
    ax.set_ylim(1e-3, 1.5)
    ax.grid(alpha=0.3, which="both")
    ax.legend(fontsize=8.5, loc="lower left", framealpha=0.95)

    rows = list(ratios)
    names = [n for n in next(iter(ratios.values())) if n not in ("passive", "bound")]
    for i, case in enumerate(rows):
        r = ratios[case]
        bx.plot([r["bound"]] * 2, [i - 0.35, i + 0.35], color="k", ls="--", lw=1.4)
        for k, name in enumerate(names):
            bx.plot(r[name], i + (k - 1) * 0.14, "o", ms=7, color=_STYLE[name][0])
        bx.annotate(
            f"passive {r['passive']:.2f} \u2192",
            (1.0, i),
            xycoords=("axes fraction", "data"),
            xytext=(-4, 0),
            textcoords="offset points",
            ha="right",
            va="center",
            fontsize=8,
            color=_STYLE["passive"][0],
        )
    bx.set_yticks(
        range(len(rows)), [f"case {c}" if c != "random" else "random loads" for c in rows]
    )
    bx.set_ylim(len(rows) - 0.5, -0.5)
    bx.set_xlim(0.6, 1.22)
    bx.axvline(1.0, color=_STYLE["lqr"][0], lw=0.8, alpha=0.6)
    bx.set_xlabel("ISE / thesis LQR (lower is better)")
    bx.set_title("(b) ISE / thesis LQR (dashes: the bound)", fontsize=10, loc="left")
    bx.grid(alpha=0.3, axis="x")
    fig.suptitle(
        "ACLDBeam-v1 (+/-120 V, 1 ms, measured tip): four policies and the bound", fontsize=11
    )
    fig.tight_layout()
    return fig


def beam_frames(policy, env_id: str = "ACLDBeam-v1", case=1, n_frames: int = 150, stride: int = 4):
    """``n_frames`` ``render()`` frames of one episode of ``policy`` on load ``case``, one
    every ``stride`` steps (episode seed 0)."""
    check_env_id(env_id, "env_id")
    env = gym.make(env_id, load_case=case, render_mode="rgb_array")
    try:
        check_compatible(policy, env.unwrapped)
        obs, _ = env.reset(seed=0)
        state, frames = None, [env.render()]
        start = getattr(policy, "start_episode", None)
        if start is not None:
            start(env.unwrapped)
        for k in range(1, n_frames * stride):
            action, state = policy.predict(obs, state=state, deterministic=True)
            obs, _, terminated, truncated, _ = env.step(action)
            if k % stride == 0:
                frames.append(env.render())
            if terminated or truncated or len(frames) == n_frames:
                break
        return frames
    finally:
        env.close()


def save_animation(frames: list, path: str | Path, fps: float = 10.0, scale: float = 1.0) -> Path:
    """``frames`` (H x W x 3 uint8) as an animated GIF or WebP (by ``path``'s suffix),
    looping, written atomically; ``scale`` resizes each frame."""
    from PIL import Image  # pillow (matplotlib's dependency): only an animation needs it

    path = Path(path)
    fmt = {".gif": "GIF", ".webp": "WEBP"}.get(path.suffix.lower())
    if fmt is None:
        raise ValueError(f"{path}: expected a .gif or .webp file name")
    images = [Image.fromarray(np.asarray(f)) for f in frames]
    if scale != 1.0:
        size = tuple(round(s * scale) for s in images[0].size)
        images = [im.resize(size, Image.LANCZOS) for im in images]
    if fmt == "GIF":  # one palette (the last frame has every colour), no dithering noise
        none = Image.Dither.NONE
        pal = images[-1].quantize(colors=32, method=Image.Quantize.MEDIANCUT, dither=none)
        images = [im.quantize(palette=pal, dither=none) for im in images]
    buffer = io.BytesIO()
    extra = {"optimize": True} if fmt == "GIF" else {"quality": 80, "method": 6}
    images[0].save(
        buffer,
        format=fmt,
        save_all=True,
        append_images=images[1:],
        duration=round(1000 / fps),
        loop=0,
        **extra,
    )
    return write_atomic(path, lambda fh: fh.write(buffer.getvalue()))


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(
        prog=prog("python -m train.figures"),
        description=plain(__doc__),
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    sub = p.add_subparsers(dest="what", required=True)
    h = sub.add_parser("hero", help="the README's figure (PNG or SVG)")
    h.add_argument("path", help="the figure file to write")
    h.add_argument(
        "--random-episodes",
        type=arg_type(int, 0, 20),
        default=20,
        help="held-out random-load episodes in the ISE panel (default 20; 0: none)",
    )
    h.add_argument("--agents", metavar="DIR", default=None, help="the agents' folder (ppo)")
    h.add_argument(
        "--episode-length",
        type=arg_type(float, 0.01, 1.0),
        default=1.0,
        help="seconds per episode (default 1; shorter only to try the command)",
    )
    a = sub.add_parser("animation", help="the environment page's animation (GIF or WebP)")
    a.add_argument("path", help="the .gif or .webp file to write")
    a.add_argument("--policy", choices=("lqr", "mpc_rig", "lqg"), default="lqr")
    a.add_argument("--frames", type=arg_type(int, 2, 1000), default=150)
    a.add_argument("--stride", type=arg_type(int, 1, 100), default=4, help="env steps per frame")
    a.add_argument("--fps", type=arg_type(float, 1, 60), default=10.0)
    a.add_argument("--scale", type=arg_type(float, 0.2, 2.0), default=1.0)
    args = p.parse_args(argv)
    try:
        check_writable(args.path, "path")
        suffixes = (".gif", ".webp") if args.what == "animation" else (".png", ".svg")
        if Path(args.path).suffix.lower() not in suffixes:
            raise ValueError(f"path: expected a {' or '.join(suffixes)} file, got {args.path!r}")
    except ValueError as exc:
        p.error(str(exc))
    if args.what == "hero":
        import matplotlib.pyplot as plt  # slow to import: only the hero needs it

        kwargs = {} if args.episode_length == 1.0 else {"episode_length": args.episode_length}
        episodes, ratios = hero_data(
            hero_policies(args.agents), args.random_episodes, kwargs or None
        )
        fig = hero_figure(episodes, ratios)
        save_figure(fig, args.path, dpi=110)
        plt.close(fig)
        for case, r in ratios.items():
            print(f"case {case}: " + ", ".join(f"{n} {v:.3f}" for n, v in r.items()))
    else:
        policy = level_references(ACLDBeamEnv())[args.policy]
        frames = beam_frames(policy, n_frames=args.frames, stride=args.stride)
        save_animation(frames, args.path, fps=args.fps, scale=args.scale)
    print(f"wrote {args.path}")
    return 0


if __name__ == "__main__":
    sys.exit(run_main(main))
