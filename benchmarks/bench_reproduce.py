"""Benchmark: the exact piecewise-affine simulator vs a straightforward fixed-step RK4.

Prints (1) the wall time of the whole Table-2 reproduction (18 rows, 1 s
each), (2) for case 1 / LQR / saturated over a short window: the error of our
default simulator and of fixed-step RK4 against a much finer reference, and
RK4's time, extrapolated to the full reproduction, and (3) what a naive
fixed step of 1e-5 s does (diverges: the loop has poles near -1e7 1/s).

Run: .venv/bin/python benchmarks/bench_reproduce.py
"""

from __future__ import annotations

import time

import numpy as np

from acld_gym.design.pipeline import design
from acld_gym.design.simulate import ClosedLoop, simulate
from acld_gym.physics.loads import thesis_load
from acld_gym.thesis.metrics import peak
from acld_gym.thesis.reproduce import run_cases

WINDOW = 0.02  # s, the RK4 comparison window (covers the pulse and many saturation switches)


def rk4(loop: ClosedLoop, load, t_end: float, h: float, t_out: np.ndarray) -> np.ndarray:
    """Classical RK4 with fixed step h on the augmented loop (load edges on steps)."""
    z = np.zeros(loop.N)
    z[loop.ix_one] = 1.0

    def f(zz):
        return (loop.F0 + np.outer(loop.bu, loop.voltage_row(loop.region(zz)))) @ zz

    n = int(round(t_end / h))
    out = np.empty(t_out.size)
    k_out = 0
    for i in range(n + 1):
        t = i * h
        while k_out < t_out.size and t_out[k_out] <= t + 0.5 * h:
            out[k_out] = loop.Cy @ z[loop.ix_x]
            k_out += 1
        if i == n:
            break
        loop.set_load(z, load, t, t + h)
        k1 = f(z)
        k2 = f(z + 0.5 * h * k1)
        k3 = f(z + 0.5 * h * k2)
        k4 = f(z + h * k3)
        z = z + h / 6.0 * (k1 + 2 * k2 + 2 * k3 + k4)
        if not np.all(np.isfinite(z)) or np.abs(z).max() > 1e6:
            out[k_out:] = np.nan
            break
    return out


def main() -> None:
    d = design()
    A, B, E, Cy = d.plant
    obs = d.observer("thesis")
    t0 = time.perf_counter()
    rows = run_cases(d)
    t_all = time.perf_counter() - t0
    print(f"exact simulator, full reproduction ({len(rows)} rows x 1 s): {t_all:.2f} s")

    load = thesis_load(1)
    ref = simulate(A, B, E, Cy, obs, d.lqr, load, t_end=WINDOW, v_max=120.0, dt=1e-6)
    t0 = time.perf_counter()
    ours = simulate(A, B, E, Cy, obs, d.lqr, load, t_end=WINDOW, v_max=120.0)
    t_ours = time.perf_counter() - t0
    grid = ours.t
    yref = ref.y[:: int(round(1e-4 / 1e-6))]
    err_ours = np.abs(ours.y - yref).max() / peak(yref)
    print(f"case 1 LQR saturated, {WINDOW * 1e3:.0f} ms window, error vs 1e-6 s reference:")
    print(f"  exact simulator (dt = 1e-4 s): rel. error {err_ours:.1e}, {t_ours * 1e3:.1f} ms")
    loop = ClosedLoop(A, B, E, Cy, obs, d.lqr, 120.0)
    poles = np.linalg.eigvals(loop.F0 + np.outer(loop.bu, loop.voltage_row((0, 0))))
    print(f"  fastest closed-loop pole {poles.real.min():.3g} 1/s")
    for h in (2e-7, 1e-7):
        t0 = time.perf_counter()
        y = rk4(loop, load, WINDOW, h, grid)
        t_rk = time.perf_counter() - t0
        err = np.abs(y - yref).max() / peak(yref)
        full = t_rk * (1.0 / WINDOW) * 15  # 15 distinct runs of 1 s
        print(
            f"  RK4 h = {h:.0e} s: rel. error {err:.1e}, {t_rk:.1f} s "
            f"(extrapolated to the full reproduction: {full / 60:.0f} min)"
        )
    y = rk4(loop, load, WINDOW, 1e-5, grid)
    print(f"  RK4 h = 1e-05 s: {'diverges' if not np.all(np.isfinite(y)) else 'finite'}")


if __name__ == "__main__":
    from acld_gym.util.blas import one_blas_thread

    with one_blas_thread():  # as the package's entry points run (acld_gym.util.blas)
        main()
