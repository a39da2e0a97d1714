"""Sparse Cholesky of MKL PARDISO, through pypardiso.

pypardiso (and the MKL it loads) is imported only when a solver is built or
:func:`available` is asked, so the package works where it is not installed.

Settings, measured on P1 elasticity step matrices (2e4 and 1e5 dofs in 2D,
9e3 and 4e4 in 3D, one thread):

- matrix type 2 (real SPD: Cholesky A = L Lᵀ on the upper triangle) instead
  of pypardiso's default 11 (real nonsymmetric LU): 0.55× the factor
  entries and 1.3–1.8× faster factorisations, residuals alike (1e-14–1e-13).
- no iterative refinement (iparm 8 = 0; MKL's default performs two steps per
  solve): a Cholesky solve is backward stable, and the refinement made every
  solve 2–2.5× slower for relative residuals of 1.7e-13 (2D) and 9e-15 (3D)
  instead of 3e-13 and 3e-14.
- parallel nested dissection (iparm 2 = 3, MKL's default ordering).

pypardiso keeps a copy of the matrix it factorised (of nnz(A) ≤ 5e7, else a
hash of it) and compares it with the matrix of every ``solve``, an O(nnz(A))
check against the O(nnz(L)) triangular solves; this class keeps the upper
triangle it factorised and passes that same matrix. MKL keeps the factors
in its own memory until the handle is released, which pypardiso never does
on its own (each forgotten factorisation stays): a finaliser releases it
when the solver is garbage-collected.

MKL runs on as many threads as ``threadpoolctl`` allows the ``blas`` API
(MKL's default: one per core).
"""

import functools
import glob
import os
import sys
import time
import weakref

import numpy as np
import scipy.sparse as sp

from .base import LinearSolver, LinearSolverError

SPD = 2   # PARDISO matrix type: real symmetric positive definite


@functools.cache
def mkl_runtime():
    """The MKL runtime library pypardiso loads, or None if it cannot.

    pip's ``mkl`` wheel puts it in the environment's own library folder,
    looked at first: pypardiso's fallback, a recursive search of the whole
    environment, took 0.6 s here."""
    if "PYPARDISO_MKL_RT" not in os.environ:
        found = sorted(glob.glob(os.path.join(sys.prefix, "lib", "libmkl_rt.so*"))
                       + glob.glob(os.path.join(sys.prefix, "lib", "libmkl_rt*.dylib"))
                       + glob.glob(os.path.join(sys.prefix, "Library", "bin", "mkl_rt*.dll")),
                       key=len)
        if found:
            os.environ["PYPARDISO_MKL_RT"] = found[0]
    try:
        from pypardiso import PyPardisoSolver
        return PyPardisoSolver().libmkl._name
    except (ImportError, OSError):
        return None


def available():
    """True if pypardiso imports and finds MKL's runtime library here."""
    return mkl_runtime() is not None


def _new_handle():
    """A PARDISO handle for an SPD matrix. pypardiso looks for MKL's runtime
    on every construction, by a recursive search of the environment when
    ``ctypes.util.find_library`` does not find it (0.1–0.3 s each time
    here); it takes the path from PYPARDISO_MKL_RT instead when that is set,
    which is done once (a user's own setting is kept)."""
    from pypardiso import PyPardisoSolver

    if mkl_runtime() is not None:
        os.environ.setdefault("PYPARDISO_MKL_RT", mkl_runtime())
    return PyPardisoSolver(mtype=SPD)


def _release(pardiso):
    """Free all of MKL's memory for this handle (phase −1)."""
    pardiso.free_memory(everything=True)


class PardisoSolver(LinearSolver):
    """A = L Lᵀ by MKL PARDISO (matrix type 2, nested dissection ordering).

    Attributes
    ----------
    pardiso : pypardiso.PyPardisoSolver or None
        The handle of the factorisation (None for n = 0).
    info : dict
        ``factor_nnz`` (nonzeros of L, as PARDISO reports it),
        ``memory_bytes`` (PARDISO's peak memory for the analysis and
        factorisation), ``matrix_type``.
    """

    name = "pardiso"
    exact = True

    def __init__(self, A):
        self.pardiso = None
        super().__init__(A)

    def _setup(self, A):
        from pypardiso.pardiso_wrapper import PyPardisoError

        self.upper = sp.triu(A, format="csr")
        self.upper.sort_indices()
        pardiso = _new_handle()
        pardiso.set_iparm(1, 1)     # the iparm below, not MKL's defaults
        pardiso.set_iparm(2, 3)     # parallel nested dissection ordering
        pardiso.set_iparm(8, 0)     # no iterative refinement
        pardiso.set_iparm(18, -1)   # report nnz(L)
        weakref.finalize(self, _release, pardiso)
        try:
            pardiso.factorize(self.upper)
        except PyPardisoError as err:
            hint = " (−4: a zero or negative pivot, A is not SPD)" if err.value == -4 else ""
            raise LinearSolverError(f"PARDISO factorisation of the {self.n}×{self.n} matrix "
                                    f"failed with error {err.value}{hint}") from err
        self.pardiso = pardiso
        self.info = {
            "factor_nnz": int(pardiso.get_iparm(18)),
            "memory_bytes": 1024 * int(max(pardiso.get_iparm(15),
                                           pardiso.get_iparm(16) + pardiso.get_iparm(17))),
            "matrix_type": SPD,
        }

    def _solve(self, B):
        return self.pardiso.solve(self.upper, B)

    def schur(self, A, interior, contact):
        """S by PARDISO's own Schur complement (iparm(36) = 1): a partial
        factorisation of the whole A with the rows of C marked in ``perm``,
        which returns S dense (about the cost of one factorisation; forming
        S by block solves cost 10× more at 1e5 dofs). A separate handle, freed
        at once; the factorisation of A_II for the step solves is kept."""
        nC = contact.size
        if nC == 0:
            return None
        from pypardiso.pardiso_wrapper import PyPardisoError

        n = A.shape[0]
        upper = sp.triu(sp.csr_matrix(A, dtype=float), format="csr")
        upper.sort_indices()
        pardiso = _new_handle()
        pardiso.set_iparm(1, 1)
        pardiso.set_iparm(2, 3)
        pardiso.set_iparm(8, 0)
        pardiso.set_iparm(36, 1)    # compute the Schur complement of the marked rows
        pardiso.perm = np.zeros(n, dtype=np.int32)
        pardiso.perm[contact] = 1
        # x receives S (nC × nC, column-major) at phase 12: give it room
        work = np.zeros((n, max(-(-nC * nC // n), 1)), order="F")
        try:
            pardiso._check_A(upper)
            pardiso.set_phase(12)
            x = pardiso._call_pardiso(upper, work)
        except PyPardisoError as err:
            raise LinearSolverError(f"PARDISO's Schur complement of the {n}×{n} matrix "
                                    f"failed with error {err.value}") from err
        finally:
            _release(pardiso)
        return np.asarray(x).ravel(order="F")[:nC * nC].reshape(nC, nC)


class PardisoSchur:
    """A partial Cholesky factorisation of A with the rows C last (PARDISO,
    iparm(36) = 2): the dense Schur complement S = A_CC − A_CI A_II⁻¹ A_IC,
    and the two halves of a solve with A_II's factors,

        forward(b)  = (y_I, c):  L_II y_I = b_I,  c = b_C − A_CI A_II⁻¹ b_I,
        backward(y_I, z) = u_I = A_II⁻¹ (b_I − A_IC z),

    so a step that condenses onto C and expands back costs one solve pair
    with one factorisation (instead of a factorisation of A_II, another for
    S and two solve pairs). The arrays PARDISO reads are kept, so a call
    costs its triangular solves only.

    Parameters
    ----------
    A : sparse SPD (n, n)
    contact : (nC,) int, the rows of C
    """

    name = "pardiso"
    exact = True

    def __init__(self, A, contact):
        import ctypes

        t0 = time.perf_counter()
        self.n, nC = A.shape[0], contact.size
        upper = sp.triu(sp.csr_matrix(A, dtype=float), format="csr")
        upper.sort_indices()
        self.data = np.ascontiguousarray(upper.data)
        self.ia = (upper.indptr + 1).astype(np.int32)   # one-based, as PARDISO reads them
        self.ja = (upper.indices + 1).astype(np.int32)
        handle = _new_handle()
        handle.set_iparm(1, 1)
        handle.set_iparm(2, 3)     # parallel nested dissection
        handle.set_iparm(8, 0)     # no iterative refinement
        handle.set_iparm(36, 2)    # Schur complement, and the partial factors kept
        handle.perm = np.zeros(self.n, dtype=np.int32)
        handle.perm[contact] = 1
        self.handle, self._ctypes = handle, ctypes
        weakref.finalize(self, _release, handle)
        # x receives S (column-major) at phase 12
        x = self._call(12, np.zeros(self.n), np.zeros(max(nC * nC, self.n)))
        self.S = x[:nC * nC].reshape(nC, nC, order="F").copy()
        self.setup_seconds = time.perf_counter() - t0
        self.info = {"matrix_type": SPD, "schur_rows": int(nC)}
        self.reason = ""

    def _call(self, phase, b, x):
        ctypes, h = self._ctypes, self.handle
        int_p, double_p = ctypes.POINTER(ctypes.c_int32), ctypes.POINTER(ctypes.c_double)
        error = ctypes.c_int32(0)
        h._mkl_pardiso(h.pt.ctypes.data_as(ctypes.POINTER(h._pt_type[0])),
                       ctypes.byref(ctypes.c_int32(1)), ctypes.byref(ctypes.c_int32(1)),
                       ctypes.byref(ctypes.c_int32(SPD)), ctypes.byref(ctypes.c_int32(phase)),
                       ctypes.byref(ctypes.c_int32(self.n)), self.data.ctypes.data_as(double_p),
                       self.ia.ctypes.data_as(int_p), self.ja.ctypes.data_as(int_p),
                       h.perm.ctypes.data_as(int_p), ctypes.byref(ctypes.c_int32(1)),
                       h.iparm.ctypes.data_as(int_p), ctypes.byref(ctypes.c_int32(0)),
                       b.ctypes.data_as(double_p), x.ctypes.data_as(double_p),
                       ctypes.byref(error))
        if error.value != 0:
            raise LinearSolverError(f"PARDISO phase {phase} on the {self.n}×{self.n} matrix "
                                    f"failed with error {error.value}")
        return x

    def forward(self, b):
        """Phase 331 on b (n,): L_II⁻¹ b_I in the rows I, c in the rows C."""
        return self._call(331, np.ascontiguousarray(b, dtype=float), np.zeros(self.n))

    def backward(self, y):
        """Phase 333 on y (n,) holding forward's rows I and z in the rows C:
        u_I = A_II⁻¹ (b_I − A_IC z) in the rows I (z in the rows C)."""
        return self._call(333, np.ascontiguousarray(y, dtype=float), np.zeros(self.n))
