r"""Continuous-time controller designs on the reduced model (thesis ch. 4).

Every controller here is a piecewise-affine state feedback on the reduced
state :math:`x_r`,

.. math::

    V = \operatorname{clip}\big(-a\,x_r - c\,\operatorname{sat}(s\,x_r/\varepsilon),
    \;-V_{max},\,V_{max}\big),

described by :class:`Feedback`. LQR is the special case :math:`c = 0`.

* LQR (eqs. 65-67): :math:`\hat Q = q\,S_R^T W S_R` (q = 1e11), R = 1, with W the
  metric of the full state (the identity on the thesis mesh's DOFs, where the thesis
  puts its weight; :attr:`acld_gym.design.pipeline.Design.metric` for other plants).
* SMC (eqs. 68-72): sliding surface :math:`s` = the LQR gain for
  :math:`q = 10^6`; equivalent control :math:`-(sB_r)^{-1} s A_r x_r`;
  switching gain :math:`\eta = 1.5\,|(sB_r)^{-1} s S_L^T \hat B|`
  (``MixedBeamModel.m``), signed so that :math:`\sigma\dot\sigma < 0`:
  :math:`c = \operatorname{sign}(sB_r)\,\eta`.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.linalg as sla

from acld_gym.design.numerics import care_gain
from acld_gym.design.reduction import ReducedModel

__all__ = [
    "Feedback",
    "passive",
    "lqr",
    "smc",
    "projected_weight",
    "discrete_lqr_gain",
    "THESIS_LQR_WEIGHT",
    "THESIS_SMC_WEIGHT",
]

#: Full-state weight of the thesis's LQR, Q = 1e11 I (Table 1).
THESIS_LQR_WEIGHT = 1e11
#: Full-state weight of the thesis's sliding surface, Q = 1e6 I (Table 1).
THESIS_SMC_WEIGHT = 1e6


@dataclass(frozen=True, eq=False)
class Feedback:
    """Piecewise-affine voltage law on the reduced state (see module docstring).

    Attributes
    ----------
    a : linear gain (k,) [V per unit x_r].
    s : sliding-surface row (k,); zero for linear laws.
    c : signed switching gain [V].
    eps : boundary-layer thickness (in units of sigma = s x_r).
    name : "passive", "lqr" or "smc".
    """

    a: np.ndarray
    s: np.ndarray
    c: float
    eps: float
    name: str

    def voltage(self, xr: np.ndarray, v_max: float | None = None) -> np.ndarray:
        """Requested voltage for reduced state(s) ``xr`` (..., k), clipped to
        +/- ``v_max`` when given."""
        xr = np.asarray(xr)
        v = -(xr @ self.a)
        if self.c != 0.0:
            v = v - self.c * np.clip((xr @ self.s) / self.eps, -1.0, 1.0)
        return v if v_max is None else np.clip(v, -v_max, v_max)

    def small_signal_gain(self) -> np.ndarray:
        """K with V = -K x_r inside the boundary layer and below the limit:
        :math:`a + (c/\varepsilon)\\,s`."""
        return self.a + (self.c / self.eps) * self.s


def passive(k: int) -> Feedback:
    """No control (V = 0): the passive (PCLD) beam."""
    z = np.zeros(k)
    return Feedback(a=z, s=z, c=0.0, eps=1.0, name="passive")


def _projected_lqr(
    red: ReducedModel, weight: float, R: float, metric: np.ndarray | None
) -> np.ndarray:
    if not weight > 0:
        raise ValueError(f"weight must be positive, got {weight!r}")
    if not R > 0:
        raise ValueError(f"R must be positive, got {R!r}")
    K, _ = care_gain(red.A, red.B, projected_weight(red, weight, metric), np.array([[R]]))
    return K[0]


def projected_weight(
    red: ReducedModel, weight: float, metric: np.ndarray | None = None
) -> np.ndarray:
    r""":math:`q\,S_R^T W S_R`: the full-state weight ``weight * W`` seen by the reduced
    state (W = ``metric``, default the identity), symmetrized."""
    SR = red.SR
    Q = weight * (SR.T @ SR if metric is None else SR.T @ metric @ SR)
    return 0.5 * (Q + Q.T)


def lqr(
    red: ReducedModel,
    weight: float = THESIS_LQR_WEIGHT,
    R: float = 1.0,
    metric: np.ndarray | None = None,
) -> Feedback:
    """LQR with the full-state weight ``weight * W`` projected by S_R (eq. 67)."""
    K = _projected_lqr(red, weight, R, metric)
    return Feedback(a=K, s=np.zeros_like(K), c=0.0, eps=1.0, name="lqr")


def smc(
    red: ReducedModel,
    weight: float = THESIS_SMC_WEIGHT,
    R: float = 1.0,
    eta_factor: float = 1.5,
    eps: float = 1.0,
    metric: np.ndarray | None = None,
) -> Feedback:
    """Sliding-mode control with boundary layer (eqs. 68-72).

    ``red.E`` must hold the reduced tip-load input :math:`S_L^T \\hat B`.
    """
    if not eps > 0:
        raise ValueError(f"eps must be positive, got {eps!r}")
    if red.E.shape[1] != 1:
        raise ValueError("red: the reduced model needs its tip-load input E (one column)")
    S = _projected_lqr(red, weight, R, metric)
    sb = float(S @ red.B[:, 0])
    eta = eta_factor * abs(float(S @ red.E[:, 0]) / sb)
    a = (S @ red.A) / sb  # u_eq = -(S B)^-1 S A x_r
    return Feedback(a=a, s=S, c=float(np.sign(sb)) * eta, eps=eps, name="smc")


def discrete_lqr_gain(
    A: np.ndarray, B: np.ndarray, Q: np.ndarray, R: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Discrete LQR: :math:`K = (R + B^T X B)^{-1} B^T X A` with X from the DARE;
    returns ``(K, X)``."""
    X = sla.solve_discrete_are(A, B, 0.5 * (Q + Q.T), R)
    return np.linalg.solve(R + B.T @ X @ B, B.T @ X @ A), X
