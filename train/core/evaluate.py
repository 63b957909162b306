"""Evaluation for the teacher-free benchmark (``python -m train.benchmark``).

The agents are scored by ISE / ISE_LQR through the env (+/-120 V, 1 ms, default Kalman
observer, deterministic policy): thesis cases 1, 2, 3 with seed 0 and the held-out
random set (:data:`HELDOUT_SEEDS`; ``ISE / LQR`` there is the mean ISE
over the set divided by LQR's mean, as in ``python -m train.compare``). LQR, SMC,
MPC and the clairvoyant bound are computed here ONLY to normalise and report the
final numbers; no training loop ever sees them.

Two evaluators:

* :func:`rollout_ise`: one single-env episode per (case, seed) with
  :func:`baselines.evaluate.rollout` (the final numbers and the references);
* :func:`batched_ise`: every episode of a case in one native vector env, the policy
  called once per step on the batch (the learning curves; equal to the former up
  to floating-point rounding).
"""

from __future__ import annotations

import json
import sys
from collections.abc import Callable, Mapping
from pathlib import Path
from typing import Any

import gymnasium as gym
import numpy as np

import acld_gym  # registers the env ids
from acld_gym.physics.loads import LOAD_CASES
from acld_gym.test_sets import (  # noqa: F401 (the seed blocks' home; re-exported)
    HELDOUT_SEEDS,
    VALIDATION_SEED0,
    validation_seeds,
)
from acld_gym.util.atomic import write_text
from acld_gym.util.validate import DataFileError

from .records import check_references, read_json

__all__ = [
    "CASES",
    "DEFAULT_ENV_ID",
    "HELDOUT_SEEDS",
    "eval_episodes",
    "rollout_ise",
    "batched_ise",
    "relative_ise",
    "VALIDATION_SEED0",
    "OBJECTIVE_LOADS",
    "validation_seeds",
    "validation_cost",
    "validation_rollout",
    "lqr_validation_cost",
    "ise_rel_lqr",
    "lqr_ise",
    "references",
    "CurveCallback",
    "eval_schedule",
]

DEFAULT_ENV_ID = acld_gym.ENV_ID
#: Learning-curve callback of a training run: ``callback(env_steps, policy)`` returns the
#: curve's point there (a mapping, or None): :func:`train.core.algos.train_algo`.
CurveCallback = Callable[[int, Any], Mapping | None]
#: Evaluation cases, in table order (every named load case).
CASES: tuple = LOAD_CASES


def eval_episodes(random_episodes: int | None = None) -> dict:
    """``{case: seeds}``: seed 0 for the thesis cases, the held-out seeds (all 20, or the
    first ``random_episodes``) for ``"random"``."""
    n = len(HELDOUT_SEEDS) if random_episodes is None else int(random_episodes)
    return {1: (0,), 2: (0,), 3: (0,), "random": tuple(HELDOUT_SEEDS[:n])}


def _make_env(env_id: str, case):
    """The env of ``env_id`` without wrappers (it truncates by itself)."""
    return gym.make(env_id, load_case=case).unwrapped


def rollout_ise(policy, env_id: str = DEFAULT_ENV_ID, episodes: dict | None = None) -> dict:
    """Mean ISE [m^2 s] per case of ``policy`` (SB3 ``predict`` in volts), one single-env
    episode per seed (:func:`baselines.evaluate.rollout`)."""
    from baselines.evaluate import metrics_row, rollout

    episodes = eval_episodes() if episodes is None else episodes
    out = {}
    for case, seeds in episodes.items():
        env = _make_env(env_id, case)
        out[case] = float(
            np.mean([metrics_row(case, "agent", rollout(policy, env, seed=s)).ise for s in seeds])
        )
    return out


def batched_ise(policy, env_id: str = DEFAULT_ENV_ID, episodes: dict | None = None) -> dict:
    """Mean ISE [m^2 s] per case, all episodes side by side (one native vector env per
    case, stepped together; ``policy.predict`` once per step on the whole batch)."""
    episodes = eval_episodes() if episodes is None else episodes
    venvs, obs = [], []
    for case, seeds in episodes.items():
        venv = gym.make_vec(env_id, num_envs=len(seeds), load_case=case)
        obs.append(venv.reset(seed=[int(s) for s in seeds])[0])
        venvs.append(venv)
    dt = venvs[0].unwrapped.dt
    ise, _ = _side_by_side(policy, venvs, obs, lambda r, info: info["tip_deflection"] ** 2 * dt)
    return {case: float(part.mean()) for case, part in zip(episodes, ise, strict=True)}


def _side_by_side(policy, venvs: list, obs: list, value) -> tuple[list, list]:
    """Run one episode in every sub-env of ``venvs`` (already reset, first observations
    ``obs``), side by side: the deterministic ``policy.predict`` once per step on all of
    them, each sub-env counted until it ends; a policy with a state (SB3's recurrent
    protocol: an engineer's reference's filter, :class:`baselines.policies.MeasurementFeedback`'s
    observer) gets it back at every step, with ``episode_start`` true at the first.
    Returns, one array per vector env, the sum over
    each sub-env's steps of ``value(reward, info)`` and its step count; closes the vector
    envs."""
    sizes = np.cumsum([venv.num_envs for venv in venvs])[:-1]
    n = sum(venv.num_envs for venv in venvs)
    total, steps = np.zeros(n), np.zeros(n)
    alive = np.ones(n, dtype=bool)
    state, start = None, np.ones(n, dtype=bool)  # SB3's recurrent protocol, as rollout()'s
    while alive.any():
        act, state = policy.predict(
            np.concatenate(obs), state=state, episode_start=start, deterministic=True
        )
        start = np.zeros(n, dtype=bool)  # a sub-env that ends is not counted afterwards
        act = np.asarray(act, dtype=np.float64).reshape(-1, 1)
        obs, got, done = [], [], []
        for venv, a in zip(venvs, np.split(act, sizes), strict=True):
            o, r, term, trunc, info = venv.step(a)
            obs.append(o)
            got.append(value(r, info))
            done.append(term | trunc)
        total += np.where(alive, np.concatenate(got), 0.0)
        steps += alive
        alive &= ~np.concatenate(done)
    for venv in venvs:
        venv.close()
    return np.split(total, sizes), np.split(steps, sizes)


#: Validation loads of the benchmark's per-seed objective figure (``validation_cost`` in a
#: trial's record and the report): the 256 the recipes select their runs on
#: (``select: {episodes: 256}`` in ``train/recipes/ppo.yaml`` and ``sac.yaml``).
OBJECTIVE_LOADS = 256


def validation_cost(policy, env_id: str = DEFAULT_ENV_ID, seeds=None) -> float:
    r"""The deterministic ``policy``'s cost on the random loads of ``seeds``, by the env's own
    reward per load (``reward_scale="passive"``, :mod:`acld_gym.envs.scale`):

    .. math:: J = \frac{1}{N} \sum_{i=1}^{N} \frac{-1}{T_i} \sum_{t < T_i} r_{i,t},

    the mean over the episodes of the step cost divided by the passive beam's on the same
    load, so 1 for the passive beam and lower is better. No reference controller enters it;
    all episodes run side by side in one native vector env. ``seeds``: default the first 32
    validation seeds (:func:`validation_seeds`). :func:`validation_rollout` also gives the
    env steps it took."""
    return validation_rollout(policy, env_id, seeds)[0]


def lqr_validation_cost(env_id: str = DEFAULT_ENV_ID, seeds=None) -> float:
    """:func:`validation_cost` of the LQR designed on ``env_id``
    (:meth:`baselines.policies.LQRPolicy.for_env`) on the loads of ``seeds``: the level a
    trained policy has to beat there."""
    from baselines.policies import LQRPolicy

    return validation_cost(LQRPolicy.for_env(_make_env(env_id, 1)), env_id, seeds)


def validation_rollout(policy, env_id: str = DEFAULT_ENV_ID, seeds=None) -> tuple[float, int]:
    """``(cost, env_steps)``: :func:`validation_cost` and the env steps of its episodes."""
    seeds = [int(s) for s in (validation_seeds(32) if seeds is None else seeds)]
    if not seeds:
        raise ValueError("seeds must hold at least one random-load seed, got none")
    venv = gym.make_vec(env_id, num_envs=len(seeds), load_case="random", reward_scale="passive")
    obs, _ = venv.reset(seed=seeds)
    (ret,), (steps,) = _side_by_side(policy, [venv], [obs], lambda r, info: r)
    return float(np.mean(-ret / steps)), int(steps.sum())


def relative_ise(ise: dict, refs: dict, to: str = "lqr") -> dict:
    """``{case: ise[case] / refs[to][case]}`` (keys of ``refs`` may be strings, as in JSON)."""
    ref = refs[to]
    return {c: ise[c] / ref[str(c)] if str(c) in ref else ise[c] / ref[c] for c in ise}


def ise_rel_lqr(policy, env_id: str = DEFAULT_ENV_ID, episodes: dict | None = None) -> dict:
    """``{case: ISE / ISE_LQR}`` of ``policy`` on ``episodes`` (default
    :func:`eval_episodes`), both by :func:`rollout_ise`, LQR designed on ``env_id``: the
    figure of a policy trained outside the benchmark (``benchmarks/zoo_eval.py``,
    ``benchmarks/single_file_ppo.py``)."""
    episodes = eval_episodes() if episodes is None else episodes
    ise = rollout_ise(policy, env_id, episodes)
    return relative_ise(ise, {"lqr": lqr_ise(env_id, episodes)})


def lqr_ise(env_id: str = DEFAULT_ENV_ID, episodes: dict | None = None) -> dict:
    """Mean ISE [m^2 s] per case of the LQR designed on ``env_id`` (:func:`rollout_ise`),
    the yardstick of ISE / LQR, without designing the other references."""
    from baselines.policies import LQRPolicy

    lqr = LQRPolicy.for_env(_make_env(env_id, 1))
    return rollout_ise(lqr, env_id, eval_episodes() if episodes is None else episodes)


def _cached_references(cache, bound: bool) -> dict | None:
    """The references cache file ``cache`` if it is whole (:func:`train.core.records.
    check_references`); None when there is none, and when it is damaged (said in one line:
    it is computed again)."""
    if cache is None or not Path(cache).is_file():
        return None
    try:
        return check_references(read_json(cache), cache, bound)
    except DataFileError as exc:
        print(f"{exc}: computing the references again", file=sys.stderr)
        return None


def references(
    env_id: str = DEFAULT_ENV_ID,
    cache: str | Path | None = None,
    random_episodes: int | None = None,
    bound: bool = True,
) -> dict[str, Any]:
    """Mean ISE per case of passive, LQR, SMC, MPC and the clairvoyant bound,
    ``{"env_id": ..., "episodes": ..., "passive": {case: ise}, ...}`` (cases as strings),
    and the :func:`validation_cost` of passive, LQR and SMC on the first
    :data:`OBJECTIVE_LOADS` validation loads, ``"validation_cost": {name: cost}`` (the
    MPC's, a QP per load and step, and the bound's are left out: not needed to read the
    agents' figure, and slow).

    Read from ``cache`` (JSON) when it holds the same env id and episodes, else computed
    (the bound takes about 30 s) and written there atomically.
    """
    from baselines.evaluate import bound_episode, metrics_row, policies_for

    episodes = eval_episodes(random_episodes)
    key = {str(c): list(s) for c, s in episodes.items()}
    data = _cached_references(cache, bound)
    if data is not None:
        if (
            data.get("env_id") == env_id
            and data.get("episodes") == key
            and (not bound or "bound" in data)
            and "validation_cost" in data
        ):
            return data
    # passive, LQR, SMC and MPC designed on env_id's own nominal model and observation
    # (to report the evaluation only, never in training)
    pols = policies_for(_make_env(env_id, 1))
    data: dict[str, Any] = {"env_id": env_id, "episodes": key}
    for name, pol in pols.items():
        data[name] = {str(c): v for c, v in rollout_ise(pol, env_id, episodes).items()}
    loads = validation_seeds(OBJECTIVE_LOADS)
    data["validation_cost"] = {
        name: validation_cost(pols[name], env_id, loads) for name in ("passive", "lqr", "smc")
    }
    if bound:
        data["bound"] = {}
        for case, seeds in episodes.items():
            env = _make_env(env_id, case)
            vals = []
            for s in seeds:
                env.reset(seed=s)
                vals.append(metrics_row(case, "bound", bound_episode(env)).ise)
            data["bound"][str(case)] = float(np.mean(vals))
    if cache is not None:
        write_text(cache, json.dumps(data, indent=2) + "\n")
    return data


class eval_schedule:  # noqa: N801  (used like a function)
    """Learning-curve evaluations: at step 0 and at ``points`` env-step counts spaced
    logarithmically from 1 % of ``budget`` to ``budget``; :meth:`due` is true once per
    threshold crossed."""

    def __init__(self, budget: int, points: int):
        self.thresholds = sorted({int(round(x)) for x in budget * np.logspace(-2, 0, points)})
        self.thresholds = [0] + [t for t in self.thresholds if t > 0]
        self._next = 0

    def due(self, steps: int) -> bool:
        if self._next >= len(self.thresholds) or steps < self.thresholds[self._next]:
            return False
        while self._next < len(self.thresholds) and steps >= self.thresholds[self._next]:
            self._next += 1
        return True
