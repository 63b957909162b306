r"""The score's references on a test set: the passive beam's, the thesis LQR's and the
clairvoyant bound's ISE per episode, computed once per test set and cached.

For each episode of an :class:`acld_gym.test_sets.EvaluationSet` (its seed, through the env
as :func:`baselines.rollout.rollout` runs it) the references are the passive beam's ISE
(:class:`baselines.policies.PassivePolicy`: score v2's 0), the thesis LQR's
(:class:`baselines.policies.LQRPolicy` on the env's nominal design: the thesis-facing
column) and the bound's (:func:`baselines.rollout.bound_episode`, 20-120 ms an episode on
one BLAS thread: score v2's 1). A hundred episodes take about 10 s, so they are cached in
the user cache (:func:`acld_gym.physics.plant_cache.user_cache_dir`), in a JSON file whose
name carries a key: the SHA-256 of the test set, the env arguments, the env's whole
configuration (:class:`acld_gym.envs.config.EnvConfig`: the actuator, temperature and
parameter-noise settings of a preset too), its observation fingerprint (its design and
observer) and the package version.

A cached file is validated before use: its format (:data:`FORMAT`; a file of an older
format, without the passive ISE, is rejected with one line and recomputed), key, seeds and
lengths, every ISE finite and positive, the bound's below the passive and LQR's, and a spot
check -- the first episode is run again and must give the same three ISE to
:data:`SPOT_RTOL`. A file that fails is recomputed and rewritten (atomically), with a note
on stderr; an unwritable cache only costs the time.
"""

from __future__ import annotations

import hashlib
import json
import sys
from dataclasses import dataclass
from pathlib import Path

import gymnasium as gym
import numpy as np

import acld_gym
from acld_gym.envs.fingerprint import observation_fingerprint
from acld_gym.physics.plant_cache import user_cache_dir
from acld_gym.test_sets import EvaluationSet
from acld_gym.util.atomic import write_json
from acld_gym.util.progress import Progress
from baselines.policies import LQRPolicy, PassivePolicy
from baselines.rollout import bound_episode, metrics_row, rollout

__all__ = [
    "References",
    "references",
    "reference_episode",
    "make_env",
    "cache_path",
    "KINDS",
    "FORMAT",
    "SPOT_RTOL",
]

#: Version of the cache files' layout and of the way references are computed (2: with the
#: passive beam's ISE, score v2's anchor).
FORMAT = 2
#: Relative agreement of the spot check's re-run with the cached first episode.
SPOT_RTOL = 1e-6


@dataclass(frozen=True)
class References:
    """The passive beam's, the thesis LQR's and the bound's ISE [m^2 s] on each episode of
    the test set ``name``."""

    name: str
    seeds: tuple[int, ...]
    passive_ise: np.ndarray
    lqr_ise: np.ndarray
    bound_ise: np.ndarray


def make_env(test: EvaluationSet, env_kwargs: dict | None = None):
    """The env of the test set's episodes (``gym.make``, its load case)."""
    return gym.make(test.env_id, load_case=test.load_case, **(env_kwargs or {}))


#: The reference ISE arrays of a file and of :class:`References`, in this order.
KINDS = ("passive_ise", "lqr_ise", "bound_ise")


def reference_episode(env, seed: int) -> tuple[float, float, float]:
    """``(passive ISE, the thesis LQR's ISE, the bound's ISE)`` of the episode ``seed`` of
    ``env``."""
    passive, lqr = (
        metrics_row("test", cls.name, rollout(cls.for_env(env), env, seed=seed)).ise
        for cls in (PassivePolicy, LQRPolicy)
    )
    env.reset(seed=seed)
    bound = metrics_row("test", "bound", bound_episode(env)).ise
    return passive, lqr, bound


def _key(test: EvaluationSet, env_kwargs: dict, env) -> str:
    blob = json.dumps(
        {
            "format": FORMAT,
            "test_set": test.name,
            "env_id": test.env_id,
            "seeds": list(test.seeds),
            "load_case": test.load_case,
            "env_kwargs": env_kwargs,
            "acld_gym": acld_gym.__version__,
            "config": repr(env.unwrapped.config),  # actuator, temperature, ...
            "observation": observation_fingerprint(env),
        },
        sort_keys=True,
    )
    return hashlib.sha256(blob.encode()).hexdigest()[:16]


def cache_path(test: EvaluationSet, key: str) -> Path:
    safe = test.name.replace("/", "_")
    return user_cache_dir() / f"references-{safe}-{len(test.seeds)}-{key}.json"


#: The largest references file read (100 episodes take ~7 kB).
MAX_BYTES = 16 * 2**20


def _numbers(value, n: int) -> np.ndarray | None:
    """``value`` as a float array if it is a list of ``n`` JSON numbers (not bools), each
    finite and positive; else None."""
    if not isinstance(value, list) or len(value) != n:
        return None
    if not all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in value):
        return None
    try:
        a = np.array(value, dtype=float)
    except OverflowError:  # an integer beyond the float range
        return None
    return a if np.all(np.isfinite(a)) and np.all(a > 0) else None


def _damage(path: Path, test: EvaluationSet, key: str) -> list[np.ndarray] | str:
    """The file's three ISE arrays (:data:`KINDS`) if it is a record of ``test`` and
    ``key`` of the checked form, else why not: a structural check of every field the
    module reads, total on any bytes (size, encoding, nesting, types, lengths)."""
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
    fmt, k = rec.get("format"), rec.get("key")
    if type(fmt) is not int or fmt != FORMAT or not isinstance(k, str) or k != key:
        return f"another format (score v2's references need format {FORMAT}) or key"
    seeds = rec.get("seeds")
    if (
        not isinstance(seeds, list)
        or not all(type(s) is int for s in seeds)
        or seeds != list(test.seeds)
    ):
        return "other seeds"
    arrays = [_numbers(rec.get(kind), len(test.seeds)) for kind in KINDS]
    for kind, a in zip(KINDS, arrays, strict=True):
        if a is None:
            return f"{kind}: expected {len(test.seeds)} finite positive numbers"
    return arrays


def _validated(path: Path, test: EvaluationSet, key: str, env) -> References | None:
    """The file's references if every check of the module docstring passes, else None
    (with the reason on stderr)."""

    def reject(why: str) -> None:
        print(
            f"baselines: recomputing the references of {test.name} ({path}: {why})", file=sys.stderr
        )

    why = _damage(path, test, key)
    if isinstance(why, str):
        reject(why)
        return None
    arrays = why
    passive, lqr, bound = arrays
    if np.any(bound > np.minimum(lqr, passive) * (1 + 1e-9)):
        reject("a bound above the passive beam or LQR")
        return None
    spot = reference_episode(env, test.seeds[0])
    first = tuple(float(a[0]) for a in arrays)
    if not np.allclose(spot, first, rtol=SPOT_RTOL, atol=0.0):
        reject(f"the first episode gives {spot}, the file {first}")
        return None
    return References(test.name, test.seeds, *arrays)


def references(
    test: EvaluationSet, env_kwargs: dict | None = None, cache: bool = True, quiet: bool = True
) -> References:
    """The references of ``test`` (from the validated cache, else computed and cached);
    a progress line on a terminal unless ``quiet``."""
    kwargs = dict(env_kwargs or {})
    env = make_env(test, kwargs)
    key = _key(test, kwargs, env)
    path = cache_path(test, key)
    if cache and path.is_file():
        refs = _validated(path, test, key, env)
        if refs is not None:
            return refs
    n = len(test.seeds)
    arrays = np.empty((len(KINDS), n))
    with Progress(n, f"references {test.name}", quiet) as progress:
        for i, s in enumerate(test.seeds):
            progress.stage(f"episode {i + 1}/{n}")
            arrays[:, i] = reference_episode(env, s)
    if cache:
        record = {"format": FORMAT, "key": key, "test_set": test.name, "seeds": list(test.seeds)}
        try:
            write_json(
                path, record | {kind: a.tolist() for kind, a in zip(KINDS, arrays, strict=True)}
            )
        except OSError:
            pass  # a read-only cache: computed again next time
    return References(test.name, test.seeds, *arrays)
