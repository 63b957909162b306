"""The env's step as algebra: one period of plant and observer as one matrix, the fused output
matrix of the whole step, the load schedule, the reward and the end of an episode."""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np

from acld_gym.design.discrete import SampledSystem
from acld_gym.design.observer import DiscreteObserver
from acld_gym.physics.loads import TipLoad

if TYPE_CHECKING:
    from acld_gym.envs.episode import Nominal

__all__ = ["Y_SCALE", "observation_size", "estimate_map", "step_matrix", "output_matrix",
           "load_schedule", "reward_of", "termination"]


#: Deflection scale of the observations [m].
Y_SCALE = 1e-3


def observation_size(nom: Nominal, obs_mode: str, hist: int) -> int:
    return {"estimate": nom.design.reduced.order + 1, "measurement": hist + 1,
            "full": nom.plant.Ad.shape[0]}[obs_mode]


def estimate_map(obs: DiscreteObserver, xr_scale: np.ndarray) -> np.ndarray:
    """Matrix M with ``[xhat, y] @ M`` = the scaled x_r estimate after the measurement
    update, ``T (xhat + L_c (y - C xhat)) / xr_scale``."""
    lc = obs.Lc[:, 0]
    M = np.vstack([(obs.T @ (np.eye(obs.n) - np.outer(lc, obs.C[0]))).T, (obs.T @ lc)[None, :]])
    return M / xr_scale


def step_matrix(plant: SampledSystem, nom_plant: SampledSystem,
                obs: DiscreteObserver) -> np.ndarray:
    """One period of plant and observer as one matrix S:
    ``[x', xhat'] = S [x, xhat, y_prev, V, f0, f1]`` with ``y_prev`` the last
    measurement, ``f0, f1`` the period's load samples (:func:`load_schedule`).
    The plant may be randomized; the observer uses the nominal load weights."""
    n, k, s = plant.Ad.shape[0], obs.n, plant.substeps
    S = np.zeros((n + k, n + k + 2 + 2 * s))
    S[:n, :n] = plant.Ad
    S[:n, n + k + 1] = plant.Bd[:, 0]
    S[:n, n + k + 2:] = np.hstack([plant.W0, plant.W1])
    lp = obs.Lp[:, 0]
    S[n:, n:n + k] = obs.A - np.outer(lp, obs.C[0])
    S[n:, n + k] = lp
    S[n:, n + k + 1] = obs.B[:, 0]
    if obs.fed_load:
        S[n:, n + k + 2:] = np.hstack([nom_plant.W0, nom_plant.W1])
    return S


def output_matrix(S: np.ndarray, n: int, k: int, output: np.ndarray, SL: np.ndarray,
                  est: np.ndarray) -> np.ndarray:
    """The single env's whole step as one matrix G, from :func:`step_matrix` S.

    Input ``z = [x, xhat, y_meas, V, f0, f1, w']`` (S's input and the noise w' of the
    new measurement); output ``G z = [x', xhat', y_meas', y', x_r', e', y_meas' / Y_SCALE]``
    with ``y' = output @ x'`` the true tip deflection, ``y_meas' = y' + w'``,
    ``x_r' = S_L^T x'`` the true reduced state and ``e' = [xhat', y_meas'] M`` the
    scaled estimate (:func:`estimate_map` M). So ``(G z)[:n+k+1]`` is the next state
    and ``(G z)[-7:]`` the ``"estimate"`` observation.
    """
    X = np.hstack([S[:n + k], np.zeros((n + k, 1))])
    y = output @ X[:n]
    y_meas = y.copy()
    y_meas[-1] = 1.0
    e = est[:k].T @ X[n:] + np.outer(est[k], y_meas)
    return np.vstack([X, y_meas, y, SL.T @ X[:n], e, y_meas / Y_SCALE])


def load_schedule(plant: SampledSystem, load: TipLoad, start: int,
                  stop: int) -> tuple[np.ndarray, np.ndarray]:
    """Load samples of periods ``start .. stop-1``: ``(F, tip)`` with F (steps, 2 substeps)
    ``[f0, f1]`` as :meth:`SampledSystem.load_samples` and tip (steps + 1,) the load at
    the period starts ``k dt`` (for ``info``)."""
    k = np.arange(start, stop + 1)
    tt = (k[:-1] * plant.dt)[:, None] + plant.times
    eps = 1e-9 * plant.dt
    F = np.hstack([load(tt[:, :-1] + eps), load(tt[:, 1:] - eps)])
    return F, load(k * plant.dt)


def termination(y: float, reward: float, state: np.ndarray, limit: float) -> str | None:
    """Why a step ends the episode: ``"non_finite_state"`` if the new state or the reward
    is not finite (never passed off as a normal step), ``"deflection_limit"`` if
    |y| > ``limit``; else None."""
    if not (math.isfinite(reward) and np.isfinite(state).all()):
        return "non_finite_state"
    if not abs(y) <= limit:
        return "deflection_limit"
    return None


def reward_of(y, v, y_ref: float, lam: float, v_max: float):
    """``-(y / y_ref)^2 - lam (V / v_max)^2`` (scalars or arrays)."""
    return -((y / y_ref) ** 2) - lam * (v / v_max) ** 2
