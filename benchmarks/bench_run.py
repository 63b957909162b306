"""Wall time of ``make run`` after the install, on a quiet machine and beside a busy one.

Runs the commands of ``make run`` (as ``make -n run`` lists them, so this script and the
Makefile cannot drift apart) one after another, first alone and then beside a second,
CPU-bound process (``benchmarks/busy.py``), and prints each command's wall time and the
total. The outputs go to ``results/`` as with ``make run``; stdout is discarded and stderr
is not a terminal, so no progress line is drawn.

Not a timed test: run ``python benchmarks/bench_run.py [--no-quiet-run]`` from the
repository's top level after ``make install`` (about four minutes on two cores: the run
twice, 125 s and 129 s on 2026-12-08).
"""

from __future__ import annotations

import argparse
import itertools
import os
import subprocess
import sys
import time
from pathlib import Path

from busy import neighbour  # benchmarks/busy.py, beside this script

TOP = Path(__file__).resolve().parent.parent


def run_commands() -> list[str]:
    """The shell commands of ``make run``; exits if the install is not up to date (its time
    is not part of the figure)."""
    if subprocess.run(["make", "-q", "install"], cwd=TOP).returncode != 0:
        sys.exit("bench_run: the install is not up to date; run `make install` first")
    out = subprocess.run(
        ["make", "-n", "run"], cwd=TOP, capture_output=True, text=True, check=True
    ).stdout
    return [line for line in out.splitlines() if line.strip() and not line.startswith("#")]


def time_commands(commands: list[str]) -> list[float]:
    """Wall time of each command, run in order by the shell as make runs them."""
    times = []
    for cmd in commands:
        t0 = time.perf_counter()
        subprocess.run(
            cmd,
            shell=True,
            cwd=TOP,
            check=True,
            stdout=subprocess.DEVNULL,
            stderr=subprocess.DEVNULL,
        )
        times.append(time.perf_counter() - t0)
    return times


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument(
        "--no-quiet-run", action="store_true", help="only the run beside the busy neighbour"
    )
    args = p.parse_args()
    commands = run_commands()
    runs = ([] if args.no_quiet_run else [False]) + [True]
    columns = {}
    for busy in runs:
        with neighbour(busy):
            columns[busy] = (time_commands(commands), os.getloadavg()[0])
    print(f"make run after the install: {len(commands)} commands, {os.cpu_count()} cores")
    head = f"{'command':<34}" + "".join(
        f"{'busy neighbour [s]' if b else 'quiet [s]':>20}" for b in columns
    )
    print(head)
    for k, cmd in enumerate(commands):
        words = cmd.replace(".venv/bin/", "").split()
        name = " ".join(itertools.takewhile(lambda w: not w.startswith("--"), words))
        print(f"{name:<34}" + "".join(f"{t[k]:20.1f}" for t, _ in columns.values()))
    print(f"{'total':<34}" + "".join(f"{sum(t):20.1f}" for t, _ in columns.values()))
    print(
        f"{'load average at the end (1 min)':<34}"
        + "".join(f"{end:20.2f}" for _, end in columns.values())
    )


if __name__ == "__main__":
    main()
