"""The training loop's evaluation: learning curves, validation during training, and the
benchmark's references table.

The protocol itself -- rollout, seed blocks, the references and their one cache, the score
and the ISE-relative-to-LQR view -- is :mod:`baselines.evaluation`; this module keeps what
the training loop needs on top of it and re-exports the view's functions under their old
names (:func:`eval_episodes`, :func:`rollout_ise`, :func:`lqr_ise`, :func:`relative_ise`,
:func:`ise_rel_lqr`, :data:`HELDOUT_SEEDS`, :func:`validation_seeds`, ...):

* :func:`batched_ise`: every episode of a case in one native vector env, the policy
  called once per step on the batch (the learning curves; equal to
  :func:`baselines.evaluation.ise.rollout_ise` up to floating-point rounding);
* :func:`validation_cost`: a run's cost on the validation loads by the env's own reward
  (checkpoint and run selection);
* :func:`references`: every reference's ISE per case (LQR, SMC, MPC and the clairvoyant
  bound, ONLY to normalise and report the final numbers; no training loop ever sees them)
  and their validation costs, cached with :mod:`baselines.evaluation.cache`;
* :class:`eval_schedule`: when the learning curve is evaluated.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from pathlib import Path
from typing import Any

import gymnasium as gym
import numpy as np

from acld_gym.util.validate import DataFileError
from baselines.evaluation.cache import cached, env_inputs, record_key
from baselines.evaluation.ise import (  # re-exported: the view's home is baselines.evaluation.ise
    CASES,
    DEFAULT_ENV_ID,
    case_references,
    eval_episodes,
    ise_rel_lqr,
    lqr_ise,
    relative_ise,
    rollout_ise,
)
from baselines.evaluation.ise import case_env as _make_env
from baselines.evaluation.seeds import (  # re-exported: the seed blocks' home
    HELDOUT_SEEDS,
    OBJECTIVE_LOADS,
    VALIDATION_SEED0,
    validation_seeds,
)
from baselines.policies import LQRPolicy, policies_for

from .records import check_references

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
    "REFERENCES_KIND",
    "CurveCallback",
    "eval_schedule",
]

#: Learning-curve callback of a training run: ``callback(env_steps, policy)`` returns the
#: curve's point there (a mapping, or None): :func:`train.core.algos.train_algo`.
CurveCallback = Callable[[int, Any], Mapping | None]
#: The cache's kind of :func:`references` (:mod:`baselines.evaluation.cache`).
REFERENCES_KIND = "case references"


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


def references(
    env_id: str = DEFAULT_ENV_ID,
    cache: str | Path | None = None,
    random_episodes: int | None = None,
    bound: bool = True,
) -> dict[str, Any]:
    """Mean ISE per case of passive, LQR, SMC, MPC and the clairvoyant bound
    (:func:`baselines.evaluation.ise.case_references`), ``{"env_id": ..., "episodes": ...,
    "passive": {case: ise}, ...}`` (cases as strings), and the :func:`validation_cost` of
    passive, LQR and SMC on the first :data:`OBJECTIVE_LOADS` validation loads,
    ``"validation_cost": {name: cost}`` (the MPC's, a QP per load and step, and the
    bound's are left out: not needed to read the agents' figure, and slow), with the
    header of :mod:`baselines.evaluation.cache` (``format``, ``kind``, ``key``).

    Read from ``cache`` (JSON) when it is a record of the same env (id, configuration,
    observation), episodes and package version that passes
    :func:`train.core.records.check_references`, else computed (the bound takes about
    30 s) and written there atomically (a file of an older format: one line on stderr,
    then computed again). ``cache`` None: computed, not written.
    """
    episodes = eval_episodes(random_episodes)
    env = _make_env(env_id, 1)
    inputs = {
        "kind": REFERENCES_KIND,
        "env_id": env_id,
        "episodes": {str(c): list(s) for c, s in episodes.items()},
        "objective_loads": OBJECTIVE_LOADS,
    }

    def compute() -> dict:
        # passive, LQR, SMC and MPC designed on env_id's own nominal model and observation
        # (to report the evaluation only, never in training)
        pols = policies_for(env)
        data = case_references(env_id, episodes, bound, pols)
        loads = validation_seeds(OBJECTIVE_LOADS)
        data["validation_cost"] = {
            name: validation_cost(pols[name], env_id, loads) for name in ("passive", "lqr", "smc")
        }
        return data

    def check(rec: dict) -> str | None:
        try:
            check_references(rec, cache, bound)
        except DataFileError as exc:
            return str(exc)
        return None

    key = record_key(inputs | env_inputs(env))
    what = f"the references of {env_id}"
    return cached(cache, REFERENCES_KIND, key, compute, check, what, required=True)


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
