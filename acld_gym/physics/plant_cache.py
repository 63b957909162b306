"""Versioned files of built plants: the shipped default and a per-user cache.

A file's name carries a key: the SHA-256 of everything the plant depends on (the
parameters, the refinement, the control period and :data:`FORMAT`, the version of
the construction). Any change to one of them gives another key, so a stale file is
never read; a plant not found is built and written to the user cache
(``$ACLD_GYM_CACHE_DIR``, else ``$XDG_CACHE_HOME/acld-gym``, else ``~/.cache/acld-gym``),
atomically (temporary file, then ``os.replace``). An unwritable cache only costs the
time to rebuild.

The package ships the default plant (``acld_gym/data/``), regenerated with
``python -m acld_gym.physics.plant_cache`` after any change that alters the key.
"""

from __future__ import annotations

import dataclasses
import hashlib
import json
import math
import os
import sys
import zipfile
import zlib
from collections.abc import Callable
from pathlib import Path

import numpy as np

from acld_gym.physics.elements import TERM_COEFFICIENTS
from acld_gym.physics.krylov import REFINEMENT, build_converged_plant
from acld_gym.physics.params import BeamParameters
from acld_gym.physics.plant import Plant
from acld_gym.util.atomic import write_atomic
from acld_gym.util.validate import (
    DataFileError,
    check_real,
    file_error,
    json_depth,
    os_error_line,
    shown,
)

__all__ = ["FORMAT", "key", "cached", "save", "load", "SHIPPED_DIR", "user_cache_dir"]

#: Version of the converged plant's construction; bump it when the construction changes.
#: 2 (acld-gym 0.20.0): modes enumerated on the fine mesh, shifts up to 1.3 x the band, the basis
#: deflated below 1e-10 (:mod:`acld_gym.physics.krylov`). The default plant has the same
#: four shifts in both: its shipped file is the format-1 build, renamed (a fresh build
#: agrees with it to 3e-9).
FORMAT = 2
SHIPPED_DIR = Path(__file__).resolve().parent / "data"


def key(params: BeamParameters, dt: float, refinement: int) -> str:
    """16 hex digits of the SHA-256 of the plant's inputs."""
    fields = {f.name: repr(float(getattr(params, f.name))) for f in dataclasses.fields(params)}
    blob = json.dumps(
        {
            "format": FORMAT,
            "plant": "converged",
            "params": fields,
            "dt": repr(float(dt)),
            "refinement": int(refinement),
        },
        sort_keys=True,
    )
    return hashlib.sha256(blob.encode()).hexdigest()[:16]


def user_cache_dir() -> Path:
    if os.environ.get("ACLD_GYM_CACHE_DIR"):
        return Path(os.environ["ACLD_GYM_CACHE_DIR"])
    base = os.environ.get("XDG_CACHE_HOME") or str(Path.home() / ".cache")
    return Path(base) / "acld-gym"


def _filename(k: str) -> str:
    return f"plant-converged-{k}.npz"


def save(plant: Plant, path: Path) -> None:
    """Write ``plant`` to ``path`` atomically (temporary file in the same directory)."""
    arrays = {f"unit:{name}": U for name, U in plant.units.items()}
    arrays.update(
        piezo=plant.piezo,
        Fd=plant.Fd,
        c=plant.c,
        physical=plant.physical,
        node_x=plant.node_x,
        node_w=plant.node_w,
    )
    meta = {
        "name": plant.name,
        "provenance": plant.provenance,
        "params": {f.name: getattr(plant.params, f.name) for f in dataclasses.fields(plant.params)},
    }
    arrays["meta"] = np.frombuffer(json.dumps(meta).encode(), dtype=np.uint8)
    write_atomic(path, lambda fh: np.savez(fh, **arrays))


#: The largest plant file :func:`load` reads (its members' declared sizes, in bytes): a
#: plant at 0.1 ms (86 states) takes about 1 MB.
MAX_BYTES = 64 * 2**20
#: The deepest nesting of the JSON ``meta`` member (a written one has 3).
MAX_DEPTH = 8
_VECTORS = ("piezo", "Fd", "c")
_MATRICES = ("physical", "node_x", "node_w")


def _meta(raw: np.ndarray, path: Path) -> dict:
    """The checked JSON of the ``meta`` member: ``name`` a string, ``provenance`` a mapping,
    ``params`` every field of :class:`BeamParameters` as a finite number (and nothing else);
    :class:`DataFileError` naming the field otherwise."""
    if raw.dtype != np.uint8 or raw.ndim != 1:
        raise file_error(path, "meta", f"expected bytes, got {raw.dtype} of shape {raw.shape}")
    try:
        meta = json.loads(raw.tobytes().decode("utf-8"))
    except RecursionError:
        raise file_error(path, "meta", "nested too deeply") from None
    except (UnicodeDecodeError, ValueError) as exc:  # JSONDecodeError is a ValueError
        raise file_error(path, "meta", f"not JSON ({shown(str(exc))})") from None
    if json_depth(meta, MAX_DEPTH) > MAX_DEPTH:
        raise file_error(path, "meta", f"nested deeper than {MAX_DEPTH} levels")
    if not isinstance(meta, dict):
        raise file_error(path, "meta", f"expected a mapping, got {shown(meta)}")
    for name, kind in (("name", str), ("provenance", dict), ("params", dict)):
        if not isinstance(meta.get(name), kind):
            raise file_error(path, f"meta.{name}", f"expected a {kind.__name__}")
    fields = {f.name for f in dataclasses.fields(BeamParameters)}
    if set(meta["params"]) != fields:
        raise file_error(path, "meta.params", "not the fields of BeamParameters")
    for name, value in meta["params"].items():
        try:
            check_real(name, value)
        except ValueError as exc:
            raise file_error(path, f"meta.params.{name}", str(exc)) from None
    return meta


def _array(z, name: str, shape: tuple, path: Path) -> np.ndarray:
    """The finite float64 member ``name`` of ``shape`` (None: any extent there)."""
    a = z[name]
    if a.dtype != np.float64 or a.ndim != len(shape):
        raise file_error(path, name, f"expected float64 of {len(shape)} dimensions")
    if any(want is not None and got != want for got, want in zip(a.shape, shape, strict=True)):
        raise file_error(path, name, f"expected shape {shape}, got {a.shape}")
    if not np.all(np.isfinite(a)):
        raise file_error(path, name, "not finite")
    return a


def _members(path: Path) -> None:
    """Refuse an archive whose members are not a plant's, whose declared sizes exceed
    :data:`MAX_BYTES`, or whose array headers declare more data than the member holds,
    before any array is read (an array's memory is taken from its header)."""
    with zipfile.ZipFile(path) as archive:
        infos = archive.infolist()
        names = {i.filename.removesuffix(".npy") for i in infos}
        want = {"meta", *_VECTORS, *_MATRICES} | {f"unit:{t}" for t in TERM_COEFFICIENTS}
        if names != want or len(infos) != len(want):
            raise file_error(path, None, f"members {sorted(names)[:4]}... are not a plant's")
        if sum(i.file_size for i in infos) > MAX_BYTES:
            raise file_error(path, None, f"larger than {MAX_BYTES} bytes: not a plant file")
        for info in infos:
            with archive.open(info) as fh:
                fmt = np.lib.format
                read = {(1, 0): fmt.read_array_header_1_0, (2, 0): fmt.read_array_header_2_0}
                reader = read.get(fmt.read_magic(fh))
                if reader is None:
                    raise file_error(path, info.filename, "not a numpy array of version 1 or 2")
                shape, _, dtype = reader(fh)
            if dtype.hasobject or math.prod(shape) * dtype.itemsize > info.file_size:
                name = info.filename.removesuffix(".npy")
                raise file_error(path, name, "its header does not describe its data")


def load(path: Path) -> Plant:
    """Read a plant written by :func:`save` (plain arrays and JSON: nothing executes).

    Every member is checked before use -- the archive's member names and sizes, each
    array's dtype, shape (r coordinates, from ``Fd``) and finiteness, the JSON ``meta``'s
    fields -- and a damaged or foreign file is a :class:`DataFileError` naming the file and
    the member; a missing or unreadable file is the ``OSError`` of reading it."""
    try:
        _members(path)
        with np.load(path, allow_pickle=False) as z:
            meta = _meta(z["meta"], path)
            r = _array(z, "Fd", (None,), path).shape[0]
            if r < 1:
                raise file_error(path, "Fd", "no coordinates")
            arrays = {name: _array(z, name, (r,), path) for name in _VECTORS}
            arrays["physical"] = _array(z, "physical", (None, r), path)
            arrays["node_x"] = _array(z, "node_x", (None,), path)
            arrays["node_w"] = _array(z, "node_w", (arrays["node_x"].size, r), path)
            units = {t: _array(z, f"unit:{t}", (r, r), path) for t in TERM_COEFFICIENTS}
    except DataFileError:
        raise
    except (ValueError, KeyError, EOFError, RuntimeError, zipfile.BadZipFile, zlib.error) as exc:
        # (RuntimeError, NotImplementedError: an encrypted member, an unknown compression)
        raise file_error(path, None, f"not a plant file ({shown(str(exc))})") from None
    try:
        params = BeamParameters(**meta["params"])
    except ValueError as exc:
        raise file_error(path, "meta.params", str(exc)) from None
    return Plant(
        name=meta["name"],
        params=params,
        units=units,
        provenance=meta["provenance"],
        **arrays,
    )


def cached(params: BeamParameters, dt: float, refinement: int, build: Callable[[], Plant]) -> Plant:
    """The plant for these inputs: the shipped file, else the user cache, else ``build()``
        (then written to the user cache when possible). A damaged or foreign file (:func:`load`)
    is rebuilt, said in one line on stderr."""
    name = _filename(key(params, dt, refinement))
    for directory in (SHIPPED_DIR, user_cache_dir()):
        path = directory / name
        if path.is_file():
            try:
                found = load(path)
                if found.params != params:
                    raise file_error(path, "meta.params", "not the parameters of its key")
                return found
            except (OSError, DataFileError) as exc:  # a damaged file: rebuilt (one line)
                why = os_error_line(exc) if isinstance(exc, OSError) else str(exc)
                print(f"acld_gym: rebuilding the plant ({why})", file=sys.stderr)
    plant = build()
    try:
        save(plant, user_cache_dir() / name)
    except OSError:
        pass  # read-only home or disk full: the plant is rebuilt next time
    return plant


def main() -> int:
    """Regenerate the shipped default plant file (and remove stale ones)."""
    params, dt = BeamParameters(), 1e-3
    path = SHIPPED_DIR / _filename(key(params, dt, REFINEMENT))
    for old in SHIPPED_DIR.glob("plant-converged-*.npz"):
        if old != path:
            old.unlink()
    save(build_converged_plant(dt, params, REFINEMENT), path)
    print(f"wrote {path}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
