r"""The score's references on a test set: the passive beam's, the thesis LQR's and the
clairvoyant bound's ISE per episode, computed once per test set and cached.

For each episode of an :class:`acld_gym.test_sets.EvaluationSet` (its seed, through the env
as :func:`baselines.evaluation.rollout.rollout` runs it) the references are the passive
beam's ISE (:class:`baselines.policies.PassivePolicy`: score v2's 0), the thesis LQR's
(:class:`baselines.policies.LQRPolicy` on the env's nominal design: the thesis-facing
column) and the bound's (:func:`baselines.evaluation.rollout.bound_episode`, 20-120 ms an
episode on one BLAS thread: score v2's 1). A hundred episodes take about 10 s, so they are
cached (:mod:`baselines.evaluation.cache`, kind :data:`KIND`) in the user cache, in a file
whose name carries the key: the SHA-256 of the test set, the env arguments, the env's whole
configuration (:class:`acld_gym.envs.config.EnvConfig`), its observation fingerprint and the
package version.

A cached file is validated before use: the cache's format, kind and key, then its seeds and
lengths, every ISE finite and positive, the bound's below the passive and LQR's, and a spot
check -- the first episode is run again and must give the same three ISE to
:data:`SPOT_RTOL`. A file that fails is recomputed and rewritten (atomically), with one line
on stderr; an unwritable cache only costs the time.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import gymnasium as gym
import numpy as np

from acld_gym.test_sets import EvaluationSet
from acld_gym.util.progress import Progress
from baselines.policies import LQRPolicy, PassivePolicy

from .cache import FORMAT, cache_dir, cached, env_inputs, record_key
from .rollout import bound_episode, metrics_row, rollout

__all__ = [
    "References",
    "references",
    "reference_episode",
    "make_env",
    "cache_path",
    "KIND",
    "KINDS",
    "FORMAT",
    "SPOT_RTOL",
]

#: The cache's kind of a test set's references (:mod:`baselines.evaluation.cache`).
KIND = "test-set references"
#: Relative agreement of the spot check's re-run with the cached first episode.
SPOT_RTOL = 1e-6
#: The reference ISE arrays of a file and of :class:`References`, in this order.
KINDS = ("passive_ise", "lqr_ise", "bound_ise")


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
    inputs = {
        "kind": KIND,
        "test_set": test.name,
        "env_id": test.env_id,
        "seeds": list(test.seeds),
        "load_case": test.load_case,
        "env_kwargs": env_kwargs,
    }
    return record_key(inputs | env_inputs(env))


def cache_path(test: EvaluationSet, key: str) -> Path:
    """The cache file of ``test``'s references under ``key``."""
    safe = test.name.replace("/", "_")
    return cache_dir() / f"references-{safe}-{len(test.seeds)}-{key}.json"


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


def _damage(rec: dict, test: EvaluationSet) -> list[np.ndarray] | str:
    """The record's three ISE arrays (:data:`KINDS`) if they are of ``test`` and of the
    checked form (:mod:`baselines.evaluation.cache` checked the header), else why not."""
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


def _check(rec: dict, test: EvaluationSet, env) -> str | None:
    """None if the record passes every check of the module docstring, else why not."""
    arrays = _damage(rec, test)
    if isinstance(arrays, str):
        return arrays
    passive, lqr, bound = arrays
    if np.any(bound > np.minimum(lqr, passive) * (1 + 1e-9)):
        return "a bound above the passive beam or LQR"
    spot = reference_episode(env, test.seeds[0])
    first = tuple(float(a[0]) for a in arrays)
    if not np.allclose(spot, first, rtol=SPOT_RTOL, atol=0.0):
        return f"the first episode gives {spot}, the file {first}"
    return None


def references(
    test: EvaluationSet, env_kwargs: dict | None = None, cache: bool = True, quiet: bool = True
) -> References:
    """The references of ``test`` (from the validated cache, else computed and cached);
    a progress line on a terminal unless ``quiet``."""
    kwargs = dict(env_kwargs or {})
    env = make_env(test, kwargs)
    key = _key(test, kwargs, env)

    def compute() -> dict:
        n = len(test.seeds)
        arrays = np.empty((len(KINDS), n))
        with Progress(n, f"references {test.name}", quiet) as progress:
            for i, s in enumerate(test.seeds):
                progress.stage(f"episode {i + 1}/{n}")
                arrays[:, i] = reference_episode(env, s)
        rec = {"test_set": test.name, "seeds": list(test.seeds)}
        return rec | {kind: a.tolist() for kind, a in zip(KINDS, arrays, strict=True)}

    rec = cached(
        cache_path(test, key) if cache else None,
        KIND,
        key,
        compute,
        lambda rec: _check(rec, test, env),
        f"the references of {test.name}",
    )
    arrays = [np.array(rec[kind], dtype=float) for kind in KINDS]
    return References(test.name, test.seeds, *arrays)
