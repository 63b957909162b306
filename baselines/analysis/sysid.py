r"""System identification of a pulse response: the eigensystem realization algorithm (ERA,
Juang & Pappa 1985; the Ho-Kalman construction on Markov parameters).

With the pulse response :math:`h_0, h_1, \dots` of a system (:math:`h_k = C A^k B`, the
output k + 1 periods after a unit input held over one period), the block Hankel matrices

.. math::

    H_0 = [h_{i+j}]_{i<r,\,j<c}, \qquad H_1 = [h_{i+j+1}]_{i<r,\,j<c},

factor as :math:`H_0 = \mathcal O \mathcal C` and :math:`H_1 = \mathcal O A \mathcal C`
(observability and controllability matrices). From the truncated singular value
decomposition :math:`H_0 \approx U_n \Sigma_n V_n^T`, a balanced realization of order n is

.. math::

    A = \Sigma_n^{-1/2} U_n^T H_1 V_n \Sigma_n^{-1/2}, \quad
    B = \Sigma_n^{1/2} V_n^T e_1, \quad C = e_1^T U_n \Sigma_n^{1/2}.

**Model order.** The sampled closed loop has many states (36 of the beam, 8 of the
observer), most of them fast or barely excited at the tip; the Hankel singular values say
how many the data carry. The order is the smallest n whose realization reproduces the
whole record to :data:`FIT_TOL` (relative RMS), or to within :data:`PLATEAU` times the
best error of any order, for data whose noise no order fits that well (the elbow of the
error against the order), and it is checked: the modes of order
n + :data:`CHECK_STEP` must agree with those of order n (:func:`order_check`). Orders at
which the singular values reach round-off (:data:`RANK_TOL`) are not tried: there ERA
fits noise with spurious, often unstable, poles (so noise-free data of a system of order
n have no check order). The SVD runs on one BLAS thread (:mod:`acld_gym.util.blas`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.linalg as sla

from acld_gym.util.blas import one_blas_thread

from .modes import Mode, poles_and_residues, select_modes

__all__ = [
    "EraRealization",
    "Identification",
    "identify",
    "order_check",
    "FIT_TOL",
    "PLATEAU",
    "RANK_TOL",
    "MAX_ORDER",
    "CHECK_STEP",
]

#: Relative RMS error of the realization's pulse response that selects the order.
FIT_TOL = 1e-4
#: ... or this factor over the best error of any order (the noise's plateau).
PLATEAU = 2.0
#: Singular values below this fraction of the largest are round-off: no order beyond them.
RANK_TOL = 1e-12
#: Largest order tried.
MAX_ORDER = 60
#: The order check compares order n with order n + CHECK_STEP.
CHECK_STEP = 4


class EraRealization:
    """The SVD of a pulse response's Hankel matrix, and the realizations of every order
    from it (module docstring)."""

    def __init__(self, h: np.ndarray, rows: int | None = None, max_order: int = MAX_ORDER):
        h = np.asarray(h, dtype=float).ravel()
        n = h.size
        if n < 8 or not np.all(np.isfinite(h)) or not np.any(h):
            raise ValueError(
                f"h must be a finite, non-zero pulse response of at least 8 "
                f"samples, got {n} samples"
            )
        r = min(n // 3, 600) if rows is None else int(rows)
        if not 2 <= r <= n - 2:
            raise ValueError(f"rows must be in [2, {n - 2}], got {rows!r}")
        self.h = h
        H0 = sla.hankel(h[:r], h[r - 1 : n - 1])
        H1 = sla.hankel(h[1 : r + 1], h[r:n])
        with one_blas_thread():
            try:
                U, S, Vt = sla.svd(H0, full_matrices=False, lapack_driver="gesdd")
            except np.linalg.LinAlgError:  # gesdd did not converge: the slower, safer driver
                U, S, Vt = sla.svd(H0, full_matrices=False, lapack_driver="gesvd")
        m = int(min(max_order, np.count_nonzero(S > RANK_TOL * S[0])))
        self.singular_values = S
        self.max_order = m
        self._U, self._S, self._Vt = U[:, :m], S[:m], Vt[:m]
        self._P = U[:, :m].T @ H1 @ Vt[:m].T

    def model(self, order: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``(A, B, C)`` of the realization of ``order`` (at most the ``max_order`` given
        at construction)."""
        if not isinstance(order, int) or not 1 <= order <= self.max_order:
            raise ValueError(f"order must be an integer in [1, {self.max_order}], got {order!r}")
        q = np.sqrt(self._S[:order])
        A = self._P[:order, :order] / q[:, None] / q[None, :]
        return A, q * self._Vt[:order, 0], self._U[0, :order] * q

    def fit_error(self, order: int) -> float:
        """Relative RMS error of the order's pulse response against the data."""
        z, r = poles_and_residues(*self.model(order))
        k = np.arange(self.h.size)
        with np.errstate(over="ignore", invalid="ignore"):
            fit = np.real(np.exp(np.outer(k, np.log(z.astype(complex)))) @ r)
        err = float(np.linalg.norm(fit - self.h) / np.linalg.norm(self.h))
        return err if np.isfinite(err) else float("inf")


@dataclass(frozen=True)
class Identification:
    """An identified model of a pulse response: the chosen order, its realization and the
    evidence for the order."""

    A: np.ndarray
    B: np.ndarray
    C: np.ndarray
    dt: float
    order: int
    fit_error: float
    """Relative RMS error of the realization's pulse response."""
    fit_errors: dict[int, float]
    """The error of every order tried."""
    singular_values: np.ndarray
    """The Hankel singular values (unnormalized, descending)."""
    n_samples: int
    check: tuple[np.ndarray, np.ndarray, np.ndarray] | None
    """The realization of order + :data:`CHECK_STEP` (None if beyond the data's rank)."""

    def modes(self, edges: np.ndarray) -> list[Mode | None]:
        """The dominant mode in each band (:func:`~baselines.analysis.modes.select_modes`)."""
        z, r = poles_and_residues(self.A, self.B, self.C)
        return select_modes(z, r, self.dt, edges, self.n_samples)


def identify(
    h: np.ndarray,
    dt: float,
    rows: int | None = None,
    max_order: int = MAX_ORDER,
    fit_tol: float = FIT_TOL,
) -> Identification:
    """ERA on the pulse response ``h`` (``h[k]`` the output k + 1 periods of ``dt`` after
    the pulse), at the order chosen as in the module docstring."""
    era = EraRealization(h, rows, max_order)
    if era.max_order < 2:
        raise ValueError(
            "h: the pulse response has fewer than two significant Hankel "
            "singular values; nothing to identify"
        )
    errors = {n: era.fit_error(n) for n in range(1, era.max_order + 1)}
    best = min(errors.values())
    order = min(n for n, e in errors.items() if e <= max(fit_tol, PLATEAU * best))
    check = era.model(order + CHECK_STEP) if order + CHECK_STEP <= era.max_order else None
    return Identification(
        *era.model(order),
        dt=float(dt),
        order=order,
        fit_error=errors[order],
        fit_errors=errors,
        singular_values=era.singular_values,
        n_samples=era.h.size,
        check=check,
    )


def order_check(ident: Identification, edges: np.ndarray) -> dict:
    """The chosen order's modes against those of order + :data:`CHECK_STEP`: the largest
    relative change of frequency and of damping ratio over the bands (None without a
    check realization or where a band has no mode at either order)."""
    out = {
        "order": ident.order,
        "check_order": None,
        "frequency_change": None,
        "damping_change": None,
    }
    if ident.check is None:
        return out
    z, r = poles_and_residues(*ident.check)
    other = select_modes(z, r, ident.dt, edges, ident.n_samples)
    mine = ident.modes(edges)
    pairs = [(a, b) for a, b in zip(mine, other, strict=True) if a is not None and b is not None]
    out["check_order"] = ident.order + CHECK_STEP
    if len(pairs) == len(mine):
        out["frequency_change"] = max(
            abs(b.frequency_rad_s / a.frequency_rad_s - 1) for a, b in pairs
        )
        out["damping_change"] = max(abs(b.damping_ratio / a.damping_ratio - 1) for a, b in pairs)
    return out
