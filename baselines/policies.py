"""Reference policies for ``ACLDBeam-v0`` with stable-baselines3's ``predict`` protocol.

They are designed on the nominal reduced model sampled at the env's control
period (:func:`acld_gym.env.nominal`) and read the reduced-state estimate
from the ``"estimate"`` observation (``obs[:6] * xr_scale``), so
``evaluate_policy`` and :mod:`baselines.evaluate` treat them like agents.
"""

from __future__ import annotations

import numpy as np
import scipy.linalg as sla

from acld_gym.control import THESIS_LQR_WEIGHT, THESIS_SMC_WEIGHT
from acld_gym.env import Nominal, nominal
from acld_gym.thesis import V_LIMIT

__all__ = ["PassivePolicy", "LQRPolicy", "SMCPolicy", "MPCPolicy", "discrete_lqr_gain"]


def discrete_lqr_gain(A: np.ndarray, B: np.ndarray, Q: np.ndarray,
                      R: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """:math:`K = (R + B^T X B)^{-1} B^T X A` with X from the DARE; returns (K, X)."""
    X = sla.solve_discrete_are(A, B, 0.5 * (Q + Q.T), R)
    return np.linalg.solve(R + B.T @ X @ B, B.T @ X @ A), X


class _Policy:
    """Common ``predict`` plumbing: batch handling, estimate decoding, clipping."""

    name = "policy"

    def __init__(self, dt: float = 1e-3, nom: Nominal | None = None):
        self.nom = nominal(dt) if nom is None else nom
        self.k = self.nom.design.reduced.order

    def reduced_state(self, obs: np.ndarray) -> np.ndarray:
        obs = np.asarray(obs, dtype=np.float64)
        if obs.shape[-1] != self.k + 1:
            raise ValueError(f"obs: {type(self).__name__} needs the env's 'estimate' observation "
                             f"({self.k + 1} values), got shape {obs.shape}")
        return obs[..., : self.k] * self.nom.xr_scale

    def voltage(self, xr: np.ndarray) -> np.ndarray:  # pragma: no cover - abstract
        raise NotImplementedError

    def predict(self, observation, state=None, episode_start=None, deterministic: bool = True):
        """SB3 protocol: returns ``(actions, state)``; actions in volts, shape (n, 1) or (1,)."""
        obs = np.asarray(observation)
        batched = obs.ndim == 2
        xr = self.reduced_state(np.atleast_2d(obs))
        v = np.clip(self.voltage(xr), -V_LIMIT, V_LIMIT).astype(np.float32)[:, None]
        return (v if batched else v[0]), state


class PassivePolicy(_Policy):
    """V = 0: the passive (PCLD) beam."""

    name = "passive"

    def voltage(self, xr):
        return np.zeros(xr.shape[0])


class LQRPolicy(_Policy):
    r"""Discrete LQR with the thesis's weights: :math:`Q = 10^{11} S_R^T S_R`, R = 1
    (eqs. 65-67), on the reduced model sampled at ``dt``."""

    name = "lqr"

    def __init__(self, dt: float = 1e-3, weight: float = THESIS_LQR_WEIGHT, nom=None):
        super().__init__(dt, nom)
        r, sr = self.nom.design.reduced, self.nom.reduced
        self.K, _ = discrete_lqr_gain(sr.Ad, sr.Bd, weight * r.SR.T @ r.SR, np.eye(1))

    def voltage(self, xr):
        return -(xr @ self.K[0])


class SMCPolicy(_Policy):
    r"""Discrete sliding-mode control with the thesis's weights (eqs. 68-72, sampled).

    * Surface :math:`\sigma = s x_r` with :math:`s = (1 + B_d^T X B_d)^{-1} B_d^T X`,
      X from the DARE with :math:`Q = 10^6 S_R^T S_R`, R = 1 (sigma in volts). The
      thesis's choice -- the LQR gain itself as the surface -- has unstable
      sliding dynamics once sampled (the discrete gain contains :math:`A_d`;
      its zero dynamics have |z| = 1.01), while :math:`B_d^T X` gives
      |z| = 0.975.
    * Equivalent control (deadbeat on sigma):
      :math:`u_{eq} = -(s B_d)^{-1} s A_d x_r`.
    * Switching term :math:`-\operatorname{sign}(s B_d)\,\eta\,
      \operatorname{sat}(\sigma/\varepsilon)` with
      :math:`\eta = 1.5 |s E_d / s B_d|` (the thesis's 1.5 margin over one
      period of 1 N load, ``MixedBeamModel.m``).
    * Boundary layer :math:`\varepsilon` = 1000 V (default). In discrete time
      the voltage limit bounds the change of sigma per step to about
      :math:`2 |s B_d| \cdot 120` V = 235 V; a layer thinner than that
      band makes the switching term a relay on sigma that never settles
      (with the thesis's eps = 1 the beam does not settle within 1 s).
    """

    name = "smc"

    def __init__(self, dt: float = 1e-3, weight: float = THESIS_SMC_WEIGHT,
                 eta_factor: float = 1.5, eps: float = 1000.0, nom=None):
        super().__init__(dt, nom)
        if not eps > 0:
            raise ValueError(f"eps must be positive [V], got {eps!r}")
        r, sr = self.nom.design.reduced, self.nom.reduced
        _, X = discrete_lqr_gain(sr.Ad, sr.Bd, weight * r.SR.T @ r.SR, np.eye(1))
        B = sr.Bd[:, 0]
        self.s = (B @ X) / (1.0 + B @ X @ B)
        self.sb = float(self.s @ B)
        self.a = (self.s @ sr.Ad) / self.sb
        self.c = float(np.sign(self.sb)) * eta_factor * abs(float(self.s @ sr.Ed[:, 0]) / self.sb)
        self.eps = float(eps)

    def voltage(self, xr):
        return -(xr @ self.a) - self.c * np.clip((xr @ self.s) / self.eps, -1.0, 1.0)


class MPCPolicy(_Policy):
    r"""Box-constrained MPC on the sampled reduced model (OSQP).

    At each step, with :math:`\hat x` the reduced estimate,

    .. math::

        \min_{|V_i| \le 120} \sum_{j=1}^{H} \hat y_{k+j}^2 + \rho \sum_{i=0}^{H-1}
        (V_{k+i} / 120)^2, \qquad \hat y = C_r \hat x \text{ predicted},

    a condensed QP in the H voltages (scaled to mm and units of 120 V),
    warm-started from the previous solution. The first voltage is applied.
    """

    name = "mpc"

    def __init__(self, dt: float = 1e-3, horizon: int = 60, rho: float = 1e-4, nom=None):
        super().__init__(dt, nom)
        import osqp
        import scipy.sparse as sp

        if not isinstance(horizon, int) or horizon < 1:
            raise ValueError(f"horizon must be a positive integer, got {horizon!r}")
        if not rho >= 0:
            raise ValueError(f"rho must be non-negative, got {rho!r}")
        sr, C = self.nom.reduced, self.nom.design.reduced.C
        A, B = sr.Ad, sr.Bd[:, 0]
        H, n = horizon, A.shape[0]
        Psi = np.empty((H, n))
        h = np.empty(H)  # impulse response C A^j B
        Aj = np.eye(n)
        for j in range(H):
            h[j] = C[0] @ Aj @ B
            Aj = A @ Aj
            Psi[j] = C[0] @ Aj
        Theta = np.zeros((H, H))
        for j in range(H):
            Theta[j, : j + 1] = h[j::-1]
        s = V_LIMIT / 1e-3  # u in units of 120 V, y in mm
        self.Theta = Theta * s
        self.Psi = Psi / 1e-3
        P = 2.0 * (self.Theta.T @ self.Theta + rho * np.eye(H))
        self._solvers: dict[int, object] = {}
        self._setup = (sp.csc_matrix(np.triu(P)), sp.identity(H, format="csc"), H)
        self._osqp = osqp

    def _solver(self, i: int):
        if i not in self._solvers:
            P, Aeq, H = self._setup
            prob = self._osqp.OSQP()
            prob.setup(P=P, q=np.zeros(H), A=Aeq, l=-np.ones(H), u=np.ones(H), verbose=False,
                       eps_abs=1e-7, eps_rel=1e-7, polishing=False, max_iter=20000)
            self._solvers[i] = prob
        return self._solvers[i]

    def voltage(self, xr):
        out = np.empty(xr.shape[0])
        for i, x in enumerate(xr):  # one QP per env (solvers warm-start per env index)
            prob = self._solver(i)
            prob.update(q=2.0 * self.Theta.T @ (self.Psi @ x))
            res = prob.solve(raise_error=False)
            if res.info.status not in ("solved", "solved inaccurate"):
                raise RuntimeError(f"MPC: OSQP returned status {res.info.status!r}")
            out[i] = V_LIMIT * float(res.x[0])
        return out
