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
:mod:`acld_gym.design.numerics`); on the raw matrices the Hankel singular values come
out wrong by orders of magnitude and the "reduced" model can be unstable.

Canonical coordinates
---------------------
The Schur method fixes the reduced model only up to a similarity: its
coordinates come from Schur vectors and an SVD, whose signs (and rotations
within clusters) depend on the LAPACK/BLAS kernels the machine picks. Anything
learned on the reduced state (an agent's observation) would then depend on
the CPU. :func:`modal_form` therefore maps the reduced model to a realization
the model itself defines, the **real modal form**:

* states ordered by the modulus of their eigenvalue, ascending; a complex pair
  :math:`\sigma \pm j\omega` (:math:`\omega > 0`) is one 2 x 2 block
  :math:`\begin{bmatrix}\sigma & \omega\\ -\omega & \sigma\end{bmatrix}`,
  a real eigenvalue a 1 x 1 block;
* each block's voltage-input entries are :math:`(\beta_i, 0)` with
  :math:`\beta_i > 0` (this fixes the rotation and sign within the block);
* each block is scaled so that its input and output rows have equal norms,
  :math:`\beta_i = \|c_i\|` (a "balanced" magnitude per mode).

This is unique when the eigenvalues are distinct and every mode is
controllable from the voltage; :func:`modal_form` raises otherwise. A balanced
realization with sign rules would be the other natural choice, but this
lightly damped beam's Hankel values come in near-equal pairs (ratios 1.002 to
1.02, one pair per mode), and within such a pair the balanced basis turns by
about round-off / gap: 100-1000 times round-off. The modes themselves are far
apart (178, 1115, 3970 rad/s), so the modal basis is determined to round-off.
The Hankel values, the transfer function and every design on the reduced
model (LQR, SMC, observers) are the same in both; only the coordinates differ.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.linalg as sla

from acld_gym.design.numerics import (
    balancing_scaling,
    lyap_controllability,
    lyap_observability,
)
from acld_gym.physics.interop import statespace

__all__ = [
    "ReducedModel",
    "ModalForm",
    "modal_form",
    "schur_balanced_truncation",
    "frequency_response",
    "hinf_norm",
    "BASES",
    "EIGEN_RTOL",
    "HANKEL_GAP_RTOL",
]

#: Coordinates of the reduced model: ``"modal"`` (canonical, see the module docstring) or
#: ``"schur"`` (the raw Schur-method coordinates; machine-dependent, kept for ACLDBeam-v0).
BASES = ("modal", "schur")
#: Smallest relative distance between two eigenvalues for the modal basis to be unique
#: to round-off (eigenvectors move by about round-off / distance).
EIGEN_RTOL = 1e-6
#: Smallest relative gap sigma_k / sigma_{k+1} - 1 between the last kept and the first
#: discarded Hankel value: below it the kept subspace is not determined by the model.
HANKEL_GAP_RTOL = 1e-4


def _ordered_schur(X: np.ndarray, big_first: bool, threshold: float, k: int) -> np.ndarray:
    n = X.shape[0]
    select = (lambda re, im: re > threshold) if big_first else (lambda re, im: re < threshold)
    _, Z, sdim = sla.schur(X, output="real", sort=select)
    want = k if big_first else n - k
    if sdim != want:
        raise np.linalg.LinAlgError(
            f"Schur ordering selected {sdim} eigenvalues of PQ, expected {want}: "
            "no clear gap between the kept and the discarded Hankel singular values"
        )
    return Z


@dataclass(frozen=True, eq=False)
class ModalForm:
    r"""A similarity :math:`x_m = T x` to the real modal form (module docstring).

    Attributes
    ----------
    T, Tinv : the transformation and its inverse (n x n).
    eigenvalues : one per block, in state order: the real eigenvalue, or
        :math:`\sigma + j\omega` with :math:`\omega > 0` for a 2 x 2 block [1/s].
    A : the exact block-diagonal state matrix :math:`T A T^{-1}`, built from
        ``eigenvalues`` (zeros off the blocks are exact).
    """

    T: np.ndarray
    Tinv: np.ndarray
    eigenvalues: np.ndarray
    A: np.ndarray

    @property
    def blocks(self) -> list[slice]:
        """The state slice of each block."""
        out, i = [], 0
        for lam in self.eigenvalues:
            size = 2 if lam.imag > 0 else 1
            out.append(slice(i, i + size))
            i += size
        return out


def modal_form(
    A: np.ndarray, B: np.ndarray, C: np.ndarray, eigen_rtol: float = EIGEN_RTOL
) -> ModalForm:
    r"""The canonical real modal form of ``(A, B, C)`` (module docstring).

    For eigenvalue :math:`\lambda_i` with left eigenvector :math:`w_i`
    (:math:`w_i^H A = \lambda_i w_i^H`) the modal coordinate is
    :math:`\eta_i = c_i w_i^H x` with the complex scale
    :math:`c_i = t_i\,\overline{w_i^H B} / |w_i^H B|`, so that its input
    :math:`c_i w_i^H B = t_i |w_i^H B|` is real and positive; a complex pair
    becomes the real states :math:`(\operatorname{Re}\eta_i, -\operatorname{Im}\eta_i)`
    and a real eigenvalue the state :math:`\eta_i`. :math:`t_i > 0` equalises the
    norms of the block's input and output rows.

    Parameters
    ----------
    A, B, C : state matrix (n x n), voltage input (n x 1), output (1 x n).
    eigen_rtol : smallest allowed relative distance between eigenvalues.

    Raises
    ------
    numpy.linalg.LinAlgError
        If two eigenvalues are closer than ``eigen_rtol`` (relative) or a mode has
        no voltage input or no output: the modal basis would not be unique.
    """
    n = A.shape[0]
    lam, W, V = sla.eig(A, left=True, right=True)
    keep = lam.imag >= -1e-12 * np.abs(lam)  # one of each complex pair (Im > 0) and reals
    real = np.abs(lam.imag) <= 1e-12 * np.abs(lam)
    lam = np.where(real, lam.real, lam)
    idx = np.flatnonzero(keep)
    order = idx[np.lexsort((lam[idx].imag, np.abs(lam[idx])))]
    lam_k = lam[order]
    if 2 * np.count_nonzero(~real[order]) + np.count_nonzero(real[order]) != n:
        raise np.linalg.LinAlgError(
            "modal_form: eigenvalues of A do not pair up into real values and conjugate pairs"
        )
    allv = np.concatenate([lam_k, lam_k[lam_k.imag > 0].conj()])
    dist = np.abs(allv[:, None] - allv[None, :]) / np.maximum(
        np.abs(allv)[:, None], np.abs(allv)[None, :]
    )
    np.fill_diagonal(dist, np.inf)
    if dist.min() < eigen_rtol:
        i, j = np.unravel_index(np.argmin(dist), dist.shape)
        raise np.linalg.LinAlgError(
            f"modal_form: eigenvalues {allv[i]:.6g} and {allv[j]:.6g} are closer than "
            f"{eigen_rtol:g} (relative): the modal basis is not unique"
        )
    rows, blocks = [], []
    for i in order:
        w = W[:, i] / np.conj(W[:, i].conj() @ V[:, i])  # w^H v = 1
        beta = complex(w.conj() @ B[:, 0])
        gamma = complex(C[0] @ V[:, i])  # output of eta = w^H x
        scale = abs(beta) * abs(gamma)
        if scale <= 1e-12 * np.linalg.norm(w) * np.linalg.norm(B) * np.linalg.norm(
            C
        ) * np.linalg.norm(V[:, i]):
            raise np.linalg.LinAlgError(
                f"modal_form: the mode at {lam[i]:.6g} 1/s has no "
                "voltage input or no output: no sign convention"
            )
        # output row norm: |gamma| / t for a real mode, 2 |gamma| / t for a pair (x holds
        # the mode and its conjugate); input row norm: t |beta|. Equal them.
        t = np.sqrt((1.0 if real[i] else 2.0) * abs(gamma) / abs(beta))
        row = (t * np.conj(beta) / abs(beta)) * w.conj()
        if real[i]:
            rows.append(row.real[None, :])
            blocks.append(np.array([[lam[i].real]]))
        else:
            rows.append(np.vstack([row.real, -row.imag]))
            s, om = lam[i].real, lam[i].imag
            blocks.append(np.array([[s, om], [-om, s]]))
    T = np.vstack(rows)
    return ModalForm(T=T, Tinv=np.linalg.inv(T), eigenvalues=lam_k, A=sla.block_diag(*blocks))


@dataclass(frozen=True, eq=False)
class ReducedModel:
    """A k-state projection of a full model.

    Attributes
    ----------
    A, B, C : reduced state-space matrices (input = voltage, output = tip).
    E : reduced tip-load input, :math:`S_L^T E`.
    SL, SR : projections (n x k), :math:`x_r = S_L^T x`, :math:`x \\approx S_R x_r`.
    hsv : Hankel singular values of the full model, descending.
    basis : ``"modal"`` (canonical) or ``"schur"`` (see :data:`BASES`).
    """

    A: np.ndarray
    B: np.ndarray
    C: np.ndarray
    E: np.ndarray
    SL: np.ndarray
    SR: np.ndarray
    hsv: np.ndarray
    basis: str = "modal"

    @property
    def order(self) -> int:
        return self.A.shape[0]

    @property
    def error_bound(self) -> float:
        """:math:`2 \\sum_{i>k} \\sigma_i`, the H-infinity bound on the truncation error."""
        return 2.0 * float(np.sum(self.hsv[self.order :]))

    def to_statespace(self):
        """The reduced model as a ``control.StateSpace`` (inputs voltage [V] and, when
        the reduction kept it, tip load [N]; :mod:`acld_gym.physics.interop`)."""
        return statespace(self.A, self.B, self.E, self.C, f"reduced-{self.order}")

    @property
    def hankel_gap(self) -> float:
        """:math:`\\sigma_k / \\sigma_{k+1}`: how clearly the kept states dominate."""
        return float(self.hsv[self.order - 1] / self.hsv[self.order])


def schur_balanced_truncation(
    A: np.ndarray,
    B: np.ndarray,
    C: np.ndarray,
    order: int,
    E: np.ndarray | None = None,
    *,
    basis: str = "modal",
) -> ReducedModel:
    """Reduce a stable ``(A, B, C)`` to ``order`` states by the Schur method.

    Parameters
    ----------
    A, B, C : full model (n x n, n x m, p x n), A Hurwitz.
    order : number of states kept, 1 <= order < n.
    E : optional further input matrix projected with :math:`S_L^T` (tip load).
    basis : ``"modal"`` (default): the canonical real modal form of the reduced
        model (:func:`modal_form`, with B's first column as the voltage), the same
        on every machine; ``"schur"``: the Schur method's own coordinates, which
        depend on the LAPACK kernels (ACLDBeam-v0's observation).

    Returns
    -------
    ReducedModel

    Raises
    ------
    numpy.linalg.LinAlgError
        If sigma_order / sigma_(order+1) - 1 < :data:`HANKEL_GAP_RTOL` (the kept
        subspace is not determined by the model), or :func:`modal_form` fails.
    """
    n = A.shape[0]
    if not isinstance(order, (int, np.integer)) or not 1 <= order < n:
        raise ValueError(f"order must be an integer in [1, {n - 1}], got {order!r}")
    if basis not in BASES:
        raise ValueError(f"basis must be one of {list(BASES)}, got {basis!r}")
    if np.max(np.linalg.eigvals(A).real) >= 0:
        raise ValueError("A: balanced truncation needs a stable (Hurwitz) state matrix")
    sc = balancing_scaling(A)
    As, Bs, Cs = sc.system(A, B, C)
    P = lyap_controllability(As, Bs)
    Q = lyap_observability(As, Cs)
    PQ = P @ Q
    lam = np.sort(np.abs(np.linalg.eigvals(PQ).real))[::-1]
    hsv = np.sqrt(lam)
    if hsv[order] > 0 and hsv[order - 1] / hsv[order] - 1.0 < HANKEL_GAP_RTOL:
        raise np.linalg.LinAlgError(
            f"order {order}: Hankel values {hsv[order - 1]:.6g} and {hsv[order]:.6g} are "
            f"nearly equal (relative gap < {HANKEL_GAP_RTOL:g}), so the kept subspace is not "
            "determined by the model; choose another order"
        )
    threshold = np.sqrt(lam[order - 1] * lam[order]) if lam[order] > 0 else 0.5 * lam[order - 1]
    VD = _ordered_schur(PQ, True, threshold, order)
    VA = _ordered_schur(PQ, False, threshold, order)
    VLbig = VA[:, n - order :]
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
    if basis == "modal":
        mf = modal_form(Ar, Br[:, :1], Cr[:1])
        # x_m = T x_r = T S_L^T x, and x ~ S_R x_r = S_R T^-1 x_m.
        SL, SR = SL @ mf.T.T, SR @ mf.Tinv
        Ar, Br, Cr = mf.A, mf.T @ Br, Cr @ mf.Tinv
        for blk, ev in zip(mf.blocks, mf.eigenvalues, strict=True):
            if ev.imag > 0:
                Br[blk.start + 1, 0] = 0.0  # (beta, 0) by construction
    Er = SL.T @ E if E is not None else np.zeros((order, 0))
    return ReducedModel(A=Ar, B=Br, C=Cr, E=Er, SL=SL, SR=SR, hsv=hsv, basis=basis)


def frequency_response(
    A: np.ndarray, B: np.ndarray, C: np.ndarray, omega: np.ndarray
) -> np.ndarray:
    """SISO response :math:`C (j\\omega I - A)^{-1} B` at each ``omega`` [rad/s].

    Evaluated in balanced coordinates for accuracy.
    """
    As, Bs, Cs = balancing_scaling(A).system(A, B, C)
    n = A.shape[0]
    eye = np.eye(n)
    return np.array([(Cs @ np.linalg.solve(1j * w * eye - As, Bs))[0, 0] for w in omega])


def hinf_norm(
    A: np.ndarray,
    B: np.ndarray,
    C: np.ndarray,
    wmin: float = 1e-1,
    wmax: float = 1e8,
    points: int = 3000,
) -> tuple[float, float]:
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
