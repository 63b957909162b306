"""The training env: the native batched ``ACLDBeam-v1`` through SB3's ``VecEnv``
adapter, with the action mapped to [-1, 1] (optionally as a residual on the
discrete LQR), optional potential-based reward shaping, and ``VecNormalize``.

Wrapper order (inner to outer)::

    SB3VecEnv (volts) -> VecAgentEnv ([-1, 1], shaping) -> VecNormalize
"""

from __future__ import annotations

import numpy as np
from gymnasium import spaces
from stable_baselines3.common.vec_env import VecEnv, VecEnvWrapper, VecNormalize

from acld_gym.design.feedback import discrete_lqr_gain
from acld_gym.design.nominal import nominal_design
from acld_gym.envs.sb3 import SB3VecEnv
from acld_gym.physics.actuator import V_LIMIT

from .voltage import VoltageMap

__all__ = ["VoltageMap", "VecAgentEnv", "lq_potential", "make_vec_env"]


def lq_potential(gamma: float, lam: float, y_ref: float = 1e-3, dt: float = 1e-3,
                 mesh: str = "converged") -> np.ndarray:
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
    _, X = discrete_lqr_gain(g * Si @ sr.Ad @ S, g * Si @ sr.Bd, S @ C.T @ C @ S / y_ref**2,
                             np.array([[lam / V_LIMIT**2]]))
    return X


class VecAgentEnv(VecEnvWrapper):
    r"""The agent's side of the env: action space ``Box(-1, 1, (1,))`` mapped to volts
    by :class:`VoltageMap` (the role of gymnasium's ``RescaleAction`` for a ``VecEnv``)
    and, for training, potential-based reward shaping (Ng, Harada & Russell 1999),

    .. math:: r' = r + \gamma \Phi(s') - \Phi(s), \qquad \Phi(z) = -z^T P z,

    with P from :func:`lq_potential` and z the observer's estimate (``obs[:-1]``).
    With the algorithm's own :math:`\gamma` shaping leaves the optimal policy
    unchanged; it gives each action immediate credit for the vibration energy it
    removes. At an episode's end s' is the terminal observation. One class for
    training and evaluation keeps both wrapped alike (``VecNormalize`` statistics
    are synchronized level by level)."""

    def __init__(self, venv: VecEnv, residual: str | None = None, gamma: float = 0.99,
                 shaping: float | None = None, mesh: str = "converged"):
        super().__init__(venv, action_space=spaces.Box(-1.0, 1.0, (1,), np.float32))
        self.map = VoltageMap(residual, mesh)
        self.gamma = float(gamma)
        self.P = None if shaping is None else lq_potential(self.gamma, shaping, mesh=mesh)
        self._obs: np.ndarray | None = None

    @property
    def residual(self) -> str | None:
        """The action map's residual (None or ``"lqr"``)."""
        return self.map.residual

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
            rewards = (rewards + self.gamma * self.potential(final)
                       - self.potential(self._obs)).astype(np.float32)
        self._obs = obs
        return obs, rewards, dones, infos


def make_vec_env(cfg, seed: int, n_envs: int | None = None, backend: str = "native",
                 load_case=None) -> VecNormalize:
    """The wrapped training env of a :class:`train.config.TrainConfig` (seeded).

    ``backend="native"``: :class:`acld_gym.envs.sb3.SB3VecEnv` (one batched env);
    ``"subproc"``: SB3's ``SubprocVecEnv`` over single envs (for comparison).
    """
    n = cfg.n_envs if n_envs is None else n_envs
    kw = dict(load_case=cfg.load_case if load_case is None else load_case,
              param_noise=cfg.param_noise, mesh=cfg.mesh)
    if backend == "native":
        venv: VecEnv = SB3VecEnv(num_envs=n, **kw)
    elif backend == "subproc":
        from stable_baselines3.common.env_util import make_vec_env as sb3_make_vec_env
        from stable_baselines3.common.vec_env import SubprocVecEnv

        venv = sb3_make_vec_env("acld_gym:ACLDBeam-v1", n_envs=n, env_kwargs=kw,
                                vec_env_cls=SubprocVecEnv)
    else:
        raise ValueError(f"backend must be 'native' or 'subproc', got {backend!r}")
    venv.seed(seed)
    venv = VecAgentEnv(venv, cfg.residual, cfg.gamma, cfg.shaping, mesh=cfg.mesh)
    return VecNormalize(venv, gamma=cfg.gamma, **cfg.normalize)
