"""Atomic file writes: a reader sees the old file or the new one, never a part of one.

Every result file of the package (JSON tables, figures, agents, cached plants) is
written to a temporary file in the same directory and moved into place with
``os.replace`` (atomic on POSIX and Windows). A write that fails midway -- a full disk,
``ulimit -f`` -- leaves the previous file intact and no temporary behind.
:func:`check_writable` lets a command refuse an unusable output path before it spends
minutes computing.
"""

from __future__ import annotations

import json
import os
import tempfile
from collections.abc import Callable
from pathlib import Path
from typing import IO, Any

__all__ = [
    "write_atomic",
    "write_text",
    "write_json",
    "check_writable",
    "check_directory",
    "save_figure",
]


def write_atomic(path: str | Path, write: Callable[[IO[bytes]], Any]) -> Path:
    """Call ``write(fh)`` on a temporary file next to ``path``, then move it into place.

    The file gets the permissions a plain ``open(path, "w")`` would give (0o644 under
    the usual umask), not ``mkstemp``'s private 0o600.
    """
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".tmp")
    try:
        with os.fdopen(fd, "wb") as fh:
            write(fh)
            fh.flush()
            os.fsync(fh.fileno())
        umask = os.umask(0)
        os.umask(umask)
        os.chmod(tmp, 0o666 & ~umask)
        os.replace(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise
    return path


def write_text(path: str | Path, text: str) -> Path:
    """Write ``text`` (UTF-8) to ``path`` atomically."""
    return write_atomic(path, lambda fh: fh.write(text.encode()))


def write_json(path: str | Path, obj: Any) -> Path:
    """Write ``obj`` as indented JSON to ``path`` atomically."""
    return write_text(path, json.dumps(obj, indent=2) + "\n")


def check_writable(path: str | Path, what: str = "output") -> Path:
    """``ValueError`` naming ``what`` unless a file can be created at ``path`` (its
    directory exists or can be made, is a directory, and accepts files); call it before
    computing anything. Creates the directory, writes nothing else."""
    path = Path(path)
    if path.is_dir():
        raise ValueError(f"{what}: {str(path)!r} is a directory, expected a file path")
    parent = path.parent
    for p in (parent, *parent.parents):
        if p.exists():
            if not p.is_dir():
                raise ValueError(
                    f"{what}: cannot write {str(path)!r} ({str(p)!r} is not a directory)"
                )
            break
    try:
        parent.mkdir(parents=True, exist_ok=True)
        fd, tmp = tempfile.mkstemp(dir=parent, prefix=f".{path.name}.", suffix=".probe")
        os.close(fd)
        os.unlink(tmp)
    except OSError as exc:
        raise ValueError(f"{what}: cannot write {str(path)!r} ({exc.strerror or exc})") from None
    return path


def check_directory(path: str | Path, what: str = "output directory") -> Path:
    """``ValueError`` naming ``what`` unless ``path`` is (or can be made) a directory that
    accepts files; call it before computing anything."""
    path = Path(path)
    if path.exists() and not path.is_dir():
        raise ValueError(f"{what}: {str(path)!r} exists and is not a directory")
    return check_writable(path / "probe", what).parent


def save_figure(fig, path: str | Path, **kwargs) -> Path:
    """``fig.savefig`` to ``path`` atomically (the format from the file's suffix)."""
    path = Path(path)
    fmt = path.suffix.lstrip(".") or "png"
    return write_atomic(path, lambda fh: fig.savefig(fh, format=fmt, **kwargs))
