"""One interface for the solvers of A x = b with a sparse SPD matrix A.

A solver is built once from A (n × n), as :func:`scipy.sparse.linalg.factorized`
is, and then solves for as many right-hand sides as wanted:

    solver = SuperLUSolver(A)
    x = solver.solve(b)          # b of shape (n,) or (n, m)
    M = solver.aslinearoperator()  # A⁻¹ (exact) or an approximation of it

Direct solvers (``exact = True``) apply A⁻¹ to round-off; iterative ones
reach a stated relative residual ‖b − A x‖₂ ≤ tol ‖b‖₂ or raise
:class:`LinearSolverError`.
"""

import time
from abc import ABC, abstractmethod

import numpy as np
import scipy.sparse as sp
from scipy.sparse.linalg import LinearOperator


class LinearSolverError(RuntimeError):
    """A factorisation or a solve that failed, with what was reached."""


class LinearSolver(ABC):
    """Base class: built once from A, then ``solve(b)``.

    Subclasses implement ``_setup(A)`` (A a CSR matrix with n > 0) and
    ``_solve(B)`` (B a float array of shape (n, m), returning the same
    shape). An empty system (n = 0) is solved by an empty vector.

    Attributes
    ----------
    name : str
        The backend: ``"superlu"``, ``"pardiso"`` or ``"amg"``.
    exact : bool
        True for a direct solver (A⁻¹ to round-off).
    n : int
        The size of A.
    setup_seconds : float
        Wall-clock time of the set-up (factorisation or AMG hierarchy).
    info : dict
        Plain JSON values describing the set-up and the last solve.
    reason : str
        Why this backend was chosen (set by
        :func:`~adhesive_contact.linear_solvers.make_linear_solver`).
    """

    name = "base"
    exact = True

    def __init__(self, A):
        if not sp.issparse(A) or A.ndim != 2 or A.shape[0] != A.shape[1]:
            raise ValueError(f"A must be a square sparse matrix, got {type(A).__name__} "
                             f"of shape {getattr(A, 'shape', None)}")
        self.n = A.shape[0]
        self.info = {}
        self.reason = ""
        t0 = time.perf_counter()
        if self.n:
            self._setup(sp.csr_matrix(A, dtype=float))
        self.setup_seconds = time.perf_counter() - t0

    @abstractmethod
    def _setup(self, A):
        """Factorise, or build the hierarchy of, A (CSR, n > 0)."""

    @abstractmethod
    def _solve(self, B):
        """A⁻¹ B for a float block B of shape (n, m), in the same shape."""

    def solve(self, b):
        """x = A⁻¹ b for b of shape (n,) or a block (n, m); x has b's shape."""
        b = np.asarray(b, dtype=float)
        if b.ndim not in (1, 2) or b.shape[0] != self.n:
            raise ValueError(f"b must have shape ({self.n},) or ({self.n}, m), got {b.shape}")
        if self.n == 0 or b.size == 0:
            return np.zeros_like(b)
        X = self._solve(np.asfortranarray(b.reshape(self.n, -1)))
        return X.reshape(b.shape)

    def schur(self, A, interior, contact):
        """The dense Schur complement S = A_CC − A_CI A_II⁻¹ A_IC of the
        matrix A whose interior block A_II this solver holds, read off a
        factorisation where the backend can (None: form it by solves)."""
        return None

    def aslinearoperator(self):
        """A⁻¹ as a :class:`~scipy.sparse.linalg.LinearOperator`, usable as
        the preconditioner ``M`` of :func:`scipy.sparse.linalg.cg`."""
        return LinearOperator((self.n, self.n), matvec=self.solve, matmat=self.solve,
                              dtype=float)

    def __repr__(self):
        return f"<{type(self).__name__} n={self.n} setup {self.setup_seconds:.3g} s>"
