r"""The two Riccati solves of an LQG, each in scaled coordinates.

The beam's continuous eigenvalues span about 1 to 1e7 1/s and its states differ by orders of
magnitude in their units, so every solve here first maps the model to states of order one:
:math:`x = D \tilde x` with D the states' magnitudes (:attr:`baselines.engineer.model.
RigModel.scale`: each reduced state's peak in the passive response to thesis case 1, 120 V
for a voltage), the input in units of 120 V and the measurement in units of the sensor's
noise. The gains are mapped back exactly; a similarity transform of the model (another sign
or basis of its states, with D transformed alike) gives the same law
(tests/baselines/engineer/test_model.py).
"""

from __future__ import annotations

import numpy as np
import scipy.linalg as sla

from acld_gym.physics.actuator import V_LIMIT

__all__ = ["lqr", "lqr_gain", "kalman_gain", "process_noise"]


def _sym(X: np.ndarray) -> np.ndarray:
    return 0.5 * (X + X.T)


def lqr_gain(
    A: np.ndarray, b: np.ndarray, Q: np.ndarray, R: np.ndarray, N: np.ndarray, scale: np.ndarray
) -> np.ndarray:
    """The discrete LQR gain K (1, n) of :func:`lqr`."""
    return lqr(A, b, Q, R, N, scale)[0]


def lqr(
    A: np.ndarray, b: np.ndarray, Q: np.ndarray, R: np.ndarray, N: np.ndarray, scale: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    r"""``(K, X)``: the discrete LQR gain K (1, n), :math:`u = -K z`, and the cost-to-go
    :math:`z^T X z` (X in the model's units), for the cost
    :math:`\sum_k z_k^T Q z_k + 2 z_k^T N u_k + u_k^T R u_k`:

    .. math:: K = (R + b^T X b)^{-1} (b^T X A + N^T),

    X the stabilizing solution of the DARE with the cross term, solved on
    :math:`\tilde A = D^{-1} A D`, :math:`\tilde b = D^{-1} b\,u_s`,
    :math:`\tilde Q = D Q D`, :math:`\tilde N = D N u_s`, :math:`\tilde R = u_s^2 R`
    (``scale`` = diag D, :math:`u_s` = 120 V), and :math:`K = u_s \tilde K D^{-1}`,
    :math:`X = D^{-1} \tilde X D^{-1}`."""
    d, us = np.asarray(scale, dtype=float), V_LIMIT
    As = A * d[None, :] / d[:, None]
    bs = b / d[:, None] * us
    Qs = _sym(Q * d[:, None] * d[None, :])
    Ns = N * d[:, None] * us
    Rs = np.atleast_2d(R) * us**2
    X = _sym(sla.solve_discrete_are(As, bs, Qs, Rs, s=Ns))
    Ks = np.linalg.solve(Rs + bs.T @ X @ bs, bs.T @ X @ As + Ns.T)
    return us * Ks / d[None, :], _sym(X / d[:, None] / d[None, :])


def process_noise(
    A: np.ndarray, e: np.ndarray, load_std: float, model_std: float, scale: np.ndarray
) -> np.ndarray:
    r"""The Kalman filter's process noise in scaled states (``scale`` = diag D):
    :math:`\tilde W = \sigma_f^2 \tilde e \tilde e^T + \mu^2 \operatorname{diag}(\tilde\Pi)`,
    :math:`\tilde\Pi = \tilde A \tilde\Pi \tilde A^T + \tilde e \tilde e^T`, as
    :func:`acld_gym.design.observer.discrete_kalman` (the load white across periods with
    standard deviation ``load_std`` [N], and every state disturbed by a fraction
    ``model_std`` of its stationary spread under a unit white load: the model's error)."""
    d = np.asarray(scale, dtype=float)
    As = A * d[None, :] / d[:, None]
    es = np.asarray(e, dtype=float).reshape(-1, 1) / d[:, None]
    W = load_std**2 * (es @ es.T)
    mu = np.broadcast_to(np.asarray(model_std, dtype=float), d.shape)
    if np.any(mu > 0):
        Pi = sla.solve_discrete_lyapunov(As, es @ es.T)
        W = W + np.diag(mu**2 * np.diag(Pi))
    return _sym(W)


def kalman_gain(
    A: np.ndarray,
    c: np.ndarray,
    e: np.ndarray,
    sensor_std: float,
    scale: np.ndarray,
    load_std: float = 1.0,
    model_std: float = 0.1,
) -> np.ndarray:
    r"""The steady-state Kalman filter's measurement-update gain M (n,),
    :math:`\hat x_{k|k} = \hat x_{k|k-1} + M (y_k - c \hat x_{k|k-1})`, for
    :math:`x_{k+1} = A x_k + b u_k + e f_k`, :math:`y_k = c x_k + w_k` (u known), the
    process noise of :func:`process_noise` and the sensor's ``sensor_std`` [m].
    Solved on :math:`\tilde A = D^{-1} A D`, :math:`\tilde c = c D / \sigma_w` (the
    measurement in units of its noise): :math:`M = D \tilde M / \sigma_w`."""
    d = np.asarray(scale, dtype=float)
    if not sensor_std > 0:
        raise ValueError(f"sensor_std must be positive [m], got {sensor_std!r}")
    As = A * d[None, :] / d[:, None]
    cs = (np.asarray(c, dtype=float) * d / sensor_std)[None, :]
    W = process_noise(A, e, load_std, model_std, d)
    X = _sym(sla.solve_discrete_are(As.T, cs.T, W, np.eye(1)))
    Ms = X @ cs.T / (float((cs @ X @ cs.T)[0, 0]) + 1.0)
    return d * Ms[:, 0] / sensor_std
