"""The dense Newton systems of the step methods (scheme.condensed.dense_solver):
the single-precision factorisation refined by CG solves as accurately as a
double-precision Cholesky, and the paths it falls back on are taken."""

import numpy as np
import pytest
import scipy.sparse as sp

from adhesive_contact.scheme import condensed
from adhesive_contact.scheme.condensed import DenseSchur, dense_solver, mixed_precision_solver

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
