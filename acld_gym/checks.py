"""Validation of user input, in one place: every check raises ``ValueError`` naming the
argument and what was expected, before any state changes.

The numeric ranges of the environment's arguments (:data:`ENV_RANGES`) are physical or
practical limits, stated here once and printed in the env's docstring and the README:
beyond them a result would be meaningless (a tip sensor with 1 m of noise), overflow
(a deflection scale of 1e-300 m makes the reward infinite) or exhaust memory (the
episode's loads and noise are tabulated at reset).
"""

from __future__ import annotations

import math
import numbers

import numpy as np

__all__ = ["check_real", "check_int", "check_choice", "check_seed", "check_actions", "arg_type",
           "check_episode_size", "closed_pipe_is_fine", "run_main", "ENV_RANGES",
           "MAX_EPISODE_STEPS", "MAX_TABLE_STEPS"]

#: Accepted ranges of the env's numeric arguments: (low, high, unit, why).
ENV_RANGES: dict[str, tuple[float, float, str, str]] = {
    "dt": (1e-4, 1e-2, "s", "control period of a piezo rig; the plant is built for 2 pi/dt"),
    "episode_length": (1e-4, 1e3, "s", "and at most MAX_EPISODE_STEPS steps"),
    "sensor_noise": (0.0, 1e-3, "m", "std of the tip sensor; 0 for none"),
    "y_ref": (1e-9, 1.0, "m", "deflection scale of the reward"),
    "lam": (0.0, 1e6, "-", "voltage weight of the reward"),
    "deflection_limit": (1e-6, 1.0, "m", "termination limit"),
}
#: Largest episode of a single env, in steps: its loads and sensor noise are tabulated at
#: reset, about 350 bytes per step (350 MB at the limit).
MAX_EPISODE_STEPS = 1_000_000
#: Largest number of tabulated env-steps of a vector env (num_envs x steps per episode),
#: about 170 bytes each (680 MB at the limit).
MAX_TABLE_STEPS = 4_000_000


def check_real(name: str, value, low: float | None = None, high: float | None = None, *,
               low_open: bool = False, unit: str = "") -> float:
    """``float(value)`` if ``value`` is a finite real number (any numpy real, not a bool or
    a string) in [low, high] (``low_open``: (low, high]); else ``ValueError`` naming it."""
    u = f" {unit}" if unit and unit != "-" else ""
    ok = isinstance(value, numbers.Real) and not isinstance(value, (bool, np.bool_))
    v = float(value) if ok else math.nan
    if not ok or not math.isfinite(v):
        raise ValueError(f"{name} must be a finite real number{u}, got {value!r}")
    if low is not None and (v < low or (low_open and v == low)):
        rel = ">" if low_open else ">="
        raise ValueError(f"{name} must be {rel} {low:g}{u}, got {value!r}")
    if high is not None and v > high:
        raise ValueError(f"{name} must be <= {high:g}{u}, got {value!r}")
    return v


def check_int(name: str, value, low: int | None = None, high: int | None = None) -> int:
    """``int(value)`` if ``value`` is an integer (Python or numpy, not a bool) in
    [low, high]; else ``ValueError`` naming it."""
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, numbers.Integral):
        raise ValueError(f"{name} must be an integer, got {value!r}")
    v = int(value)
    if (low is not None and v < low) or (high is not None and v > high):
        lo = "-inf" if low is None else low
        hi = "inf" if high is None else high
        raise ValueError(f"{name} must be an integer in [{lo}, {hi}], got {value!r}")
    return v


def check_choice(name: str, value, choices) -> None:
    """``ValueError`` unless ``value`` is one of ``choices`` (bools are never a choice)."""
    if isinstance(value, (bool, np.bool_)) or value not in choices:
        raise ValueError(f"{name} must be one of {list(choices)}, got {value!r}")


def check_seed(value) -> int | None:
    """A seed: None or an integer in [0, 2**63) (numpy's generators take any non-negative
    integer; this bound keeps it a 64-bit value that other tools accept)."""
    if value is None:
        return None
    return check_int("seed", value, 0, 2**63 - 1)


def check_episode_size(episode_length: float, dt: float, num_envs: int = 1) -> int:
    """The episode's step count, ``round(episode_length / dt)``; ``ValueError`` beyond
    :data:`MAX_EPISODE_STEPS` (or :data:`MAX_TABLE_STEPS` over ``num_envs``)."""
    steps = int(round(episode_length / dt))
    if steps < 1:
        raise ValueError(f"episode_length must be at least dt, got {episode_length!r}")
    if steps > MAX_EPISODE_STEPS:
        raise ValueError(f"episode_length / dt = {steps} steps exceeds {MAX_EPISODE_STEPS} "
                         "(an episode's loads and noise are tabulated at reset, ~350 bytes "
                         "per step)")
    if num_envs * steps > MAX_TABLE_STEPS:
        raise ValueError(f"num_envs x episode steps = {num_envs * steps} exceeds "
                         f"{MAX_TABLE_STEPS} (the vector env tabulates every sub-env's "
                         "episode, ~170 bytes per step)")
    return steps


def check_actions(action, n: int, v_max: float, vector: bool = False):
    """``n`` requested voltages as float64 and their clipped values.

    A single env takes real numbers of shape (1,); a vector env shape (n,) or (n, 1).
    Anything else -- strings, bytes, bools, complex numbers, other shapes, NaN or
    inf -- raises ``ValueError`` before any state changes.
    """
    a = np.asarray(action)
    if a.dtype.kind not in "iuf":
        raise ValueError(f"action must be real numbers (volts), got {action!r} "
                         f"(dtype {a.dtype})")
    shapes = ((n,), (n, 1)) if vector else ((1,),)
    if a.shape not in shapes:
        want = " or ".join(str(s) for s in shapes)
        raise ValueError(f"action must have shape {want} (voltages [V]), got shape {a.shape}")
    a = a.astype(np.float64).reshape(-1)
    if not np.isfinite(a).all():
        raise ValueError(f"action must be finite, got {a[~np.isfinite(a)][0]!r}")
    return a, np.clip(a, -v_max, v_max)


def arg_type(kind: type, low=None, high=None, *, low_open: bool = False):
    """An argparse ``type=`` that parses ``kind`` (int or float) and applies
    :func:`check_int` / :func:`check_real` with these bounds: one validation for every
    command line of the package."""
    import argparse

    def parse(text: str):
        try:
            value = int(text) if kind is int else float(text)
            if kind is int:
                return check_int("value", value, low, high)
            return check_real("value", value, low, high, low_open=low_open)
        except ValueError as exc:
            msg = str(exc).replace("value must be", "expected").split(", got")[0]
            raise argparse.ArgumentTypeError(f"{msg}, got {text!r}") from None

    return parse


class closed_pipe_is_fine:  # noqa: N801 (a context manager used like a function)
    """Context manager for a command's output: a reader that closes the pipe early
    (``acld-gym params | head -1``) ends the command quietly instead of with a
    ``BrokenPipeError`` traceback (Python's documented recipe: point stdout at devnull)."""

    def __enter__(self):
        return self

    def __exit__(self, kind, exc, tb) -> bool:
        if kind is not None and issubclass(kind, BrokenPipeError):
            import os
            import sys

            devnull = os.open(os.devnull, os.O_WRONLY)
            os.dup2(devnull, sys.stdout.fileno())
            return True
        return False


def run_main(main) -> int:
    """``main()`` for a ``python -m`` entry point: one BLAS thread
    (:mod:`acld_gym.blas`) and a quiet end when the reader closes the pipe."""
    from .blas import one_blas_thread

    with closed_pipe_is_fine(), one_blas_thread():
        return main()
    return 0
