r"""The slew-limited clairvoyant bound (:mod:`baselines.bound` with ``slew_step``): the
box and the slew limit :math:`|w_m - w_{m-1}| \le \rho` as one quadratic program solved by
OSQP (:func:`_solve_slew`), its answer made feasible (:func:`_feasible`) and certified by
:class:`baselines.bound_certificate.SlewCertificate`.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from acld_gym.design.discrete import convolution_matrix

from .bound_certificate import SlewCertificate, slew_certificate

__all__ = ["EPS", "MAX_ITER"]


def _difference(n: int):
    """The difference operator D (n x n): (D w)_m = w_m - w_{m-1}, w_{-1} = 0 (sparse)."""
    return sp.eye(n, format="csc") - sp.eye(n, k=-1, format="csc")


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
    import osqp  # optional dependency: the extra acld-gym[baselines]

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
