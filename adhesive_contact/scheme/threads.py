"""Thread limits scoped to the calls that need them.

The step solves factorise dense matrices of the size of Γ_C, for which a
threaded OpenBLAS on a shared machine was 10–100× slower (a 160 × 160
Cholesky: 0.25 ms on one thread, 2.7 ms on two, 34 ms with the second
core busy). Only the step solve is limited, and only while it runs; one
controller is inspected once per process (entering its limit costs about
30 µs, against 1.4 ms for a fresh ``threadpool_limits``).
"""

from functools import lru_cache

from threadpoolctl import ThreadpoolController


@lru_cache(maxsize=1)
def _controller():
    return ThreadpoolController()


def one_blas_thread():
    """A context manager that runs its block with one BLAS thread."""
    return _controller().limit(limits=1, user_api="blas")
