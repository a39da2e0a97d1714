"""The condensation onto the contact unknowns against dense linear algebra."""

import numpy as np
import pytest
import scipy.sparse as sp

from adhesive_contact.linear_solvers import (
    AMGSolver,
    PardisoSolver,
    SuperLUSolver,
    pardiso,
)
from adhesive_contact.scheme.condensed import CondensedOperator


def stiffness_like(n, seed):
    """A sparse SPD matrix with the pattern of a 2D grid Laplacian plus noise."""
    m = int(np.sqrt(n))
    lap1 = sp.diags([-1, 2.5, -1], [-1, 0, 1], shape=(m, m))
    A = sp.kronsum(lap1, lap1).tocsr()
    rng = np.random.default_rng(seed)
    D = sp.diags(rng.uniform(0.1, 1.0, A.shape[0]))
    return (A + D).tocsr()


#: backend -> (factorise, whether S comes from a factorisation, tolerance):
#: direct backends to round-off, AMG-CG (relative residual 1e-10 per
#: column) to 1e-8 of |S| for this well-conditioned matrix (κ ≈ 30)
BACKENDS = {
    "superlu": (lambda A, rows: SuperLUSolver(A), True, 1e-12),
    "amg": (lambda A, rows: AMGSolver(A, tol=1e-10), False, 1e-8),
}
if pardiso.available():
    BACKENDS["pardiso"] = (lambda A, rows: PardisoSolver(A), True, 1e-12)


@pytest.mark.parametrize("backend", sorted(BACKENDS))
@pytest.mark.parametrize("seed", [0, 1])
def test_schur_complement_and_solves_match_dense_algebra(seed, backend):
    factorise, factorised, tol = BACKENDS[backend]
    A = stiffness_like(400, seed)
    rng = np.random.default_rng(seed)
    contact = np.sort(rng.choice(A.shape[0], 23, replace=False))
    op = CondensedOperator(A, contact, factorise=factorise)
    dense = A.toarray()
    interior = np.setdiff1d(np.arange(A.shape[0]), contact)
    AII = dense[np.ix_(interior, interior)]
    S = dense[np.ix_(contact, contact)] - dense[np.ix_(contact, interior)] @ np.linalg.solve(
        AII, dense[np.ix_(interior, contact)])
    assert np.allclose(op.S.matrix, S, rtol=0, atol=tol * np.abs(S).max())
    # which path: read off a factorisation (no reordering of the C block
    # here), or formed by solves
    assert (op.solver.schur(A, op.interior, op.contact) is not None) == factorised
    # reduce/expand solve the full system when z solves the reduced one
    b = rng.standard_normal(A.shape[0])
    z = np.linalg.solve(op.S.matrix, op.reduce(b))
    assert np.allclose(op.expand(z, b), np.linalg.solve(dense, b), rtol=0, atol=100 * tol)
