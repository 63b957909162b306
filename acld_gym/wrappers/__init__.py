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

Each has a vector version of the same name in :mod:`acld_gym.wrappers.vector`, for
``gym.make_vec`` (the native batched env, one matrix product per step, or a sync/async
vector env) and for the SB3 adapter (:class:`acld_gym.envs.sb3.SB3VecEnv`); both versions
apply the same map (:mod:`acld_gym.wrappers.transforms`), so a sub-env of the wrapped vector
env sees exactly what a wrapped single env sees.

The reward per load is an env option, not a wrapper, because it needs the episode's load:
``reward_scale="passive"`` (:mod:`acld_gym.envs.scale`), with ``observe_reward_scale`` for
an asymmetric critic.

Example::

    import gymnasium as gym
    import acld_gym
    from acld_gym.wrappers import UnitAction

    env = UnitAction(gym.make("ACLDBeam-v1", load_case="random", reward_scale="passive"))

    from acld_gym.wrappers import vector

    envs = vector.UnitAction(gym.make_vec("ACLDBeam-v1", num_envs=16, load_case="random"))
"""

from acld_gym.wrappers.single import ObserveModes, UnitAction, WhitenObservation
from acld_gym.wrappers.transforms import MAX_HEADROOM, check_headroom, whitening

__all__ = [
    "UnitAction",
    "ObserveModes",
    "WhitenObservation",
    "whitening",
    "check_headroom",
    "MAX_HEADROOM",
]
