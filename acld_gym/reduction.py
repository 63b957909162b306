r"""Schur balanced truncation (Safonov & Chiang 1989; thesis sec. 3.3, ``schurmrJAK.m``).

With Gramians :math:`P, Q` of :math:`(A, B, C)`, the real Schur forms of
:math:`PQ` ordered ascending (:math:`V_A`) and descending (:math:`V_D`) give
orthonormal bases :math:`V_{L,BIG}` (last k columns of :math:`V_A`) and
:math:`V_{R,BIG}` (first k columns of :math:`V_D`). With the SVD
:math:`V_{L,BIG}^T V_{R,BIG} = U_E \Sigma_E V_E^T`,

.. math::

    S_L = V_{L,BIG} U_E \Sigma_E^{-1/2},\qquad S_R = V_{R,BIG} V_E \Sigma_E^{-1/2},
    \qquad S_L^T S_R = I_k,

    A_r = S_L^T A S_R,\quad B_r = S_L^T B,\quad C_r = C S_R .

The reduced state is :math:`x_r = S_L^T x` and :math:`x \approx S_R x_r`. The
error obeys :math:`\|G - G_r\|_\infty \le 2 \sum_{i>k} \sigma_i`.

The Gramians are computed after a diagonal balancing of A (see
:mod:`acld_gym.numerics`); on the raw matrices the Hankel singular values come
out wrong by orders of magnitude and the "reduced" model can be unstable.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.linalg as sla

from .numerics import balancing_scaling, lyap_controllability, lyap_observability

__all__ = ["ReducedModel", "schur_balanced_truncation", "frequency_response", "hinf_norm"]


@dataclass(frozen=True, eq=False)
class ReducedModel:
    """A k-state projection of a full model.

    Attributes
    ----------
    A, B, C : reduced state-space matrices (input = voltage, output = tip).
    E : reduced tip-load input, :math:`S_L^T E`.
    SL, SR : projections (n x k), :math:`x_r = S_L^T x`, :math:`x \\approx S_R x_r`.
    hsv : Hankel singular values of the full model, descending.
    """

    A: np.ndarray
    B: np.ndarray
    C: np.ndarray
    E: np.ndarray
    SL: np.ndarray
    SR: np.ndarray
    hsv: np.ndarray

    @property
    def order(self) -> int:
        return self.A.shape[0]

    @property
    def error_bound(self) -> float:
        """:math:`2 \\sum_{i>k} \\sigma_i`, the H-infinity bound on the truncation error."""
        return 2.0 * float(np.sum(self.hsv[self.order:]))


def _ordered_schur(X: np.ndarray, big_first: bool, threshold: float, k: int) -> np.ndarray:
    n = X.shape[0]
    select = (lambda re, im: re > threshold) if big_first else (lambda re, im: re < threshold)
    _, Z, sdim = sla.schur(X, output="real", sort=select)
    want = k if big_first else n - k
    if sdim != want:
        raise np.linalg.LinAlgError(
            f"Schur ordering selected {sdim} eigenvalues of PQ, expected {want}: "
            "no clear gap between the kept and the discarded Hankel singular values")
    return Z


def schur_balanced_truncation(A: np.ndarray, B: np.ndarray, C: np.ndarray, order: int,
                              E: np.ndarray | None = None) -> ReducedModel:
    """Reduce a stable ``(A, B, C)`` to ``order`` states by the Schur method.

    Parameters
    ----------
    A, B, C : full model (n x n, n x m, p x n), A Hurwitz.
    order : number of states kept, 1 <= order < n.
    E : optional further input matrix projected with :math:`S_L^T` (tip load).

    Returns
    -------
    ReducedModel
    """
    n = A.shape[0]
    if not isinstance(order, (int, np.integer)) or not 1 <= order < n:
        raise ValueError(f"order must be an integer in [1, {n - 1}], got {order!r}")
    if np.max(np.linalg.eigvals(A).real) >= 0:
        raise ValueError("A: balanced truncation needs a stable (Hurwitz) state matrix")
    sc = balancing_scaling(A)
    As, Bs, Cs = sc.system(A, B, C)
    # Normalise the Gramians' scale (HSVs are invariant to input/output scaling
    # only up to the same factors, so the factors are undone below).
    P = lyap_controllability(As, Bs)
    Q = lyap_observability(As, Cs)
    PQ = P @ Q
    lam = np.sort(np.abs(np.linalg.eigvals(PQ).real))[::-1]
    hsv = np.sqrt(lam)
    threshold = np.sqrt(lam[order - 1] * lam[order]) if lam[order] > 0 else 0.5 * lam[order - 1]
    VD = _ordered_schur(PQ, True, threshold, order)
    VA = _ordered_schur(PQ, False, threshold, order)
    VLbig = VA[:, n - order:]
    VRbig = VD[:, :order]
    U, s, Vt = np.linalg.svd(VLbig.T @ VRbig)
    SLs = VLbig @ U / np.sqrt(s)[None, :]
    SRs = VRbig @ Vt.T / np.sqrt(s)[None, :]
    # Back to physical coordinates: x = D x_s  =>  S_L = D^-1 S_L,s, S_R = D S_R,s.
    SL = SLs / sc.d[:, None]
    SR = SRs * sc.d[:, None]
    Ar = SL.T @ A @ SR
    Br = SL.T @ B
    Cr = C @ SR
    Er = SL.T @ E if E is not None else np.zeros((order, 0))
    return ReducedModel(A=Ar, B=Br, C=Cr, E=Er, SL=SL, SR=SR, hsv=hsv)


def frequency_response(A: np.ndarray, B: np.ndarray, C: np.ndarray,
                       omega: np.ndarray) -> np.ndarray:
    """SISO response :math:`C (j\\omega I - A)^{-1} B` at each ``omega`` [rad/s].

    Evaluated in balanced coordinates for accuracy.
    """
    As, Bs, Cs = balancing_scaling(A).system(A, B, C)
    n = A.shape[0]
    eye = np.eye(n)
    return np.array([(Cs @ np.linalg.solve(1j * w * eye - As, Bs))[0, 0] for w in omega])


def hinf_norm(A: np.ndarray, B: np.ndarray, C: np.ndarray, wmin: float = 1e-1,
              wmax: float = 1e8, points: int = 3000) -> tuple[float, float]:
    """H-infinity norm of a stable SISO system by a dense log sweep refined
    around the peak. Returns ``(norm, omega_peak)``."""
    w = np.logspace(np.log10(wmin), np.log10(wmax), points)
    g = np.abs(frequency_response(A, B, C, w))
    i = int(np.argmax(g))
    lo, hi = w[max(i - 1, 0)], w[min(i + 1, points - 1)]
    wf = np.linspace(lo, hi, 400)
    gf = np.abs(frequency_response(A, B, C, wf))
    j = int(np.argmax(gf))
    return float(max(gf[j], g[i])), float(wf[j] if gf[j] >= g[i] else w[i])
