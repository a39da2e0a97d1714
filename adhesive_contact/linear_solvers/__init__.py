"""Linear solvers for the SPD step matrices, behind one interface.

    solver = make_linear_solver(A, "auto", dim=2, points=mesh.p, dofs=free)
    x = solver.solve(b)

Backends (:mod:`.base` states the interface):

- ``"pardiso"``: MKL PARDISO sparse Cholesky (:mod:`.pardiso`), where
  pypardiso and MKL are installed;
- ``"superlu"``: SciPy's SuperLU (:mod:`.superlu`), always there;
- ``"amg"``: CG preconditioned by smoothed aggregation AMG with the rigid
  body modes (:mod:`.amg`), for matrices whose factors would not fit.

``"auto"`` (:func:`choose`) takes PARDISO where it is available, else
SuperLU, unless the estimated memory of that factorisation
(:func:`factor_bytes`) exceeds the memory limit: then AMG.
"""

import os

import numpy as np

from . import pardiso
from .amg import AMGSolver, rigid_body_modes
from .base import LinearSolver, LinearSolverError
from .pardiso import PardisoSolver
from .superlu import SuperLUSolver

METHODS = ("auto", "pardiso", "superlu", "amg")

# nnz(factors)/nnz(A) = c·log2(n) in 2D, c·n^p in 3D (nested dissection
# gives n log n and n^(4/3) factor entries in 2D and 3D; SuperLU's minimum
# degree ordering about n^(5/3) in 3D). Fitted to P1 elasticity step
# matrices of the unit square and cube clamped on one side, 1.9e3–2.6e5
# dofs in 2D and 1.9e3–8.6e4 in 3D, and rounded up:
# PARDISO c = 0.31–0.42 (2D), 0.38–0.51 (3D, rising slowly with n);
# SuperLU (L and U) c = 0.55–1.01 (2D), 0.079–0.082 (3D, p = 2/3).
# studies/bench/linear_backends.py measures factors and memory at 1e4–2.6e5
# dofs: the estimates were 0.6–1.4× the measured peak memory of the solver
# (PARDISO in 2D takes 18–25 bytes per entry of L with its work arrays).
FILL = {
    ("pardiso", 2): (0.45, None),
    ("pardiso", 3): (0.6, 1 / 3),
    ("superlu", 2): (1.1, None),
    ("superlu", 3): (0.085, 2 / 3),
}
# an 8-byte value and a 4-byte index per factor entry (PARDISO's own peak
# was 9.3–14.6 bytes per entry of L from 1e4 dofs on)
BYTES_PER_ENTRY = 12
MEMORY_FRACTION = 0.5   # of physical memory, the default limit
# below these sizes SuperLU sets up faster than PARDISO, whose first
# factorisation in a process loads MKL (about 1 s here): at 1e4 dofs 0.74
# against 1.66 s in 2D, 0.05 against 1.06 s at 1e3 in 3D (studies/bench/ladder.py)
SMALL = {2: 30_000, 3: 5_000}
# The seconds of one Newton iteration of the step method "newton" on m
# contact unknowns: with a direct backend a dense Cholesky of S + ∂²Φ and
# the O(m²) work around it, DENSE_NEWTON[0] m³ + DENSE_NEWTON[1] m²; with AMG
# on all n free dofs, AMG_NEWTON n (a few CG iterations, the hierarchy's
# update). Fitted to the 3D full model of studies/bench/ladder.py: dense
# 0.4 s at m = 6336, 0.09 s at 2520; AMG 0.2 s at 1.1e5 dofs, 0.055 s at
# 2.8e4. So AMG is 1.5 times faster at 2520 unknowns and 2.8e4 dofs, 2.3
# times at 6336 and 1.1e5, and the dense route ahead for a frictionless 3D
# step (2112 unknowns at 1.1e5 dofs) and in 2D (7 times at 1282 unknowns and
# 1e5 dofs, measured).
DENSE_NEWTON = (1.6e-12, 1e-8)
AMG_NEWTON = 2e-6


def factor_bytes(n, nnz, dim, method):
    """Estimated memory of the factors of an n × n P1 elasticity matrix
    with nnz entries: BYTES_PER_ENTRY · nnz · c·log2(n) (2D) or c·n^p (3D)."""
    c, p = FILL[(method, dim)]
    growth = np.log2(max(n, 2)) if p is None else max(n, 1) ** p
    return float(BYTES_PER_ENTRY * nnz * c * growth)


def default_memory_limit():
    """MEMORY_FRACTION of the physical memory (4 GiB if it cannot be read)."""
    try:
        physical = os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES")
    except (AttributeError, ValueError, OSError):
        return 4 * 2**30
    return MEMORY_FRACTION * physical


def _gb(nbytes):
    return f"{nbytes / 1e9:.3g} GB"


def choose(n, nnz, dim, memory_limit=None, contact_unknowns=0):
    """The backend for ``method = "auto"`` and one sentence saying why.

    AMG is taken when the factors would not fit in ``memory_limit``, and
    where a Newton iteration costs less with it (:data:`DENSE_NEWTON`,
    :data:`AMG_NEWTON`): a direct backend leaves the step method a dense
    Schur complement on the contact unknowns, AMG the sparse Newton systems
    of all free dofs (:mod:`adhesive_contact.scheme.full_system`).

    Parameters
    ----------
    n, nnz : int
        Size and number of stored entries of the matrix.
    dim : 2 or 3
    memory_limit : float, optional
        Bytes the factors may take (default: :func:`default_memory_limit`).

    contact_unknowns : int
        The unknowns on Γ_C a step solves for (0 where the step method
        needs a Schur complement whatever the backend: all but "newton").

    Returns
    -------
    (name, reason) : (str, str)
    """
    if dim not in (2, 3):
        raise ValueError(f"dim must be 2 or 3, got {dim!r}")
    m = contact_unknowns
    dense, sparse = DENSE_NEWTON[0] * m**3 + DENSE_NEWTON[1] * m**2, AMG_NEWTON * n
    if m and sparse < dense:
        return "amg", (f"the step solves for {m} contact unknowns among {n} dofs: a Newton "
                       f"iteration on all free dofs with AMG (about {sparse:.2g} s) is faster "
                       f"than a dense Schur complement on them (about {dense:.2g} s).")
    limit = default_memory_limit() if memory_limit is None else float(memory_limit)
    if n < SMALL[dim]:   # decided before asking for MKL, whose loading is the cost
        direct, label, why = "superlu", "SuperLU", (
            f"the matrix is small ({n} < {SMALL[dim]} dofs in {dim}D: SuperLU sets up faster "
            "than PARDISO, whose first use loads MKL)")
    elif pardiso.available():
        direct, label, why = "pardiso", "PARDISO", "MKL PARDISO is available"
    else:
        direct, label, why = "superlu", "SuperLU", "PARDISO is not available here (no pypardiso or MKL)"
    need = factor_bytes(n, nnz, dim, direct)
    if need > limit:
        return "amg", (f"{label}'s factors of the {n}-dof matrix would take about {_gb(need)}, "
                       f"more than the {_gb(limit)} limit, so AMG-preconditioned CG is used.")
    return direct, (f"{why} and {label}'s factors of the {n}-dof matrix take about {_gb(need)}, "
                    f"within the {_gb(limit)} limit.")


def make_linear_solver(A, method="auto", *, dim, points=None, dofs=None, tol=1e-10,
                       memory_limit=None):
    """A solver of A x = b by the named backend, or the one :func:`choose` picks.

    Parameters
    ----------
    A : sparse SPD (n, n)
    method : one of METHODS
    dim : 2 or 3
    points, dofs : the mesh nodes (dim, npoints) and the free dofs of A in
        the interleaved numbering dof = dim·node + c: needed for AMG (its
        near-nullspace, :func:`rigid_body_modes`).
    tol : float
        Relative residual of the AMG-preconditioned CG.
    memory_limit : float, optional
        Bytes the factors may take, for ``"auto"``.

    Returns
    -------
    LinearSolver, with ``reason`` saying why it was chosen.
    """
    if method not in METHODS:
        raise ValueError(f"method {method!r}: allowed are {', '.join(METHODS)}")
    if method == "auto":
        method, reason = choose(A.shape[0], A.nnz, dim, memory_limit)
    else:
        reason = f"method {method!r} was asked for."
    if method == "pardiso" and not pardiso.available():
        raise ValueError("method 'pardiso': pypardiso or MKL is not installed here; "
                         "allowed are auto, superlu, amg")
    if method == "amg":
        if points is None or dofs is None:
            raise ValueError("method 'amg' needs the mesh points and the free dofs "
                             "(its near-nullspace is the rigid body modes)")
        if np.shape(points)[0] != dim:
            raise ValueError(f"points must have shape ({dim}, npoints), got {np.shape(points)}")
        solver = AMGSolver(A, B=rigid_body_modes(points, dofs), tol=tol)
    else:
        solver = {"pardiso": PardisoSolver, "superlu": SuperLUSolver}[method](A)
    solver.reason = reason
    return solver


__all__ = ["METHODS", "AMGSolver", "LinearSolver", "LinearSolverError", "PardisoSolver",
           "SuperLUSolver", "choose", "default_memory_limit", "factor_bytes",
           "make_linear_solver", "rigid_body_modes"]
