"""The SB3 algorithms' training env (:func:`train.bench.sb3_envs.make_sb3_env`): the native batched
env
(``SB3VecEnv``) with actions in [-1, 1], no residual and no shaping, split over the
training loads (:class:`train.bench.sb3_envs.ConcatVecEnv`), optionally whitened
(:class:`train.bench.sb3_envs.VecWhiten`) or
as direction features (:class:`train.bench.sb3_envs.VecDirectionFeatures`), under
``VecNormalize``."""

from __future__ import annotations

import gymnasium as gym
import numpy as np
from gymnasium import spaces
from stable_baselines3.common.vec_env import VecEnv, VecEnvWrapper, VecNormalize

import acld_gym  # noqa: F401  (registers the env ids)

from ..features import direction_features
from .config import AlgoConfig

__all__ = ["VecDirectionFeatures", "VecWhiten", "ConcatVecEnv", "make_sb3_env"]


# --- stable-baselines3 algorithms -------------------------------------------------
class VecDirectionFeatures(VecEnvWrapper):
    """Observation ``z`` -> ``[z/|z|, log|z|]`` (:func:`train.features.direction_features`),
    so that every SB3 algorithm (ARS included, whose policy takes no feature extractor)
    sees the same scale-free features."""

    def __init__(self, venv: VecEnv):
        d = venv.observation_space.shape[0] + 1
        super().__init__(venv, observation_space=spaces.Box(-np.inf, np.inf, (d,), np.float32))

    def _f(self, obs: np.ndarray) -> np.ndarray:
        return direction_features(obs).astype(np.float32)

    def reset(self) -> np.ndarray:
        return self._f(self.venv.reset())

    def step_wait(self):
        obs, rewards, dones, infos = self.venv.step_wait()
        for i in np.flatnonzero(dones):
            infos[i]["terminal_observation"] = self._f(infos[i]["terminal_observation"][None])[0]
        return self._f(obs), rewards, dones, infos


class VecWhiten(VecEnvWrapper):
    r"""Observation ``z`` -> ``u = T^T z`` with a fixed matrix T (identity until
    :meth:`set_transform`). While ``collect`` is a list, the raw observation directions
    ``z/|z|`` seen (every sub-env, every step) are appended to it, from which
    :func:`acld_gym.wrappers.whitening` estimates T (:func:`train.bench.sb3_train.train_sb3` with
    ``whiten_steps``)."""

    def __init__(self, venv: VecEnv, passthrough: int = 0):
        super().__init__(venv)
        self.passthrough = int(passthrough)
        self.transform = np.eye(venv.observation_space.shape[0] - self.passthrough)
        self.collect: list | None = None

    def set_transform(self, transform: np.ndarray) -> None:
        self.transform = np.asarray(transform, dtype=np.float64)

    def _u(self, obs: np.ndarray) -> np.ndarray:
        """``[T^T z, rest]``: the last ``passthrough`` entries are not whitened."""
        obs = np.asarray(obs, dtype=np.float64)
        d = obs.shape[-1] - self.passthrough
        z = obs[..., :d]
        if self.collect is not None:
            r = np.linalg.norm(z, axis=-1, keepdims=True)
            self.collect.append((z / np.maximum(r, 1e-12))[r[:, 0] > 0])
        return np.concatenate([z @ self.transform, obs[..., d:]], axis=-1).astype(np.float32)

    def reset(self) -> np.ndarray:
        return self._u(self.venv.reset())

    def step_wait(self):
        obs, rewards, dones, infos = self.venv.step_wait()
        for i in np.flatnonzero(dones):
            terminal = np.asarray(infos[i]["terminal_observation"], dtype=np.float64)
            d = terminal.shape[-1] - self.passthrough
            infos[i]["terminal_observation"] = np.concatenate(
                [terminal[:d] @ self.transform, terminal[d:]]).astype(np.float32)
        return self._u(obs), rewards, dones, infos


class ConcatVecEnv(VecEnv):
    """Several SB3 ``VecEnv`` with the same spaces side by side as one (sub-envs in order)."""

    def __init__(self, venvs: list[VecEnv]):
        self.venvs = list(venvs)
        self._sizes = [v.num_envs for v in self.venvs]
        self._splits = np.cumsum(self._sizes)[:-1]
        v0 = self.venvs[0]
        super().__init__(sum(self._sizes), v0.observation_space, v0.action_space)

    def reset(self):
        return np.concatenate([v.reset() for v in self.venvs])

    def step_async(self, actions) -> None:
        for v, a in zip(self.venvs, np.split(np.asarray(actions), self._splits), strict=True):
            v.step_async(a)

    def step_wait(self):
        parts = [v.step_wait() for v in self.venvs]
        return (
            np.concatenate([p[0] for p in parts]),
            np.concatenate([p[1] for p in parts]),
            np.concatenate([p[2] for p in parts]),
            [i for p in parts for i in p[3]],
        )

    def close(self) -> None:
        for v in self.venvs:
            v.close()

    def seed(self, seed: int | None = None):
        out, offset = [], 0
        for v in self.venvs:
            out += v.seed(None if seed is None else seed + offset)
            offset += v.num_envs
        return out

    def _split_indices(self, indices):
        idx = (
            range(self.num_envs)
            if indices is None
            else ([indices] if isinstance(indices, int) else indices)
        )
        bounds = np.cumsum([0, *self._sizes])
        for i in idx:
            k = int(np.searchsorted(bounds, i, side="right") - 1)
            yield self.venvs[k], int(i - bounds[k])

    def get_attr(self, attr_name, indices=None):
        return [v.get_attr(attr_name, j)[0] for v, j in self._split_indices(indices)]

    def set_attr(self, attr_name, value, indices=None) -> None:
        for v in self.venvs:
            v.set_attr(attr_name, value)

    def env_method(self, method_name, *method_args, indices=None, **method_kwargs):
        return [
            v.env_method(method_name, *method_args, indices=j, **method_kwargs)[0]
            for v, j in self._split_indices(indices)
        ]

    def env_is_wrapped(self, wrapper_class, indices=None):
        return [False for _ in self._split_indices(indices)]

    def get_images(self):
        return [None] * self.num_envs

    def set_options(self, options=None) -> None:
        for v in self.venvs:
            v.set_options(options)


def _split_envs(weights: dict, n_envs: int) -> dict:
    """Sub-envs per load case, in proportion to ``weights`` (at least one each)."""
    total = float(sum(weights.values()))
    counts = {c: max(1, int(round(n_envs * w / total))) for c, w in weights.items()}
    last = list(counts)[-1]
    counts[last] = max(1, n_envs - sum(v for c, v in counts.items() if c != last))
    return counts


def make_sb3_env(cfg: AlgoConfig, seed: int, env_id: str, gamma: float = 0.99) -> VecNormalize:
    """The SB3 training env: per training load case a native batched env
    (``SB3VecEnv`` over ``gym.make_vec(env_id)``) side by side, actions in [-1, 1]
    (``VecAgentEnv``: no residual, no shaping), :class:`train.bench.sb3_envs.VecWhiten` if
    ``cfg.whiten_steps`` (identity until :func:`train.bench.sb3_train.train_sb3` sets it), optional
    direction
    features, and
    ``VecNormalize`` with ``cfg.normalize`` (seeded: sub-env i gets ``seed + i``)."""
    from acld_gym.envs.sb3 import SB3VecEnv

    from ..vec import VecAgentEnv

    parts = []
    for case, n in _split_envs(cfg.load_weights, cfg.n_envs).items():
        parts.append(SB3VecEnv(venv=gym.make_vec(env_id, num_envs=n, load_case=case,
                                                 **cfg.env_kwargs).unwrapped))
    venv: VecEnv = parts[0] if len(parts) == 1 else ConcatVecEnv(parts)
    venv.seed(seed)
    venv = VecAgentEnv(venv, residual=None, gamma=gamma, shaping=None)
    if cfg.whiten_steps:  # log c, if observed, stays as it is (the critic's scale)
        venv = VecWhiten(venv, passthrough=int(bool(cfg.env_kwargs.get("observe_reward_scale"))))
    if cfg.features == "direction":
        venv = VecDirectionFeatures(venv)
    return VecNormalize(venv, gamma=gamma, **cfg.normalize)
