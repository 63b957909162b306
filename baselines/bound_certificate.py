r"""Certificates of the clairvoyant bound's optimum (:mod:`baselines.bound`), in the
solvers' scaled units (deflections in mm, voltages in units of the limit).

:class:`KKTCheck` certifies a solution of the box-constrained problem by its duality gap
(:func:`kkt_check`); :class:`SlewCertificate` gives a certified lower bound of the
slew-limited problem's optimum from any multipliers (:func:`slew_certificate`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from acld_gym.physics.actuator import V_LIMIT

__all__ = ["ATOL", "RTOL", "KKTCheck", "SlewCertificate", "kkt_check", "slew_certificate"]

#: Certification of the PDAS solver: duality gap <= RTOL * cost + ATOL * free cost, a bound
#: on the excess ISE over the optimum (the comparison with BVLS asks for 1e-6 relative). The
#: absolute part, relative to the cost without control, matters only when the optimum is
#: nearly zero (a small load that the voltage cancels), where a relative gap cannot be met.
RTOL = 1e-8
ATOL = 1e-9
_Y_UNIT = 1e-3  # scaled problem: deflections in mm ...
_V_UNIT = V_LIMIT  # ... and voltages in units of the limit, so |v| <= 1


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
