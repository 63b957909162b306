r"""Closed-loop simulation of full plant + observer + controller, exactly.

The loop is piecewise affine: the plant, the observer and the load generator
are linear, and the voltage law (:class:`acld_gym.design.feedback.Feedback`) is
affine in each of at most nine regions (boundary layer below/inside/above x
voltage below/inside/above the limit). With the augmented state

.. math::

    z = [x;\ \hat x;\ c;\ s_1, s_2, \dots;\ 1]

(plant, observer, the load's constant part, one quadrature pair per harmonic
frequency, and a constant 1), each region has linear dynamics
:math:`\dot z = F_i z`, which are propagated with the matrix exponential
:math:`e^{F_i h}` -- exact, and stable however stiff the loop is (the
unsaturated LQR loop has poles near -1e7 1/s, where an explicit fixed-step
method would need steps below 1e-7 s). Region switches inside a step are
located by bisection on a dyadic grid of ``h / 2**refine``; load edges are
step boundaries. The only approximation is that localisation (default
1e-4 s / 2**12 = 24 ns).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from acld_gym.design.feedback import Feedback
from acld_gym.design.numerics import expm_balanced
from acld_gym.design.observer import Observer
from acld_gym.physics.loads import TipLoad

__all__ = ["ClosedLoop", "SimulationResult", "simulate"]


@dataclass(frozen=True)
class SimulationResult:
    """Sampled closed-loop response.

    Attributes
    ----------
    t : time [s]; y : tip deflection [m]; voltage : applied voltage [V];
    load : tip load [N]; xr : reduced-state estimate (len(t), k).
    """

    t: np.ndarray
    y: np.ndarray
    voltage: np.ndarray
    load: np.ndarray
    xr: np.ndarray


class ClosedLoop:
    """Augmented piecewise-affine closed loop (see module docstring).

    Parameters
    ----------
    A, B, E, Cy : full plant (truth model).
    observer : observer description (continuous-time).
    feedback : voltage law on the reduced state.
    v_max : voltage limit [V] or None for no saturation.
    frequencies : harmonic load frequencies [rad/s] the loop must carry.
    """

    def __init__(
        self,
        A,
        B,
        E,
        Cy,
        observer: Observer,
        feedback: Feedback,
        v_max: float | None,
        frequencies: tuple[float, ...] = (),
    ):
        if not isinstance(observer, Observer):
            raise ValueError(
                f"observer: the continuous-time simulator needs an Observer, got "
                f"{type(observer).__name__}"
            )
        if v_max is not None and not v_max > 0:
            raise ValueError(f"v_max must be positive or None, got {v_max!r}")
        n, no, nh = A.shape[0], observer.n, len(frequencies)
        self.n, self.no, self.freqs = n, no, tuple(frequencies)
        self.ix_x = slice(0, n)
        self.ix_o = slice(n, n + no)
        self.ix_c = n + no
        self.ix_s = n + no + 1
        self.ix_one = n + no + 1 + 2 * nh
        N = self.ix_one + 1
        self.N = N
        F0 = np.zeros((N, N))
        fl = np.zeros(N)  # load row: f = c + sum s1
        fl[self.ix_c] = 1.0
        fl[self.ix_s : self.ix_one : 2] = 1.0
        F0[self.ix_x, self.ix_x] = A
        F0[self.ix_x, :] += np.outer(E[:, 0], fl)
        F0[self.ix_o, self.ix_o] = observer.A - observer.L @ observer.C
        F0[self.ix_o, self.ix_x] = observer.L @ Cy
        F0[self.ix_o, :] += np.outer(observer.E[:, 0], fl)
        for j, w in enumerate(frequencies):
            k = self.ix_s + 2 * j
            F0[k, k + 1] = w
            F0[k + 1, k] = -w
        self.F0 = F0
        self.bu = np.zeros(N)
        self.bu[self.ix_x] = B[:, 0]
        self.bu[self.ix_o] = observer.B[:, 0]
        self.fl = fl
        self.Cy = Cy[0]
        self.T = observer.T
        self.fb = feedback
        self.v_max = v_max
        # Rows of z giving x_r, sigma and the linear part of v.
        self.R_xr = np.zeros((self.T.shape[0], N))
        self.R_xr[:, self.ix_o] = self.T
        self._cache: dict = {}

    # --- regions -----------------------------------------------------------
    def region(self, z: np.ndarray) -> tuple[int, int]:
        xr = self.R_xr @ z
        fb = self.fb
        js = 0
        sat = 0.0
        if fb.c != 0.0:
            sig = float(fb.s @ xr) / fb.eps
            js = 1 if sig > 1.0 else (-1 if sig < -1.0 else 0)
            sat = float(js) if js else sig
        jv = 0
        if self.v_max is not None:
            v = -float(fb.a @ xr) - fb.c * sat
            jv = 1 if v > self.v_max else (-1 if v < -self.v_max else 0)
        return js, jv

    def voltage_row(self, reg: tuple[int, int]) -> np.ndarray:
        """Row g with u = g z in region ``reg``."""
        js, jv = reg
        g = np.zeros(self.N)
        if jv:
            g[self.ix_one] = jv * self.v_max
            return g
        fb = self.fb
        lin = fb.a + (fb.c / fb.eps) * fb.s if (fb.c != 0.0 and js == 0) else fb.a
        g -= lin @ self.R_xr
        if js:
            g[self.ix_one] -= fb.c * js
        return g

    def propagator(self, reg: tuple[int, int], h: float) -> np.ndarray:
        key = (reg, round(h, 15))
        P = self._cache.get(key)
        if P is None:
            P = expm_balanced(self.F0 + np.outer(self.bu, self.voltage_row(reg)), h)
            self._cache[key] = P
        return P

    # --- exo-system reset at load pieces -------------------------------------
    def set_load(self, z: np.ndarray, load: TipLoad, t0: float, t1: float) -> None:
        piece = load.piece(t0, t1)
        z[self.ix_c] = piece.const
        z[self.ix_s : self.ix_one] = 0.0
        for amp, w, ph in piece.harmonics:
            j = self.freqs.index(w)
            z[self.ix_s + 2 * j] += amp * np.sin(w * t0 + ph)
            z[self.ix_s + 2 * j + 1] += amp * np.cos(w * t0 + ph)

    def advance(self, z: np.ndarray, h: float, refine: int) -> np.ndarray:
        """Advance ``z`` by ``h`` exactly, switching regions where they change."""
        units = 1 << refine
        du = h / units

        def go(zz, reg, k):  # advance k dyadic units with region reg's dynamics
            bit = 0
            while k:
                if k & 1:
                    zz = self.propagator(reg, du * (1 << bit)) @ zz
                k >>= 1
                bit += 1
            return zz

        p = 0
        while p < units:
            reg = self.region(z)
            z1 = self.propagator(reg, h) @ z if p == 0 else go(z, reg, units - p)
            if self.region(z1) == reg:
                return z1
            lo, hi, zlo = 0, units - p, z
            while hi - lo > 1:
                mid = (lo + hi) // 2
                zm = go(zlo, reg, mid - lo)
                if self.region(zm) == reg:
                    lo, zlo = mid, zm
                else:
                    hi = mid
            z = go(zlo, reg, hi - lo)
            p += hi
        return z

    def run(
        self, load: TipLoad, t_end: float, dt: float = 1e-4, refine: int = 12, progress=None
    ) -> SimulationResult:
        """Simulate from rest over [0, t_end], sampling every ``dt``."""
        if not t_end > 0 or not dt > 0:
            raise ValueError(f"t_end and dt must be positive, got {t_end!r}, {dt!r}")
        grid = np.round(np.arange(0.0, t_end + 0.5 * dt, dt), 12)
        bp = load.breakpoints()
        grid = np.unique(np.concatenate([grid, np.round(bp[(bp > 0) & (bp < t_end)], 12)]))
        z = np.zeros(self.N)
        z[self.ix_one] = 1.0
        Z = np.empty((grid.size, self.N))
        Z[0] = z
        for i in range(grid.size - 1):
            t0, t1 = grid[i], grid[i + 1]
            self.set_load(z, load, t0, t1)
            if i == 0:
                Z[0] = z
            z = self.advance(z, t1 - t0, refine)
            Z[i + 1] = z
            if progress is not None:
                progress(i + 1, grid.size - 1)
        y = Z[:, self.ix_x] @ self.Cy
        xr = Z @ self.R_xr.T
        v = self.fb.voltage(xr, self.v_max)
        # Samples at a load edge hold the value after the edge (left-closed intervals).
        return SimulationResult(t=grid, y=y, voltage=v, load=load(grid), xr=xr)


def simulate(
    A,
    B,
    E,
    Cy,
    observer: Observer,
    feedback: Feedback,
    load: TipLoad,
    t_end: float = 1.0,
    v_max: float | None = 120.0,
    dt: float = 1e-4,
    refine: int = 12,
    progress=None,
) -> SimulationResult:
    """Simulate the closed loop from rest (see :class:`ClosedLoop`)."""
    loop = ClosedLoop(A, B, E, Cy, observer, feedback, v_max, load.harmonic_frequencies)
    return loop.run(load, t_end, dt=dt, refine=refine, progress=progress)
