"""The step problem on all free dofs, for the AMG backend.

A Schur complement onto the contact unknowns costs one iterative solve
per contact unknown when A_II has no factorisation to read it from (28,000
of them on a 3D mesh of 1e6 dofs, and a dense S of 6 GB). With AMG the step
method therefore iterates on the whole free vector u instead,

    E(u) = ½ uᵀ a_n u − bᵀ u + Φ(u_C)   subject to  u_ν ≤ g  on Γ_C,

the same minimisation as the condensed one (minimising over u_I first
gives it back), with the same projected Newton method
(:mod:`adhesive_contact.step_methods.newton`): its sets and kinks live on
the contact unknowns u_C, and its Newton systems

    (a_n + H_φ)_FF d = r,   F the coordinates not held (on the wall, stuck),

are sparse and are solved by CG preconditioned with one V-cycle of the
hierarchy of a_n, built once per run, whose level matrices are updated by
the Galerkin products of the change (a_n + H_φ)_FF − a_n, which lies on
the rows of Γ_C (:meth:`~adhesive_contact.linear_solvers.amg.AMGSolver.updated`).
The systems are solved inexactly, to the relative residual η_k of
Eisenstat and Walker (:func:`~adhesive_contact.step_methods.newton.eisenstat_walker`:
rough while the sets move, tight once Newton converges), and no further
than the step's own tolerance needs; a nonconvex φ (slip weakening) may
make a_n + H_φ indefinite, and CG then stops at the first direction of
negative curvature with its last iterate, a descent direction (Steihaug).

A step then costs the Newton iterations' CG iterations, each a product with
a_n and a V-cycle (measured: 3.4–3.8 CG iterations a Newton system on the 3D
full model of studies/bench/ladder.py from 2.8e4 to 1e6 dofs), and no
solve pair.
"""

import time

import numpy as np
import scipy.sparse as sp

from .condensed import RememberedProduct


def truncated_cg(apply, precondition, rhs, rtol, atol, maxiter, restarts=3,
                 on_negative_curvature=None):
    """Preconditioned CG for K x = rhs from x = 0, until the true residual
    ‖rhs − K x‖₂ ≤ max(rtol ‖rhs‖₂, atol) (restarted on it, up to
    ``restarts`` times, when the recurrence's residual has drifted from
    it), or to the first p with pᵀ K p ≤ 0 (K indefinite): ``(x,
    converged, iterations)``, x then the last iterate (the preconditioned
    residual if there is none yet), along which ½ xᵀ K x − rhsᵀ x decreases;
    ``on_negative_curvature()`` is then called, if given."""
    x = np.zeros_like(rhs)
    bound = max(rtol * np.linalg.norm(rhs), atol)
    r = rhs.copy()
    iterations = 0
    for restart in range(restarts + 1):
        if np.linalg.norm(r) <= bound:
            return x, True, iterations
        z = precondition(r)
        p, rz = z.copy(), r @ z
        while iterations < maxiter:
            q = apply(p)
            curvature = p @ q
            iterations += 1
            if not curvature > 0:
                if on_negative_curvature is not None:
                    on_negative_curvature()
                return (x if iterations > 1 or restart else z), False, iterations
            alpha = rz / curvature
            x += alpha * p
            r -= alpha * q
            if np.linalg.norm(r) <= bound:
                break
            z = precondition(r)
            rz, rz_old = r @ z, rz
            p = z + (rz / rz_old) * p
        r = rhs - apply(x)   # the true residual
        if iterations >= maxiter:
            break
    return x, bool(np.linalg.norm(r) <= bound), iterations


class FullSystemMatrix(RememberedProduct):
    """a_n on the free dofs as the step method's operator (``@``,
    ``diagonal()``, ``newton_solve``), with CG preconditioned by the AMG
    hierarchy of ``solver`` (that of a_n, also for the t = 0 matrix A: the
    two are spectrally equivalent, within 1 ± ρ of the module
    :mod:`adhesive_contact.scheme.operators`)."""

    def __init__(self, A, solver, maxiter=1000):
        self.A = sp.csr_matrix(A)
        self.shape = self.A.shape
        self.solver = solver
        self.maxiter = maxiter
        self._diagonal = self.A.diagonal()
        self.iterations = 0         # CG iterations of all Newton systems so far
        self.indefinite = False     # CG of the last Newton system met pᵀ K p ≤ 0
        self.indefinite_solves = 0  # and how many did so far

    @property
    def matrix(self):
        """a_n, for the products z ↦ a_n z (the last one kept)."""
        return self.A

    def diagonal(self):
        return self._diagonal

    def newton_solve(self, H_phi, rhs, free, accuracy=None):
        """Solve (a_n + H_φ)_FF d = rhs by :func:`truncated_cg` to the
        relative and absolute residual ``accuracy = (rtol, atol)`` (default:
        the AMG solver's tolerance): ``(d, converged)``.

        The system is written on all free dofs, the held coordinates by
        identity rows, K = Π(a_n + H_φ)Π + I − Π (Π the projection onto F),
        and preconditioned by the hierarchy of a_n updated by K − a_n
        (:meth:`~adhesive_contact.linear_solvers.amg.AMGSolver.updated`),
        which lies on the rows of Γ_C: against the V-cycle of a_n alone this
        takes 3–5 times fewer CG iterations (measured: 689 against 3295 on
        the 3D full model of studies/bench/ladder.py at 2.8e4 dofs; slip
        weakening and a breaking glue make a_n + H_φ far from a_n near Γ_C)."""
        rtol, atol = accuracy if accuracy is not None else (self.solver.tol, 0.0)
        shift = self._shift(sp.csr_matrix(H_phi), ~free)
        _, precondition = self.solver.updated(shift)
        full = np.zeros(free.size)
        full[free] = rhs
        # K v = a_n v + (K − a_n) v, with this operator's a_n (A at t = 0, whose
        # preconditioner is the hierarchy of A + k R(0))
        self.indefinite = False

        def negative():
            self.indefinite = True
            self.indefinite_solves += 1

        d, converged, iterations = truncated_cg(lambda v: self.A @ v + shift @ v,
                                                lambda r: precondition @ r,
                                                full, rtol, atol, self.maxiter,
                                                on_negative_curvature=negative)
        self.iterations += iterations
        return d[free], converged

    def _shift(self, H, held):
        """K − a_n for K of :meth:`newton_solve`: Π H Π − (the entries of a_n
        in a held row or column) + the held coordinates' identity."""
        if not held.any():
            return H
        n = held.size
        keep = sp.diags(np.where(held, 0.0, 1.0))
        rows = np.flatnonzero(held)
        counts = np.zeros(n, dtype=np.int64)
        counts[rows] = np.diff(self.A.indptr)[rows]
        sub = self.A[rows]   # the held rows of a_n, kept in place in an (n, n) matrix
        A_held = sp.csr_matrix((sub.data, sub.indices, np.concatenate([[0], np.cumsum(counts)])),
                               shape=(n, n))
        touched = A_held + A_held.T - A_held @ sp.diags(held.astype(float))
        return keep @ H @ keep - touched + sp.diags(held.astype(float))


class FullSystemOperator:
    """A step matrix on the free dofs, not condensed: the counterpart of
    :class:`~adhesive_contact.scheme.condensed.CondensedOperator` whose
    step unknowns are the whole free vector, the contact unknowns at
    ``unknowns`` within it.

    Parameters
    ----------
    A : sparse (nfree, nfree), the step matrix on the free dofs
    contact : (nC,) int, positions of the contact unknowns within the free dofs
    factorise : callable (A, rows) -> LinearSolver, the AMG set-up
        (not called when ``solver`` is given)
    solver : an AMG solver of a nearby matrix to precondition with, optional
    """

    def __init__(self, A, contact, factorise=None, solver=None):
        t0 = time.perf_counter()
        self.unknowns = np.asarray(contact, dtype=np.int64)
        self.contact = self.unknowns
        A = sp.csr_matrix(A)
        self.solver = solver if solver is not None else factorise(A, np.arange(A.shape[0]))
        self.S = FullSystemMatrix(A, self.solver)
        self.factor_seconds = time.perf_counter() - t0
        self.schur_seconds = 0.0

    def reduce(self, b):
        """The load of the step problem: b itself."""
        return b

    def expand(self, z, b):
        """The free-dof solution: the step unknowns themselves."""
        return z
