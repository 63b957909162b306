"""Atomic file writes: a reader sees the old file or the new one, never a part of one.

Every result file of the package (JSON tables, figures, agents, cached plants) is
written to a temporary file in the same directory and moved into place with
``os.replace`` (atomic on POSIX and Windows). A write that fails midway -- a full disk,
``ulimit -f`` -- leaves the previous file intact and no temporary behind.
:func:`write_files` (:func:`write_texts`) writes several files all or none;
:func:`replace_dir` replaces a whole folder (an agent) with one rename, so a reader sees
the old folder or the new one.
:func:`check_writable` lets a command refuse an unusable output path before it spends
minutes computing.
"""

from __future__ import annotations

import ctypes
import ctypes.util
import io
import json
import math
import os
import shutil
import tempfile
from collections.abc import Callable
from pathlib import Path
from typing import IO, Any

__all__ = [
    "write_atomic",
    "write_text",
    "write_json",
    "strict_json",
    "write_texts",
    "write_files",
    "replace_dir",
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


def strict_json(obj: Any) -> Any:
    """JSON data with every non-finite float as None (strict JSON: ``json.dumps(...,
    allow_nan=False)`` accepts it and every reader parses it)."""
    if isinstance(obj, dict):
        return {k: strict_json(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [strict_json(v) for v in obj]
    if isinstance(obj, float) and not math.isfinite(obj):
        return None
    return obj


def write_json(path: str | Path, obj: Any) -> Path:
    """Write ``obj`` as indented JSON to ``path`` atomically."""
    return write_text(path, json.dumps(obj, indent=2) + "\n")


def write_texts(texts: dict[str | Path, str]) -> list[Path]:
    """Write several UTF-8 files all or none (:func:`write_files`). Returns the paths written."""
    return write_files({path: text.encode() for path, text in texts.items()})


def write_files(files: dict[str | Path, bytes]) -> list[Path]:
    """Write several files (their bytes) all or none: every file goes to a temporary file
    beside its target first (a full disk fails here, before any target changes), then each
    is moved into place with ``os.replace``. Returns the paths written."""
    staged: list[tuple[str, Path]] = []
    try:
        for path, data in files.items():
            path = Path(path)
            path.parent.mkdir(parents=True, exist_ok=True)
            fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".tmp")
            staged.append((tmp, path))
            with os.fdopen(fd, "wb") as fh:
                fh.write(data)
                fh.flush()
                os.fsync(fh.fileno())
            umask = os.umask(0)
            os.umask(umask)
            os.chmod(tmp, 0o666 & ~umask)
    except BaseException:
        for tmp, _ in staged:
            Path(tmp).unlink(missing_ok=True)
        raise
    for tmp, path in staged:
        os.replace(tmp, path)
    return [path for _, path in staged]


_RENAME_EXCHANGE = 2  # linux/fs.h


def _exchange(a: Path, b: Path) -> bool:
    """Swap two paths atomically (Linux ``renameat2(RENAME_EXCHANGE)``); False where the
    call is unavailable (another OS, an old kernel, a file system without it)."""
    try:
        libc = ctypes.CDLL(ctypes.util.find_library("c") or "libc.so.6", use_errno=True)
        renameat2 = libc.renameat2
    except (OSError, AttributeError):
        return False
    at_fdcwd = -100
    rc = renameat2(at_fdcwd, os.fsencode(a), at_fdcwd, os.fsencode(b), _RENAME_EXCHANGE)
    return rc == 0


def replace_dir(path: str | Path, fill: Callable[[Path], Any]) -> Path:
    """Build a folder with ``fill(tmp)`` in a temporary sibling of ``path``, then put it in
    place whole: a new ``path`` is one ``rename``; an existing one is swapped with the new
    folder in one atomic exchange where the OS has it (Linux), else renamed aside and
    replaced (a reader may then briefly find no folder, never a mixed one). A ``fill`` that
    fails -- a full disk, ``ulimit -f`` -- leaves ``path`` as it was and no temporary."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = Path(tempfile.mkdtemp(dir=path.parent, prefix=f".{path.name}.", suffix=".tmp"))
    try:
        fill(tmp)
        for f in tmp.rglob("*"):
            if f.is_file():
                with open(f, "rb") as fh:
                    os.fsync(fh.fileno())
        umask = os.umask(0)
        os.umask(umask)
        os.chmod(tmp, 0o777 & ~umask)
        if not path.exists() and not path.is_symlink():
            os.rename(tmp, path)
        elif path.is_dir() and not path.is_symlink() and _exchange(tmp, path):
            shutil.rmtree(tmp)  # now the old folder
        else:
            old = Path(tempfile.mkdtemp(dir=path.parent, prefix=f".{path.name}.", suffix=".old"))
            os.rmdir(old)
            os.rename(path, old)
            os.rename(tmp, path)
            if old.is_dir() and not old.is_symlink():
                shutil.rmtree(old)
            else:
                old.unlink()
    except BaseException:
        if tmp.exists():
            shutil.rmtree(tmp, ignore_errors=True)
        raise
    return path


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


def save_figure(fig, path: str | Path, out: dict | None = None, **kwargs) -> Path:
    """``fig.savefig`` to ``path`` atomically (the format from the file's suffix); with
    ``out``, the figure's bytes go to ``out[path]`` instead, for :func:`write_files` to
    write with the command's other outputs, all or none."""
    path = Path(path)
    fmt = path.suffix.lstrip(".") or "png"
    if out is None:
        return write_atomic(path, lambda fh: fig.savefig(fh, format=fmt, **kwargs))
    buffer = io.BytesIO()
    fig.savefig(buffer, format=fmt, **kwargs)
    out[path] = buffer.getvalue()
    return path
