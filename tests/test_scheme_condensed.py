"""adhesive_contact.scheme.condensed: the condensation onto the contact
unknowns against dense linear algebra, and the dense Newton systems of the
step methods (mixed precision refined to a double Cholesky's accuracy)."""

import numpy as np
import pytest
import scipy.sparse as sp

from adhesive_contact.linear_solvers import (
    AMGSolver,
    PardisoSolver,
    SuperLUSolver,
    pardiso,
)
from adhesive_contact.scheme import condensed
from adhesive_contact.scheme.condensed import (
    CondensedOperator,
    DenseSchur,
    dense_solver,
    mixed_precision_solver,
)


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


# ----------------------------------------------------------------
# The dense Newton systems of the step methods (scheme.condensed.dense_solver):
# the single-precision factorisation refined by CG solves as accurately as a
# double-precision Cholesky, and the paths it falls back on are taken.


M = 300


def spd(cond, m=M, seed=0):
    """A symmetric matrix with eigenvalues spread log-evenly over [1, cond]."""
    rng = np.random.default_rng(seed)
    Q, _ = np.linalg.qr(rng.standard_normal((m, m)))
    H = (Q * np.logspace(0, np.log10(cond), m)) @ Q.T
    return 0.5 * (H + H.T), rng.standard_normal(m)


def single(H):
    """The arguments of mixed_precision_solver for the dense H."""
    return H.astype(np.float32), lambda v: H @ v, np.abs(np.diag(H)).max(), lambda: H


@pytest.mark.parametrize("cond", [1e2, 1e5])
def test_mixed_precision_solves_as_a_double_cholesky(cond):
    H, b = spd(cond)
    x = dense_solver(H, mixed_from=0)(b)
    ref = dense_solver(H, mixed_from=np.inf)(b)
    # backward error of a direct solve: ‖b − Hx‖ ≲ 10 m ε ‖H‖ ‖x‖
    assert np.linalg.norm(b - H @ x) <= 1e-13 * cond * np.linalg.norm(x) * 10
    # forward error within κ times that
    assert np.linalg.norm(x - ref) <= 1e-12 * cond * np.linalg.norm(ref)


def test_mixed_precision_refuses_what_single_precision_cannot_factorise():
    H, b = spd(1e2)
    H[0, 0] = -1.0   # indefinite
    assert mixed_precision_solver(*single(H)) is None
    # dense_solver then takes the modified factorisation: |eigenvalues|
    vals, vecs = np.linalg.eigh(H)
    expected = vecs @ ((vecs.T @ b) / np.abs(vals))
    x = dense_solver(H, mixed_from=0)(b)
    assert np.linalg.norm(x - expected) <= 1e-10 * np.linalg.norm(expected)


def test_refinement_that_stops_early_factorises_in_double_precision():
    H, b = spd(1e5)
    # one CG product cannot reach the backward error at κ = 1e5 from the
    # single-precision solve (error about κ ε₃₂ ≈ 6e-3)
    x = mixed_precision_solver(*single(H), maxiter=1)(b)
    ref = dense_solver(H, mixed_from=np.inf)(b)
    assert np.linalg.norm(x - ref) <= 1e-10 * np.linalg.norm(ref)


def test_refinement_stops_at_the_accuracy_asked_for():
    """With accuracy = (rtol, atol) the refinement stops once
    ‖b − Hx‖ ≤ rtol ‖b‖ (an inexact Newton step), in fewer products than
    refining to round-off; without it, to round-off."""
    H, b = spd(1e5)
    products = []

    def counted(v):
        products.append(1)
        return H @ v

    H32, _, largest, exact = single(H)
    loose = mixed_precision_solver(H32, counted, largest, exact)
    x = loose(b, (1e-2, 0.0))
    rough = len(products)
    assert np.linalg.norm(b - H @ x) <= 1e-2 * np.linalg.norm(b)
    products.clear()
    y = loose(b)
    assert len(products) > rough
    assert np.linalg.norm(b - H @ y) <= 1e-13 * 1e5 * np.linalg.norm(y) * 10


@pytest.mark.parametrize("fraction", [1.0, 0.6])
def test_newton_systems_in_single_precision_equal_the_double_ones(monkeypatch, fraction):
    """DenseSchur.newton_solve from MIXED_FROM free coordinates on: S_FF
    taken in single precision, H_φ's entries added, products with S itself;
    the same d as the double-precision Cholesky of (S + H_φ)_FF."""
    S, b = spd(1e4, m=M)
    rng = np.random.default_rng(3)
    H_phi = sp.diags(rng.uniform(0.0, 50.0, M)) + sp.diags(rng.uniform(-1, 1, M - 1), 1)
    H_phi = sp.csr_matrix(H_phi + H_phi.T)
    free = rng.random(M) < fraction
    rhs = b[free]
    H = (S + H_phi.toarray())[np.ix_(free, free)]
    expected = np.linalg.solve(H, rhs)
    monkeypatch.setattr(condensed, "MIXED_FROM", 10)
    d, converged = DenseSchur(S).newton_solve(H_phi, rhs, free)
    assert converged
    assert np.linalg.norm(d - expected) <= 1e-10 * np.linalg.norm(expected)
    monkeypatch.setattr(condensed, "MIXED_FROM", np.inf)
    double, _ = DenseSchur(S).newton_solve(H_phi, rhs, free)
    assert np.linalg.norm(d - double) <= 1e-10 * np.linalg.norm(expected)
