r"""The structured solver of the clairvoyant bound (:mod:`baselines.bound`): a primal-dual
active-set method on a proximal homotopy for the box-constrained least-squares problem
:math:`\min_{|v| \le 1} \tfrac12 \|y + Gv\|^2` with a lower-triangular Toeplitz G
(:func:`_solve_pdas` has the method), certified by :class:`baselines.bound_certificate.KKTCheck`.

The pieces: the Gram matrix in reversed time in O(N^2) (:func:`reversed_gram`), its
products by FFT (:class:`_ReversedGramOperator`) and the Cholesky factors of its free
blocks, updated between iterations (:class:`_OrderedCholesky`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.linalg as sla
from numpy.lib.stride_tricks import as_strided, sliding_window_view
from scipy.linalg.lapack import dtrtrs

from .bound_certificate import ATOL, RTOL, KKTCheck, _kkt

__all__ = ["reversed_gram"]


def reversed_gram(h: np.ndarray) -> np.ndarray:
    r"""The Gram matrix :math:`G^T G` in reversed time order, :math:`K = J G^T G J = G G^T`.

    A Toeplitz G is persymmetric (:math:`JGJ = G^T`), so in reversed order
    the Gram matrix is :math:`G G^T`, whose entries are partial
    autocorrelations of h,

    .. math::

        K_{a,a+d} = \sum_{s=0}^{a} h_s h_{s+d},

    i.e. running sums along each diagonal: O(n^2) work instead of the
    O(n^3) product.
    """
    h = np.asarray(h, dtype=float)
    n = h.size
    hp = np.zeros(2 * n - 1)
    hp[:n] = h
    S = h[:, None] * sliding_window_view(hp, n)[:n]  # S[s, d] = h_s h_{s+d}
    np.cumsum(S, axis=0, out=S)  # S[a, d] = K[a, a + d]
    # Scatter S onto the diagonals with strided views of a 2n x n buffer: element (a, d)
    # at flat a (n + 1) + d is K[a, a + d] (upper triangle; a + d >= n spills into the
    # lower triangle of the next row), at flat a (n + 1) + d n it is K[a + d, a] (lower
    # triangle, written second so it overwrites the spill; a + d >= n lands in rows >= n).
    buf = np.empty((2 * n, n))
    it = buf.itemsize
    as_strided(buf, (n, n), ((n + 1) * it, it))[...] = S
    as_strided(buf, (n, n), ((n + 1) * it, n * it))[...] = S
    return buf[:n]


class _OrderedCholesky:
    r"""Cholesky factors of :math:`K_{FF} + \rho I` for a changing, ordered free set F.

    Between two active-set iterations only some variables change, and
    mostly those at the edges of the runs of free ones (next to a switch),
    while the inside of a long run (the singular arc that holds the tip
    still, a quiet stretch before the load) stays free. So the free set is
    kept in an order with those stable variables first (:func:`_stable_order`),
    and a new free set keeps the factor's leading block for the common
    prefix of the old and new orders and recomputes only the rows after it,
    by block elimination: with :math:`L_{11}` kept,

    .. math::

        L_{21} = K_{21} L_{11}^{-T}, \qquad
        L_{22} L_{22}^T = K_{22} + \rho I - L_{21} L_{21}^T,

    where the rows of :math:`L_{21}` of variables that were free before are
    rows of the old factor. For a prefix of p variables, r after it of which
    e newly freed, that costs about :math:`p^2 e + r^2 p + r^3/3` instead of
    :math:`(p + r)^3 / 3`.
    """

    def __init__(self, K: np.ndarray):
        self.K = K
        self.order = np.empty(0, dtype=np.intp)
        self.row = np.full(K.shape[0], -1)  # row of each variable in the factor, -1: none
        self.rho = np.nan
        # The factor is the leading n x n block of a Fortran-ordered buffer: its first p
        # columns are one contiguous array that LAPACK reads in place (lda = N), so the
        # kept block is neither copied nor moved.
        self.L = np.zeros(K.shape, order="F")

    def _trsm(self, m: int, b: np.ndarray, trans: int = 0) -> np.ndarray:
        """Solve with the leading m x m block of the factor (or its transpose)."""
        x, info = dtrtrs(self.L[:, :m], b, lower=1, trans=trans)
        if info:
            raise np.linalg.LinAlgError(f"dtrtrs: info = {info}")
        return x

    def factor(self, order: np.ndarray, rho: float) -> None:
        """Factor for the free positions ``order`` (in that order) and regularization
        ``rho`` (raises ``LinAlgError`` if not positive definite to working precision)."""
        n, old, L = order.size, self.order, self.L
        p = 0
        if rho == self.rho:
            m = min(n, old.size)
            same = order[:m] == old[:m]
            p = m if same.all() else int(np.argmin(same))
        self.rho = np.nan  # until the new factor is complete (a failure leaves a partial one)
        rest = order[p:]
        if rest.size:
            S = self.K.take(rest, axis=0).take(rest, axis=1)  # (take is much faster than ix_)
            S.flat[:: rest.size + 1] += rho
            if p:
                rows = self.row[rest]
                known = rows >= 0
                W = L[np.where(known, rows, 0), :p]  # a copy, taken before rows p.. change
                if not known.all():
                    new = np.flatnonzero(~known)
                    # K[prefix, new] as the transpose of rows of the symmetric K
                    W[new] = self._trsm(
                        p, self.K.take(rest[new], axis=0).take(order[:p], axis=1).T
                    ).T
                S -= W @ W.T
                L[p:n, :p] = W
            L[p:n, p:n] = sla.cholesky(S, lower=True, overwrite_a=True, check_finite=False)
        self.row[old] = -1
        self.row[order] = np.arange(n)
        self.order, self.rho = order, rho

    def solve(self, b: np.ndarray) -> np.ndarray:
        """Solve with the current factor (``b`` and the result in the factor's order)."""
        n = self.order.size
        z = self._trsm(n, b[:, None])
        return self._trsm(n, z, trans=1)[:, 0]


def _stable_order(free: np.ndarray, reach: int = 8) -> np.ndarray:
    """Free positions in factor order: the ones within ``reach`` of an active one (the
    edges of runs, where the active set changes) last, nearest last; the others first, by
    position (the end of the episode first)."""
    n = free.size
    idx = np.arange(n)
    prev = np.maximum.accumulate(np.where(~free, idx, -n))  # last active at or before
    nxt = np.minimum.accumulate(np.where(~free, idx, 2 * n)[::-1])[::-1]  # first at or after
    dist = np.minimum(np.minimum(idx - prev, nxt - idx), reach)
    pos = np.flatnonzero(free)
    return pos[np.lexsort((pos, -dist[pos]))]


class _ReversedGramOperator:
    r"""Products with :math:`K = J G^T G J` by FFT, O(N log N) and without a pass over
    the N x N matrix: :math:`Gx` is the causal convolution ``h * x`` and :math:`G^T x`
    the correlation, both exact for a transform length M >= 2N - 1 (no wrap-around)."""

    def __init__(self, h: np.ndarray):
        self.n = h.size
        self.m = 1 << (2 * self.n - 1).bit_length()
        self.hf = np.fft.rfft(h, self.m)

    def __matmul__(self, w: np.ndarray) -> np.ndarray:
        n, m = self.n, self.m
        gv = np.fft.irfft(self.hf * np.fft.rfft(w[::-1], m), m)[:n]  # G J w
        return np.fft.irfft(np.conj(self.hf) * np.fft.rfft(gv, m), m)[:n][::-1]  # J G^T G J w


@dataclass(frozen=True)
class _PDASResult:
    v: np.ndarray
    check: KKTCheck
    iterations: int
    stages: int


@dataclass
class _Problem:
    """The scaled problem in reversed time (w = J v): f = 1/2 w^T K w + qr^T w + const."""

    K: np.ndarray
    Kop: _ReversedGramOperator
    qr: np.ndarray
    chol: _OrderedCholesky


def _pdas_stage(
    P: _Problem, rho: float, center: np.ndarray, up: np.ndarray, lo: np.ndarray, max_iter: int
) -> tuple[np.ndarray, np.ndarray, np.ndarray, bool, int]:
    """Primal-dual active-set iterations for min f(w) + rho/2 |w - center|^2, |w| <= 1, from
    the active sets ``up`` (w = 1) and ``lo`` (w = -1). Returns the last iterate, its sets,
    whether they converged (else they cycled, ran out of iterations or the factorization
    failed) and the number of iterations."""
    seen: set[bytes] = set()
    order = None
    for it in range(1, max_iter + 1):
        w = up.astype(float) - lo
        is_free = ~(up | lo)
        # Keep the order of the variables that stay free and append new ones, unless less
        # than half of the factor would be kept (always so for a new rho, which changes all
        # of it): then order the free set afresh, for the iterations to come.
        still = is_free[order] if order is not None else np.zeros(0, dtype=bool)
        kept = still.size if still.all() else int(np.argmin(still))
        if order is None or 2 * kept < np.count_nonzero(is_free):
            order = _stable_order(is_free)
        else:
            fresh = is_free.copy()
            fresh[order[still]] = False
            order = np.concatenate([order[still], np.flatnonzero(fresh)])
        if order.size:
            try:
                P.chol.factor(order, rho)
                w[order] = P.chol.solve((rho * center - P.qr - P.Kop @ w)[order])
            except np.linalg.LinAlgError:  # rho too small for the conditioning
                return w, up, lo, False, it
        grad = P.Kop @ w + P.qr + rho * (w - center)  # of the regularized objective
        new_up = np.where(up, grad < 0, w > 1)
        new_lo = np.where(lo, grad > 0, w < -1)
        if np.array_equal(new_up, up) and np.array_equal(new_lo, lo):
            return w, up, lo, True, it
        key = new_up.tobytes() + new_lo.tobytes()
        if key in seen:  # cycling
            return w, up, lo, False, it
        seen.add(key)
        up, lo = new_up, new_lo
    return w, up, lo, False, max_iter


def _solve_pdas(
    h: np.ndarray,
    y: np.ndarray,
    rtol: float = RTOL,
    atol: float = ATOL,
    rho0: float = 1e-3,
    shrink: float = 1e4,
    rho_min: float = 1e-14,
    max_iter: int = 60,
    max_stages: int = 16,
) -> _PDASResult:
    r"""Box-constrained least squares :math:`\min_{|v| \le 1} f(v) = \tfrac12 \|y + Gv\|^2`
    for a lower-triangular Toeplitz G with first column ``h``.

    The Hessian :math:`H = G^T G` is badly conditioned (the voltage-to-tip
    response is non-minimum phase: the smallest singular value of G is ~1e-19
    of the largest), and at the optimum most voltages sit at a bound (bang-bang)
    while the rest form singular arcs, long ones once the tip can be held
    nearly still. The method:

    * **Proximal homotopy.** Stage k solves
      :math:`\min f(v) + \tfrac{\rho_k}{2}\|v - c_k\|^2` with
      :math:`\rho_0 = 10^{-3} \|G\|^2`, :math:`\rho_{k+1} = \rho_k / 10^4` and
      the centre :math:`c_k` the previous stage's solution (:math:`c_0 = 0`).
      A large :math:`\rho` makes the problem well conditioned, so the active
      set is found in a few iterations, and each stage starts from the
      previous stage's active set, which is nearly right. At a stage's
      solution the gradient of f is :math:`-\rho_k (v - c_k)` on the free
      variables, so the duality gap (:class:`KKTCheck`) is small once the
      solutions settle, and the homotopy stops as soon as it certifies
      ``gap <= rtol * f + atol * f(0)``.
    * **Primal-dual active set** (a semismooth Newton method on
      :math:`v = \mathrm{clip}(v - \nabla f_\rho(v))`) within a stage
      (:func:`_pdas_stage`): fix the active variables at their bounds, solve
      :math:`(H_{FF} + \rho I) v_F = \rho c_F - q_F - H_{FA} v_A`
      (:math:`q = G^T y`) for the free ones, then move to their bounds the free
      variables that crossed them and free the bound ones whose gradient
      points inside; stop when the sets repeat. Many variables change per
      iteration, unlike a primal active-set method (BVLS) that moves one at a
      time. The start is the bang-bang guess :math:`v = -\mathrm{sign}(q)`.
      PDAS converges for a large enough :math:`\rho` but may cycle for a small
      one (H is not an M-matrix); a stage that cycles is retried from the last
      converged one with the square root of the step in :math:`\rho`, and
      the smaller step is kept.
    * **Structure.** In reversed time the Gram matrix is :math:`K = G G^T`,
      built in O(N^2) (:func:`reversed_gram`); products with it go by FFT
      (:class:`_ReversedGramOperator`); the Cholesky factors of the free
      blocks are updated, not recomputed, between iterations
      (:class:`_OrderedCholesky`).

    The caller checks the returned certificate (it may fail after
    ``max_stages`` stages, or when :math:`\rho` reaches ``rho_min`` times
    :math:`\|G\|^2`).
    """
    n = h.size
    # Reversed time, so that the factor order starts with the end of the episode (see
    # _stable_order); K = J G^T G J = G G^T, qr = J G^T y.
    K = reversed_gram(h)
    P = _Problem(
        K=K,
        Kop=_ReversedGramOperator(h),
        chol=_OrderedCholesky(K),
        qr=np.correlate(y, h, "full")[n - 1 :][::-1].copy(),
    )
    scale = float(np.max(np.abs(P.Kop.hf)) ** 2)  # ||G||^2 <= max |h(e^iw)|^2
    floor = rho_min * scale
    rho, step = rho0 * scale, shrink
    up, lo = P.qr < 0, P.qr > 0  # the bang-bang guess v = -sign(G^T y)
    center = np.zeros(n)
    last_ok = None  # (rho, up, lo) of the last converged stage
    iterations = stages = 0
    while stages < max_stages:
        stages += 1
        w, up_k, lo_k, converged, its = _pdas_stage(P, rho, center, up, lo, max_iter)
        iterations += its
        w = np.clip(w, -1.0, 1.0)
        check = _kkt(h, y, w[::-1], 1.0)
        if check.certifies(rtol, atol):
            break
        if converged:
            last_ok, center, up, lo = (rho, up_k, lo_k), w, up_k, lo_k
            if rho <= floor:
                break
            rho = max(rho / step, floor)
        elif last_ok is None:  # the first stage cycled: regularize more
            rho *= np.sqrt(shrink)
        else:  # retry from the last converged stage with a smaller step in rho
            step = np.sqrt(step)
            if step < 2.0:
                break
            rho, up, lo = last_ok[0] / step, last_ok[1], last_ok[2]
    return _PDASResult(v=w[::-1].copy(), check=check, iterations=iterations, stages=stages)
