"""Thread limits scoped to the calls that need them.

The time loop's work is small or latency-bound: dense factorisations of
the size of Γ_C, for which a threaded OpenBLAS on a shared machine was
10–100× slower (a 160 × 160 Cholesky: 0.25 ms on one thread, 2.7 ms on
two, 34 ms with the second core busy), and the triangular solves of a
stored factorisation (PARDISO at 1e5 dofs: 9 ms a half on one thread or
two alone, 46 ms with MKL's threads beside a busy core). So the loop runs
on one BLAS/MKL thread, and the set-up (the factorisations) keeps the
default. One controller is inspected once per process (entering its
limit costs about 30 µs, against 1.4 ms for a fresh ``threadpool_limits``).
"""

from functools import lru_cache

from threadpoolctl import ThreadpoolController


@lru_cache(maxsize=1)
def _controller():
    return ThreadpoolController()


def one_blas_thread():
    """A context manager that runs its block with one BLAS thread."""
    return _controller().limit(limits=1, user_api="blas")
