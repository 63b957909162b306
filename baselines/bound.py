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
    (:func:`baselines.bound_pdas._solve_pdas` has the details): 10-30 ms for a typical 1000-step
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

The parts: the certificates in :mod:`baselines.bound_certificate`, the structured solver
in :mod:`baselines.bound_pdas`, the slew-limited problem in :mod:`baselines.bound_slew`;
this module sets up an episode's problem and is the public face (every name above is
importable from here).
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass

import numpy as np
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

from .bound_certificate import (
    _Y_UNIT,
    ATOL,
    RTOL,
    KKTCheck,
    SlewCertificate,
    kkt_check,
    slew_certificate,
)
from .bound_pdas import _solve_pdas, reversed_gram
from .bound_slew import EPS, MAX_ITER, _solve_slew

__all__ = [
    "ATOL",
    "EPS",
    "MAX_ITER",
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


def _solve_bvls(h: np.ndarray, y: np.ndarray) -> np.ndarray:
    """The reference: BVLS on the dense matrix (one variable enters or leaves the free
    set per iteration, each a least-squares solve in Python: seconds for 1000 steps)."""
    n = h.size
    res = lsq_linear(
        convolution_matrix(h), -y, bounds=(-1.0, 1.0), method="bvls", tol=1e-12, max_iter=10 * n
    )
    return res.x


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
