r"""Exact sampled-data form of the beam for a control period ``dt`` (zero-order hold).

Over one period :math:`[t_k, t_k + \Delta]` with the voltage held,

.. math::

    x_{k+1} = A_d x_k + B_d V_k + \int_0^{\Delta} e^{A(\Delta - s)} E f(t_k + s)\,ds,
    \qquad A_d = e^{A\Delta},\quad B_d = \int_0^\Delta e^{As} ds\,B .

The load integral is evaluated on ``substeps`` equal sub-intervals with the load
linear in each, between its right limit at the sub-interval's start and its
left limit at the end (first-order hold). That is exact for pulses whose edges
lie on the sub-interval grid (the environment draws its random pulses on that
grid) and second-order accurate for harmonics (relative error about
(omega h)^2 / 12, 2.7e-5 for 179 rad/s and h = 0.1 ms):

.. math::

    \int_0^{\Delta} e^{A(\Delta - s)} E f\,ds
    = \sum_i \big(H^0_i f(\tau_i^+) + H^1_i f(\tau_{i+1}^-)\big),

where :math:`H^0_i, H^1_i` are the hold weights of sub-interval i. Every
matrix comes from one matrix exponential of an augmented (Van Loan) matrix,
computed in balanced coordinates, so the sampled model is exact for any
stiffness; :func:`discretize` is tested against a much finer reference
(tests/design/test_discrete.py).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.linalg as sla

from acld_gym.design.numerics import expm_balanced

__all__ = ["SampledSystem", "discretize", "impulse_response", "convolution_matrix"]


@dataclass(frozen=True, eq=False)
class SampledSystem:
    """Sampled system :math:`x_{k+1} = A_d x_k + B_d V_k + W_0 f_0 + W_1 f_1`.

    ``W0`` and ``W1`` (n x substeps) weight the load at the start and at the
    end of each sub-interval (first-order hold); ``times`` are the sub-interval
    edges within a period, ``0 .. dt``.
    """

    Ad: np.ndarray
    Bd: np.ndarray
    W0: np.ndarray
    W1: np.ndarray
    dt: float

    @property
    def substeps(self) -> int:
        return self.W0.shape[1]

    @property
    def times(self) -> np.ndarray:
        return np.linspace(0.0, self.dt, self.substeps + 1)

    @property
    def Ed(self) -> np.ndarray:
        """Response to a load held constant at 1 N over the period (n x 1)."""
        return (self.W0.sum(axis=1) + self.W1.sum(axis=1))[:, None]

    def load_samples(self, load, t0: float) -> tuple[np.ndarray, np.ndarray]:
        """Right limits at the sub-interval starts and left limits at their ends of
        ``load(t)`` for the period starting at ``t0`` (evaluated 1e-9 dt inside, so
        edges on the grid are not misread by rounding)."""
        tt = t0 + self.times
        eps = 1e-9 * self.dt
        return load(tt[:-1] + eps), load(tt[1:] - eps)

    def load_increment(self, f0: np.ndarray, f1: np.ndarray) -> np.ndarray:
        """Load contribution for sub-interval start/end samples ``f0, f1``
        (..., substeps) -> (..., n)."""
        return f0 @ self.W0.T + f1 @ self.W1.T


def discretize(
    A: np.ndarray, B: np.ndarray, E: np.ndarray, dt: float, substeps: int = 10
) -> SampledSystem:
    """Zero-order-hold discretization with first-order-hold load sub-steps.

    Parameters
    ----------
    A, B, E : continuous model (n x n, n x 1, n x 1).
    dt : control period [s], > 0.
    substeps : number of load sub-intervals per period, >= 1.
    """
    if not (isinstance(dt, (int, float)) and np.isfinite(dt) and dt > 0):
        raise ValueError(f"dt must be a positive number of seconds, got {dt!r}")
    if not isinstance(substeps, (int, np.integer)) or substeps < 1:
        raise ValueError(f"substeps must be a positive integer, got {substeps!r}")
    n = A.shape[0]
    h = dt / substeps
    # Van Loan: expm([[A, B], [0, 0]] dt) holds Ad and Bd.
    F = np.zeros((n + 1, n + 1))
    F[:n, :n] = A
    F[:n, n] = B[:, 0]
    Phi = expm_balanced(F, dt)
    Ad, Bd = Phi[:n, :n], Phi[:n, n : n + 1]
    # One sub-step h with a constant input c and a ramp r(s) = s/h (r' = 1/h):
    # expm gives G = int e^{A(h-s)} E ds and Rm = int e^{A(h-s)} E s/h ds.
    Fh = np.zeros((n + 3, n + 3))
    Fh[:n, :n] = A
    Fh[:n, n] = E[:, 0]
    Fh[:n, n + 1] = E[:, 0]
    Fh[n + 1, n + 2] = 1.0 / h
    P = expm_balanced(Fh, h)
    G = P[:n, n]  # int_0^h e^{A(h-s)} E ds
    Rm = P[:n, n + 2]  # int_0^h e^{A(h-s)} E (s/h) ds
    # Linear interpolation f = f0 (1 - s/h) + f1 s/h on a sub-interval.
    w0, w1 = G - Rm, Rm
    Ah = expm_balanced(A, h)
    W0 = np.empty((n, substeps))
    W1 = np.empty((n, substeps))
    prop = np.eye(n)
    for i in range(substeps - 1, -1, -1):  # sub-interval i is propagated (substeps-1-i) * h
        W0[:, i] = prop @ w0
        W1[:, i] = prop @ w1
        prop = Ah @ prop
    return SampledSystem(Ad=Ad, Bd=Bd, W0=W0, W1=W1, dt=float(dt))


# --- responses of a sampled system ---------------------------------------------------
def _output_rows(Ad: np.ndarray, c: np.ndarray, n: int) -> np.ndarray:
    """Rows :math:`c A_d^m`, m = 0..n-1, as an (n, nx) array.

    By doubling: with rows 0..p-1 known, rows p..2p-1 are those times
    :math:`A_d^p`; about log2(n) matrix products instead of n vector products.
    """
    rows = np.empty((n, Ad.shape[0]))
    rows[0] = c
    p, Ap = 1, Ad
    while p < n:
        m = min(p, n - p)
        rows[p : p + m] = rows[:m] @ Ap
        p += m
        if p < n:
            Ap = Ap @ Ap
    return rows


def _system_matrices(system) -> tuple[np.ndarray, np.ndarray]:
    """(Ad, b): the state matrix and the voltage column of a plant or an (Ad, Bd) pair."""
    if isinstance(system, SampledSystem):
        return system.Ad, system.Bd[:, 0]
    Ad, Bd = (np.asarray(a, dtype=float) for a in system)
    return Ad, Bd.reshape(Ad.shape[0], -1)[:, 0]


def _output_vector(output, nx: int) -> np.ndarray:
    if isinstance(output, (int, np.integer)) and not isinstance(output, bool):
        if not 0 <= output < nx:
            raise ValueError(f"output must be a state index in [0, {nx}), got {output!r}")
        c = np.zeros(nx)
        c[output] = 1.0
        return c
    c = np.asarray(output, dtype=float).reshape(-1)
    if c.size != nx:
        raise ValueError(
            f"output must be a state index or a row of {nx} weights, got shape {np.shape(output)}"
        )
    return c


def _check_steps(n: int, name: str) -> None:
    if not isinstance(n, (int, np.integer)) or isinstance(n, bool) or n < 1:
        raise ValueError(f"{name} must be a positive integer, got {n!r}")


def impulse_response(system, output: int | np.ndarray, n: int) -> np.ndarray:
    r"""Voltage impulse response :math:`h_m = c\,A_d^m B_d`, m = 0..n-1.

    Parameters
    ----------
    system : SampledSystem or (Ad, Bd)
        The sampled plant (any state dimension; the first input column is used,
        ``Bd`` may be a 1-D column).
    output : int or array_like
        A state index (the tip deflection of the full model) or an output row
        :math:`c` (e.g. ``C[0]`` of a reduced model).
    n : int
        Number of samples, >= 1.

    Returns
    -------
    h : ndarray, shape (n,)
        ``h[m]`` is the output m steps after the period with a unit voltage,
        i.e. the first column of :func:`convolution_matrix`'s ``G``.
    """
    _check_steps(n, "n")
    Ad, b = _system_matrices(system)
    return _output_rows(Ad, _output_vector(output, Ad.shape[0]), n) @ b


def convolution_matrix(h: np.ndarray) -> np.ndarray:
    """Lower-triangular Toeplitz matrix ``G[k, j] = h[k - j]`` (k >= j), so ``G @ v`` is the
    response to the input sequence ``v`` (dense, n x n)."""
    h = np.asarray(h, dtype=float)
    return sla.toeplitz(h, np.zeros_like(h))
