"""Stable-Baselines3 adapter for :class:`acld_gym.envs.vector_env.ACLDBeamVectorEnv`.

SB3 does not take a :class:`gymnasium.vector.VectorEnv`; :class:`SB3VecEnv` is
an SB3 ``VecEnv`` over the native batched env, optionally in Gymnasium vector wrappers
(the package's :mod:`acld_gym.wrappers.vector`, or Gymnasium's action and observation
wrappers). It converts the gymnasium ``NEXT_STEP`` autoreset to SB3's same-step
autoreset: a sub-env that ends is reset at once (the vector env's ``reset`` path for that
sub-env), its reset observation passed through the observation wrappers, and its final
observation (wrapped) is in ``infos[i]["terminal_observation"]``;
``infos[i]["TimeLimit.truncated"]`` is ``truncated and not terminated``.

Example, with what the guide gives any library (actions in [-1, 1], the reward per load,
mode 1 and the tip where the level observes the estimate, normalized observations, one
torch thread; ``docs/examples/sb3_ppo.py`` is the complete script, with its budget)::

    from functools import partial

    import gymnasium as gym
    import torch
    from stable_baselines3 import PPO
    from stable_baselines3.common.vec_env import VecNormalize

    from acld_gym.envs import SB3VecEnv
    from acld_gym.wrappers import vector

    torch.set_num_threads(1)  # torch's default threads make SB3 many times slower
    # mode 1 and the tip: on the levels that observe the estimate (all but ACLDBeamHard-v1)
    wrappers = [vector.UnitAction, partial(vector.ObserveModes, modes=1)]
    venv = SB3VecEnv(16, load_case="random", reward_scale="passive", wrappers=wrappers)
    PPO("MlpPolicy", VecNormalize(venv)).learn(100_000)

    # another level: its id
    venv = SB3VecEnv(16, env_id="ACLDBeamLab-v1", load_case="random",
                     reward_scale="passive", wrappers=wrappers)

    # the same: a wrapped vector env of gym.make_vec, adapted
    envs = gym.make_vec("ACLDBeam-v1", 16, load_case="random", reward_scale="passive")
    venv = SB3VecEnv(venv=vector.ObserveModes(vector.UnitAction(envs), modes=1))

Without wrappers the actions are volts (+/-120); ``VecNormalize`` goes outside, as usual.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import fields
from typing import Any

import gymnasium as gym
import numpy as np
from gymnasium.vector import (
    VectorActionWrapper,
    VectorEnv,
    VectorObservationWrapper,
    VectorRewardWrapper,
    VectorWrapper,
)
from stable_baselines3.common.vec_env import VecEnv

from acld_gym.envs.config import EnvConfig
from acld_gym.envs.sb3_args import build_venv, count_of
from acld_gym.envs.step import INFO_KEYS
from acld_gym.envs.vector_env import ACLDBeamVectorEnv
from acld_gym.util.validate import check_int, check_seed, shown

#: Attributes the env derives its tables and design from at construction: every field of
#: the configuration but ``load_case`` (settable: the next resets' case), and what follows.
_CONFIGURED = tuple(f.name for f in fields(EnvConfig) if f.name != "load_case") + (
    "config",
    "observer_kind",
    "num_envs",
    "nom",
    "horizon",
    "max_episode_steps",
    "harmonic_modes",
    "v_max",
    "obs_hist",
)

__all__ = ["SB3VecEnv"]


def _scalar(x):
    """A numpy scalar as a Python value (``None`` and other objects as they are)."""
    return x.item() if isinstance(x, np.generic) else x


def _per_env(values) -> list:
    """One vector-env info entry as a list with one value per sub-env: sub-env i's is
    ``_scalar(values[i])`` (a row for a 2-D array), converted a column at a time (a numeric
    column's ``tolist()`` gives the same Python values as ``item()``, without a call per
    value: the step's infos were a tenth of SAC's training time)."""
    if isinstance(values, np.ndarray) and values.dtype != object:
        return values.tolist() if values.ndim == 1 else list(values)
    return [_scalar(x) for x in values]


def apply_wrappers(env: VectorEnv, wrappers) -> VectorEnv:
    """``env`` in ``wrappers`` (callables taking and returning a Gymnasium vector env, the
    first innermost: :mod:`acld_gym.wrappers.vector`'s classes, ``functools.partial`` of
    them, Gymnasium's vector wrappers); one line naming ``wrappers`` for anything else."""
    if wrappers is None:
        return env
    if not isinstance(wrappers, (list, tuple)):
        raise ValueError(
            f"wrappers: expected a list of vector wrappers (callables taking and returning a "
            f"gymnasium VectorEnv), got {type(wrappers).__name__}"
        )
    for w in wrappers:
        cls = getattr(w, "func", w)  # a functools.partial's class
        name = getattr(cls, "__name__", repr(cls))
        if isinstance(cls, type) and issubclass(cls, gym.Wrapper):
            raise ValueError(
                f"wrappers: {name} is a single-env wrapper; use its vector version "
                f"(acld_gym.wrappers.vector.{name}, gymnasium.wrappers.vector.{name})"
            )
        if not callable(w):
            raise ValueError(f"wrappers: expected callables, got {w!r}")
        out = w(env)
        if not isinstance(out, VectorEnv):
            raise ValueError(
                f"wrappers: {name} returned {type(out).__name__}, not a gymnasium VectorEnv"
            )
        env = out
    return env


def wrapper_chain(env: VectorEnv) -> tuple[ACLDBeamVectorEnv, list[VectorWrapper]]:
    """The native env under ``env`` and the vector wrappers over it, innermost first.

    The same-step autoreset resets a sub-env under the wrappers and passes its reset
    observation through the observation wrappers alone; so the wrappers must be action,
    observation or reward wrappers (``VectorActionWrapper``, ``VectorObservationWrapper``,
    ``VectorRewardWrapper``), whose maps work row by row. Anything else (episode statistics,
    reward normalization, which follow gymnasium's next-step autoreset) is refused with one
    line naming ``venv``: use SB3's ``VecMonitor``/``VecNormalize`` outside the adapter."""
    chain: list[VectorWrapper] = []
    inner = env
    while isinstance(inner, VectorWrapper):
        if not isinstance(
            inner, (VectorActionWrapper, VectorObservationWrapper, VectorRewardWrapper)
        ):
            raise ValueError(
                f"venv: SB3VecEnv takes action, observation and reward wrappers, got "
                f"{type(inner).__name__} (use SB3's VecMonitor/VecNormalize outside the adapter)"
            )
        chain.append(inner)
        inner = inner.env
    if not isinstance(inner, ACLDBeamVectorEnv):
        raise ValueError(
            f"venv: expected an ACLDBeamVectorEnv (gym.make_vec of an acld_gym id), possibly "
            f"in vector wrappers, got {type(inner).__name__} (for single envs use SB3's "
            f"DummyVecEnv or SubprocVecEnv)"
        )
    return inner, chain[::-1]


class SB3VecEnv(VecEnv):
    """SB3 ``VecEnv`` over :class:`ACLDBeamVectorEnv`, optionally in Gymnasium vector
    wrappers: the fast path (one matrix product per step for all sub-envs) with the
    package's wrappers (:mod:`acld_gym.wrappers.vector`).

    Parameters
    ----------
    num_envs : int, optional
        Number of sub-envs (default 1) when the adapter builds the env; with ``venv=``,
        omitted or ``venv``'s own count (another count is refused). The first positional
        argument or a keyword; a string there (a level id) is refused: pass ``env_id=``.
    venv : VectorEnv, optional
        An existing env: an :class:`ACLDBeamVectorEnv` (``gym.make_vec`` of an acld_gym
        id), bare or in vector action, observation and reward wrappers (e.g.
        ``vector.ObserveModes(vector.UnitAction(gym.make_vec(...)))``; see
        :func:`wrapper_chain`). Not together with ``env_id``, ``config`` or the env's
        keywords.
    config : EnvConfig, optional
        The env's configuration, with or instead of its fields as keywords (``**env_kwargs``).
        Not together with ``env_id`` (a level's configuration with changes:
        ``config=acld_gym.envs.presets.preset(id, ...)``).
    env_id : str, optional
        One of this package's ids (``"ACLDBeamLab-v1"``, ...; keyword only): the level's
        env, built as ``gym.make_vec(env_id, num_envs=num_envs, **env_kwargs)`` builds it
        (its preset configuration, the keywords on top), e.g.
        ``SB3VecEnv(8, env_id="ACLDBeamLab-v1", load_case="random")``. Without it (and
        without ``venv``/``config``) the env is ``ACLDBeam-v1``'s defaults with the
        keywords.
    seed_group : int
        (default 1) :meth:`seed` gives each run of ``seed_group`` consecutive sub-envs one
        seed, so they draw the same episodes (loads, sensor noise) as long as they end
        together: common random numbers, e.g. for antithetic exploration in pairs
        (``seed_group=2``). An episode that leaves the deflection limit early puts its group
        out of step from then on. It must divide the number of sub-envs.
    wrappers : list of callable, optional
        Vector wrappers applied to the env (built or ``venv=``), the first innermost, e.g.
        ``[vector.UnitAction, functools.partial(vector.ObserveModes, modes=2)]`` with
        ``from acld_gym.wrappers import vector``: actions then in [-1, 1] (not volts
        [V]) and the observation the first two modes and the tip, as for
        ``ObserveModes(UnitAction(gym.make(...)), 2)``.

    Attributes
    ----------
    venv : ACLDBeamVectorEnv
        The native env (unwrapped): ``get_attr``, ``set_attr`` and ``env_method`` reach it.
    vector_env : VectorEnv
        The env this adapter steps: ``venv`` in the wrappers (``venv`` itself without).

    Notes
    -----
    The spaces are the outermost wrapper's. A sub-env that ends is reset at once under the
    wrappers (:meth:`ACLDBeamVectorEnv.reset_done`) and its reset observation passed through
    the observation wrappers' ``observations`` (those rows only), so sub-env i sees what
    a single env in the single-env wrappers, reset after each episode, sees.
    ``env_is_wrapped(cls)`` is True where a wrapper of class ``cls`` is in the chain.
    """

    def __init__(
        self,
        num_envs: int | None = None,
        /,
        venv: VectorEnv | None = None,
        config: EnvConfig | None = None,
        seed_group: int = 1,
        wrappers: Sequence[Callable[[VectorEnv], VectorEnv]] | None = None,
        *,
        env_id: str | None = None,
        **env_kwargs,
    ):
        # num_envs is positional-only so that SB3VecEnv("ACLDBeamLab-v1", num_envs=8) reaches
        # count_of (which names num_envs and env_id=), not Python's "multiple values"
        num_envs = count_of(num_envs, env_kwargs)
        venv = build_venv(num_envs, venv, config, env_id, env_kwargs)
        base, _ = wrapper_chain(venv)  # checked before the wrappers are applied
        if num_envs is not None and num_envs != base.num_envs:
            raise ValueError(
                f"num_envs={shown(num_envs)} differs from venv's {base.num_envs} sub-envs: "
                "omit num_envs with venv= (the env's count is used)"
            )
        check_int("seed_group", seed_group, 1, base.num_envs)
        if base.num_envs % seed_group:
            raise ValueError(
                f"seed_group: expected a divisor of the {base.num_envs} sub-envs, got {seed_group}"
            )
        outer = apply_wrappers(venv, wrappers)
        base, self._chain = wrapper_chain(outer)
        self._observers = [w for w in self._chain if isinstance(w, VectorObservationWrapper)]
        self.seed_group = seed_group
        self.venv = base
        self.vector_env = outer
        super().__init__(base.num_envs, outer.single_observation_space, outer.single_action_space)
        self.render_mode = base.render_mode
        self._actions: np.ndarray | None = None
        self._seed: int | list[int] | None = None
        self._reset_options: dict = {}

    def reset(self) -> np.ndarray:
        obs, _ = self.vector_env.reset(seed=self._seed, options=self._reset_options or None)
        self._seed = None
        self._reset_options = {}
        self.reset_infos = [{} for _ in range(self.num_envs)]
        return obs

    def step_async(self, actions: np.ndarray) -> None:
        if self.venv.needs_reset:
            raise RuntimeError("SB3VecEnv: call reset() before step()")
        self._actions = np.asarray(actions)

    def _reset_ended(self, obs: np.ndarray, ended: np.ndarray) -> np.ndarray:
        """The batch's observation with the sub-envs ``ended`` reset now: the native env's
        (unwrapped) without observation wrappers, else ``obs`` with those rows replaced by
        their reset observations through the observation wrappers, innermost first."""
        raw = self.venv.reset_done(ended)
        if not self._observers:
            return raw
        rows = raw[ended]
        for w in self._observers:
            rows = w.observations(rows)
        obs = np.array(obs)
        obs[ended] = rows
        return obs

    def step_wait(self):
        if self._actions is None:
            raise RuntimeError("step_wait() called without step_async()")
        obs, rewards, terminated, truncated, info = self.vector_env.step(self._actions)
        self._actions = None
        done = terminated | truncated
        keys = INFO_KEYS + (("reward_scale",) if "reward_scale" in info else ())
        columns = [_per_env(info[key]) for key in keys]
        infos: list[dict[str, Any]] = [
            dict(zip(keys, row, strict=True)) for row in zip(*columns, strict=True)
        ]
        if done.any():
            ended = np.flatnonzero(done)
            for i in ended:
                infos[i]["terminal_observation"] = obs[i].copy()
                infos[i]["TimeLimit.truncated"] = bool(truncated[i] and not terminated[i])
            obs = self._reset_ended(obs, ended)
        return obs, rewards.astype(np.float32), done, infos

    def close(self) -> None:
        self.vector_env.close()

    def seed(self, seed: int | None = None) -> Sequence[None | int]:
        """Seeds the next ``reset()``: sub-env i gets ``seed + i // seed_group`` (``seed +
        i`` by default)."""
        first = check_seed(seed)
        g = self.seed_group
        seeds = [None if first is None else first + i // g for i in range(self.num_envs)]
        self._seed = seeds if (g > 1 and first is not None) else first
        return seeds

    def set_options(self, options: list[dict] | dict | None = None) -> None:
        if isinstance(options, list):
            if any(o != options[0] for o in options):
                raise ValueError("SB3VecEnv: options must be the same for all sub-envs")
            options = options[0] if options else None
        self._reset_options = dict(options or {})

    def get_images(self) -> Sequence[np.ndarray | None]:
        frame = self.vector_env.render() if self.render_mode == "rgb_array" else None
        return [frame] + [None] * (self.num_envs - 1)

    def _indices(self, indices) -> list[int]:
        if indices is None:
            return list(range(self.num_envs))
        if isinstance(indices, int):
            return [indices]
        return list(indices)

    def get_attr(self, attr_name: str, indices=None) -> list[Any]:
        """The attribute of the (shared) vector env, once per requested index."""
        value = getattr(self.venv, attr_name)
        return [value for _ in self._indices(indices)]

    def set_attr(self, attr_name: str, value: Any, indices=None) -> None:
        """Set an attribute of the (shared) vector env, validated now: ``load_case`` (takes
        effect at the next reset) is the one meant to change; anything else that the env
        validates at construction is refused rather than left to fail later. The vector env
        checks ``load_case`` as its constructor does
        (:func:`acld_gym.envs.conflicts.check_case`)."""
        idx = self._indices(indices)
        if idx != list(range(self.num_envs)):
            raise ValueError("SB3VecEnv: attributes are shared; set them for all sub-envs")
        if attr_name in _CONFIGURED:
            raise ValueError(
                f"SB3VecEnv: {attr_name} is fixed at construction; build a new env to change it"
            )
        elif not hasattr(self.venv, attr_name):
            raise ValueError(f"SB3VecEnv: the vector env has no attribute {attr_name!r}")
        setattr(self.venv, attr_name, value)

    def env_method(self, method_name: str, *method_args, indices=None, **method_kwargs):
        """Calls the vector env's method once per requested index."""
        method = getattr(self.venv, method_name)
        return [method(*method_args, **method_kwargs) for _ in self._indices(indices)]

    def env_is_wrapped(self, wrapper_class, indices=None) -> list[bool]:
        """True for every index if a vector wrapper of class ``wrapper_class`` is in the
        chain (the wrappers are shared by all sub-envs)."""
        wrapped = any(isinstance(w, wrapper_class) for w in self._chain)
        return [wrapped for _ in self._indices(indices)]
