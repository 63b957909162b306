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
import os
import sys
from collections.abc import Callable
from pathlib import Path

import numpy as np

from acld_gym.physics.params import BeamParameters
from acld_gym.physics.plant import Plant
from acld_gym.util.atomic import write_atomic

__all__ = ["FORMAT", "key", "cached", "save", "load", "SHIPPED_DIR", "user_cache_dir"]

#: Version of the converged plant's construction; bump it when the construction changes.
#: 2 (issue 65): modes enumerated on the fine mesh, shifts up to 1.3 x the band, the basis
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


def load(path: Path) -> Plant:
    """Read a plant written by :func:`save` (plain arrays and JSON: nothing executes)."""
    with np.load(path, allow_pickle=False) as z:
        meta = json.loads(bytes(z["meta"]).decode())
        units = {k.split(":", 1)[1]: z[k] for k in z.files if k.startswith("unit:")}
        return Plant(
            name=meta["name"],
            params=BeamParameters(**meta["params"]),
            units=units,
            piezo=z["piezo"],
            Fd=z["Fd"],
            c=z["c"],
            physical=z["physical"],
            node_x=z["node_x"],
            node_w=z["node_w"],
            provenance=meta["provenance"],
        )


def cached(params: BeamParameters, dt: float, refinement: int, build: Callable[[], Plant]) -> Plant:
    """The plant for these inputs: the shipped file, else the user cache, else ``build()``
    (then written to the user cache when possible)."""
    name = _filename(key(params, dt, refinement))
    for directory in (SHIPPED_DIR, user_cache_dir()):
        path = directory / name
        if path.is_file():
            try:
                return load(path)
            except (OSError, ValueError, KeyError) as exc:  # a damaged file: rebuild
                print(f"acld_gym: ignoring unreadable plant file {path}: {exc}", file=sys.stderr)
    plant = build()
    try:
        save(plant, user_cache_dir() / name)
    except OSError:
        pass  # read-only home or disk full: the plant is rebuilt next time
    return plant


def main() -> int:
    """Regenerate the shipped default plant file (and remove stale ones)."""
    from acld_gym.physics.krylov import REFINEMENT, build_converged_plant

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
