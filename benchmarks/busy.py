"""The busy neighbour of the speed benchmarks: a second, CPU-bound process.

A user's laptop or a CI runner usually has another job running; small dense problems on
oversubscribed BLAS threads are slowest then. ``with neighbour():`` runs one core's worth
of pure-Python work in a child process for the duration of the block.
"""

from __future__ import annotations

import contextlib
import multiprocessing as mp
import os
from collections.abc import Iterator


def _spin(parent: int) -> None:
    """One core's worth of pure-Python work, until its parent is gone."""
    x = 0
    while os.getppid() == parent:
        for _ in range(1_000_000):
            x = (x + 1) % 1_000_003


@contextlib.contextmanager
def neighbour(busy: bool = True) -> Iterator[None]:
    """A CPU-bound child process during the block (none if not ``busy``)."""
    if not busy:
        yield
        return
    proc = mp.Process(target=_spin, args=(os.getpid(),), daemon=True)
    proc.start()
    try:
        yield
    finally:
        proc.terminate()
        proc.join()
