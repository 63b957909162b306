"""Numerical helpers shared by the reduction, observer and controller designs.

The beam's state matrix has eigenvalues from about 60 to 1.3e7 1/s and
``cond(A)`` of order 1e15 in physical units. Lyapunov and Riccati solves on
the raw matrices lose most of their digits, so every such solve here first
applies a diagonal similarity :math:`A_s = D^{-1} A D` (Parlett-Reinsch
balancing, powers of two, hence exact) and maps the result back.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.linalg as sla

__all__ = [
    "DiagonalScaling",
    "balancing_scaling",
    "expm_balanced",
    "lyap_controllability",
    "lyap_observability",
    "care_gain",
]


@dataclass(frozen=True)
class DiagonalScaling:
    """State scaling :math:`x = D x_s` with ``D = diag(d)``."""

    d: np.ndarray

    def system(self, A: np.ndarray, B: np.ndarray, C: np.ndarray):
        """Scaled ``(D^-1 A D, D^-1 B, C D)``."""
        d = self.d
        return A * d[None, :] / d[:, None], B / d[:, None], C * d[None, :]


def balancing_scaling(A: np.ndarray) -> DiagonalScaling:
    """Diagonal scaling that balances row and column norms of ``A`` (no permutation)."""
    _, (d, _) = sla.matrix_balance(A, permute=False, separate=True)
    return DiagonalScaling(np.asarray(d, dtype=float))


def expm_balanced(F: np.ndarray, t: float = 1.0) -> np.ndarray:
    r""":math:`e^{F t} = D\,e^{D^{-1} F D\,t}\,D^{-1}` with the balancing D of F: the
    exponential of a badly scaled matrix (this model's span ~1e7 1/s) without losing
    the small entries. The one matrix exponential of the package."""
    _, (d, _) = sla.matrix_balance(F, permute=False, separate=True)
    return sla.expm((F * d[None, :] / d[:, None]) * t) * d[:, None] / d[None, :]


def _sym(X: np.ndarray) -> np.ndarray:
    return 0.5 * (X + X.T)


def lyap_controllability(A: np.ndarray, B: np.ndarray) -> np.ndarray:
    """P solving :math:`A P + P A^T + B B^T = 0` (scipy solves ``A X + X A^H = Q``)."""
    return _sym(sla.solve_continuous_lyapunov(A, -B @ B.T))


def lyap_observability(A: np.ndarray, C: np.ndarray) -> np.ndarray:
    """Q solving :math:`A^T Q + Q A + C^T C = 0`."""
    return _sym(sla.solve_continuous_lyapunov(A.T, -C.T @ C))


def care_gain(
    A: np.ndarray, B: np.ndarray, Q: np.ndarray, R: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Continuous LQR: ``K = R^-1 B^T X`` with X the stabilizing CARE solution.

    Solved in balanced coordinates: with :math:`x = D x_s`,
    :math:`A_s = D^{-1} A D`, :math:`B_s = D^{-1} B`, :math:`Q_s = D Q D`, and
    :math:`K = K_s D^{-1}`, :math:`X = D^{-1} X_s D^{-1}`.
    """
    R = np.atleast_2d(R)
    sc = balancing_scaling(A)
    d = sc.d
    As, Bs, _ = sc.system(A, B, np.zeros((1, A.shape[0])))
    Qs = Q * d[:, None] * d[None, :]
    Xs = sla.solve_continuous_are(As, Bs, _sym(Qs), R)
    Ks = np.linalg.solve(R, Bs.T @ Xs)
    return Ks / d[None, :], _sym(Xs / d[:, None] / d[None, :])
