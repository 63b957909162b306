r"""Gymnasium wrappers that help every RL library on ACLDBeam (not one algorithm's code).

* :class:`UnitAction`: actions in [-1, 1] instead of volts. A standard Gaussian policy
  (unit std) explores +/-1 V on the +/-120 V actuator without it and learns nothing. With
  ``headroom`` k > 1 the action's range spans k times the actuator's (the env clips and
  reports): a tanh-squashed policy (SAC) then reaches the limit at a = 1/k, not only
  in tanh's flat tail, where its entropy bonus forbids it.
* :class:`ObserveModes`: the ``"estimate"`` observation restricted to the first modes and
  the tip. Modes 3 and 4 of the design model (422 and 848 Hz) lie near and above the
  500 Hz Nyquist frequency of the 1 kHz loop; per-entry observation normalization scales
  their small, noise-dominated estimates up 5-30 times, and an MLP policy that feeds back
  on them chatters at +/-120 V.
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

__all__ = [
    "UnitAction",
    "ObserveModes",
    "WhitenObservation",
    "whitening",
    "check_headroom",
    "MAX_HEADROOM",
]


class UnitAction(gym.ActionWrapper, gym.utils.RecordConstructorArgs):
    r"""Actions ``a`` in [-1, 1] for an env whose action is a voltage in [-v_max, v_max]:
    ``V = k v_max a`` with the ``headroom`` k (default 1), computed in float64, so the
    round trip :meth:`reverse_action` of :meth:`action` is exact for every float32 action
    when :math:`k v_{max}` is a small integer times a power of two (120 V is 15 2^3, and
    360 V, k = 3, is 45 2^3: a float32 times it is exact in float64, and so is the
    division back). Out-of-range voltages are passed on, and the env clips and reports them
    (``info["clipped"]``), as it does for volts.

    ``headroom`` k >= 1 makes the actuator's limit the action :math:`\pm 1/k`. For a policy
    whose actions are squashed by tanh (SAC and its kin), reaching the limit with k = 1
    takes tanh's flat tail, where the log-density correction
    :math:`-\log(1 - \tanh^2)` grows without bound, so an entropy-regularised agent keeps
    away from a limit that the optimal control of this beam sits on for much of an
    episode; with k = 3 the limit is at tanh's argument 0.35. The deterministic policy
    :math:`V = v_{max}\,\mathrm{clip}(k \tanh(\cdot), -1, 1)` is then a saturated law, like
    LQR's and the random search's. Evaluate the trained policy through the same wrapper.
    """

    def __init__(self, env: gym.Env, headroom: float = 1.0):
        gym.utils.RecordConstructorArgs.__init__(self, headroom=headroom)
        gym.ActionWrapper.__init__(self, env)
        box = env.action_space
        if not (
            isinstance(box, spaces.Box)
            and box.shape == (1,)
            and np.all(box.low == -box.high)
            and np.all(box.high > 0)
        ):
            raise ValueError(
                f"env: UnitAction needs a symmetric 1-D Box action space "
                f"(-v_max, v_max), got {box!r}"
            )
        self.headroom = check_headroom(headroom)
        self.v_max = float(box.high[0])
        self.action_space = spaces.Box(-1.0, 1.0, (1,), np.float32)

    def action(self, action):
        return (self.headroom * self.v_max) * np.asarray(action, dtype=np.float64)

    def reverse_action(self, action):
        return (np.asarray(action, dtype=np.float64) / (self.headroom * self.v_max)).astype(
            np.float32
        )


#: Largest ``headroom`` of :class:`UnitAction` and the training configs (the limit at
#: a = 0.01).
MAX_HEADROOM = 100.0


def check_headroom(headroom, name: str = "headroom") -> float:
    """``headroom`` as a float in [1, :data:`MAX_HEADROOM`], or ``ValueError`` naming it
    (as ``name``)."""
    from acld_gym.util.validate import check_real

    try:
        return check_real(name, headroom, 1.0, MAX_HEADROOM)
    except ValueError:
        raise ValueError(
            f"{name} must be a number in [1, {MAX_HEADROOM:g}] (the action "
            f"range over the actuator's), got {headroom!r}"
        ) from None


class ObserveModes(gym.ObservationWrapper, gym.utils.RecordConstructorArgs):
    r"""The ``"estimate"`` observation (``obs_mode="estimate"``, the default) restricted to
    the first ``modes`` modes of the design model and the tip: the slots of
    :func:`acld_gym.envs.step.estimate_slots`, then any appended entries (``log c`` of
    ``observe_reward_scale``) as they are. ``modes=2`` on ``ACLDBeam-v1`` gives 5 entries
    (modes 1 and 2, 28 and 155 Hz, and the tip) of the 9.

    A training aid for policies without a structure of their own (an MLP on normalized
    inputs): the estimates of modes 3 and 4 (422 and 848 Hz, near and above the 500 Hz
    Nyquist frequency; the Kalman filter sees mode 4 at about a tenth) are small and
    dominated by the sensor noise and by the policy's own voltage, so normalizing each entry
    (``NormalizeObservation``, ``VecNormalize``) magnifies them, and a policy that feeds
    back on them chatters. Mode 2 (155 Hz, 6.5 samples a period) can be too much as well:
    CleanRL's single-file PPO with ``modes=2`` ended at 1.15-2.63x LQR's ISE on case 1 over
    five seeds, and at 0.92-1.17x with ``modes=1`` (docs/training.md). What a policy
    loses by not seeing the higher modes was not measured; the wrapper is a training aid,
    off unless applied. Evaluate a policy trained through this wrapper through it too (or
    apply the same slots).
    """

    def __init__(self, env: gym.Env, modes: int = 2):
        gym.utils.RecordConstructorArgs.__init__(self, modes=modes)
        gym.ObservationWrapper.__init__(self, env)
        config = getattr(env.unwrapped, "config", None)
        if config is None or config.obs_mode != "estimate":
            raise ValueError("env: ObserveModes needs an ACLDBeam env with obs_mode='estimate'")
        if isinstance(modes, bool) or not isinstance(modes, (int, np.integer)):
            raise ValueError(f"modes must be an integer, got {modes!r}")
        from acld_gym.envs.step import estimate_slots, observation_size

        # the layout's owner (acld_gym.envs.step) says where the modes are and how many
        nom = env.unwrapped.nom
        base = observation_size(nom, config.obs_mode)
        n = base + int(bool(config.observe_reward_scale))
        if env.observation_space.shape != (n,):
            raise ValueError(
                f"env: ObserveModes needs the ACLDBeam env's own observation of "
                f"{n} entries, got shape {env.observation_space.shape} (wrap it "
                f"before any wrapper that changes the observation)"
            )
        self.modes = int(modes)
        self.slots = np.r_[estimate_slots(nom.design.reduced.order, self.modes), np.arange(base, n)]
        self.observation_space = spaces.Box(-np.inf, np.inf, (len(self.slots),), np.float32)

    def observation(self, observation):
        return np.asarray(observation, dtype=np.float32)[..., self.slots]


class WhitenObservation(gym.ObservationWrapper, gym.utils.RecordConstructorArgs):
    r"""The observation ``z`` as ``[T^T z_{:d}, z_{d:}]``: a fixed matrix T (d x d) on its
    first d entries, the last ``passthrough`` (e.g. the appended log reward scale) as they
    are. T is given (e.g. :func:`whitening`), not learned while the wrapper runs, so the
    wrapped env stays a fixed MDP."""

    def __init__(self, env: gym.Env, transform, passthrough: int = 0):
        gym.utils.RecordConstructorArgs.__init__(self, transform=transform, passthrough=passthrough)
        gym.ObservationWrapper.__init__(self, env)
        n = env.observation_space.shape[0]
        if (
            isinstance(passthrough, bool)
            or not isinstance(passthrough, (int, np.integer))
            or not 0 <= passthrough < n
        ):
            raise ValueError(f"passthrough must be an integer in [0, {n}), got {passthrough!r}")
        d = n - int(passthrough)
        T = np.asarray(transform, dtype=np.float64)
        if T.shape != (d, d) or not np.all(np.isfinite(T)):
            raise ValueError(f"transform must be a finite ({d}, {d}) matrix, got shape {T.shape}")
        self.transform, self.passthrough, self._d = T, int(passthrough), d
        self.observation_space = spaces.Box(-np.inf, np.inf, (n,), np.float32)

    def observation(self, observation):
        z = np.asarray(observation, dtype=np.float64)
        return np.concatenate([z[: self._d] @ self.transform, z[self._d :]]).astype(np.float32)


def whitening(directions: np.ndarray, ridge: float = 1e-3) -> np.ndarray:
    r"""ZCA whitening matrix :math:`T = \Sigma^{-1/2}` (ridge-regularised, relative to the
    largest eigenvalue) of the second moment of the observation directions ``z/|z|``
    (rows), so that the direction features of ``z @ T`` are isotropic on average."""
    u = np.asarray(directions, dtype=np.float64)
    if u.ndim != 2 or u.shape[0] < 1 or not np.all(np.isfinite(u)):
        raise ValueError(
            f"directions must be a finite (n, d) array with n >= 1, got shape {u.shape}"
        )
    sigma = u.T @ u / u.shape[0]
    lam, vec = np.linalg.eigh(sigma)
    lam = np.maximum(lam, 0.0) + ridge * lam.max()
    return (vec / np.sqrt(lam)) @ vec.T
