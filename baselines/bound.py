r"""The clairvoyant bound: the best any policy could do, knowing the whole load.

For an episode of N steps on the (nominal, noise-free) sampled plant, the tip
deflections are affine in the voltages, :math:`y = y_{free} + G V`, where
:math:`G_{kj} = h_{k-j} = c\,A_d^{k-j} B_d` (:math:`k \ge j`, zero above the
diagonal) is the lower-triangular Toeplitz matrix of the voltage impulse
response (:func:`impulse_response`, :func:`convolution_matrix`). The bound solves

.. math::

    \min_{|V_j| \le 120} \|y_{free} + G V\|_2^2 ,

a box-constrained least-squares problem. No causal policy, which must act
without knowing the future load, can have a smaller ISE on the same episode.

Two solvers (``method``):

``"pdas"`` (default)
    A primal-dual active-set method on a proximal homotopy that uses the
    Toeplitz structure and reuses its Cholesky factors between iterations
    (:func:`_solve_pdas` has the details): 10-30 ms for a typical 1000-step
    episode on one core, up to about 0.1 s when nearly all voltages are
    free. Its result is *certified*: the duality gap of the returned
    voltages, which bounds their excess cost over the true optimum, must be
    below ``RTOL = 1e-8`` of the cost (plus ``ATOL = 1e-9`` of the cost
    without control, which only matters when the optimum is nearly zero;
    :class:`KKTCheck`); if it is not, the bound falls back to BVLS with a
    ``RuntimeWarning``.
``"bvls"``
    ``scipy.optimize.lsq_linear(method="bvls")`` on the dense N x N matrix
    (the reference; 0.4-60 s for 1000 steps).

Both work in scaled units (deflections in mm, voltages in units of 120 V), in
which :math:`\|G\|_2` is of order one. ``benchmarks/bench_bound.py`` compares them.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass

import numpy as np
import scipy.linalg as sla
from numpy.lib.stride_tricks import as_strided, sliding_window_view
from scipy.linalg.lapack import dtrtrs
from scipy.optimize import lsq_linear

from acld_gym.design.discrete import (
    SampledSystem,
    _check_steps,
    _output_rows,
    _output_vector,
    convolution_matrix,
    impulse_response,
)
from acld_gym.physics.actuator import V_LIMIT
from acld_gym.physics.loads import TipLoad

__all__ = [
    "ATOL",
    "BoundSolution",
    "KKTCheck",
    "METHODS",
    "RTOL",
    "SlewCertificate",
    "clairvoyant_bound",
    "convolution_matrix",
    "free_response",
    "impulse_response",
    "kkt_check",
    "reversed_gram",
    "slew_certificate",
]

#: Solvers accepted by :func:`clairvoyant_bound`.
METHODS = ("pdas", "bvls")
#: Certification of the PDAS solver: duality gap <= RTOL * cost + ATOL * free cost, a bound
#: on the excess ISE over the optimum (the comparison with BVLS asks for 1e-6 relative). The
#: absolute part, relative to the cost without control, matters only when the optimum is
#: nearly zero (a small load that the voltage cancels), where a relative gap cannot be met.
RTOL = 1e-8
ATOL = 1e-9
_Y_UNIT = 1e-3  # scaled problem: deflections in mm ...
_V_UNIT = V_LIMIT  # ... and voltages in units of the limit, so |v| <= 1


@dataclass(frozen=True)
class BoundSolution:
    """Optimal voltages [V] (N,) and resulting tip deflections [m] (N,) at t = dt..N dt."""

    voltage: np.ndarray
    y: np.ndarray
    dt: float
    #: With a binding slew limit, the :class:`SlewCertificate` of the solution (its
    #: ``lower`` is a certified lower bound of the optimum, in the solver's scaled units).
    certificate: object = None

    @property
    def ise(self) -> float:
        return float(np.sum(self.y**2) * self.dt)


# --- the linear model of an episode --------------------------------------------------------


def free_response(
    plant: SampledSystem, tip_index: int | np.ndarray, load: TipLoad, n_steps: int
) -> np.ndarray:
    r"""Tip deflection [m] without control at t = dt..N dt, from rest.

    The same sampled load as the environment (:meth:`SampledSystem.load_samples`,
    first-order hold on the sub-steps), evaluated for all periods in one call;
    :math:`y_k = \sum_{j \le k} c\,A_d^{k-j} u_j` with :math:`u_j` the load
    increment of period j, i.e. one convolution per state, done by FFT.
    ``tip_index`` is a state index or an output row, as ``output`` of
    :func:`impulse_response`.
    """
    _check_steps(n_steps, "n_steps")
    # Sub-interval edges of every period, as load_samples computes them (k dt + times).
    tt = np.arange(n_steps)[:, None] * plant.dt + plant.times[None, :]
    eps = 1e-9 * plant.dt
    f0 = np.asarray(load(tt[:, :-1] + eps), dtype=float)
    f1 = np.asarray(load(tt[:, 1:] - eps), dtype=float)
    u = plant.load_increment(f0, f1)  # (n_steps, nx)
    c = _output_vector(tip_index, plant.Ad.shape[0])
    rows = _output_rows(plant.Ad, c, n_steps)  # (n_steps, nx): e^T Ad^m
    m = 1 << (2 * n_steps - 1).bit_length()
    spec = np.fft.rfft(rows, m, axis=0) * np.fft.rfft(u, m, axis=0)
    return np.fft.irfft(spec.sum(axis=1), m)[:n_steps]


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


# --- certification ---------------------------------------------------------------------------


@dataclass(frozen=True)
class KKTCheck:
    r"""Optimality certificate of ``v`` for :math:`\min_{|v| \le b} f(v) = \tfrac12\|y + Gv\|^2`.

    With the gradient :math:`g = G^T (y + G v)`, the KKT conditions are
    :math:`g_j \ge 0` where :math:`v_j = -b`, :math:`g_j \le 0` where
    :math:`v_j = b` and :math:`g_j = 0` in between; ``violation[j]`` is by
    how much index j misses them. By convexity, for any feasible v,

    .. math::

        f(v) - f^* \le \max_{|u| \le b} g^T (v - u) = \sum_j (g_j v_j + b|g_j|)
        = \text{gap},

    the Frank-Wolfe (duality) gap, a sum of the violations weighted by the
    room left to the bound the gradient points at (2b at a wrong bound). So
    ``gap / objective`` bounds the relative excess cost (and ISE);
    ``free_objective`` is :math:`f(0)`, the cost without control.
    """

    objective: float
    free_objective: float
    gap: float
    violation: np.ndarray
    feasible: bool

    @property
    def relative_gap(self) -> float:
        if self.objective > 0:
            return self.gap / self.objective
        return 0.0 if self.gap == 0 else float("inf")

    def certifies(self, rtol: float = RTOL, atol: float = ATOL) -> bool:
        """Feasible and ``gap <= rtol * objective + atol * free_objective``."""
        return self.feasible and self.gap <= rtol * self.objective + atol * self.free_objective


def _kkt(h: np.ndarray, y: np.ndarray, v: np.ndarray, bound: float) -> KKTCheck:
    n = h.size
    r = y + np.convolve(h, v)[:n]  # direct sums (no FFT round-off in the certificate)
    g = np.correlate(r, h, "full")[n - 1 :]  # G^T r
    # A voltage scaled back and forth may miss its bound by an ulp: count it as at the bound.
    edge = bound * (1.0 - 1e-12)
    at_lo, at_hi = v <= -edge, v >= edge
    viol = np.where(at_lo, np.maximum(-g, 0.0), np.where(at_hi, np.maximum(g, 0.0), np.abs(g)))
    return KKTCheck(
        objective=0.5 * float(r @ r),
        free_objective=0.5 * float(y @ y),
        gap=float(np.sum(g * v + bound * np.abs(g))),
        violation=viol,
        feasible=bool(np.all(np.abs(v) <= bound * (1.0 + 1e-12))),
    )


def kkt_check(
    h: np.ndarray, y_free: np.ndarray, voltage: np.ndarray, v_max: float = V_LIMIT
) -> KKTCheck:
    """:class:`KKTCheck` of ``voltage`` [V] for the bound with impulse response ``h`` [m/V],
    free response ``y_free`` [m] and limit ``v_max`` [V], in the scaled units of the
    solvers (mm, units of ``v_max``; the objective is half the sum of squares in mm^2)."""
    h = np.asarray(h, dtype=float)
    return _kkt(
        h * (v_max / _Y_UNIT),
        np.asarray(y_free, dtype=float) / _Y_UNIT,
        np.asarray(voltage, dtype=float) / v_max,
        1.0,
    )


# --- solvers (scaled problem: min 1/2 ||y + G v||^2, |v| <= 1) -------------------------------


def _solve_bvls(h: np.ndarray, y: np.ndarray) -> np.ndarray:
    """The reference: BVLS on the dense matrix (one variable enters or leaves the free
    set per iteration, each a least-squares solve in Python: seconds for 1000 steps)."""
    n = h.size
    res = lsq_linear(
        convolution_matrix(h), -y, bounds=(-1.0, 1.0), method="bvls", tol=1e-12, max_iter=10 * n
    )
    return res.x


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


# --- the bound -------------------------------------------------------------------------------


@dataclass(frozen=True)
class SlewCertificate:
    r"""Optimality certificate of ``w`` for the slew-limited problem
    :math:`\min f(w) = \tfrac12\|y + Gw\|^2` over
    :math:`\mathcal C = \{|w_m| \le 1, |w_m - w_{m-1}| \le \rho\}` (:math:`w_{-1} = 0`;
    scaled units, as :class:`KKTCheck`).

    By convexity, for every :math:`u \in \mathcal C`,
    :math:`f(u) \ge f(w) + g^T (u - w)` with :math:`g = \nabla f(w)`, and for every
    multiplier vector :math:`\lambda` of the difference constraints :math:`|Du| \le \rho`,

    .. math::

        g^T u = (g + D^T\lambda)^T u - \lambda^T D u
              \ge -\|g + D^T\lambda\|_1 - \rho\|\lambda\|_1 ,

    so :math:`f^* \ge` ``lower`` :math:`= f(w) - g^T w - \|g + D^T\lambda\|_1 -
    \rho \|\lambda\|_1`: a dual-feasible point's dual objective, a lower bound of the
    optimum for *any* w and :math:`\lambda` (the solver's multipliers make it tight).
    ``objective`` is f at the feasible ``w``, so ``lower <= f* <= objective``."""

    objective: float
    lower: float
    free_objective: float
    feasible: bool

    @property
    def gap(self) -> float:
        return self.objective - self.lower

    def certifies(self, rtol: float = 1e-6, atol: float = ATOL) -> bool:
        """Feasible and ``gap <= rtol * objective + atol * free_objective``."""
        return self.feasible and self.gap <= rtol * self.objective + atol * self.free_objective


def _difference(n: int):
    """The difference operator D (n x n): (D w)_m = w_m - w_{m-1}, w_{-1} = 0 (sparse)."""
    import scipy.sparse as sp

    return sp.eye(n, format="csc") - sp.eye(n, k=-1, format="csc")


def slew_certificate(
    h: np.ndarray, y: np.ndarray, w: np.ndarray, lam: np.ndarray, rho: float
) -> SlewCertificate:
    """:class:`SlewCertificate` of ``w`` with multipliers ``lam`` (scaled units)."""
    n = h.size
    r = y + np.convolve(h, w)[:n]
    g = np.correlate(r, h, "full")[n - 1 :]  # G^T r
    dl = lam - np.append(lam[1:], 0.0)  # D^T lam
    lower = (
        0.5 * float(r @ r)
        - float(g @ w)
        - float(np.abs(g + dl).sum())
        - rho * float(np.abs(lam).sum())
    )
    steps = np.diff(np.concatenate([[0.0], w]))
    feasible = bool(np.all(np.abs(w) <= 1.0 + 1e-12) and np.all(np.abs(steps) <= rho * (1 + 1e-12)))
    return SlewCertificate(
        objective=0.5 * float(r @ r),
        lower=lower,
        free_objective=0.5 * float(y @ y),
        feasible=feasible,
    )


def _feasible(w: np.ndarray, rho: float) -> np.ndarray:
    """``w`` moved into the slew-limited box, step by step (each w_m clipped to
    [w_{m-1} - rho, w_{m-1} + rho] and [-1, 1], which meet since |w_{m-1}| <= 1)."""
    out = np.empty_like(w)
    prev = 0.0
    for m, wm in enumerate(w.tolist()):
        prev = min(max(wm, prev - rho, -1.0), prev + rho, 1.0)
        out[m] = prev
    return out


#: OSQP's tolerances and iteration budget for the slew-limited bound: the certificate, not
#: the solver, decides what the bound is worth (its lower bound holds for any answer).
EPS = 1e-7
MAX_ITER = 20_000


def _solve_slew(h: np.ndarray, y: np.ndarray, rho: float) -> tuple[np.ndarray, SlewCertificate]:
    r"""The slew-limited problem (:class:`SlewCertificate`) by OSQP, an ADMM method on the
    quadratic program :math:`\min \tfrac12 w^T G^T G w + (G^T y)^T w` subject to
    :math:`l \le [I; D] w \le u`: the box and the slew limit, a general linear
    inequality, are rows of one constraint matrix (OSQP factors its KKT matrix once and
    iterates; polished). Its answer is moved into the feasible set (:func:`_feasible`) and
    certified with its multipliers of the difference rows."""
    import osqp
    import scipy.sparse as sp

    n = h.size
    G = convolution_matrix(h)
    P = sp.csc_matrix(np.triu(G.T @ G))
    A = sp.vstack([sp.eye(n, format="csc"), _difference(n)], format="csc")
    one = np.ones(n)
    solver = osqp.OSQP()
    solver.setup(
        P,
        G.T @ y,
        A,
        np.concatenate([-one, -rho * one]),
        np.concatenate([one, rho * one]),
        eps_abs=EPS,
        eps_rel=EPS,
        max_iter=MAX_ITER,
        polishing=True,
        verbose=False,
    )
    res = solver.solve(raise_error=False)
    w = _feasible(np.asarray(res.x, dtype=float), rho)
    return w, slew_certificate(h, y, w, np.asarray(res.y, dtype=float)[n:], rho)


def clairvoyant_bound(
    plant: SampledSystem,
    tip_index: int | np.ndarray,
    load: TipLoad,
    n_steps: int,
    *,
    method: str = "pdas",
    delay: int = 0,
    slew_step: float | None = None,
    v_max: float = V_LIMIT,
) -> BoundSolution:
    r"""Solve the bound for ``load`` over ``n_steps`` periods of ``plant``.

    Parameters
    ----------
    plant : SampledSystem
        Sampled plant (any state dimension; with an amplifier's lag its state includes the
        patch voltage and its input is the amplifier's output).
    tip_index : int or ndarray
        State index of the tip deflection, or its output row (y = row @ x).
    load : TipLoad
        Tip load (any callable of time that accepts arrays).
    n_steps : int
        Episode length in control periods, >= 1.
    method : {"pdas", "bvls"}
        ``"pdas"``: the structured, certified solver (falls back to BVLS with a
        ``RuntimeWarning`` if it cannot certify its optimum); ``"bvls"``:
        ``scipy.optimize.lsq_linear`` on the dense matrix (the reference).
    delay : int
        Periods from a command to the amplifier (``actuator_delay``): the first ``delay``
        voltages are zero, the tip's response to the rest is the plant's impulse response
        ``delay`` periods late. The bound's voltages are the amplifier's outputs (the
        commands ``delay`` periods earlier).
    slew_step : float or None
        Largest change of the amplifier's output per period [V] (``slew_rate * dt``): a
        constraint :math:`|V_k - V_{k-1}| \le` ``slew_step``, handled by
        :func:`_solve_slew` and certified by :class:`SlewCertificate` (if it cannot bind,
        ``slew_step >= 2 v_max``, the box problem is the same one and PDAS solves it).
    v_max : float
        The voltage limit [V].

    Returns
    -------
    BoundSolution
    """
    _check_steps(n_steps, "n_steps")
    if method not in METHODS:
        raise ValueError(f"method must be one of {METHODS}, got {method!r}")
    if (
        isinstance(delay, bool)
        or not isinstance(delay, (int, np.integer))
        or not 0 <= delay < n_steps
    ):
        raise ValueError(f"delay must be an integer in [0, n_steps), got {delay!r}")
    y_free = free_response(plant, tip_index, load, n_steps)
    m = n_steps - delay  # the voltages that reach the tip within the episode
    h = impulse_response(plant, tip_index, m)
    hs, ys = h * (v_max / _Y_UNIT), y_free[delay:] / _Y_UNIT
    if slew_step is not None and slew_step < 2 * v_max:
        v, certificate = _solve_slew(hs, ys, slew_step / v_max)
        cert = certificate
        if not cert.certifies():
            warnings.warn(
                f"clairvoyant_bound: the slew-limited solution is certified only to "
                f"a relative gap of {cert.gap / max(cert.objective, 1e-300):.1e}",
                RuntimeWarning,
                stacklevel=2,
            )
    elif method == "pdas":
        certificate = None
        res = _solve_pdas(hs, ys)
        v = res.v
        if not res.check.certifies():
            warnings.warn(
                f"clairvoyant_bound: the active-set solver could not certify its "
                f"optimum (relative gap {res.check.relative_gap:.1e}, tolerance "
                f"{RTOL:g}); using BVLS",
                RuntimeWarning,
                stacklevel=2,
            )
            v = _solve_bvls(hs, ys)
    else:
        certificate = None
        v = _solve_bvls(hs, ys)
    voltage = np.concatenate([np.zeros(delay), v_max * v])
    y = y_free.copy()
    y[delay:] += np.convolve(h, voltage[delay:])[:m]
    return BoundSolution(voltage=voltage, y=y, dt=plant.dt, certificate=certificate)
