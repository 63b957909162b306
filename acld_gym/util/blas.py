"""BLAS threads: one, for the package's many small dense problems.

OpenBLAS starts one thread per core. The work here is many small products and solves
(a 60 x 60 QP per MPC step, the bound's Newton steps, 36-state designs): threads cost
more than they give, and when another process is busy on the machine -- a user's
browser, a training run, a CI neighbour -- oversubscribed threads spin and the same
work runs 10-20 times slower (benchmarks/bench_bound.py --busy measures it). So the
command-line entry points, and the hot calls that users reach from Python (the bound),
run with one BLAS thread via ``threadpoolctl``; the library never changes the global
setting behind a user's back otherwise.
"""

from __future__ import annotations

from contextlib import contextmanager

from threadpoolctl import threadpool_limits

__all__ = ["one_blas_thread"]


@contextmanager
def one_blas_thread():
    """Limit BLAS (OpenBLAS, MKL, ...) to one thread inside the ``with`` block."""
    with threadpool_limits(limits=1, user_api="blas"):
        yield
