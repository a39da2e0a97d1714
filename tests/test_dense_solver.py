"""The dense Newton systems of the step methods (scheme.condensed.dense_solver):
the single-precision factorisation refined by CG solves as accurately as a
double-precision Cholesky, and the paths it falls back on are taken."""

import numpy as np
import pytest

from adhesive_contact.scheme.condensed import dense_solver, mixed_precision_solver

M = 300


def spd(cond, m=M, seed=0):
    """A symmetric matrix with eigenvalues spread log-evenly over [1, cond]."""
    rng = np.random.default_rng(seed)
    Q, _ = np.linalg.qr(rng.standard_normal((m, m)))
    H = (Q * np.logspace(0, np.log10(cond), m)) @ Q.T
    return 0.5 * (H + H.T), rng.standard_normal(m)


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
    assert mixed_precision_solver(H) is None
    # dense_solver then takes the modified factorisation: |eigenvalues|
    vals, vecs = np.linalg.eigh(H)
    expected = vecs @ ((vecs.T @ b) / np.abs(vals))
    x = dense_solver(H, mixed_from=0)(b)
    assert np.linalg.norm(x - expected) <= 1e-10 * np.linalg.norm(expected)


def test_refinement_that_stops_early_factorises_in_double_precision():
    H, b = spd(1e5)
    # one CG product cannot reach the backward error at κ = 1e5 from the
    # single-precision solve (error about κ ε₃₂ ≈ 6e-3)
    x = mixed_precision_solver(H, maxiter=1)(b)
    ref = dense_solver(H, mixed_from=np.inf)(b)
    assert np.linalg.norm(x - ref) <= 1e-10 * np.linalg.norm(ref)
