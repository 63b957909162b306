"""An agent folder's files, read without trusting them and written whole.

Reading (:class:`AgentFolder`, :func:`read_arrays`) never leaves the folder: the folder and
each file are opened without following a symbolic link (``O_NOFOLLOW``, the files relative
to the folder's descriptor), only regular files are read, and each has a size limit. The
policy archive is checked by its central directory -- member names against the arrays
the actor program uses, declared sizes against :data:`MAX_POLICY_BYTES`, no encryption,
stored or deflated -- and each member's ``.npy`` header (a real dtype, one or two
dimensions, the declared size) before its data is decompressed. Every fault is an
:class:`AgentFileError` naming the file.

Writing is :mod:`train.agent_write`'s (re-exported here): :func:`write_folder` builds the
whole folder in a temporary sibling and swaps it in with one rename; a reader that meets
the swap mid-read reads again from the new folder (:func:`read_files`).
"""

from __future__ import annotations

import errno
import io
import math
import os
import stat
import struct
import zipfile
import zlib
from collections.abc import Iterable
from pathlib import Path

import numpy as np

from .agent_schema import AgentFileError, parse_metadata
from .agent_write import REPLACEABLE, check_replaceable, write_folder

__all__ = [
    "MAX_METADATA_BYTES",
    "MAX_POLICY_BYTES",
    "MAX_CURVE_BYTES",
    "REPLACEABLE",
    "AgentFolder",
    "read_files",
    "read_arrays",
    "read_metadata",
    "curve_rows",
    "read_curve",
    "check_replaceable",
    "write_folder",
]

#: Largest ``metadata.json`` read (a shipped one is about 5 kB).
MAX_METADATA_BYTES = 1 << 20
#: Largest total of the arrays in ``policy.npz``, as declared and as read (a shipped agent
#: has 336 bytes; a 3 x 1024 float64 MLP about 17 MB).
MAX_POLICY_BYTES = 64 << 20
#: Largest ``learning_curve.csv`` read (a shipped one is about 1.5 kB).
MAX_CURVE_BYTES = 4 << 20
#: Most members a policy archive may list.
MAX_MEMBERS = 256
#: What zipfile, zlib and numpy's header reader raise on damaged bytes (zipfile's
#: NotImplementedError for an unknown zip version, struct.error for a short record).
_ZIP_ERRORS = (
    zipfile.BadZipFile,
    zipfile.LargeZipFile,
    OSError,
    ValueError,
    EOFError,
    NotImplementedError,
    RuntimeError,
    struct.error,
    zlib.error,
)
_NOFOLLOW = getattr(os, "O_NOFOLLOW", 0)
_FLAGS = os.O_RDONLY | _NOFOLLOW | getattr(os, "O_NONBLOCK", 0) | getattr(os, "O_CLOEXEC", 0)
_BY_FD = os.open in os.supports_dir_fd and bool(_NOFOLLOW)


class AgentFolder:
    """An agent folder opened for reading (a context manager): :meth:`read` returns a
    file's bytes, never through a symbolic link and never from outside the folder.

    ``FileNotFoundError`` / ``NotADirectoryError`` if ``path`` is not a folder;
    :class:`AgentFileError` if it is a symbolic link.
    """

    def __init__(self, path: str | Path):
        self.path = Path(path)
        try:
            info = os.lstat(self.path)
        except FileNotFoundError:
            raise FileNotFoundError(f"agent directory {str(self.path)!r} does not exist") from None
        if stat.S_ISLNK(info.st_mode):
            raise AgentFileError(
                f"{self.path}: is a symbolic link; an agent is read from a real folder only "
                "(pass the folder it points to)"
            )
        if not stat.S_ISDIR(info.st_mode):
            raise NotADirectoryError(f"agent directory {str(self.path)!r} is not a directory")
        self.fd = None
        if _BY_FD:
            flags = os.O_RDONLY | _NOFOLLOW | getattr(os, "O_DIRECTORY", 0)
            try:
                self.fd = os.open(self.path, flags | getattr(os, "O_CLOEXEC", 0))
            except OSError as exc:
                raise AgentFileError(f"{self.path}: cannot be opened ({exc.strerror})") from None

    def __enter__(self) -> AgentFolder:
        return self

    def __exit__(self, *exc) -> None:
        self.close()

    def close(self) -> None:
        if self.fd is not None:
            os.close(self.fd)
            self.fd = None

    def replaced(self) -> bool:
        """Whether ``path`` no longer names the folder opened (it was swapped or removed
        since: a ship writing it whole)."""
        if self.fd is None:
            return False
        try:
            now = os.stat(self.path, follow_symlinks=False)
        except OSError:
            return True
        opened = os.fstat(self.fd)
        return (now.st_dev, now.st_ino) != (opened.st_dev, opened.st_ino)

    def exists(self, name: str) -> bool:
        """Whether the folder has an entry ``name`` (a link counts; :meth:`read` refuses it)."""
        try:
            self._lstat(name)
        except FileNotFoundError:
            return False
        return True

    def _lstat(self, name: str) -> os.stat_result:
        if self.fd is not None:
            return os.stat(name, dir_fd=self.fd, follow_symlinks=False)
        return os.lstat(self.path / name)

    def read(self, name: str, limit: int) -> bytes:
        """The bytes of the regular file ``name`` of the folder, at most ``limit`` of them;
        :class:`AgentFileError` naming it if it is missing, a link, not a regular file or
        larger."""
        where = self.path / name
        try:
            info = self._lstat(name)
        except FileNotFoundError:
            raise AgentFileError(f"agent directory {str(self.path)!r} lacks {name}") from None
        except OSError as exc:
            raise AgentFileError(f"{where}: cannot be read ({exc.strerror})") from None
        if stat.S_ISLNK(info.st_mode):
            raise AgentFileError(
                f"{where}: is a symbolic link; an agent's files must be regular files in its "
                "own folder"
            )
        if not stat.S_ISREG(info.st_mode):
            raise AgentFileError(f"{where}: is not a regular file")
        try:
            if self.fd is not None:
                fd = os.open(name, _FLAGS, dir_fd=self.fd)
            else:
                fd = os.open(where, _FLAGS)
        except OSError as exc:
            why = "a symbolic link" if exc.errno in (errno.ELOOP, errno.EMLINK) else exc.strerror
            raise AgentFileError(f"{where}: cannot be read ({why})") from None
        try:
            now = os.fstat(fd)
            if not stat.S_ISREG(now.st_mode):  # replaced between lstat and open
                raise AgentFileError(f"{where}: is not a regular file")
            if now.st_size > limit:
                raise AgentFileError(
                    f"{where}: {now.st_size} bytes, more than the {limit} an agent's {name} "
                    "may have"
                )
            with os.fdopen(os.dup(fd), "rb") as fh:  # (read(n) would allocate n bytes)
                data = fh.read(now.st_size + 1)
        except OSError as exc:
            raise AgentFileError(f"{where}: cannot be read ({exc.strerror})") from None
        finally:
            os.close(fd)
        if len(data) > now.st_size:
            raise AgentFileError(f"{where}: changed while it was read")
        return data


def read_files(path: str | Path, limits: dict[str, int], attempts: int = 3) -> dict[str, bytes]:
    """The bytes of the files ``limits`` names (name: size limit) of the agent folder
    ``path``, all from one folder: read through one descriptor of it, and read again
    from the start if the folder was replaced meanwhile and a file of the old one was
    gone (a ship swapping in a new agent), so a reader gets the old agent or the new one."""
    for attempt in range(attempts):
        with AgentFolder(path) as folder:
            try:
                return {name: folder.read(name, limit) for name, limit in limits.items()}
            except AgentFileError:
                if attempt + 1 == attempts or not folder.replaced():
                    raise
    raise AssertionError("unreachable")  # pragma: no cover


def read_arrays(data: bytes, needed: Iterable[str], where: str) -> dict[str, np.ndarray]:
    """The arrays of a ``policy.npz`` read as ``data``, exactly those named ``needed`` (the
    actor program's), as float64; checked (module docstring) before any member's data is
    decompressed. :class:`AgentFileError` naming ``where`` and the member otherwise."""
    needed = sorted(set(needed))
    if data.count(b"PK\x01\x02") > 16 * MAX_MEMBERS:  # before zipfile builds every entry
        raise AgentFileError(f"{where}: more than {MAX_MEMBERS} members")
    try:
        archive = zipfile.ZipFile(io.BytesIO(data))
        infos = archive.infolist()
    except _ZIP_ERRORS as exc:
        raise AgentFileError(f"{where}: not a readable numpy archive ({_cut(str(exc))})") from None
    if len(infos) > MAX_MEMBERS:
        raise AgentFileError(f"{where}: {len(infos)} members, more than {MAX_MEMBERS}")
    names = [i.filename for i in infos]
    if len(set(names)) != len(names):
        raise AgentFileError(f"{where}: a member name appears twice")
    held = {n[: -len(".npy")] for n in names if n.endswith(".npy")}
    unused = sorted(n for n in names if not (n.endswith(".npy") and n[: -len(".npy")] in needed))
    if unused:
        raise AgentFileError(
            f"{where}: members {[_cut(n) for n in unused][:8]} are not arrays the actor "
            f"program uses (it uses {needed})"
        )
    for key in needed:
        if key not in held:
            raise AgentFileError(f"{where}: missing array {key!r}")
    total = sum(i.file_size for i in infos)
    if total > MAX_POLICY_BYTES:
        raise AgentFileError(
            f"{where}: its arrays declare {total} bytes, more than {MAX_POLICY_BYTES}"
        )
    for info in infos:
        key = info.filename[: -len(".npy")]
        if info.flag_bits & 0x1:
            raise AgentFileError(f"{where}: array {key!r} is encrypted")
        if info.compress_type not in (zipfile.ZIP_STORED, zipfile.ZIP_DEFLATED):
            raise AgentFileError(f"{where}: array {key!r} uses an unsupported compression")
    out = {}
    with archive:
        for info in infos:
            out[info.filename[: -len(".npy")]] = _read_member(archive, info, where)
    return out


def read_metadata(path: str | Path) -> dict:
    """The checked ``metadata.json`` of the agent folder ``path``
    (:func:`train.agent_schema.parse_metadata`), read as :class:`AgentFolder` reads: for a
    listing that needs the metadata only (which env, which mesh)."""
    with AgentFolder(path) as folder:
        data = folder.read("metadata.json", MAX_METADATA_BYTES)
    return parse_metadata(data, str(Path(path) / "metadata.json"))


def curve_rows(text: str, where: str) -> list[dict]:
    """The rows of a ``learning_curve.csv`` (``timesteps,case,ise``) as
    ``{"timesteps": int >= 0, "case": str, "ise": float >= 0}``; :class:`AgentFileError`
    naming ``where`` and the line otherwise."""
    lines = text.splitlines()
    if not lines or [c.strip() for c in lines[0].split(",")] != ["timesteps", "case", "ise"]:
        raise AgentFileError(f"{where}: expected the header 'timesteps,case,ise'")
    rows = []
    for i, line in enumerate(lines[1:], start=2):
        parts = line.split(",")
        try:
            steps, case, ise = int(parts[0]), parts[1].strip(), float(parts[2])
            ok = len(parts) == 3 and steps >= 0 and bool(case) and math.isfinite(ise) and ise >= 0
        except (ValueError, IndexError):
            ok = False
        if not ok:
            raise AgentFileError(
                f"{where}: line {i}: expected timesteps (an integer >= 0), a case and an ISE "
                f"(a finite number >= 0), got {_cut(line)!r}"
            )
        rows.append({"timesteps": steps, "case": case, "ise": ise})
    return rows


def read_curve(path: str | Path) -> list[dict] | None:
    """The rows (:func:`curve_rows`) of the ``learning_curve.csv`` of the agent folder
    ``path``, read as :class:`AgentFolder` reads; None if it has none."""
    with AgentFolder(path) as folder:
        if not folder.exists("learning_curve.csv"):
            return None
        data = folder.read("learning_curve.csv", MAX_CURVE_BYTES)
    where = str(Path(path) / "learning_curve.csv")
    try:
        return curve_rows(data.decode("utf-8"), where)
    except UnicodeDecodeError:
        raise AgentFileError(f"{where}: not UTF-8 text") from None


def _cut(name: str) -> str:
    return name if len(name) <= 40 else name[:37] + "..."


def _read_member(archive: zipfile.ZipFile, info: zipfile.ZipInfo, where: str) -> np.ndarray:
    """One ``.npy`` member: its header checked against its declared size, then its data."""
    key = info.filename[: -len(".npy")]
    fmt = np.lib.format
    try:
        with archive.open(info) as fh:
            version = fmt.read_magic(fh)
            readers = {(1, 0): fmt.read_array_header_1_0, (2, 0): fmt.read_array_header_2_0}
            if version not in readers:
                raise ValueError(f"unsupported .npy version {version}")
            shape, fortran, dtype = readers[version](fh, max_header_size=10000)
            if dtype.kind not in "fiu" or dtype.fields is not None or dtype.subdtype is not None:
                raise AgentFileError(
                    f"{where}: array {key!r} holds {dtype.str!r} values, expected real numbers"
                )
            if not 1 <= len(shape) <= 2 or any(n < 0 for n in shape):
                raise AgentFileError(
                    f"{where}: array {key!r} has shape {shape}, expected a vector or a matrix"
                )
            nbytes = math.prod(shape) * dtype.itemsize
            if fh.tell() + nbytes != info.file_size:
                raise AgentFileError(
                    f"{where}: array {key!r} declares {info.file_size} bytes, its header "
                    f"{fh.tell() + nbytes}"
                )
            raw = fh.read(nbytes)
            if len(raw) != nbytes or fh.read(1):
                raise ValueError("its data do not match its header")
    except AgentFileError:
        raise
    except (*_ZIP_ERRORS, TypeError) as exc:
        raise AgentFileError(f"{where}: array {key!r} is damaged ({_cut(str(exc))})") from None
    arr = np.frombuffer(raw, dtype=dtype).reshape(shape, order="F" if fortran else "C")
    return arr.astype(np.float64)
