"""Thread limits scoped to the calls that need them.

The time loop's work is small or latency-bound: dense factorisations of
the size of Γ_C, for which a threaded OpenBLAS on a shared machine was
10–100× slower (a 160 × 160 Cholesky: 0.25 ms on one thread, 2.7 ms on
two, 34 ms with the second core busy), and the triangular solves of a
stored factorisation (PARDISO at 1e5 dofs: 9 ms a half on one thread or
two alone, 46 ms with MKL's threads beside a busy core). So the loop runs
on one BLAS/MKL thread, and the set-up (the factorisations) keeps the
default; inside the loop, a dense factorisation of thousands of contact
unknowns takes all cores again (:func:`all_blas_threads`): a single-precision
Cholesky of 6336 unknowns took 1.07 s on one thread and 0.66 s on two
here, 1.08 and 1.29 s with the other core busy (0.28 and 0.19 s at 4000,
equal at 2000 with a busy core, slower on two below 1000). What reads a
finished run level by level (the energies, :mod:`adhesive_contact.postprocess`)
runs on one thread too: a dot product of 12,050 floats took 0.57 ms on two
threads with the other core busy, 3.4 µs on one. One controller
is inspected once per process (entering its limit costs about 30 µs,
against 1.4 ms for a fresh ``threadpool_limits``).
"""

from functools import lru_cache

from threadpoolctl import ThreadpoolController


@lru_cache(maxsize=1)
def _controller():
    """The controller and BLAS's default thread count, read before any limit."""
    controller = ThreadpoolController()
    default = max((lib.num_threads for lib in controller.lib_controllers
                   if lib.user_api == "blas"), default=1)
    return controller, default


def one_blas_thread():
    """A context manager that runs its block with one BLAS thread."""
    return _controller()[0].limit(limits=1, user_api="blas")


def all_blas_threads():
    """A context manager that runs its block with BLAS's default threads."""
    controller, default = _controller()
    return controller.limit(limits=default, user_api="blas")
