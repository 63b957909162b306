"""Stable-Baselines3 adapter for :class:`acld_gym.envs.vector_env.ACLDBeamVectorEnv`.

SB3 does not take a :class:`gymnasium.vector.VectorEnv`; :class:`SB3VecEnv` is
an SB3 ``VecEnv`` over the native batched env. It converts the gymnasium
``NEXT_STEP`` autoreset to SB3's same-step autoreset: a sub-env that ends is
reset at once (the vector env's ``reset`` path for that sub-env) and its
final observation is in ``infos[i]["terminal_observation"]``;
``infos[i]["TimeLimit.truncated"]`` is ``truncated and not terminated``.

Example::

    from stable_baselines3 import PPO
    from acld_gym.envs import SB3VecEnv

    venv = SB3VecEnv(num_envs=16, load_case="random")
    PPO("MlpPolicy", venv).learn(100_000)

Actions are volts (+/-120); wrap with ``VecNormalize`` as usual, and rescale
the policy output yourself if you want [-1, 1] actions.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import fields
from typing import Any

import numpy as np
from stable_baselines3.common.vec_env import VecEnv

from acld_gym.envs.config import EnvConfig
from acld_gym.envs.step import INFO_KEYS
from acld_gym.envs.vector_env import ACLDBeamVectorEnv
from acld_gym.util.validate import check_int, check_seed

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


class SB3VecEnv(VecEnv):
    """SB3 ``VecEnv`` over :class:`ACLDBeamVectorEnv` (``num_envs`` and the env's
    configuration -- ``config=`` and/or its fields as keywords --, or an existing
    ``venv=``).

    ``seed_group`` (default 1): :meth:`seed` gives each run of ``seed_group`` consecutive
    sub-envs one seed, so they draw the same episodes (loads, sensor noise) as long as
    they end together: common random numbers, e.g. for antithetic exploration in pairs
    (``seed_group=2``). An episode that leaves the deflection limit early puts its group
    out of step from then on. It must divide the number of sub-envs."""

    def __init__(
        self,
        num_envs: int = 1,
        venv: ACLDBeamVectorEnv | None = None,
        config: EnvConfig | None = None,
        seed_group: int = 1,
        **env_kwargs,
    ):
        if venv is None:
            venv = ACLDBeamVectorEnv(num_envs=num_envs, config=config, **env_kwargs)
        elif env_kwargs or config is not None:
            raise ValueError("pass either venv= or the env's configuration, not both")
        check_int("seed_group", seed_group, 1, venv.num_envs)
        if venv.num_envs % seed_group:
            raise ValueError(
                f"seed_group: expected a divisor of the {venv.num_envs} sub-envs, got {seed_group}"
            )
        self.seed_group = seed_group
        self.venv = venv
        super().__init__(venv.num_envs, venv.single_observation_space, venv.single_action_space)
        self.render_mode = venv.render_mode
        self._actions: np.ndarray | None = None
        self._seed: int | list[int] | None = None
        self._reset_options: dict = {}

    def reset(self) -> np.ndarray:
        obs, _ = self.venv.reset(seed=self._seed, options=self._reset_options or None)
        self._seed = None
        self._reset_options = {}
        self.reset_infos = [{} for _ in range(self.num_envs)]
        return obs

    def step_async(self, actions: np.ndarray) -> None:
        if self.venv.needs_reset:
            raise RuntimeError("SB3VecEnv: call reset() before step()")
        self._actions = np.asarray(actions)

    def step_wait(self):
        if self._actions is None:
            raise RuntimeError("step_wait() called without step_async()")
        v = self.venv
        obs, rewards, terminated, truncated, info = v.step(self._actions)
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
            obs = v.reset_done(ended)
        return obs, rewards.astype(np.float32), done, infos

    def close(self) -> None:
        self.venv.close()

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
        frame = self.venv.render() if self.render_mode == "rgb_array" else None
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
        return [False for _ in self._indices(indices)]
