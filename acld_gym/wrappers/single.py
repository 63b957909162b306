r"""The single-env wrappers (:class:`gymnasium.Wrapper`); their maps are
:mod:`acld_gym.wrappers.transforms`, shared with the vector versions
(:mod:`acld_gym.wrappers.vector`). Import them from :mod:`acld_gym.wrappers`."""

from __future__ import annotations

import gymnasium as gym

from acld_gym.wrappers.transforms import LinearMap, ModeSlots, UnitMap

__all__ = ["UnitAction", "ObserveModes", "WhitenObservation"]


def _check_single(env, owner: str) -> None:
    """One line naming ``env`` if it is not a single Gymnasium env (a vector env has its
    own version of the wrapper)."""
    if isinstance(env, gym.vector.VectorEnv):
        raise ValueError(
            f"env: {owner} wraps a single env; for a vector env use "
            f"acld_gym.wrappers.vector.{owner}"
        )
    if not isinstance(env, gym.Env):
        raise ValueError(f"env: {owner} wraps a gymnasium.Env, got {type(env).__name__}")


class UnitAction(gym.ActionWrapper, gym.utils.RecordConstructorArgs):
    r"""Actions ``a`` in [-1, 1] for an env whose action is a voltage in [-v_max, v_max]:
    ``V = k v_max a`` [V] with the ``headroom`` k (default 1), computed in float64, so the
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

    Parameters
    ----------
    env : gymnasium.Env
        An env whose action is one voltage [V] in a symmetric Box (ACLDBeam: +/-120 V).
    headroom : float
        k in [1, 100] (dimensionless).

    See Also
    --------
    acld_gym.wrappers.vector.UnitAction : the same map on a vector env (``gym.make_vec``).
    """

    def __init__(self, env: gym.Env, headroom: float = 1.0):
        gym.utils.RecordConstructorArgs.__init__(self, headroom=headroom)
        _check_single(env, "UnitAction")
        gym.ActionWrapper.__init__(self, env)
        self.map = UnitMap(env.action_space, headroom, "UnitAction")
        self.headroom, self.v_max = self.map.headroom, self.map.v_max
        self.action_space = self.map.space

    def action(self, action):
        return self.map(action)

    def reverse_action(self, action):
        return self.map.inverse(action)


class ObserveModes(gym.ObservationWrapper, gym.utils.RecordConstructorArgs):
    r"""The ``"estimate"`` observation (``obs_mode="estimate"``, the default) restricted to
    the first ``modes`` modes of the design model and the tip: the slots of
    :func:`acld_gym.envs.step.estimate_slots`, then any appended entries (``log c`` of
    ``observe_reward_scale``) as they are. ``modes=2`` on ``ACLDBeam-v1`` gives 5 entries
    (modes 1 and 2, 28 and 155 Hz, and the tip) of the 9; the entries keep their units (the
    env's scaled, dimensionless estimate).

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

    Parameters
    ----------
    env : gymnasium.Env
        An ACLDBeam env with ``obs_mode="estimate"``, its observation not yet changed by
        another wrapper.
    modes : int
        How many modes to keep, 1 .. 4 (1 .. 3 on the thesis mesh).

    See Also
    --------
    acld_gym.wrappers.vector.ObserveModes : the same slots on a vector env.
    """

    def __init__(self, env: gym.Env, modes: int = 2):
        gym.utils.RecordConstructorArgs.__init__(self, modes=modes)
        _check_single(env, "ObserveModes")
        gym.ObservationWrapper.__init__(self, env)
        config = getattr(env.unwrapped, "config", None)
        self.map = ModeSlots(config, env.observation_space.shape, modes, "ObserveModes")
        self.modes, self.slots = self.map.modes, self.map.slots
        self.observation_space = self.map.space

    def observation(self, observation):
        return self.map(observation)


class WhitenObservation(gym.ObservationWrapper, gym.utils.RecordConstructorArgs):
    r"""The observation ``z`` as ``[T^T z_{:d}, z_{d:}]``: a fixed matrix T (d x d) on its
    first d entries, the last ``passthrough`` (e.g. the appended log reward scale) as they
    are. T is given (e.g. :func:`acld_gym.wrappers.whitening`), not learned while the
    wrapper runs, so the wrapped env stays a fixed MDP.

    Parameters
    ----------
    env : gymnasium.Env
        An env with a 1-D Box observation of n entries.
    transform : array_like
        T, a finite (d, d) matrix, d = n - ``passthrough`` (dimensionless on the env's
        scaled observation).
    passthrough : int
        Trailing entries left as they are, in [0, n).

    See Also
    --------
    acld_gym.wrappers.vector.WhitenObservation : the same map on a vector env.
    """

    def __init__(self, env: gym.Env, transform, passthrough: int = 0):
        gym.utils.RecordConstructorArgs.__init__(self, transform=transform, passthrough=passthrough)
        _check_single(env, "WhitenObservation")
        gym.ObservationWrapper.__init__(self, env)
        self.map = LinearMap(env.observation_space.shape, transform, passthrough)
        self.transform, self.passthrough = self.map.transform, self.map.passthrough
        self.observation_space = self.map.space

    def observation(self, observation):
        return self.map(observation)
