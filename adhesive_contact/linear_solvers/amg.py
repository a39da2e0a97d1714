"""Smoothed aggregation AMG (pyamg) as the preconditioner of CG.

For elasticity the near-nullspace handed to the aggregation is the space of
rigid body motions r(x) = a + W x (W skew): two translations and one
rotation in 2D, three and three in 3D. With it the tentative prolongator
reproduces them exactly on every level, and CG needs a number of
iterations that grows slowly with the mesh: for a relative residual of
1e-10, 18, 29 and 36 for 1e4, 1e5 and 2.6e5 dofs in 2D, 21–25 for 9e3–9e4
dofs in 3D (unit square and cube clamped on one side).
"""

import numpy as np
import scipy.sparse as sp

from .base import LinearSolver, LinearSolverError

#: the smoother on every level, before and after the coarse correction
#: (pyamg's default for smoothed aggregation, named so that an updated
#: hierarchy, :meth:`AMGSolver.updated`, gets the same)
SMOOTHER = ("block_gauss_seidel", {"sweep": "symmetric"})


def rigid_body_modes(points, dofs=None):
    """The rigid body motions as columns, on the free dofs.

    Parameters
    ----------
    points : (d, npoints) array
        The mesh nodes, d = 2 or 3.
    dofs : (nfree,) int array, optional
        Indices into the interleaved P1 vector numbering, dof = d·node + c
        (that of :class:`~adhesive_contact.fem.assembly.Assembly`); all dofs if
        omitted.

    Returns
    -------
    B : (nfree, 3) in 2D, (nfree, 6) in 3D
        Translations e_c, then rotations about the centroid x̄ of the
        nodes: (−y, x) in 2D; e_a × (x − x̄) for a = x, y, z in 3D.
    """
    points = np.asarray(points, dtype=float)
    d, npoints = points.shape
    if d not in (2, 3):
        raise ValueError(f"points must have shape (2, npoints) or (3, npoints), got {points.shape}")
    x = points - points.mean(axis=1, keepdims=True)
    zero = np.zeros(npoints)
    if d == 2:
        rotations = [(-x[1], x[0])]
    else:
        rotations = [(zero, -x[2], x[1]), (x[2], zero, -x[0]), (-x[1], x[0], zero)]
    translations = [tuple(np.full(npoints, float(a == c)) for c in range(d)) for a in range(d)]
    modes = translations + rotations
    B = np.stack([np.stack(mode, axis=1).ravel() for mode in modes], axis=1)
    return B if dofs is None else B[np.asarray(dofs)]


class AMGSolver(LinearSolver):
    """CG preconditioned by one V-cycle of smoothed aggregation AMG.

    ``solve`` iterates until the true residual (per column of a block)

        ‖b − A x‖₂ ≤ tol ‖b‖₂ + 10 ε ‖A‖₁ ‖x‖₂,

    the second term the round-off of forming b − A x itself, below which no
    solver gets (a slender cantilever at 1e4 dofs: a direct solve leaves
    2.5e-10 ‖b‖, the bound 7e-10 ‖b‖). CG is restarted on the correction,
    A δ = b − A x, while the residual still falls by half each time; it
    raises :class:`LinearSolverError` if ``maxiter`` iterations do not get
    there.

    Parameters
    ----------
    A : sparse SPD (n, n)
    B : (n, k) array, optional
        Near-nullspace candidates (:func:`rigid_body_modes`); pyamg's
        constant vector if omitted.
    tol : float
        Relative residual to reach.
    maxiter : int
        CG iterations allowed per right-hand side.
    **options
        Passed to :func:`pyamg.smoothed_aggregation_solver`.

    Attributes
    ----------
    ml : pyamg.multilevel.MultilevelSolver or None
        The hierarchy (None for n = 0).
    info : dict
        ``levels``, ``operator_complexity``, ``grid_complexity``,
        ``coarse_size``, ``near_nullspace``, ``tol``, ``maxiter`` and, after
        a solve, ``iterations`` and ``relative_residual`` (the largest over
        the columns of the last block).
    """

    name = "amg"
    exact = False

    def __init__(self, A, B=None, tol=1e-10, maxiter=200, **options):
        if not tol > 0:
            raise ValueError(f"tol must be positive, got {tol}")
        self.B, self.tol, self.maxiter = B, float(tol), int(maxiter)
        self.options = {"max_coarse": 100, "presmoother": SMOOTHER, "postsmoother": SMOOTHER,
                        **options}
        self.ml = None
        self._sums = self._prolongators = None   # for updated(), made on first use
        super().__init__(A)

    def _setup(self, A):
        import pyamg

        self.A = A
        self.norm_A = float(abs(A).sum(axis=0).max()) if A.nnz else 0.0   # ≥ ‖A‖₂
        self.ml = pyamg.smoothed_aggregation_solver(A, B=self.B, **self.options)
        coarse = self.ml.levels[-1].A
        self.ml.coarse_solver(coarse, np.zeros(coarse.shape[0]))  # its set-up is lazy
        self.info = {
            "levels": len(self.ml.levels),
            "operator_complexity": float(self.ml.operator_complexity()),
            "grid_complexity": float(self.ml.grid_complexity()),
            "coarse_size": int(coarse.shape[0]),
            "near_nullspace": 1 if self.B is None else int(np.shape(self.B)[1]),
            "tol": self.tol,
            "maxiter": self.maxiter,
        }

    def _solve_one(self, b):
        """CG from zero, then on the correction while the true residual (not
        CG's recurrence) is above the bound of the class doc and still
        halves: (x, iterations, relative residual, converged). (pyamg's CG
        restarted from an x0 whose residual is near round-off diverges.)"""
        norm_b = np.linalg.norm(b)
        x = np.zeros_like(b)
        r, norm_r = b, norm_b
        iterations = 0
        def bound(x):   # the class doc's: tol ‖b‖ + the round-off of b − A x
            return self.tol * norm_b + 10 * np.finfo(float).eps * self.norm_A * np.linalg.norm(x)

        while iterations < self.maxiter:
            if norm_r <= bound(x):
                return x, iterations, norm_r / norm_b if norm_b else 0.0, True
            history = []
            x = x + self.ml.solve(r, tol=min(bound(x) / norm_r, 0.5),
                                  maxiter=self.maxiter - iterations, accel="cg",
                                  residuals=history)
            iterations += max(len(history) - 1, 1)
            r = b - self.A @ x
            norm_r, last = np.linalg.norm(r), norm_r
            if norm_r > 0.5 * last:   # stagnation: round-off, or CG gone astray
                break
        return x, iterations, norm_r / norm_b, norm_r <= bound(x)

    def _solve(self, B):
        X = np.empty_like(B)
        iterations, residual = 0, 0.0
        for j in range(B.shape[1]):
            X[:, j], k, r, converged = self._solve_one(np.ascontiguousarray(B[:, j]))
            iterations, residual = max(iterations, k), max(residual, r)
            if not converged:
                raise LinearSolverError(
                    f"AMG-preconditioned CG did not converge: relative residual {r:.2e} after "
                    f"{k} iterations (tol {self.tol:.1e}, maxiter {self.maxiter}); allow more "
                    f"iterations or use a direct method")
        self.info.update(iterations=iterations, relative_residual=float(residual))
        return X

    def aslinearoperator(self):
        """One V-cycle, an SPD approximation of A⁻¹ (not the CG solve, which
        is not linear in b), as the preconditioner of an outer CG."""
        if self.ml is None:
            return super().aslinearoperator()
        return self.ml.aspreconditioner(cycle="V")

    def updated(self, delta):
        """One V-cycle for A + Δ on the hierarchy of A: its aggregates and
        prolongators P_l kept, the level matrices

            A_l + Δ_l,   Δ_0 = Δ,   Δ_{l+1} = P_lᵀ Δ_l P_l

        (the Galerkin products of A + Δ), the smoothers set up anew. For a Δ
        on a few rows, as a contact term's Hessian is, this costs O(nnz Δ)
        and the smoothers' set-up on the coarse levels: P_lᵀ Δ_l P_l takes
        only the rows of P_l where Δ_l lies, and Δ_l is added to A_l in
        place (in A_l's pattern, widened once for entries outside it; each
        call undoes the previous one's). For Δ = 0 it is :meth:`aslinearoperator`'s V-cycle.

        Returns ``(matrix, preconditioner)``: A + Δ (CSR) and the V-cycle,
        both valid until the next call."""
        from pyamg.multilevel import MultilevelSolver
        from pyamg.relaxation.smoothing import change_smoothers

        if self._sums is None:   # set up on first use
            self._sums = [_PatternSum(level.A) for level in self.ml.levels]
            self._prolongators = [sp.csr_matrix(level.P) for level in self.ml.levels[:-1]]
        delta = sp.csr_matrix(delta)
        levels = []
        for l, level in enumerate(self.ml.levels):
            new = MultilevelSolver.Level()
            new.A = self._sums[l](delta)
            if l + 1 < len(self.ml.levels):
                new.P, new.R = level.P, level.R
                rows = np.unique(delta.tocoo().row)
                P = self._prolongators[l][rows]
                delta = sp.csr_matrix(P.T @ delta[rows][:, rows] @ P)
            levels.append(new)
        ml = MultilevelSolver(levels)
        change_smoothers(ml, self.options["presmoother"], self.options["postsmoother"])
        return sp.csr_matrix(levels[0].A), ml.aspreconditioner(cycle="V")


class _PatternSum:
    """M + Δ for a fixed sparse M (CSR or BSR), in O(nnz Δ): M's values are
    copied once, and each call undoes the previous call's additions before
    making its own (so the matrix it returns is valid until the next call).
    Entries of Δ outside M's pattern (a coupling that is zero in M, such as
    one a rotation into nodal frames cancelled) join the pattern, stored as
    zeros of M, at one O(nnz M) cost the first time they come."""

    def __init__(self, M):
        M.sort_indices()   # in place: the same matrix
        self.M = M
        self.block = M.blocksize if M.format == "bsr" else (1, 1)
        rows, cols = M.shape[0] // self.block[0], M.shape[1] // self.block[1]
        self.columns = cols
        row = np.repeat(np.arange(rows, dtype=np.int64), np.diff(M.indptr))
        self.keys = row * cols + M.indices   # increasing: M's entries in order
        self.values = M.data.copy()
        self.changed = None

    def _positions(self, delta):
        R, C = self.block
        key = (delta.row // R).astype(np.int64) * self.columns + delta.col // C
        pos = np.minimum(np.searchsorted(self.keys, key), max(self.keys.size - 1, 0))
        return pos, self.keys[pos] == key

    def _widen(self, rows, cols):
        """M's pattern with the entries (rows, cols) added as stored zeros."""
        M = self.M.tocoo()
        wide = sp.coo_matrix((np.r_[M.data, np.zeros(rows.size)],
                              (np.r_[M.row, rows], np.r_[M.col, cols])),
                             shape=M.shape).tocsr()   # sums duplicates, keeps the zeros
        self.__init__(wide.tobsr(blocksize=self.block) if self.M.format == "bsr" else wide)

    def __call__(self, delta):
        delta = delta.tocoo()
        delta.sum_duplicates()
        pos, inside = self._positions(delta)
        if not inside.all():
            self._widen(delta.row[~inside], delta.col[~inside])
            pos, inside = self._positions(delta)
        M = self.M
        if self.changed is not None:
            self.values[self.changed] = M.data[self.changed]
        R, C = self.block
        self.changed = (pos,) if M.format != "bsr" else (pos, delta.row % R, delta.col % C)
        self.values[self.changed] += delta.data
        if M.format == "bsr":
            return sp.bsr_matrix((self.values, M.indices, M.indptr), shape=M.shape,
                                 blocksize=self.block)
        return sp.csr_matrix((self.values, M.indices, M.indptr), shape=M.shape)
