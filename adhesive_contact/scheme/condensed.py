"""The step matrix condensed onto the contact unknowns.

The step problem of (4.1) has the quadratic part ½ uᵀ a_n u − bᵀ u on the
free dofs. Splitting them into contact dofs C and the rest I,

    S = A_CC − A_CI A_II⁻¹ A_IC,    c = b_C − A_CI A_II⁻¹ b_I,

the minimisation over u becomes one over the contact unknowns z = u_C
only, ½ zᵀ S z − cᵀ z + contact terms; then u_I = A_II⁻¹ (b_I − A_IC z).
(The caller writes the system in the nodal frames of
:mod:`adhesive_contact.fem.contact_boundary`, so z are frame components.)

A_II is factorised once per mesh and step size by a linear backend of
:mod:`adhesive_contact.linear_solvers`. S is read off a factorisation of
the whole matrix where the backend can (SuperLU: the trailing block with
the contact unknowns ordered last; PARDISO: its own Schur complement),
else formed by solves with blocks of the columns of A_IC (AMG). A step then
costs two solves with A_II.

S reaches the step solver as one of two operators with the same interface
(``S @ z``, ``diagonal()``, ``newton_solve``): :class:`DenseSchur`, formed,
or :class:`ImplicitSchur`, applied only.
"""

import time
from contextlib import nullcontext

import numpy as np
import scipy.linalg as la
import scipy.sparse as sp
from scipy.sparse.linalg import LinearOperator, cg

from ..linear_solvers import SuperLUSolver
from ..threads import all_blas_threads

#: from this size on, a dense Newton system is factorised in single precision
MIXED_FROM = 1000
#: and from this size on with all BLAS threads (:mod:`.threads`)
THREADED_FROM = 2000


def dense_solver(H, mixed_from=MIXED_FROM):
    """A solver for the dense symmetric H: Cholesky, or, when H is not
    positive definite (a nonconvex step energy), the modified factorisation
    with |eigenvalues| floored at 1e-8 of the largest.

    From ``mixed_from`` rows on, the Cholesky factor is computed in single
    precision (about 1.8 times faster here, the whole cost of a Newton
    iteration at thousands of contact unknowns) and the solution refined to
    double precision by :func:`mixed_precision_solver`.

    The returned solve has the attribute ``indefinite``: True when H has an
    eigenvalue below −INDEFINITE times its largest, so that the
    factorisation had to modify it (the step energy is not locally
    strictly convex where H was taken)."""
    if H.shape[0] >= mixed_from:
        solve = mixed_precision_solver(H.astype(np.float32), lambda v: H @ v,
                                       np.abs(np.diag(H)).max(), lambda: H)
        if solve is not None:
            return solve
    try:
        # H is symmetric and C-ordered: its transpose is the same matrix in
        # Fortran order, which LAPACK takes without the transposing copy
        # f2py makes of a C-ordered array (a 6000² Cholesky: 0.72 → 0.42 s)
        factor = la.cho_factor(H.T, check_finite=False)
        return flagged(lambda rhs, accuracy=None: la.cho_solve(factor, rhs, check_finite=False),
                       False)
    except la.LinAlgError:
        vals, vecs = la.eigh(H)
        largest = max(np.abs(vals).max(initial=0.0), 1e-300)
        indefinite = bool(vals.min(initial=0.0) < -INDEFINITE * largest)
        vals = np.maximum(np.abs(vals), 1e-8 * largest)
        return flagged(lambda rhs, accuracy=None: vecs @ ((vecs.T @ rhs) / vals), indefinite)


#: an eigenvalue below −INDEFINITE·(the largest) makes a Newton matrix
#: indefinite (above it, a Cholesky that failed met round-off only)
INDEFINITE = 1e-10


def flagged(solve, indefinite):
    """``solve`` with the attribute ``indefinite`` (see :func:`dense_solver`)."""
    solve.indefinite = indefinite
    return solve


def mixed_precision_solver(H32, apply, largest, exact, rtol=1e-14, maxiter=30):
    """Solve H x = b (H symmetric positive definite, double precision) by CG
    on H preconditioned with the Cholesky factor of H in single precision:
    with κ(H) ε₃₂ < 1 the preconditioned matrix has its eigenvalues within
    1 ± κ(H) ε₃₂, and CG reaches the backward error of a direct solve,
    ‖b − H x‖ ≤ rtol (max_i H_ii) ‖x‖, in a few products (x from the
    single-precision solve in the bound).

    Parameters
    ----------
    H32 : (m, m) float32, H rounded (overwritten by its factor)
    apply : callable v -> H v in double precision
    largest : max_i |H_ii|
    exact : callable () -> H in double precision, for the fallback

    Returns None where single precision does not factorise H (H not
    positive definite, or too ill-conditioned); the solver factorises H in
    double precision if CG does not reach rtol in ``maxiter`` products.
    Its ``accuracy = (rtol, atol)``, when given, lets CG stop as soon as
    ‖b − H x‖₂ ≤ max(rtol ‖b‖₂, atol) (an inexact Newton step: the
    single-precision solve alone, after one product, where that is as
    good as the forcing term asks)."""
    m = H32.shape[0]
    threads = all_blas_threads() if m >= THREADED_FROM else nullcontext()
    try:
        with threads:
            factor = la.cho_factor(H32.T, check_finite=False, overwrite_a=True)   # as above
    except la.LinAlgError:
        return None
    precondition = LinearOperator(
        (m, m), dtype=float,
        matvec=lambda r: la.cho_solve(factor, r.astype(np.float32), check_finite=False))
    operator = LinearOperator((m, m), dtype=float, matvec=apply)
    scale = rtol * largest

    def solve(rhs, accuracy=None):
        start = precondition @ rhs
        bound = scale * np.linalg.norm(start)
        if accuracy is not None:
            bound = max(bound, accuracy[0] * np.linalg.norm(rhs), accuracy[1])
        x, info = cg(operator, rhs, x0=start, M=precondition, rtol=0.0, atol=bound,
                     maxiter=maxiter)
        if info == 0:
            return x
        return dense_solver(exact(), mixed_from=np.inf)(rhs)
    return flagged(solve, False)   # single precision factorised it: not indefinite


class RememberedProduct:
    """``M @ z`` by ``self.matrix``, the last product with a vector kept:
    the step methods ask for M z of the iterate a line search has just
    tried (an O(m) comparison against a product); and M 0 = 0 without
    one (the moves of the held coordinates, zero once the sets hold: a
    fifth of the products of a step solve on the 2D strip)."""

    _last = (None, None)   # (z, M z) of the last product

    def __matmul__(self, z):
        if np.ndim(z) == 1 and not np.any(z):
            return np.zeros(self.matrix.shape[0])
        last, product = self._last
        if last is not None and last.shape == np.shape(z) and np.array_equal(last, z):
            return product.copy()
        product = self.matrix @ z
        if np.ndim(z) == 1:
            self._last = (np.array(z, copy=True), product.copy())
        return product


def restricted(H, free):
    """H_FF (coo) of a sparse H on the coordinates where ``free`` is True."""
    H = sp.coo_matrix(H)
    keep = free[H.row] & free[H.col]
    position = np.cumsum(free) - 1
    n = int(position[-1]) + 1 if free.size else 0
    return sp.coo_matrix((H.data[keep], (position[H.row[keep]], position[H.col[keep]])),
                         shape=(n, n))


class DenseSchur(RememberedProduct):
    """S formed: a dense symmetric (nC, nC) matrix."""

    #: whether the Newton matrix of the last :meth:`newton_solve` was
    #: indefinite (:func:`dense_solver`), and how many were so far
    indefinite, indefinite_solves = False, 0

    def __init__(self, S):
        self.matrix = S
        self.shape = S.shape
        self._single = None   # S in single precision, made on first use
        self.kept = None         # (F, solve) of the last Newton system, for chord_solve
        self.chord_start = None  # the step method's sets of that system (its chord step)

    def diagonal(self):
        return np.diag(self.matrix)

    def newton_solve(self, H_phi, rhs, free, accuracy=None):
        """Solve (S + H_φ)_FF d = rhs on the free coordinates F (a boolean
        mask; H_φ sparse): ``(d, converged)``, by :func:`dense_solver`.
        Only the entries of H_φ are added to the copy of S_FF. Below
        MIXED_FROM free coordinates the copy is double precision and d
        exact to round-off; from there on it is taken in single precision
        and refined, by products with S itself, to ``accuracy = (rtol,
        atol)`` (the step method's forcing term; to round-off without it:
        a refinement iteration costs a third of a factorisation at 4000
        unknowns, studies/README.md)."""
        self.release()   # the last factor goes before the next is made
        idx = np.flatnonzero(free)
        everything = idx.size == free.size
        block = restricted(H_phi, free)

        def exact():
            H = self.matrix.copy() if everything else self.matrix.take(idx, 0).take(idx, 1)
            H[block.row, block.col] += block.data
            return H

        if idx.size >= MIXED_FROM:
            if self._single is None:
                self._single = self.matrix.astype(np.float32)
            H32 = (self._single.copy() if everything
                   else self._single.take(idx, axis=0).take(idx, axis=1))
            H32[block.row, block.col] += block.data.astype(np.float32)
            H_FF = block.tocsr()
            full = np.zeros(free.size)

            def apply(v):
                full[idx] = v
                return (self.matrix @ full)[idx] + H_FF @ v

            largest = np.abs(self.matrix[idx, idx] + H_FF.diagonal()).max()
            solve = mixed_precision_solver(H32, apply, largest, exact)
            if solve is not None:
                self.indefinite = False
                self.kept = (free.copy(), solve)
                return solve(rhs, accuracy), True
        solve = dense_solver(exact(), mixed_from=np.inf)
        self.indefinite = solve.indefinite
        self.indefinite_solves += solve.indefinite
        if not solve.indefinite:
            self.kept = (free.copy(), solve)
        return solve(rhs), True

    def chord_solve(self, rhs, free, accuracy=None, system=None):
        """Solve the matrix (S + H_φ)_FF of the last :meth:`newton_solve`
        again, its factorisation reused, for a new right-hand side (the
        chord step of :mod:`adhesive_contact.step_methods.newton`; to
        ``accuracy`` as in :meth:`newton_solve`): d, or None when
        ``system`` (:attr:`kept` when the caller solved it) is no longer
        the kept one, ``free`` is not its F, or that matrix was
        indefinite."""
        if self.kept is None or system is not self.kept or not np.array_equal(self.kept[0], free):
            return None
        return self.kept[1](rhs, accuracy)

    def release(self):
        """Let the factor kept for :meth:`chord_solve` go."""
        self.kept = self.chord_start = None


class ImplicitSchur:
    """S = A_CC − A_CI A_II⁻¹ A_IC applied to vectors, never formed, with a
    dense ``approximation`` of it (a nearby Schur complement) that
    preconditions its Newton systems.

    For the t = 0 problem of a scene with memory (A instead of A + k R(0)),
    used once: forming S would cost one solve per contact unknown, a product
    costs one, and preconditioned by the Schur complement of A + k R(0) (a
    relative perturbation of size k R(0)/A) CG needs a few.
    """

    def __init__(self, A_CC, A_CI, A_IC, solver, approximation, tol=1e-12, max_iter=100):
        self.A_CC, self.A_CI, self.A_IC, self.solver = A_CC, A_CI, A_IC, solver
        self.approximation = approximation
        self.shape = approximation.shape
        self.tol, self.max_iter = tol, max_iter
        self.indefinite, self.indefinite_solves = False, 0   # as in DenseSchur

    def __matmul__(self, z):
        return self.A_CC @ z - self.A_CI @ self.solver.solve(self.A_IC @ z)

    def diagonal(self):
        return np.diag(self.approximation)

    def newton_solve(self, H_phi, rhs, free, accuracy=None):
        """Solve (S + H_φ)_FF d = rhs by CG with S applied, preconditioned by
        (approximation + H_φ)_FF: ``(d, converged)``, to the relative
        residual ``tol`` (each product is a solve pair: ``accuracy`` is not
        used)."""
        idx = np.flatnonzero(free)
        H_FF = restricted(H_phi, free).tocsr()
        precondition = dense_solver(self.approximation.take(idx, 0).take(idx, 1)
                                    + H_FF.toarray())
        self.indefinite = precondition.indefinite   # of the nearby matrix
        self.indefinite_solves += precondition.indefinite
        full = np.zeros(self.shape[0])

        def apply(v):
            full[free] = v
            return (self @ full)[free] + H_FF @ v

        m = rhs.size
        d, info = cg(LinearOperator((m, m), matvec=apply, dtype=float), rhs,
                     M=LinearOperator((m, m), matvec=precondition, dtype=float),
                     rtol=self.tol, atol=0.0, maxiter=self.max_iter)
        return d, info == 0


def superlu(A, rows):
    """The default backend of :class:`CondensedOperator`."""
    return SuperLUSolver(A)


class CondensedOperator:
    """A step matrix on the free dofs, condensed onto the contact unknowns.

    Parameters
    ----------
    A : sparse (nfree, nfree)
        The step matrix restricted to the free dofs.
    contact : (nC,) int
        Positions, within the free dofs, of the contact unknowns.
    factorise : callable (A_II, interior) -> LinearSolver, ``interior`` the
        positions of A_II's rows within the free dofs (default: SuperLU)
    chunk : int, optional
        Right-hand sides per block solve when forming S (SuperLU's block
        solve is fastest per column for a few columns at a time, 16; the
        other backends take 64).
    approximation : dense (nC, nC), optional
        A nearby Schur complement: then S is not formed but applied
        (:class:`ImplicitSchur`), for an operator used for one step only.
    """

    def __init__(self, A, contact, factorise=None, chunk=None, approximation=None):
        t0 = time.perf_counter()
        n = A.shape[0]
        self.contact = np.asarray(contact, dtype=np.int64)
        mask = np.ones(n, dtype=bool)
        mask[self.contact] = False
        self.interior = np.flatnonzero(mask)
        A = sp.csr_matrix(A)
        A_II = A[self.interior][:, self.interior]
        self.A_IC = A[self.interior][:, self.contact].tocsc()
        self.A_CI = self.A_IC.T.tocsr()
        self.solver = (factorise or superlu)(A_II, self.interior)   # the linear backend
        chunk = chunk or (16 if self.solver.name == "superlu" else 64)
        self.factor_seconds = time.perf_counter() - t0

        t0 = time.perf_counter()
        nC = self.contact.size
        if approximation is not None:
            # S is applied, not formed: one solve pair per product
            self.S = ImplicitSchur(A[self.contact][:, self.contact].tocsr(), self.A_CI,
                                   self.A_IC, self.solver, approximation)
            self.schur_seconds = time.perf_counter() - t0
            return
        S = self.solver.schur(A, self.interior, self.contact) if nC else None
        if S is None:   # one block solve per contact unknown
            S = A[self.contact][:, self.contact].toarray()
            for start in range(0, nC, chunk):
                cols = slice(start, min(start + chunk, nC))
                X = self.solver.solve(np.asfortranarray(self.A_IC[:, cols].toarray()))
                S[:, cols] -= self.A_CI @ X
        self.S = DenseSchur(0.5 * (S + S.T))
        self.schur_seconds = time.perf_counter() - t0

    def reduce(self, b):
        """c = b_C − A_CI A_II⁻¹ b_I for a load b on the free dofs."""
        if self.contact.size == 0:
            return np.zeros(0)
        y = self.solver.solve(b[self.interior])
        return b[self.contact] - self.A_CI @ y

    def expand(self, z, b):
        """The free-dof solution u with u_C = z and u_I = A_II⁻¹(b_I − A_IC z)."""
        u = np.empty(b.size)
        u[self.contact] = z
        u[self.interior] = self.solver.solve(b[self.interior] - self.A_IC @ z)
        return u


class PartialCondensation:
    """The same operator as :class:`CondensedOperator` from one partial
    Cholesky factorisation of the whole step matrix with the contact
    unknowns last (:class:`~adhesive_contact.linear_solvers.pardiso.PardisoSchur`):
    S comes with the factorisation, ``reduce`` is its forward half and
    ``expand`` its backward half, so a step costs one solve pair.

    Parameters
    ----------
    A : sparse (nfree, nfree), contact : (nC,) int, as for CondensedOperator
    """

    def __init__(self, A, contact):
        from ..linear_solvers.pardiso import PardisoSchur

        t0 = time.perf_counter()
        self.contact = np.asarray(contact, dtype=np.int64)
        self.solver = PardisoSchur(sp.csr_matrix(A), self.contact)
        S = self.solver.S
        self.S = DenseSchur(0.5 * (S + S.T))
        self.factor_seconds = self.schur_seconds = time.perf_counter() - t0
        self._forward = (None, None)   # (b, its forward half)

    def reduce(self, b):
        """c = b_C − A_CI A_II⁻¹ b_I (the forward half, kept for expand)."""
        y = self.solver.forward(b)
        self._forward = (b, y)
        return y[self.contact].copy()

    def expand(self, z, b):
        """u with u_C = z and u_I = A_II⁻¹(b_I − A_IC z): the backward half
        of the solve whose forward half :meth:`reduce` did for this b (done
        again for another b)."""
        done, y = self._forward
        y = (y if done is b else self.solver.forward(b)).copy()
        y[self.contact] = z
        u = self.solver.backward(y)
        u[self.contact] = z
        return u
