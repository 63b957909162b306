r"""State observers (thesis sec. 3.2 and the realistic Kalman alternative).

Both are Luenberger-type observers

.. math::

    \dot{\hat x} = A_o \hat x + B_o V + E_o f + L (y - C_o \hat x),
    \qquad x_r = T \hat x,

described by :class:`Observer`; the simulator and the environment only see
this description.

* :func:`thesis_observer` -- the thesis's observer on the full 38-state model,
  gain from the CARE on :math:`(A^T, C^T)` with :math:`Q = I`, :math:`R = 1`
  (``MixedBeamModel.m``). That gain is tiny (the CARE weights are in metres),
  so the thesis's results only come out when this observer is *also fed the
  tip load* -- it then runs as a copy of the plant. This is the mode used to
  reproduce Table 2 (``fed_load=True``).
* :func:`kalman_observer` -- a steady-state Kalman filter on the nominal
  reduced model, with the tip load as process noise and a tip-sensor noise
  level. It is not fed the load: the realistic default everywhere else.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.linalg as sla

from acld_gym.design.numerics import care_gain
from acld_gym.design.reduction import ReducedModel

__all__ = [
    "Observer",
    "DiscreteObserver",
    "thesis_observer",
    "kalman_observer",
    "discrete_kalman",
    "discrete_thesis",
    "MODEL_STD",
]


@dataclass(frozen=True, eq=False)
class Observer:
    """Observer matrices; ``T`` maps its state to the reduced state x_r.

    ``E`` is the load input; it is zero when the observer is not fed the load.
    """

    A: np.ndarray
    B: np.ndarray
    E: np.ndarray
    C: np.ndarray
    L: np.ndarray
    T: np.ndarray
    name: str

    @property
    def n(self) -> int:
        return self.A.shape[0]

    @property
    def fed_load(self) -> bool:
        return bool(np.any(self.E))


def thesis_observer(
    A: np.ndarray,
    B: np.ndarray,
    E: np.ndarray,
    Cy: np.ndarray,
    red: ReducedModel,
    fed_load: bool = True,
) -> Observer:
    """Full-order observer with the thesis's CARE gain (Q = I, R = 1)."""
    Lt, _ = care_gain(A.T, Cy.T, np.eye(A.shape[0]), np.eye(1))
    return Observer(
        A=A,
        B=B,
        E=E if fed_load else np.zeros_like(E),
        C=Cy,
        L=Lt.T,
        T=red.SL.T,
        name="thesis" + ("+load" if fed_load else ""),
    )


def _noise_covariances(E: np.ndarray, load_std: float, sensor_std: float):
    """Process-noise covariance through the load input E and sensor-noise variance."""
    if not load_std > 0:
        raise ValueError(f"load_std must be positive [N], got {load_std!r}")
    if not sensor_std > 0:
        raise ValueError(f"sensor_std must be positive [m], got {sensor_std!r}")
    W = E @ E.T * load_std**2
    return 0.5 * (W + W.T), np.array([[sensor_std**2]])


def kalman_observer(
    red: ReducedModel, load_std: float = 1.0, sensor_std: float = 1e-7, bandwidth_s: float = 1e-3
) -> Observer:
    """Continuous steady-state Kalman filter on the reduced model.

    The tip load is white process noise of standard deviation ``load_std`` [N]
    over a correlation time ``bandwidth_s`` [s] (intensity load_std^2 * bandwidth_s,
    N^2 s), the tip sensor white noise of standard deviation ``sensor_std`` [m]
    at the same sampling (intensity sensor_std^2 * bandwidth_s, m^2 s).
    :math:`L = X C_r^T V^{-1}` with X from the filter Riccati equation.
    """
    W, V = _noise_covariances(red.E, load_std, sensor_std)
    Lt, _ = care_gain(red.A.T, red.C.T, W * bandwidth_s, V * bandwidth_s)
    k = red.order
    return Observer(
        A=red.A, B=red.B, E=np.zeros_like(red.E), C=red.C, L=Lt.T, T=np.eye(k), name="kalman"
    )


@dataclass(frozen=True, eq=False)
class DiscreteObserver:
    r"""Sampled observer, one form for both kinds:

    .. math::

        \hat x_{k|k} = \hat x_k + L_c (y_k - C \hat x_k), \qquad
        \hat x_{k+1} = A \hat x_k + B V_k + L_p (y_k - C \hat x_k) \;[+\ \text{load increment}],

    and :math:`x_{r,k} = T \hat x_{k|k}`. The steady-state Kalman filter has
    :math:`L_c = M` (measurement update) and :math:`L_p = A M`; the thesis's
    observer has :math:`L_c = 0` and :math:`L_p = \int_0^{\Delta} e^{As}ds\,L`
    and, when ``fed_load``, receives the same load increment as the plant.
    """

    A: np.ndarray
    B: np.ndarray
    C: np.ndarray
    Lc: np.ndarray
    Lp: np.ndarray
    T: np.ndarray
    fed_load: bool
    name: str

    @property
    def n(self) -> int:
        return self.A.shape[0]


#: Default model-error process noise of the Kalman filter (see :func:`discrete_kalman`).
MODEL_STD = 0.1


def discrete_kalman(
    Ad: np.ndarray,
    Bd: np.ndarray,
    Ed: np.ndarray,
    Cr: np.ndarray,
    load_std: float = 1.0,
    sensor_std: float = 1e-7,
    model_std: float = MODEL_STD,
) -> DiscreteObserver:
    r"""Steady-state discrete Kalman filter for the sampled reduced model.

    ``Ed`` is the sampled load input (state increment for 1 N held over a
    period). The load is white across periods with standard deviation
    ``load_std`` [N]; the tip sensor noise is white with ``sensor_std`` [m].
    :math:`M = X C^T (C X C^T + V)^{-1}`, X the prior covariance from the DARE
    with process noise

    .. math:: W = \sigma_f^2 E_d E_d^T + \mu^2 \operatorname{diag}(\Pi), \qquad
              \Pi = A_d \Pi A_d^T + E_d E_d^T,

    where the second term (``model_std`` :math:`= \mu`) stands for the model's own
    error: every reduced state is disturbed by a fraction :math:`\mu` of its stationary
    spread under a unit white load. With the load alone (rank-one W, :math:`\mu = 0`,
    ACLDBeam-v0) the filter trusts the lightly damped model so much that a 10 % change
    of the beam's stiffness destabilizes LQR + observer; with :math:`\mu = 0.1` the
    loop stays stable on every plant the env's ``param_noise`` accepts
    (tests/baselines/test_robustness.py).
    """
    if not (isinstance(model_std, (int, float)) and np.isfinite(model_std) and model_std >= 0):
        raise ValueError(f"model_std must be a non-negative number, got {model_std!r}")
    W, V = _noise_covariances(Ed, load_std, sensor_std)
    if model_std > 0:
        Pi = sla.solve_discrete_lyapunov(Ad, Ed @ Ed.T)
        W = W + model_std**2 * np.diag(np.diag(Pi))
    X = sla.solve_discrete_are(Ad.T, Cr.T, W, V)
    M = X @ Cr.T @ np.linalg.inv(Cr @ X @ Cr.T + V)
    return DiscreteObserver(
        A=Ad, B=Bd, C=Cr, Lc=M, Lp=Ad @ M, T=np.eye(Ad.shape[0]), fed_load=False, name="kalman"
    )


def discrete_thesis(
    Ad: np.ndarray, Bd_of_L: np.ndarray, Bd: np.ndarray, Cy: np.ndarray, continuous: Observer
) -> DiscreteObserver:
    """The thesis's observer sampled with the period of ``Ad`` (``Bd_of_L`` is the
    held-input matrix of the gain, :math:`\\int_0^\\Delta e^{As}ds\\,L`)."""
    return DiscreteObserver(
        A=Ad,
        B=Bd,
        C=Cy,
        Lc=np.zeros_like(Bd_of_L),
        Lp=Bd_of_L,
        T=continuous.T,
        fed_load=continuous.fed_load,
        name=continuous.name,
    )
