r"""The engineer's MPC for the level's known actuator, on the env's reward."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from acld_gym.design.feedback import THESIS_LQR_WEIGHT
from acld_gym.physics.actuator import V_LIMIT
from baselines.policies import MPCPolicy

from .. import arguments
from ..qp import SETTINGS, solution
from .base import RigPolicy
from .riccati import lqr

__all__ = ["ActuatorMPCPolicy"]


@dataclass(frozen=True, eq=False)
class _Reduced:
    C: np.ndarray
    order: int


@dataclass(frozen=True, eq=False)
class _Design:
    reduced: _Reduced
    weight: np.ndarray

    def state_weight(self, weight: float) -> np.ndarray:
        return weight * self.weight


@dataclass(frozen=True, eq=False)
class _PlantPart:
    """The plant part of a :class:`~baselines.engineer.model.RigModel` (the reduced model
    with the amplifier's lag) presented as the nominal design :class:`MPCPolicy` builds
    its prediction matrices from (``reduced.Ad``, ``reduced.Bd``, ``design.reduced.C``,
    ``design.state_weight``): the QP machinery is reused as it is."""

    reduced: object
    design: _Design


class _RateMPC(MPCPolicy):
    """:class:`MPCPolicy`'s QP with the slew limit as rate constraints on the voltages:
    :math:`|u_0 - v_{-1}| \\le \\sigma`, :math:`|u_j - u_{j-1}| \\le \\sigma` (units of
    120 V; σ the slew per period), besides the box."""

    slew = None  # per period, units of 120 V; None: the box alone
    terminal = None  # (Gamma_H, A^H, S): the tail's cost x_H^T S x_H (None: none)

    def _nominal(self, dt, nom, mesh):
        return nom  # the plant part (_PlantPart), built and checked by ActuatorMPCPolicy

    def set_terminal(self, S: np.ndarray, A: np.ndarray, b: np.ndarray) -> None:
        r"""Add the terminal cost :math:`x_{k+H}^T S x_{k+H}`, with
        :math:`x_{k+H} = A^H x + \Gamma_H u` (u in units of 120 V), to the QP."""
        H = self._setup[2]
        gam = np.empty((A.shape[0], H))
        Aj = np.eye(A.shape[0])
        for i in range(H - 1, -1, -1):
            gam[:, i] = Aj @ b * V_LIMIT
            Aj = A @ Aj
        self.terminal = (gam, Aj, S)
        self._hessian = self._hessian + gam.T @ S @ gam
        self._setup = (sp.csc_matrix(np.triu(2.0 * self._hessian)), self._setup[1], H)
        self._solvers.clear()

    def _linear_term(self, x: np.ndarray) -> np.ndarray:
        q = super()._linear_term(x)
        if self.terminal is not None:
            gam, AH, S = self.terminal
            q = q + 2.0 * (gam.T @ (S @ (AH @ x)))
        return q

    def small_signal_gain(self) -> np.ndarray:
        """:meth:`MPCPolicy.small_signal_gain` with the terminal cost."""
        G = self.Theta.T @ self.Psi
        if self._Lx is not None:
            G = G + self._Lx[0].T @ self._Lx[1]
        if self.terminal is not None:
            gam, AH, S = self.terminal
            G = G + gam.T @ S @ AH
        return V_LIMIT * np.linalg.solve(self._hessian, G)[0]

    def _solver(self, i: int):
        if self.slew is None:
            return super()._solver(i)
        if i not in self._solvers:
            P, _, H = self._setup
            D = sp.eye(H, format="csc") - sp.eye(H, k=-1, format="csc")
            prob = self._osqp.OSQP()
            prob.setup(
                P=P,
                q=np.zeros(H),
                A=sp.vstack([sp.identity(H, format="csc"), D], format="csc"),
                l=np.r_[-np.ones(H), -self.slew * np.ones(H)],
                u=np.r_[np.ones(H), self.slew * np.ones(H)],
                **SETTINGS,
            )
            self._solvers[i] = prob
        return self._solvers[i]

    def first_moves(self, x: np.ndarray, held: np.ndarray) -> np.ndarray:
        """The first voltage [V] of the QP from plant states ``x`` (N, n) after the
        amplifier's output ``held`` (N,) [V]."""
        out = np.empty(x.shape[0])
        H = self._setup[2]
        for i in range(x.shape[0]):
            prob = self._solver(i)
            if self.slew is None:
                prob.update(q=self._linear_term(x[i]))
            else:
                h = held[i] / V_LIMIT
                lo = np.r_[-np.ones(H), h - self.slew, -self.slew * np.ones(H - 1)]
                hi = np.r_[np.ones(H), h + self.slew, self.slew * np.ones(H - 1)]
                prob.update(q=self._linear_term(x[i]), l=lo, u=hi)
            res = prob.solve(raise_error=False)
            out[i] = V_LIMIT * float(solution(res, "MPC")[0])
        return out


class ActuatorMPCPolicy(RigPolicy):
    r"""MPC of the env's reward that knows the level's actuator.

    * **The delay by prediction.** The d commands in flight are known, so the filter's
      estimate (:mod:`baselines.engineer.base`) is carried d periods ahead exactly,
      :math:`\hat x_{k+d|k} = A_p^d \hat x_{k|k} + \sum_{j<d} A_p^{d-1-j} b_p v_{k+j}`
      (:math:`v` the voltages they produce at the amplifier), and the command
      :math:`u_k` chosen now is the first that can still be chosen: it reaches the
      amplifier at k + d.
    * **The QP** from :math:`\hat x_{k+d|k}` is :class:`baselines.policies.MPCPolicy`'s
      (OSQP, warm-started, condensed in the H voltages) on the plant part of the design
      model -- with the amplifier's lag as a state where the level has one -- and the
      env's reward as its cost, as :class:`baselines.policies.RewardMPCPolicy`:

      .. math::

          \min_{u} \sum_{j=1}^{H} \hat y_{k+d+j}^2 + \rho \sum_{i=0}^{H-1} (u_{k+i}/120)^2,
          \qquad \rho = \lambda (y_{ref} / 1\ \mathrm{mm})^2 / w,
          \qquad |u| \le 120\ \mathrm{V},

      plus, with a slew limit σ = ``slew_rate * dt``, the rate constraints
      :math:`|u_k - v_{k+d-1}| \le σ`, :math:`|u_{k+i} - u_{k+i-1}| \le σ`.
      w (``weight``) multiplies the deflection term (1: the env's reward), as
      :class:`~baselines.engineer.lqg.DelayLQGPolicy`'s; ``state_weight`` adds
      :class:`MPCPolicy`'s small multiple of the thesis LQR's state
      weight (its robustness term; 0: the reward alone).
    * **The tail** (``terminal``, default): the cost beyond the horizon is the LQR's
      cost-to-go :math:`\hat x_{k+d+H}^T S\, \hat x_{k+d+H}` of the same stage cost
      (:func:`baselines.engineer.riccati.lqr`), so where no constraint is active the MPC
      is the infinite-horizon LQR -- the LQG's law
      (:class:`~baselines.engineer.lqg.DelayLQGPolicy`) -- and where the voltage limit is
      active it plans the saturated stretch and the linear tail together.

    **Knows**: the nominal beam, the delay, the amplifier's bandwidth and slew rate, the
    sensor's noise, the reward. **Does not know**: the episode's load, temperature and
    parameters. The first voltage is applied; about rest, with no constraint active, it is
    the linear law :meth:`small_signal_gain` on :math:`\hat z`.
    """

    name = "mpc_rig"

    def __init__(
        self,
        nom,
        config,
        horizon: int = 60,
        weight: float = 1.0,
        state_weight: float = 0.0,
        terminal: bool = True,
        model_std: float | None = None,
        load_std: float = 1.0,
        model=None,
    ):
        horizon, self.weight = arguments.horizon(horizon), arguments.positive("weight", weight)
        state_weight = arguments.non_negative("state_weight", state_weight)
        terminal = arguments.flag("terminal", terminal)
        super().__init__(nom, config, model_std=model_std, load_std=load_std, model=model)
        m = self.model
        k = nom.design.reduced.order
        W = np.zeros((m.n_plant, m.n_plant))
        if state_weight > 0:  # the thesis LQR's weight, on the reduced state (its own basis)
            W[:k, :k] = nom.design.state_weight(1.0)
        part = _PlantPart(
            reduced=m.plant, design=_Design(_Reduced(C=m.c[None, :], order=m.n_plant), W)
        )
        rho = m.lam * (m.y_ref / 1e-3) ** 2 / self.weight
        self.mpc = _RateMPC(horizon=horizon, rho=rho, state_weight=state_weight, nom=part)
        self.mpc.slew = None if m.slew_step is None else m.slew_step / V_LIMIT
        self.horizon = horizon
        if terminal:
            # the tail's stage cost on (x_i, u_i): |c (A x + b u)|^2 / (1 mm)^2 + the state
            # weight of x_{i+1}, and rho (u / 120)^2 -- the QP's own stage, in volts
            A, b = m.plant.Ad, m.plant.Bd
            Qy = np.outer(m.c, m.c) / 1e-6 + state_weight * THESIS_LQR_WEIGHT * W / V_LIMIT**2
            Q, N = A.T @ Qy @ A, A.T @ Qy @ b
            R = b.T @ Qy @ b + rho / V_LIMIT**2
            _, S = lqr(A, b, Q, R, N, m.scale)
            self.mpc.set_terminal(S, A, b[:, 0])

    def _ahead(self, z: np.ndarray, held: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """``(x̂_{k+d|k}, v_{k+d-1})``: the plant's estimate carried over the commands in
        flight, and the amplifier's output when the next command reaches it."""
        m, n_p = self.model, self.model.n_plant
        x, v = z[:, :n_p].copy(), np.asarray(held, dtype=float).copy()
        for j in range(m.delay):
            v = m.drive(z[:, n_p + j], v)
            x = x @ m.plant.Ad.T + np.outer(v, m.plant.Bd[:, 0])
        return x, v

    def command(self, z: np.ndarray, held: np.ndarray) -> np.ndarray:
        x, v = self._ahead(z, held)
        return self.mpc.first_moves(x, v)

    def prediction_map(self) -> np.ndarray:
        r"""P (n_p, n) with :math:`\hat x_{k+d|k} = P \hat z_k` (no slew limit binding)."""
        m, n_p, d = self.model, self.model.n_plant, self.model.delay
        P = np.zeros((n_p, n_p + d))
        P[:, :n_p] = np.eye(n_p)
        Ap, bp = m.plant.Ad, m.plant.Bd[:, 0]
        for j in range(d):
            P = Ap @ P
            P[:, n_p + j] += bp
        return P

    def small_signal_gain(self) -> np.ndarray:
        """The unconstrained QP's first move as a gain on :math:`\\hat z`,
        :math:`u = -K_{QP} P \\hat z` (:meth:`prediction_map` P)."""
        return self.mpc.small_signal_gain() @ self.prediction_map()
