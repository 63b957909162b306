"""Checks at the envs' edges: the actions (every check raises ``ValueError`` naming the
argument and what was expected, before any state changes) and the render mode. The
configuration is validated once, in :mod:`acld_gym.envs.config` (the registration spec and
settings that conflict: :mod:`acld_gym.envs.conflicts`)."""

from __future__ import annotations

import numpy as np

__all__ = ["check_actions", "check_render_mode"]


def check_actions(action, n: int, v_max: float, vector: bool = False):
    """``n`` requested voltages as float64 and their clipped values.

    A single env takes real numbers of shape (1,); a vector env shape (n,) or (n, 1).
    Anything else -- strings, bytes, bools, complex numbers, other shapes, NaN or
    inf -- raises ``ValueError`` before any state changes.
    """
    a = np.asarray(action)
    if a.dtype.kind not in "iuf":
        raise ValueError(f"action must be real numbers (volts), got {action!r} (dtype {a.dtype})")
    shapes = ((n,), (n, 1)) if vector else ((1,),)
    if a.shape not in shapes:
        want = " or ".join(str(s) for s in shapes)
        raise ValueError(f"action must have shape {want} (voltages [V]), got shape {a.shape}")
    a = a.astype(np.float64).reshape(-1)
    if not np.isfinite(a).all():
        raise ValueError(f"action must be finite, got {a[~np.isfinite(a)][0]!r}")
    return a, np.clip(a, -v_max, v_max)


def check_render_mode(render_mode, render_modes) -> None:
    """``ValueError`` unless ``render_mode`` is None or one of ``render_modes``."""
    if render_mode is not None and render_mode not in render_modes:
        raise ValueError(
            f"render_mode must be one of {list(render_modes)} or None, got {render_mode!r}"
        )
