"""The training env of every SB3 algorithm: the native batched env (``SB3VecEnv`` over
``gym.make_vec``), one per training load case side by side (:class:`ConcatVecEnv`), the
agent's action in [-1, 1] mapped to volts (optionally as a residual on the discrete LQR)
with optional potential-based reward shaping (:class:`VecAgentEnv`), optionally a fixed
whitening (:class:`VecWhiten`) or direction features (:class:`VecDirectionFeatures`) of
the observation, and ``VecNormalize``: :func:`make_vec_env`, the one factory.

Wrapper order (inner to outer)::

    SB3VecEnv (volts) [-> ConcatVecEnv] -> VecAgentEnv ([-1, 1], shaping)
        [-> VecWhiten | VecDirectionFeatures] -> VecNormalize
"""

from __future__ import annotations

import gymnasium as gym
import numpy as np
from gymnasium import spaces
from stable_baselines3.common.vec_env import VecEnv, VecEnvWrapper, VecNormalize

import acld_gym  # noqa: F401  (registers the env ids)
from acld_gym.design.feedback import discrete_lqr_gain
from acld_gym.design.nominal import nominal_design
from acld_gym.physics.actuator import V_LIMIT

from .features import direction_features
from .voltage import VoltageMap

__all__ = [
    "VoltageMap",
    "VecAgentEnv",
    "VecDirectionFeatures",
    "VecWhiten",
    "ConcatVecEnv",
    "lq_potential",
    "find_wrapper",
    "make_vec_env",
]


def lq_potential(
    gamma: float, lam: float, y_ref: float = 1e-3, dt: float = 1e-3, mesh: str = "converged"
) -> np.ndarray:
    r"""Matrix P of the shaping potential :math:`\Phi(z) = -z^T P z`, z = the observation's
    reduced-state part.

    P is the value of the discounted LQ problem with the env's reward weights on
    the nominal reduced model, :math:`\min \sum_k \gamma^k ((y_k/y_\mathrm{ref})^2
    + \lambda (V_k/120)^2)`, i.e. the DARE solution for
    :math:`(\sqrt\gamma A_d, \sqrt\gamma B_d)`, solved in the observation's scaled
    coordinates (entries of order one instead of 1e-6 .. 1e4).
    """
    nom = nominal_design(dt, mesh=mesh)
    sr, C = nom.reduced, nom.design.reduced.C
    S = np.diag(nom.xr_scale)
    Si = np.diag(1.0 / nom.xr_scale)
    g = np.sqrt(gamma)
    _, X = discrete_lqr_gain(
        g * Si @ sr.Ad @ S,
        g * Si @ sr.Bd,
        S @ C.T @ C @ S / y_ref**2,
        np.array([[lam / V_LIMIT**2]]),
    )
    return X


class VecAgentEnv(VecEnvWrapper):
    r"""The agent's side of the env: action space ``Box(-1, 1, (1,))`` mapped to volts
    by :class:`VoltageMap` (the role of :class:`acld_gym.wrappers.UnitAction` for a
    ``VecEnv``, ``headroom`` included)
    and, for training, potential-based reward shaping (Ng, Harada & Russell 1999),

    .. math:: r' = r + \gamma \Phi(s') - \Phi(s), \qquad \Phi(z) = -z^T P z,

    with P from :func:`lq_potential` and z the observer's estimate (``obs[:-1]``).
    With the algorithm's own :math:`\gamma` shaping leaves the optimal policy
    unchanged; it gives each action immediate credit for the vibration energy it
    removes. At an episode's end s' is the terminal observation. One class for
    training and evaluation keeps both wrapped alike (``VecNormalize`` statistics
    are synchronized level by level)."""

    def __init__(
        self,
        venv: VecEnv,
        residual: str | None = None,
        gamma: float = 0.99,
        shaping: float | None = None,
        mesh: str = "converged",
        headroom: float = 1.0,
    ):
        super().__init__(venv, action_space=spaces.Box(-1.0, 1.0, (1,), np.float32))
        self.map = VoltageMap(residual, mesh, headroom)
        self.gamma = float(gamma)
        self.P = None if shaping is None else lq_potential(self.gamma, shaping, mesh=mesh)
        self._obs: np.ndarray | None = None

    @property
    def residual(self) -> str | None:
        """The action map's residual (None or ``"lqr"``)."""
        return self.map.residual

    @property
    def last_obs(self) -> np.ndarray | None:
        """The raw observation of the last reset or step (what the voltage map and a
        teacher see), before any outer wrapper."""
        return self._obs

    def potential(self, obs: np.ndarray) -> np.ndarray:
        z = np.asarray(obs, dtype=np.float64)[:, : self.P.shape[0]]
        return -np.einsum("ni,ij,nj->n", z, self.P, z)

    def reset(self) -> np.ndarray:
        self._obs = self.venv.reset()
        return self._obs

    def step_async(self, actions: np.ndarray) -> None:
        self.venv.step_async(self.map(actions, self._obs))

    def step_wait(self):
        obs, rewards, dones, infos = self.venv.step_wait()
        if self.P is not None:
            final = obs.copy()
            for i in np.flatnonzero(dones):
                final[i] = infos[i]["terminal_observation"]
            rewards = (
                rewards + self.gamma * self.potential(final) - self.potential(self._obs)
            ).astype(np.float32)
        self._obs = obs
        return obs, rewards, dones, infos


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
    :func:`acld_gym.wrappers.whitening` estimates T (:func:`train.core.sb3_train.train_sb3` with
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
                [terminal[:d] @ self.transform, terminal[d:]]
            ).astype(np.float32)
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


def find_wrapper(venv: VecEnv, cls: type) -> VecEnv | None:
    """The outermost ``cls`` in a chain of SB3 ``VecEnvWrapper`` (or None)."""
    while venv is not None:
        if isinstance(venv, cls):
            return venv
        venv = getattr(venv, "venv", None)
    return None


def make_vec_env(
    cfg, seed: int, env_id: str = acld_gym.ENV_ID, backend: str = "native"
) -> VecNormalize:
    """The training env of a :class:`train.config.TrainConfig`, seeded (sub-env i gets
    ``seed + i``, or with ``cfg.paired_loads`` ``seed + i // 2`` within each load case):
    per training load case a batched env of ``env_id`` with the config's ``env_kwargs``
    (sub-envs split as ``cfg.envs_per_load``), :class:`VecAgentEnv` with the config's
    ``residual``, ``action_headroom`` and ``shaping``, :class:`VecWhiten` if
    ``cfg.whiten_steps`` (identity until :func:`train.core.sb3_train.train_sb3` sets it),
    direction features if ``cfg.features``, and ``VecNormalize`` with ``cfg.normalize``.

    ``backend="native"``: :class:`acld_gym.envs.sb3.SB3VecEnv` over ``gym.make_vec``;
    ``"subproc"``: SB3's ``SubprocVecEnv`` over single envs (the same envs, for
    comparing throughput).
    """
    from acld_gym.envs.sb3 import SB3VecEnv

    if backend not in ("native", "subproc"):
        raise ValueError(f"backend must be 'native' or 'subproc', got {backend!r}")
    if cfg.paired_loads and backend != "native":
        raise ValueError(f"paired_loads needs backend 'native', got {backend!r}")
    parts = []
    for case, n in cfg.envs_per_load.items():
        kwargs = dict(cfg.env_kwargs, load_case=case)
        if backend == "native":
            vec = gym.make_vec(env_id, num_envs=n, **kwargs).unwrapped
            parts.append(SB3VecEnv(venv=vec, seed_group=2 if cfg.paired_loads else 1))
        else:
            from stable_baselines3.common.env_util import make_vec_env as sb3_make_vec_env
            from stable_baselines3.common.vec_env import SubprocVecEnv

            # "module:id": the worker processes import acld_gym, which registers the ids
            full_id = env_id if ":" in env_id else f"acld_gym:{env_id}"
            parts.append(
                sb3_make_vec_env(full_id, n_envs=n, env_kwargs=kwargs, vec_env_cls=SubprocVecEnv)
            )
    venv: VecEnv = parts[0] if len(parts) == 1 else ConcatVecEnv(parts)
    venv.seed(seed)
    venv = VecAgentEnv(
        venv, cfg.residual, cfg.gamma, cfg.shaping, mesh=cfg.mesh, headroom=cfg.action_headroom
    )
    if cfg.whiten_steps:  # log c, if observed, stays as it is (the critic's scale)
        venv = VecWhiten(venv, passthrough=int(bool(cfg.env_kwargs.get("observe_reward_scale"))))
    if cfg.features == "direction":
        venv = VecDirectionFeatures(venv)
    return VecNormalize(venv, gamma=cfg.gamma, **cfg.normalize)
