"""The offline search behind each level's design (:data:`baselines.engineer.designs.
DESIGNS`): what an engineer computes from the level's description before deploying, on
episodes of their own -- never the published test set's.

The search runs each candidate LQG (:class:`~baselines.engineer.lqg.DelayLQGPolicy` with a
deflection weight and a Kalman noise model) on training episodes of the level -- random
loads and, on a randomized level, plants drawn from the level's distribution (temperature,
parameter scatter), reset with :data:`TRAINING_SEEDS`, a block disjoint from every test set
(:data:`acld_gym.test_sets.RESERVED_SEEDS`) and from model selection's seeds -- and scores it
as the fixed-anchor score does: per episode (ISE_passive - ISE) / (ISE_passive - ISE_bound),
the interquartile mean over the episodes. A candidate is admissible when its small-signal
loop is stable on every plant of the stability seeds, with a margin: a spectral radius at
most :data:`RADIUS_MARGIN`.
"""

from __future__ import annotations

import itertools

import numpy as np

from acld_gym.test_sets import RESERVED_SEEDS
from acld_gym.util.stats import iqm
from acld_gym.util.validate import check_int

from .. import arguments
from ..policies import PassivePolicy
from ..rollout import bound_episode
from .designs import design_kwargs
from .loop import env_plant, spectral_radius
from .lqg import DelayLQGPolicy

__all__ = ["TRAINING_SEEDS", "RADIUS_MARGIN", "episode_ise", "search", "grid"]

#: The search's episodes: far from the test sets' reserved block and model selection's
#: seeds (:mod:`acld_gym.test_sets`).
TRAINING_SEEDS = range(3_000_000, 3_000_100)
assert not set(TRAINING_SEEDS) & set(RESERVED_SEEDS)

#: Largest admissible spectral radius of the small-signal loop on a training plant.
RADIUS_MARGIN = 0.9995


def episode_ise(policy, env, seed: int) -> float:
    """The tip's ISE [m^2 s] of one episode of ``policy`` in ``env`` (SB3 protocol)."""
    obs, _ = env.reset(seed=seed)
    state, start, total, done = None, np.ones(1, bool), 0.0, False
    while not done:
        action, state = policy.predict(obs, state=state, episode_start=start)
        start = np.zeros(1, bool)
        obs, _, term, trunc, info = env.step(action)
        total += float(info["tip_deflection"]) ** 2
        done = term or trunc
    return total * env.unwrapped.dt


def _anchors(env, seeds) -> tuple[np.ndarray, np.ndarray]:
    """The passive beam's and the clairvoyant bound's ISE on each episode."""
    passive = PassivePolicy.for_env(env)
    pas, bnd = [], []
    for s in seeds:
        pas.append(episode_ise(passive, env, s))
        env.reset(seed=s)
        bnd.append(float(np.sum(bound_episode(env).y ** 2)) * env.unwrapped.dt)
    return np.array(pas), np.array(bnd)


def search(env, candidates, n_episodes: int = 40, n_plants: int = 100) -> list:
    """Each candidate design's training score and worst spectral radius, the admissible
    ones first, best first: a list of ``(iqm, radius, design)``. ``env`` is the level's
    env with ``load_case="random"``; a design is a dict of :data:`~baselines.engineer.
    designs.DESIGNS`' form."""
    e = arguments.acld_env(env, ids=False)  # an env in an episode
    n_episodes = check_int("n_episodes", n_episodes, 1, len(TRAINING_SEEDS))
    n_plants = check_int("n_plants", n_plants, 1, len(TRAINING_SEEDS))
    seeds = list(TRAINING_SEEDS)[:n_episodes]
    pas, bnd = _anchors(env, seeds)
    plants = []
    for s in list(TRAINING_SEEDS)[: n_plants if e.config.randomized else 1]:
        env.reset(seed=s)
        plants.append(env_plant(env))
    out = []
    for design in candidates:
        pol = DelayLQGPolicy(e.nom, e.config, **design_kwargs(e.nom, e.config, design))
        radius = max(spectral_radius(pol, *p) for p in plants)
        ise = np.array([episode_ise(pol, env, s) for s in seeds])
        out.append((iqm((pas - ise) / (pas - bnd)), radius, design))
    return sorted(out, key=lambda r: (r[1] > RADIUS_MARGIN, -r[0]))


def grid(**values) -> list[dict]:
    """The candidate designs of every combination of ``values`` (name -> list), e.g.
    ``grid(model_std=[0, 0.03], load_std=[1, 3])``; a None value leaves the key out."""
    names = list(values)
    return [
        {k: v for k, v in zip(names, combo, strict=True) if v is not None}
        for combo in itertools.product(*(values[k] for k in names))
    ]
