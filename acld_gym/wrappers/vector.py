r"""Vector versions of the package's wrappers, for a :class:`gymnasium.vector.VectorEnv`:
the native batched env of ``gym.make_vec`` (one matrix product per step), a sync or an
async vector env, or the SB3 adapter's env (:class:`acld_gym.envs.sb3.SB3VecEnv` takes them:
``SB3VecEnv(venv=wrapped)`` or ``SB3VecEnv(..., wrappers=[...])``). Same names as the
single-env wrappers of :mod:`acld_gym.wrappers`, as Gymnasium names its own
(``gymnasium.wrappers.vector.RescaleAction``); same maps
(:mod:`acld_gym.wrappers.transforms`), so sub-env i of a wrapped vector env sees exactly
what a single env in the single-env wrapper sees.

Example::

    import gymnasium as gym
    import acld_gym
    from acld_gym.wrappers.vector import ObserveModes, UnitAction

    envs = ObserveModes(UnitAction(gym.make_vec("ACLDBeam-v1", num_envs=16), headroom=3), 2)
"""

from __future__ import annotations

import gymnasium as gym
from gymnasium.vector import VectorActionWrapper, VectorEnv, VectorObservationWrapper
from gymnasium.vector.utils import batch_space

from acld_gym.wrappers.transforms import LinearMap, ModeSlots, UnitMap

__all__ = ["UnitAction", "ObserveModes", "WhitenObservation", "beam_config"]


def _check_vector(env, owner: str) -> None:
    """One line naming ``env`` if it is not a Gymnasium vector env."""
    if not isinstance(env, VectorEnv):
        raise ValueError(
            f"env: the vector {owner} wraps a gymnasium.vector.VectorEnv (gym.make_vec), got "
            f"{type(env).__name__}; for a single env use acld_gym.wrappers.{owner}"
        )


def beam_config(env: VectorEnv):
    """The :class:`acld_gym.envs.config.EnvConfig` shared by the sub-envs of ``env`` (the
    native batched env's, or every sub-env's of a sync/async vector env, which must agree),
    or None if they are not ACLDBeam envs."""
    base = env.unwrapped
    config = getattr(base, "config", None)
    if config is not None or not hasattr(base, "get_attr"):
        return config
    try:
        configs = base.get_attr("config")
    except AttributeError:
        return None
    if any(c != configs[0] for c in configs):
        raise ValueError("env: the sub-envs' configurations differ; wrap each sub-env instead")
    return configs[0]


class UnitAction(VectorActionWrapper, gym.utils.RecordConstructorArgs):
    r"""Actions in [-1, 1] for a vector env of voltages: sub-env i gets
    :math:`V_i = k\,v_{max}\,a_i` [V] (float64), the map of
    :class:`acld_gym.wrappers.UnitAction` (whose docstring says why: a unit-std policy and
    a tanh-squashed one with ``headroom`` k).

    Parameters
    ----------
    env : VectorEnv
        A vector env whose sub-env action is one voltage [V] in a symmetric Box.
    headroom : float
        k in [1, 100] (dimensionless): the actuator's limit is the action :math:`\pm 1/k`.
    """

    def __init__(self, env: VectorEnv, headroom: float = 1.0):
        _check_vector(env, "UnitAction")
        gym.utils.RecordConstructorArgs.__init__(self, headroom=headroom)
        VectorActionWrapper.__init__(self, env)
        self.map = UnitMap(env.single_action_space, headroom, "UnitAction")
        self.headroom, self.v_max = self.map.headroom, self.map.v_max
        self.single_action_space = self.map.space
        self.action_space = batch_space(self.map.space, env.num_envs)

    def actions(self, actions):
        return self.map(actions)


class ObserveModes(VectorObservationWrapper, gym.utils.RecordConstructorArgs):
    """Each sub-env's ``"estimate"`` observation restricted to the first ``modes`` modes and
    the tip, the slots of :class:`acld_gym.wrappers.ObserveModes` (whose docstring says
    why: a training aid for MLP policies on normalized inputs).

    Parameters
    ----------
    env : VectorEnv
        A vector env of ACLDBeam envs with ``obs_mode="estimate"`` (``gym.make_vec`` of
        ``ACLDBeam-v1``, ``-v0`` or ``ACLDBeamLab-v1``), its observation not yet changed.
    modes : int
        How many modes to keep, 1 .. 4 (1 .. 3 on the thesis mesh).
    """

    def __init__(self, env: VectorEnv, modes: int = 2):
        _check_vector(env, "ObserveModes")
        gym.utils.RecordConstructorArgs.__init__(self, modes=modes)
        VectorObservationWrapper.__init__(self, env)
        config = beam_config(env)
        self.map = ModeSlots(config, env.single_observation_space.shape, modes, "ObserveModes")
        self.modes, self.slots = self.map.modes, self.map.slots
        self.single_observation_space = self.map.space
        self.observation_space = batch_space(self.map.space, env.num_envs)

    def observations(self, observations):
        return self.map(observations)


class WhitenObservation(VectorObservationWrapper, gym.utils.RecordConstructorArgs):
    r"""Each sub-env's observation ``z`` as :math:`[T^T z_{:d}, z_{d:}]`, the map of
    :class:`acld_gym.wrappers.WhitenObservation` (a fixed T, e.g.
    :func:`acld_gym.wrappers.whitening`).

    Parameters
    ----------
    env : VectorEnv
        A vector env whose sub-env observation is a 1-D Box of n entries.
    transform : array_like
        T, a finite (d, d) matrix, d = n - ``passthrough`` (dimensionless on the env's
        scaled observation).
    passthrough : int
        Trailing entries left as they are, in [0, n).
    """

    def __init__(self, env: VectorEnv, transform, passthrough: int = 0):
        _check_vector(env, "WhitenObservation")
        gym.utils.RecordConstructorArgs.__init__(self, transform=transform, passthrough=passthrough)
        VectorObservationWrapper.__init__(self, env)
        self.map = LinearMap(env.single_observation_space.shape, transform, passthrough)
        self.transform, self.passthrough = self.map.transform, self.map.passthrough
        self.single_observation_space = self.map.space
        self.observation_space = batch_space(self.map.space, env.num_envs)

    def observations(self, observations):
        return self.map(observations)
