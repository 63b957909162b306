"""Validation of user input shared by every layer: each check raises ``ValueError`` naming the
argument and what was expected, before any state changes; and the command-line glue
(argparse number types, quiet closed pipes, one BLAS thread)."""

from __future__ import annotations

import math
import numbers

import numpy as np

__all__ = [
    "check_real",
    "check_int",
    "check_choice",
    "check_seed",
    "arg_type",
    "closed_pipe_is_fine",
    "run_main",
]


def check_real(
    name: str,
    value,
    low: float | None = None,
    high: float | None = None,
    *,
    low_open: bool = False,
    unit: str = "",
) -> float:
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
    (:mod:`acld_gym.util.blas`) and a quiet end when the reader closes the pipe."""
    from acld_gym.util.blas import one_blas_thread

    with closed_pipe_is_fine(), one_blas_thread():
        return main()
    return 0
