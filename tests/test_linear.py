"""The condensation onto the contact unknowns against dense linear algebra."""

import numpy as np
import pytest
import scipy.sparse as sp

from adhesive_contact.scheme.condensed import CondensedOperator


def stiffness_like(n, seed):
    """A sparse SPD matrix with the pattern of a 2D grid Laplacian plus noise."""
    m = int(np.sqrt(n))
    lap1 = sp.diags([-1, 2.5, -1], [-1, 0, 1], shape=(m, m))
    A = sp.kronsum(lap1, lap1).tocsr()
    rng = np.random.default_rng(seed)
    D = sp.diags(rng.uniform(0.1, 1.0, A.shape[0]))
    return (A + D).tocsr()


@pytest.mark.parametrize("seed", [0, 1])
def test_schur_complement_and_solves_match_dense_algebra(seed):
    A = stiffness_like(400, seed)
    rng = np.random.default_rng(seed)
    contact = np.sort(rng.choice(A.shape[0], 23, replace=False))
    op = CondensedOperator(A, contact)
    dense = A.toarray()
    interior = np.setdiff1d(np.arange(A.shape[0]), contact)
    AII = dense[np.ix_(interior, interior)]
    S = dense[np.ix_(contact, contact)] - dense[np.ix_(contact, interior)] @ np.linalg.solve(
        AII, dense[np.ix_(interior, contact)])
    assert np.allclose(op.S.matrix, S, rtol=0, atol=1e-12 * np.abs(S).max())
    # the factorisation path was taken (no reordering of the C block here)
    assert op._schur_by_factorisation(A) is not None
    # reduce/expand solve the full system when z solves the reduced one
    b = rng.standard_normal(A.shape[0])
    z = np.linalg.solve(op.S.matrix, op.reduce(b))
    assert np.allclose(op.expand(z, b), np.linalg.solve(dense, b), rtol=0, atol=1e-10)
