"""Clairvoyant bound: the structured active-set solver (``method="pdas"``) against BVLS.

For each thesis load case and a few random-load episodes (1000 steps), prints the
wall time of each solver (the whole ``clairvoyant_bound`` call, model included),
the speed-up and the relative ISE difference, with OpenBLAS on one thread. The
PDAS time is the median of ``--repeat`` runs, BVLS's a single run (0.4-60 s).

``--busy`` adds the same timings beside a second, CPU-bound process (a Python
busy loop), once with one BLAS thread and once with two, to show the behaviour
on a busy machine. That takes many minutes on two cores: two BLAS threads next
to a busy core slow BVLS down by an order of magnitude (restrict it with
``--thesis 3 --random 1``).

Not a timed test: run ``python benchmarks/bench_bound.py [--thesis 1 2 3] [--random 3]
[--busy]`` (about a minute without ``--busy``, BVLS being most of it).
The BLAS thread count must be set before numpy loads (threadpoolctl is not a
dependency), so each configuration runs in a fresh worker process with
``OPENBLAS_NUM_THREADS`` (and the OMP/MKL equivalents) set.
"""

from __future__ import annotations

import argparse
import os
import signal
import subprocess
import sys
import time

from busy import neighbour  # benchmarks/busy.py, beside this script


def _blas_threads() -> str:
    """Threads OpenBLAS reports (it honours OPENBLAS_NUM_THREADS), or '?'."""
    import ctypes
    import re

    try:
        with open("/proc/self/maps") as f:
            libs = sorted(set(re.findall(r"(/\S*openblas\S*\.so\S*)", f.read())))
        for lib in libs:
            dll = ctypes.CDLL(lib)
            for name in (
                "scipy_openblas_get_num_threads64_",
                "scipy_openblas_get_num_threads",
                "openblas_get_num_threads64_",
                "openblas_get_num_threads",
            ):
                if hasattr(dll, name):
                    return str(getattr(dll, name)())
    except OSError:
        pass
    return "?"


def _worker(args) -> None:
    import numpy as np

    from acld_gym.design.nominal import nominal_design
    from acld_gym.physics.loads import random_load, thesis_load
    from baselines.bound import clairvoyant_bound

    nom = nominal_design()
    tip = getattr(nom, "output", None)
    tip = nom.design.model.tip_index if tip is None else tip
    plant, n = nom.plant, args.steps
    episodes = [(f"thesis {c}", thesis_load(c)) for c in args.thesis]
    episodes += [
        (
            f"random {s}",
            random_load(np.random.default_rng(s), n * plant.dt, plant.dt / plant.substeps),
        )
        for s in range(args.random)
    ]
    clairvoyant_bound(plant, tip, thesis_load(3), n)  # warm-up (imports, first allocations)
    print(
        f"OpenBLAS threads: {_blas_threads()} | busy neighbour: "
        f"{'yes' if args.busy_label else 'no'} | load average {os.getloadavg()[0]:.2f} | "
        f"{plant.Ad.shape[0]} states, {n} steps"
    )
    print(
        f"{'episode':<10} {'PDAS [ms]':>9} {'BVLS [s]':>9} {'speed-up':>9} "
        f"{'ISE PDAS [m^2 s]':>17} {'rel. diff':>10}"
    )
    for name, load in episodes:
        times = []
        for _ in range(args.repeat):
            t0 = time.perf_counter()
            new = clairvoyant_bound(plant, tip, load, n)
            times.append(time.perf_counter() - t0)
        t_new = float(np.median(times))
        t0 = time.perf_counter()
        ref = clairvoyant_bound(plant, tip, load, n, method="bvls")
        t_ref = time.perf_counter() - t0
        print(
            f"{name:<10} {1e3 * t_new:9.1f} {t_ref:9.2f} {t_ref / t_new:8.0f}x "
            f"{new.ise:17.6e} {(new.ise - ref.ise) / ref.ise:10.1e}",
            flush=True,
        )


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument(
        "--thesis",
        type=int,
        nargs="*",
        default=[1, 2, 3],
        choices=[1, 2, 3],
        help="thesis load cases",
    )
    p.add_argument("--random", type=int, default=3, help="random-load episodes (seeds 0..)")
    p.add_argument("--steps", type=int, default=1000, help="episode length")
    p.add_argument("--repeat", type=int, default=3, help="PDAS runs per episode (median)")
    p.add_argument(
        "--busy",
        action="store_true",
        help="also time beside a CPU-bound process, with 1 and 2 BLAS threads",
    )
    p.add_argument("--worker", action="store_true", help=argparse.SUPPRESS)
    p.add_argument("--busy-label", action="store_true", help=argparse.SUPPRESS)
    args = p.parse_args()
    if args.worker:
        _worker(args)
        return
    # On SIGTERM, unwind through `neighbour` (it stops the busy process; subprocess.run
    # kills the worker on the way out).
    signal.signal(signal.SIGTERM, lambda *_: sys.exit(1))
    runs = [(1, False)] + ([(1, True), (2, True)] if args.busy else [])
    for threads, busy in runs:
        env = dict(
            os.environ,
            OPENBLAS_NUM_THREADS=str(threads),
            OMP_NUM_THREADS=str(threads),
            MKL_NUM_THREADS=str(threads),
        )
        cmd = [
            sys.executable,
            os.path.abspath(__file__),
            "--worker",
            "--random",
            str(args.random),
            "--steps",
            str(args.steps),
            "--repeat",
            str(args.repeat),
            "--thesis",
            *map(str, args.thesis),
        ]
        if busy:
            cmd.append("--busy-label")
        with neighbour(busy):
            subprocess.run(cmd, env=env, check=True)
        print()


if __name__ == "__main__":
    main()
