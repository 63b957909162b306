"""The thesis-facing view: ISE relative to the thesis LQR on thesis cases 1, 2, 3 and the
held-out random loads.

A policy's mean ISE per case (:func:`rollout_ise`: one deterministic single-env episode per
seed, :func:`baselines.evaluation.rollout.rollout`) divided by the LQR's designed on the
same level (:func:`lqr_ise`): thesis cases 1, 2, 3 with seed 0 and the held-out random
loads :data:`baselines.evaluation.seeds.HELDOUT_SEEDS` (:func:`eval_episodes`; ``ISE / LQR``
there is the mean ISE over the set divided by LQR's mean). Below 1: better than the thesis
LQR. :func:`case_references` is every reference's mean ISE per case (passive, LQR, SMC,
MPC, the clairvoyant bound), the table the training benchmark reports its agents against
(``train.core.evaluate.references`` caches it with :mod:`baselines.evaluation.cache`). The
score on the test sets is the other view (:mod:`baselines.evaluation.score`).
"""

from __future__ import annotations

import functools

import gymnasium as gym
import numpy as np

import acld_gym  # registers the env ids
from acld_gym.physics.loads import LOAD_CASES
from baselines.policies import LQRPolicy, policies_for

from .rollout import bound_episode, metrics_row, rollout
from .seeds import HELDOUT_SEEDS

__all__ = [
    "CASES",
    "DEFAULT_ENV_ID",
    "eval_episodes",
    "case_env",
    "rollout_ise",
    "lqr_ise",
    "relative_ise",
    "ise_rel_lqr",
    "bound_ise",
    "case_references",
]

DEFAULT_ENV_ID = acld_gym.ENV_ID
#: Evaluation cases, in table order (every named load case).
CASES: tuple = LOAD_CASES


def eval_episodes(random_episodes: int | None = None) -> dict:
    """``{case: seeds}``: seed 0 for the thesis cases, the held-out seeds (all 20, or the
    first ``random_episodes``) for ``"random"``."""
    n = len(HELDOUT_SEEDS) if random_episodes is None else int(random_episodes)
    return {1: (0,), 2: (0,), 3: (0,), "random": tuple(HELDOUT_SEEDS[:n])}


def case_env(env_id: str, case):
    """The env of ``env_id`` on load case ``case``, without wrappers (it truncates by
    itself)."""
    return gym.make(env_id, load_case=case).unwrapped


def rollout_ise(policy, env_id: str = DEFAULT_ENV_ID, episodes: dict | None = None) -> dict:
    """Mean ISE [m^2 s] per case of ``policy`` (SB3 ``predict`` in volts), one single-env
    episode per seed of ``episodes`` (default :func:`eval_episodes`)."""
    episodes = eval_episodes() if episodes is None else episodes
    out = {}
    for case, seeds in episodes.items():
        env = case_env(env_id, case)
        out[case] = float(
            np.mean([metrics_row(case, "agent", rollout(policy, env, seed=s)).ise for s in seeds])
        )
    return out


def lqr_ise(env_id: str = DEFAULT_ENV_ID, episodes: dict | None = None) -> dict:
    """Mean ISE [m^2 s] per case of the LQR designed on ``env_id`` (:func:`rollout_ise`),
    the yardstick of ISE / LQR, without designing the other references. Computed once per
    process for an id and a set of episodes (the design and the episodes are deterministic),
    a fresh dict each call."""
    episodes = eval_episodes() if episodes is None else episodes
    key = tuple((c, tuple(int(s) for s in seeds)) for c, seeds in episodes.items())
    return dict(_lqr_ise(env_id, key))


@functools.lru_cache(maxsize=32)
def _lqr_ise(env_id: str, episodes: tuple) -> tuple:
    lqr = LQRPolicy.for_env(case_env(env_id, 1))
    return tuple(rollout_ise(lqr, env_id, dict(episodes)).items())


def relative_ise(ise: dict, refs: dict, to: str = "lqr") -> dict:
    """``{case: ise[case] / refs[to][case]}`` (keys of ``refs`` may be strings, as in JSON)."""
    ref = refs[to]
    return {c: ise[c] / ref[str(c)] if str(c) in ref else ise[c] / ref[c] for c in ise}


def ise_rel_lqr(policy, env_id: str = DEFAULT_ENV_ID, episodes: dict | None = None) -> dict:
    """``{case: ISE / ISE_LQR}`` of ``policy`` on ``episodes`` (default
    :func:`eval_episodes`), both by :func:`rollout_ise`, LQR designed on ``env_id``."""
    episodes = eval_episodes() if episodes is None else episodes
    ise = rollout_ise(policy, env_id, episodes)
    return relative_ise(ise, {"lqr": lqr_ise(env_id, episodes)})


def bound_ise(env_id: str = DEFAULT_ENV_ID, episodes: dict | None = None) -> dict:
    """Mean ISE [m^2 s] per case of the clairvoyant bound
    (:func:`baselines.evaluation.rollout.bound_episode`) on ``episodes``."""
    episodes = eval_episodes() if episodes is None else episodes
    out = {}
    for case, seeds in episodes.items():
        env = case_env(env_id, case)
        vals = []
        for s in seeds:
            env.reset(seed=s)
            vals.append(metrics_row(case, "bound", bound_episode(env)).ise)
        out[case] = float(np.mean(vals))
    return out


def case_references(
    env_id: str = DEFAULT_ENV_ID,
    episodes: dict | None = None,
    bound: bool = True,
    policies: dict | None = None,
) -> dict:
    """``{"env_id", "episodes": {case: seeds}, name: {case: mean ISE}, ...}`` (cases as
    strings) of passive, LQR, SMC and MPC designed on ``env_id``'s own nominal model and
    observation (:func:`baselines.policies.policies_for`; or ``policies``, name ->
    ``predict``), and of the clairvoyant bound with ``bound``."""
    episodes = eval_episodes() if episodes is None else episodes
    pols = policies_for(case_env(env_id, 1)) if policies is None else policies
    data: dict = {"env_id": env_id, "episodes": {str(c): list(s) for c, s in episodes.items()}}
    for name, pol in pols.items():
        data[name] = {str(c): v for c, v in rollout_ise(pol, env_id, episodes).items()}
    if bound:
        data["bound"] = {str(c): v for c, v in bound_ise(env_id, episodes).items()}
    return data
