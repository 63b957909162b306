r"""Gymnasium wrappers that help every RL library on ACLDBeam (not one algorithm's code).

* :class:`UnitAction`: actions in [-1, 1] instead of volts. A standard Gaussian policy
  (unit std) explores +/-1 V on the +/-120 V actuator without it and learns nothing.
* :class:`WhitenObservation`: a fixed linear map of the observation, ``u = T^T z``, e.g.
  :func:`whitening` of observation directions collected with an initial policy.

The reward per load is an env option, not a wrapper, because it needs the episode's load:
``reward_scale="passive"`` (:mod:`acld_gym.envs.scale`), with ``observe_reward_scale`` for
an asymmetric critic.

Example::

    import gymnasium as gym
    import acld_gym
    from acld_gym.wrappers import UnitAction

    env = UnitAction(gym.make("ACLDBeam-v1", load_case="random", reward_scale="passive"))
"""

from __future__ import annotations

import gymnasium as gym
import numpy as np
from gymnasium import spaces

__all__ = ["UnitAction", "WhitenObservation", "whitening"]


class UnitAction(gym.ActionWrapper):
    r"""Actions ``a`` in [-1, 1] for an env whose action is a voltage in [-v_max, v_max]:
    ``V = v_max a``, computed in float64, so the round trip :meth:`reverse_action` of
    :meth:`action` is exact for every float32 action (v_max = 120 V is 15 2^3: a float32
    times it is exact in float64, and so is the division back). Out-of-range actions are
    passed on scaled, and the env clips and reports them (``info["clipped"]``), as it
    does for volts."""

    def __init__(self, env: gym.Env):
        super().__init__(env)
        box = env.action_space
        if not (isinstance(box, spaces.Box) and box.shape == (1,)
                and np.all(box.low == -box.high) and np.all(box.high > 0)):
            raise ValueError(f"env: UnitAction needs a symmetric 1-D Box action space "
                             f"(-v_max, v_max), got {box!r}")
        self.v_max = float(box.high[0])
        self.action_space = spaces.Box(-1.0, 1.0, (1,), np.float32)

    def action(self, action):
        return self.v_max * np.asarray(action, dtype=np.float64)

    def reverse_action(self, action):
        return (np.asarray(action, dtype=np.float64) / self.v_max).astype(np.float32)


class WhitenObservation(gym.ObservationWrapper):
    r"""The observation ``z`` as ``[T^T z_{:d}, z_{d:}]``: a fixed matrix T (d x d) on its
    first d entries, the last ``passthrough`` (e.g. the appended log reward scale) as they
    are. T is given (e.g. :func:`whitening`), not learned while the wrapper runs, so the
    wrapped env stays a fixed MDP."""

    def __init__(self, env: gym.Env, transform, passthrough: int = 0):
        super().__init__(env)
        n = env.observation_space.shape[0]
        if isinstance(passthrough, bool) or not isinstance(passthrough, (int, np.integer)) \
                or not 0 <= passthrough < n:
            raise ValueError(f"passthrough must be an integer in [0, {n}), got {passthrough!r}")
        d = n - int(passthrough)
        T = np.asarray(transform, dtype=np.float64)
        if T.shape != (d, d) or not np.all(np.isfinite(T)):
            raise ValueError(f"transform must be a finite ({d}, {d}) matrix, got shape "
                             f"{T.shape}")
        self.transform, self.passthrough, self._d = T, int(passthrough), d
        self.observation_space = spaces.Box(-np.inf, np.inf, (n,), np.float32)

    def observation(self, observation):
        z = np.asarray(observation, dtype=np.float64)
        return np.concatenate([z[:self._d] @ self.transform, z[self._d:]]).astype(np.float32)


def whitening(directions: np.ndarray, ridge: float = 1e-3) -> np.ndarray:
    r"""ZCA whitening matrix :math:`T = \Sigma^{-1/2}` (ridge-regularised, relative to the
    largest eigenvalue) of the second moment of the observation directions ``z/|z|``
    (rows), so that the direction features of ``z @ T`` are isotropic on average."""
    u = np.asarray(directions, dtype=np.float64)
    if u.ndim != 2 or u.shape[0] < 1 or not np.all(np.isfinite(u)):
        raise ValueError(f"directions must be a finite (n, d) array with n >= 1, got shape "
                         f"{u.shape}")
    sigma = u.T @ u / u.shape[0]
    lam, vec = np.linalg.eigh(sigma)
    lam = np.maximum(lam, 0.0) + ridge * lam.max()
    return (vec / np.sqrt(lam)) @ vec.T
