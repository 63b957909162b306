"""The one cache of the references: a JSON record per computation, keyed, validated, replaced
atomically.

Every cached reference of the package -- a test set's per-episode references
(:func:`baselines.evaluation.references.references`, in the user cache,
:func:`acld_gym.physics.plant_cache.user_cache_dir`) and the per-case references of the
ISE-relative-to-LQR view (``train.core.evaluate.references``, in the benchmark's output
folder) -- is one file of this form::

    {"format": FORMAT, "kind": "<what it holds>", "key": "<16 hex digits>", ...payload}

The key is the SHA-256 of what the numbers depend on (:func:`record_key`: the kind's
inputs, the env's whole configuration and observation fingerprint, :data:`FORMAT` and the
package version). :func:`cached` reads a file back only if it is UTF-8 JSON of at most
:data:`MAX_BYTES`, of this format, kind and key, and passes the kind's own check; else it
says why in one line on stderr, computes the record again and replaces the file (an
unwritable file only costs the time). A file of an older format (before acld-gym 0.21.0:
without ``"format"``/``"kind"``, or format 2) is one such line, then recomputed.
"""

from __future__ import annotations

import hashlib
import json
import sys
from collections.abc import Callable
from pathlib import Path

import acld_gym
from acld_gym.envs.fingerprint import observation_fingerprint
from acld_gym.physics.plant_cache import user_cache_dir
from acld_gym.util.atomic import write_json

__all__ = ["FORMAT", "MAX_BYTES", "record_key", "env_inputs", "read_record", "cached", "cache_dir"]

#: Version of the records' layout and of the way references are computed (3: one format
#: for every kind; 2 was the test sets' alone, with the passive beam's ISE).
FORMAT = 3
#: The largest record read (100 episodes' references take ~7 kB).
MAX_BYTES = 16 * 2**20


def cache_dir() -> Path:
    """The user cache folder (:func:`acld_gym.physics.plant_cache.user_cache_dir`)."""
    return user_cache_dir()


def env_inputs(env) -> dict:
    """What an env's numbers depend on beyond its id: its whole configuration (actuator,
    temperature, parameter noise, ...) and its observation fingerprint (design, observer)."""
    return {"config": repr(env.unwrapped.config), "observation": observation_fingerprint(env)}


def record_key(inputs: dict) -> str:
    """16 hex digits of the SHA-256 of ``inputs`` (JSON-able), :data:`FORMAT` and the package
    version."""
    blob = json.dumps({"format": FORMAT, "acld_gym": acld_gym.__version__} | inputs, sort_keys=True)
    return hashlib.sha256(blob.encode()).hexdigest()[:16]


def read_record(path: Path, kind: str, key: str) -> dict | str:
    """The record in the file ``path`` if it is one of this format, ``kind`` and ``key``;
    else why not (total on any bytes: size, encoding, nesting, types)."""
    try:
        with open(path, "rb") as fh:
            data = fh.read(MAX_BYTES + 1)
    except OSError as exc:
        return f"unreadable: {exc.strerror or exc}"
    if len(data) > MAX_BYTES:
        return f"larger than {MAX_BYTES} bytes"
    try:
        rec = json.loads(data.decode("utf-8"))
    except RecursionError:
        return "not JSON (nested too deeply)"
    except (UnicodeDecodeError, ValueError) as exc:  # JSONDecodeError is a ValueError
        return f"not JSON ({str(exc)[:60]})"
    if not isinstance(rec, dict):
        return "not a mapping"
    fmt = rec.get("format")
    if type(fmt) is not int or fmt != FORMAT or rec.get("kind") != kind:
        return f"another format (the references need format {FORMAT}, kind {kind!r})"
    if rec.get("key") != key:
        return "another key (other inputs, or another version of the package)"
    return rec


def cached(
    path: Path | None,
    kind: str,
    key: str,
    compute: Callable[[], dict],
    check: Callable[[dict], str | None],
    what: str,
    required: bool = False,
) -> dict:
    """The record of ``kind`` and ``key`` from the file ``path`` if it passes
    :func:`read_record` and ``check`` (None: fine; a string: why not), else
    ``compute()`` (the payload) with its header, written to ``path`` atomically. ``path``
    None: computed, not cached. ``what`` names the references in the stderr line. A file
    that cannot be written costs only the time, unless ``required`` (then its ``OSError``)."""
    if path is not None and Path(path).is_file():
        rec = read_record(Path(path), kind, key)
        why = rec if isinstance(rec, str) else check(rec)
        if why is None:
            return rec
        print(f"baselines: recomputing {what} ({path}: {why})", file=sys.stderr)
    record = {"format": FORMAT, "kind": kind, "key": key} | compute()
    if path is not None:
        try:
            write_json(Path(path), record)
        except OSError:
            if required:
                raise
            # a read-only cache: computed again next time
    return record
