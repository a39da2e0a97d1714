"""The step on all free dofs (adhesive_contact.scheme.full_system), the
AMG backend's path: its truncated CG, the hierarchy updated by a contact
Hessian, and its Newton systems against dense solves."""

import numpy as np
import pytest
import scipy.sparse as sp
from conftest import glued_contact, prony, scene_dict
from test_linear_solvers import elasticity

from adhesive_contact import build_problem, scene_from_dict, solve
from adhesive_contact.linear_solvers import AMGSolver, choose, rigid_body_modes
from adhesive_contact.resources import estimate
from adhesive_contact.scheme.full_system import FullSystemMatrix, truncated_cg


def amg(dim):
    A, K, mesh, free = elasticity(dim)
    return A, AMGSolver(A, B=rigid_body_modes(mesh.p, free), tol=1e-12)


def boundary_shift(A, rows, scale, rng):
    """A symmetric Δ on a few rows of A, inside A's pattern, of size
    ``scale`` times A's diagonal there: what a contact Hessian looks like."""
    D = sp.csr_matrix(A)[rows][:, rows].toarray()
    W = rng.uniform(0.5, 1.5, D.shape) * (D != 0)
    delta = np.zeros(A.shape)
    delta[np.ix_(rows, rows)] = scale * 0.5 * (W + W.T) * np.abs(D)
    return sp.csr_matrix(delta)


def test_truncated_cg_reaches_its_tolerance():
    """On an SPD system: the true residual is below max(rtol‖b‖, atol)
    (the first bound reached stops it), the error within κ of it."""
    A, solver = amg(2)
    b = np.random.default_rng(1).standard_normal(A.shape[0])
    exact = sp.linalg.spsolve(A.tocsc(), b)
    M = solver.aslinearoperator()
    for rtol, atol in ((0.5, 1e-9 * np.linalg.norm(b)), (1e-3, 0.0), (1e-8, 0.0),
                       (1e-12, 1e-9 * np.linalg.norm(b))):
        x, converged, iterations = truncated_cg(lambda v: A @ v, lambda r: M @ r, b,
                                                rtol, atol, 500)
        assert converged and iterations > 0
        assert np.linalg.norm(b - A @ x) <= max(rtol * np.linalg.norm(b), atol)
    # the last: relative residual 1e-9, the error within κ₂(A) (about 1e3) of it
    assert np.linalg.norm(x - exact) <= 1e-5 * np.linalg.norm(exact)


def test_truncated_cg_stops_at_negative_curvature_with_a_descent_direction():
    """K indefinite: CG stops, says so, and returns x with ½xᵀKx − bᵀx < 0
    (a direction along which the quadratic model decreases)."""
    rng = np.random.default_rng(2)
    Q, _ = np.linalg.qr(rng.standard_normal((40, 40)))
    K = Q @ np.diag(np.r_[np.linspace(1.0, 10.0, 39), -5.0]) @ Q.T
    b = rng.standard_normal(40)
    x, converged, iterations = truncated_cg(lambda v: K @ v, lambda r: r, b, 1e-12, 0.0, 200)
    assert not converged
    assert 0.5 * x @ K @ x - b @ x < 0 and b @ x > 0


@pytest.mark.parametrize("dim", [2, 3])
def test_updated_hierarchy_is_that_of_a_plus_delta(dim):
    """updated(Δ) returns A + Δ exactly (its second call undoes the first);
    updated(0) is the V-cycle of A; for a Δ of the size of A near a few
    rows, PCG on A + Δ needs fewer iterations with the updated V-cycle than
    with that of A (measured: 13 against 34–39 in 2D and 3D)."""
    A, solver = amg(dim)
    rng = np.random.default_rng(3)
    rows = np.arange(0, A.shape[0], 7)[:40]
    b = rng.standard_normal(A.shape[0])
    K0, V0 = solver.updated(sp.csr_matrix(A.shape))
    assert abs(K0 - A).max() == 0.0
    assert np.allclose(V0 @ b, solver.aslinearoperator() @ b, rtol=1e-13, atol=0.0)
    first = boundary_shift(A, rows, 3.0, rng)
    K1, _ = solver.updated(first)
    assert abs(K1 - (A + first)).max() == 0.0
    delta = boundary_shift(A, rows[::2], 5.0, rng)
    K, V = solver.updated(delta)
    assert abs(K - (A + delta)).max() <= 1e-15 * abs(A).max()
    plain = solver.aslinearoperator()
    counts = [truncated_cg(lambda v: K @ v, lambda r: M @ r, b, 1e-10, 0.0, 500)[2]
              for M in (V, plain)]
    assert counts[0] < 0.6 * counts[1]
    # outside the pattern: added the ordinary way
    far = sp.csr_matrix(([1.0, 1.0], ([0, A.shape[0] - 1], [A.shape[0] - 1, 0])),
                        shape=A.shape)
    K, _ = solver.updated(far)
    assert abs(K - (A + far)).max() == 0.0


@pytest.mark.parametrize("held", [False, True])
def test_newton_systems_match_a_dense_solve(held):
    """(a_n + H_φ)_FF d = r with the held coordinates out, against a dense
    solve, to the accuracy asked for (relative 1e-10)."""
    A, solver = amg(3)
    rng = np.random.default_rng(4)
    rows = np.arange(0, A.shape[0], 5)[:60]
    H = boundary_shift(A, rows, 2.0, rng)
    free = np.ones(A.shape[0], dtype=bool)
    if held:
        free[rows[::3]] = False
    rhs = rng.standard_normal(free.sum())
    d, converged = FullSystemMatrix(A, solver).newton_solve(H, rhs, free, accuracy=(1e-10, 0.0))
    dense = (A + H).toarray()[np.ix_(free, free)]
    assert converged
    assert np.linalg.norm(dense @ d - rhs) <= 1e-10 * np.linalg.norm(rhs)
    exact = np.linalg.solve(dense, rhs)
    assert np.linalg.norm(d - exact) <= 1e-7 * np.linalg.norm(exact)


def test_auto_takes_amg_where_a_newton_iteration_is_cheaper_with_it():
    """The choice of the cost model: the 3D full model of the benchmark at
    2.8e4 dofs with 2520 contact unknowns and at 1.1e5 with 6336 (where AMG
    was faster), not the frictionless one at 1.1e5 with 2112 nor the 2D
    full model at 1e5 with 1282 (where the dense route was), whatever the
    memory; a scene without contact unknowns gets a direct backend."""
    cases = (((27720, 2520), True), ((109395, 6336), True), ((109395, 2112), False),
             ((103842, 1282), False), ((109395, 0), False))
    for (n, unknowns), expected in cases:
        name, reason = choose(n, 45 * n, 3, memory_limit=1e15, contact_unknowns=unknowns)
        assert (name == "amg") == expected, (n, unknowns)
    name, reason = choose(27720, 45 * 27720, 3, contact_unknowns=2520)
    assert reason.startswith("the step solves for 2520 contact unknowns among 27720 dofs")


GLUED_BLOCK = {"dim": 3, "mesh": {"domain": "box", "size": [4.0, 0.5, 2.0], "cells": [36, 3, 18]},
         "memory": prony((200.0, 0.3, 0.5)), "contact": glued_contact(),
         "boundary": {"dirichlet": ["left"], "contact": ["bottom"]},
         "loads": {"traction": {"right": ["7*t", "14*t", "0"]}},
         "time": {"T": 0.2, "steps": 4}}


def test_auto_runs_a_3d_glued_block_on_all_free_dofs():
    """A thin 3D block with 2052 contact unknowns: auto picks AMG, says why, and
    its run is that of SuperLU to 1e-9; the estimate has no dense S."""
    scene = scene_from_dict(scene_dict(GLUED_BLOCK))
    problem = build_problem(scene)
    assert problem.contact_positions.size >= 2000
    run = solve(problem)
    assert run.success, run.message
    assert run.linear["method"] == "amg" and "contact unknowns among" in run.linear["reason"]
    assert run.linear["cg_iterations"] > 0
    direct = solve(build_problem(scene_from_dict(scene_dict({**GLUED_BLOCK,
                                                             "solver.linear": "superlu"}))))
    assert direct.success and "cg_iterations" not in direct.linear
    assert np.abs(run.u - direct.u).max() <= 1e-9 * np.abs(direct.u).max()
    guess = estimate(scene)
    assert guess.backend == "amg"
    dense = estimate(scene_from_dict(scene_dict({**GLUED_BLOCK, "solver.linear": "superlu"})))
    assert guess.memory_bytes < dense.memory_bytes


PRESSED = {"dim": 3, "mesh": {"domain": "box", "size": [4.0, 1.0, 2.0], "cells": [12, 4, 4]},
           "boundary": {"dirichlet": ["left"], "contact": ["bottom"]},
           "loads": {"body": ["0", "-40*t", "0"]}, "time": {"T": 1.0, "steps": 5},
           "contact": {"gap": 0.002, "normal": {"law": "compliance", "c": 1e4}}}


@pytest.mark.parametrize("method", ["penalty", "newton-plain"])
def test_other_step_methods_take_the_schur_complement_with_amg(method):
    """With AMG only "newton" iterates on all free dofs: "penalty" (whose
    penalty is scaled by the diagonal of S) and "newton-plain" (whose full
    steps, clipped at the wall, would leave the interior behind) get the
    Schur complement, and give the run of SuperLU on a block pressed onto a
    compliant layer and a wall to 1e-8 (their AMG solves reach linear_tol =
    1e-10)."""
    runs = {}
    for backend in ("amg", "superlu"):
        changes = {**PRESSED, "solver": {"method": method, "linear": backend}}
        runs[backend] = solve(build_problem(scene_from_dict(scene_dict(changes))))
        assert runs[backend].success, (backend, runs[backend].message)
    assert "cg_iterations" not in runs["amg"].linear
    scale = np.abs(runs["superlu"].u).max()
    assert np.abs(runs["amg"].u - runs["superlu"].u).max() <= 1e-8 * scale
