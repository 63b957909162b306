"""Validation of user input shared by every layer: each check raises ``ValueError`` naming the
argument and what was expected, before any state changes; :class:`DataFileError` for a file
the package reads that is damaged or malformed; and the command-line glue (argparse number
types, quiet closed pipes, one BLAS thread, one line for a failed file operation)."""

from __future__ import annotations

import argparse
import errno
import math
import numbers
import os
import stat
import sys
from pathlib import Path

import numpy as np

from acld_gym.util.atomic import check_writable
from acld_gym.util.blas import one_blas_thread

__all__ = [
    "check_real",
    "json_depth",
    "shown",
    "check_int",
    "check_choice",
    "check_seed",
    "DataFileError",
    "file_error",
    "arg_type",
    "arg_dir",
    "closed_pipe_is_fine",
    "os_error_line",
    "check_figure_path",
    "run_main",
]


def shown(value, limit: int = 60) -> str:
    """``repr(value)`` cut to ``limit`` characters (an error message names a value, it does
    not echo a 400-digit integer or a file's bytes)."""
    text = repr(value)
    return text if len(text) <= limit else f"{text[: limit - 3]}..."


def json_depth(obj, limit: int) -> int:
    """The nesting depth of parsed JSON data (lists and dicts), found without recursion and
    given up past ``limit`` (a file nested 200,000 deep is measured in ``limit`` steps of
    depth, not walked whole)."""
    deepest, stack = 0, [(obj, 1)]
    while stack:
        item, d = stack.pop()
        if isinstance(item, (list, dict)):
            deepest = max(deepest, d)
            if d > limit:
                return d
            stack.extend((v, d + 1) for v in (item.values() if isinstance(item, dict) else item))
    return deepest


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
    try:
        v = float(value) if ok else math.nan
    except OverflowError:  # an integer beyond the float range
        v = math.nan
    if not ok or not math.isfinite(v):
        raise ValueError(f"{name} must be a finite real number{u}, got {shown(value)}")
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


class DataFileError(ValueError):
    """A file the package reads (a results table, a config, a resume record) is damaged or
    not of the expected form; the message names the file and the field (:func:`file_error`).
    A ``ValueError``, so callers that catch bad input catch it too."""


def file_error(path, field: str | None, message: str) -> DataFileError:
    """The :class:`DataFileError` ``"<path>: <field>: <message>"`` (no field: the file as a
    whole, ``"<path>: <message>"``)."""
    where = f"{path}: {field}" if field else str(path)
    return DataFileError(f"{where}: {message}")


def arg_type(kind: type, low=None, high=None, *, low_open: bool = False):
    """An argparse ``type=`` that parses ``kind`` (int or float) and applies
    :func:`check_int` / :func:`check_real` with these bounds: one validation for every
    command line of the package."""

    def parse(text: str):
        try:
            value = int(text) if kind is int else float(text)
        except ValueError:
            expected = "an integer" if kind is int else "a real number"
            raise argparse.ArgumentTypeError(f"expected {expected}, got {text!r}") from None
        try:
            if kind is int:
                return check_int("value", value, low, high)
            return check_real("value", value, low, high, low_open=low_open)
        except ValueError as exc:
            msg = str(exc).replace("value must be", "expected").split(", got")[0]
            raise argparse.ArgumentTypeError(f"{msg}, got {text!r}") from None

    return parse


def arg_dir(text: str) -> str:
    """An argparse ``type=`` for an output folder: ``text`` if it is a folder, or can be made
    as one under the nearest folder on its path that exists and is writable; checked when
    the command line is parsed, before anything is computed, and nothing is created (a
    later refusal of another argument leaves no folder behind)."""
    path = Path(text)

    def refuse(why: str):
        raise argparse.ArgumentTypeError(
            f"expected a folder that can hold files, got {text!r}: {why}"
        )

    if path.exists() and not path.is_dir():
        refuse("it exists and is not a folder")
    existing = next(p for p in (path, *path.parents) if p.exists())
    if not existing.is_dir():
        refuse(f"{str(existing)!r} is not a folder")
    if not os.access(existing, os.W_OK | os.X_OK):
        refuse(f"{str(existing)!r} is not writable")
    return text


class closed_pipe_is_fine:  # noqa: N801 (a context manager used like a function)
    """Context manager for a command's output: a reader that closes the pipe early
    (``acld-gym params | head -1``) ends the command quietly instead of with a
    ``BrokenPipeError`` traceback (Python's documented recipe: point stdout at devnull)."""

    def __enter__(self):
        return self

    def __exit__(self, kind, exc, tb) -> bool:
        if kind is not None and issubclass(kind, BrokenPipeError):
            devnull = os.open(os.devnull, os.O_WRONLY)
            os.dup2(devnull, sys.stdout.fileno())
            return True
        return False


def check_figure_path(path, what: str = "--plot"):
    """``path`` if a figure can be written there: a format matplotlib writes by itself (from
    the suffix; none: PNG) and a writable place (:func:`acld_gym.util.atomic.check_writable`); else
    ``ValueError`` naming ``what``. Call it before computing the figure."""
    from matplotlib.figure import Figure  # ~0.4 s to import: only a figure path needs it

    formats = set(Figure().canvas.get_supported_filetypes()) - {"pgf"}  # pgf needs LaTeX
    suffix = os.path.splitext(os.fspath(path))[1].lstrip(".").lower() or "png"  # save_figure's
    if suffix not in formats:
        raise ValueError(
            f"{what}: cannot draw {os.fspath(path)!r}: expected a suffix of {sorted(formats)}"
        )
    return check_writable(path, what)


def _os_error_file(exc: OSError):
    """The file an ``OSError`` is about: its ``filename``, else (a write to an open file
    fails without one: a full disk, ``ulimit -f``) the innermost ``path`` of the frames it
    passed through (:mod:`acld_gym.util.atomic`'s writers name their target so)."""
    if exc.filename is not None:
        return exc.filename
    found, tb = None, exc.__traceback__
    while tb is not None:
        path = tb.tb_frame.f_locals.get("path")
        if isinstance(path, (str, os.PathLike)):
            found = path
        tb = tb.tb_next
    return found


def os_error_line(exc: OSError) -> str:
    """One line for a failed file operation: the file and the system's reason
    (``standard output`` if the error names no file and stdout is a file that cannot grow:
    the command's printed output under ``> file`` on a full disk)."""
    path = _os_error_file(exc)
    if path is None and _stdout_full(exc):
        path = "standard output"
    reason = exc.strerror or str(exc) or type(exc).__name__
    return f"{os.fspath(path)}: {reason}" if path is not None else reason


def _stdout_full(exc: OSError) -> bool:
    """Whether ``exc`` is a full disk or file-size limit that stdout, a regular file, has
    reached (then stdout is pointed at the null device: the exit's flush adds no error)."""
    try:
        fd = sys.stdout.fileno()
        info = os.fstat(fd)
        if not stat.S_ISREG(info.st_mode):
            return False
        if exc.errno == errno.EFBIG:
            import resource  # POSIX only (ImportError below: not POSIX)

            soft = resource.getrlimit(resource.RLIMIT_FSIZE)[0]
            full = soft != resource.RLIM_INFINITY and info.st_size >= soft
        else:
            full = exc.errno in (errno.ENOSPC, errno.EDQUOT) and os.fstatvfs(fd).f_bavail == 0
    except (AttributeError, ValueError, OSError, ImportError):  # no stdout; not POSIX
        return False
    if full:
        os.dup2(os.open(os.devnull, os.O_WRONLY), fd)
    return full


def _flush_stdout() -> None:
    """Flush what the command printed (a full disk under ``> file`` fails here, inside
    :func:`run_main`'s handler, rather than at the exit)."""
    try:
        sys.stdout.flush()
    except (AttributeError, ValueError):  # no stdout, or a closed one
        pass


def _prog(main) -> str:
    """The command's name: ``python -m <module>`` of the running module, else the script."""
    spec = getattr(sys.modules.get("__main__"), "__spec__", None)
    if spec is not None and spec.name:
        return f"python -m {spec.name.removesuffix('.__main__')}"
    module = getattr(main, "__module__", None)
    if module and module != "__main__":
        return f"python -m {module}"
    return os.path.basename(sys.argv[0]) or "acld-gym"


def run_main(main, prog: str | None = None) -> int:
    """``main()`` for an entry point (every ``python -m`` of the package and ``acld-gym``):
    one BLAS thread (:mod:`acld_gym.util.blas`), a quiet end when the reader closes the pipe,
    and no traceback for a failed file operation (a full disk, a vanished or unreadable
    file) or a damaged input file (:class:`DataFileError`): one line on stderr,
    ``<prog>: error: <file>: <reason>``, and exit status 1 (2 for a damaged input, as for
    a bad argument); Ctrl-C (``KeyboardInterrupt``) is one line too, exit status 130 (the
    shell's 128 + SIGINT)."""
    with closed_pipe_is_fine(), one_blas_thread():
        try:
            status = main()
            _flush_stdout()  # (a full disk under "> file" fails here, not at the exit)
            return status
        except BrokenPipeError:
            raise  # closed_pipe_is_fine's
        except OSError as exc:
            print(f"{prog or _prog(main)}: error: {os_error_line(exc)}", file=sys.stderr)
            return 1
        except DataFileError as exc:
            print(f"{prog or _prog(main)}: error: {exc}", file=sys.stderr)
            return 2
        except KeyboardInterrupt:  # Ctrl-C: one line, not a traceback of where it landed
            print(f"{prog or _prog(main)}: interrupted", file=sys.stderr)
            return 130
    return 0
