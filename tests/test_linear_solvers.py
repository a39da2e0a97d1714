"""The linear-solver backends against dense solves, as CG preconditioners,
the automatic choice, and the rigid body modes of AMG.

Matrices: P1 elasticity stiffness λ K_λ + μ K_μ (E = 1000, ν = 0.3) of a
2D rectangle and a 3D box, clamped on the side x = 0, assembled by
:class:`adhesive_contact.fem.assembly.Assembly`.
"""

import gc
import platform
import sys

import numpy as np
import pytest
import scipy.sparse as sp
from scipy.sparse.linalg import cg, spsolve
from skfem import MeshTet, MeshTri

from adhesive_contact.fem.assembly import Assembly, stiffness_basis
from adhesive_contact.linear_solvers import (
    METHODS,
    AMGSolver,
    LinearSolverError,
    PardisoSolver,
    SuperLUSolver,
    choose,
    factor_bytes,
    make_linear_solver,
    pardiso,
    rigid_body_modes,
)
from adhesive_contact.fem.meshes import side_tests

LAM, MU = 576.9230769230769, 384.6153846153846   # E = 1000, ν = 0.3
EPS = np.finfo(float).eps
# direct backends here; PARDISO is installed wherever MKL wheels exist
# (test_pardiso_is_available_where_mkl_wheels_exist holds that)
DIRECT = ["superlu"] + (["pardiso"] if pardiso.available() else [])


def elasticity(dim):
    """(A, K, mesh, free): the clamped step matrix on the free dofs, the
    unconstrained stiffness, the mesh and the free dofs (about 300 dofs)."""
    if dim == 2:
        size, cells, Mesh = (2.0, 1.0), (16, 8), MeshTri
    else:
        size, cells, Mesh = (1.0, 1.0, 1.0), (4, 4, 4), MeshTet
    axes = [np.linspace(0.0, s, c + 1) for s, c in zip(size, cells)]
    mesh = Mesh.init_tensor(*axes).with_boundaries(side_tests(size))
    assembly = Assembly(mesh)
    K = assembly.stiffness(LAM, MU)
    clamped = stiffness_basis(mesh).get_dofs("left").flatten()
    free = np.setdiff1d(np.arange(assembly.ndofs), clamped)
    return K[free][:, free].tocsr(), K, mesh, free


@pytest.fixture(scope="module", params=[2, 3])
def system(request):
    """A, its dense solution of a block of 5 right-hand sides and κ₂(A)."""
    A, K, mesh, free = elasticity(request.param)
    dense = A.toarray()
    b = np.random.default_rng(request.param).standard_normal((A.shape[0], 5))
    eigs = np.linalg.eigvalsh(dense)
    return {"dim": request.param, "A": A, "K": K, "mesh": mesh, "free": free, "b": b,
            "x": np.linalg.solve(dense, b), "kappa": eigs[-1] / eigs[0]}


def relative(x, y):
    return np.linalg.norm(x - y) / np.linalg.norm(y)


@pytest.mark.parametrize("method", DIRECT)
def test_direct_backends_match_a_dense_solve(system, method):
    """‖x − x*‖/‖x*‖ ≤ κ(A) η for a backward error η; Cholesky of an SPD
    matrix (and LU with diagonal pivots on it) has no growth, η a few ε:
    with κ ≤ 1.6e4 here, 10 ε κ < 4e-11, under 1e-10."""
    assert 10 * EPS * system["kappa"] < 1e-10
    solver = make_linear_solver(system["A"], method, dim=system["dim"])
    assert solver.name == method and solver.exact and solver.setup_seconds > 0
    X = solver.solve(system["b"])
    assert X.shape == system["b"].shape
    assert relative(X, system["x"]) < 1e-10
    x = solver.solve(system["b"][:, 2])
    assert x.shape == (system["A"].shape[0],)
    assert relative(x, system["x"][:, 2]) < 1e-10
    assert solver.info["factor_nnz"] >= system["A"].nnz // 2


def test_direct_backends_agree(system):
    X = [make_linear_solver(system["A"], m, dim=system["dim"]).solve(system["b"]) for m in DIRECT]
    for other in X[1:]:
        assert relative(other, X[0]) < 1e-10


def test_amg_reaches_its_tolerance_and_the_error_bound(system):
    """CG stops at ‖b − A x‖ ≤ tol ‖b‖; then ‖x − x*‖/‖x*‖ ≤ κ(A) tol
    (‖e‖ = ‖A⁻¹ r‖ ≤ ‖r‖/λ_min, ‖x*‖ ≥ ‖b‖/λ_max): exact, κ computed."""
    A, b, tol = system["A"], system["b"], 1e-10
    solver = make_linear_solver(A, "amg", dim=system["dim"], points=system["mesh"].p,
                                dofs=system["free"], tol=tol)
    assert solver.name == "amg" and not solver.exact
    assert solver.info["near_nullspace"] == (3 if system["dim"] == 2 else 6)
    assert solver.info["levels"] >= 2   # a hierarchy, not only the coarse solve
    X = solver.solve(b)
    for j in range(b.shape[1]):
        assert np.linalg.norm(b[:, j] - A @ X[:, j]) <= tol * np.linalg.norm(b[:, j])
        assert relative(X[:, j], system["x"][:, j]) <= system["kappa"] * tol
    assert 0 < solver.info["iterations"] < solver.maxiter
    assert solver.info["relative_residual"] <= tol
    # a single vector: same solution, its own iteration count
    x = solver.solve(b[:, 0])
    assert relative(x, X[:, 0]) <= 2 * system["kappa"] * tol


def test_amg_reports_non_convergence(system):
    solver = AMGSolver(system["A"], B=rigid_body_modes(system["mesh"].p, system["free"]),
                       tol=1e-10, maxiter=1)
    with pytest.raises(LinearSolverError,
                       match=r"did not converge: relative residual .* after 1 iterations "
                             r"\(tol 1.0e-10, maxiter 1\)"):
        solver.solve(system["b"][:, 0])


@pytest.mark.parametrize("method", DIRECT + ["amg"])
def test_backend_as_cg_preconditioner(system, method):
    """With M = A⁻¹ CG converges in one iteration (two with round-off);
    with one AMG V-cycle in far fewer than unpreconditioned CG."""
    A, b = system["A"], system["b"][:, 0]
    solver = make_linear_solver(A, method, dim=system["dim"], points=system["mesh"].p,
                                dofs=system["free"])
    counts = {}
    for label, M in (("plain", None), ("preconditioned", solver.aslinearoperator())):
        history = []
        x, status = cg(A, b, rtol=1e-10, maxiter=5000, M=M, callback=history.append)
        assert status == 0
        assert np.linalg.norm(b - A @ x) <= 1e-10 * np.linalg.norm(b)
        counts[label] = len(history)
    if solver.exact:
        assert counts["preconditioned"] <= 2
    else:
        assert counts["preconditioned"] <= counts["plain"] / 5


def test_rigid_body_modes_are_the_kernel_of_the_free_stiffness(system):
    """K r = 0 for a rigid motion r(x) = a + W x (ε(r) = 0 on every cell):
    exact up to the round-off of summing the entries of a row,
    |(K B)_i| ≤ Σ_j |K_ij| |B_j| · few ε."""
    K, mesh, dim = system["K"], system["mesh"], system["dim"]
    B = rigid_body_modes(mesh.p)
    assert B.shape == (dim * mesh.p.shape[1], 3 if dim == 2 else 6)
    assert np.linalg.matrix_rank(B) == B.shape[1]
    bound = 16 * EPS * (abs(K) @ np.abs(B))
    assert np.all(np.abs(K @ B) <= bound)
    # translations in the interleaved numbering dof = d·node + c
    nodal = stiffness_basis(mesh).nodal_dofs   # scikit-fem's own numbering
    for c in range(dim):
        assert np.array_equal(B[nodal[c], c], np.ones(mesh.p.shape[1]))
        assert np.array_equal(np.flatnonzero(B[:, c]), np.sort(nodal[c]))
    # a rotation is not in the kernel of the clamped matrix, and dofs select rows
    Bf = rigid_body_modes(mesh.p, system["free"])
    assert np.array_equal(Bf, B[system["free"]])
    assert np.linalg.norm(system["A"] @ Bf[:, -1]) > 1e-3 * abs(K).max()


def test_auto_prefers_pardiso_then_superlu(system, monkeypatch):
    A, dim = system["A"], system["dim"]
    monkeypatch.setattr(pardiso, "available", lambda: False)
    name, reason = choose(10**5, 14 * 10**5, dim)
    assert name == "superlu"
    assert reason.startswith("PARDISO is not available here") and "within the" in reason
    solver = make_linear_solver(A, "auto", dim=dim)
    assert solver.name == "superlu" and solver.reason.startswith("the matrix is small")
    assert relative(solver.solve(system["b"]), system["x"]) < 1e-10
    with pytest.raises(ValueError, match="method 'pardiso': pypardiso or MKL is not installed"):
        make_linear_solver(A, "pardiso", dim=dim)
    monkeypatch.setattr(pardiso, "available", lambda: True)
    name, reason = choose(10**5, 14 * 10**5, dim)
    assert name == "pardiso" and reason.startswith("MKL PARDISO is available")
    # a small matrix goes to SuperLU all the same: PARDISO's first call loads MKL
    name, reason = choose(A.shape[0], A.nnz, dim)
    assert name == "superlu" and reason.startswith("the matrix is small")


def test_auto_takes_amg_above_the_memory_limit(system):
    A, dim = system["A"], system["dim"]
    name, reason = choose(A.shape[0], A.nnz, dim, memory_limit=1e3)
    assert name == "amg"
    assert reason.endswith("more than the 1e-06 GB limit, so AMG-preconditioned CG is used.")
    solver = make_linear_solver(A, "auto", dim=dim, points=system["mesh"].p,
                                dofs=system["free"], memory_limit=1e3)
    assert solver.name == "amg" and solver.reason == reason
    with pytest.raises(ValueError, match="method 'amg' needs the mesh points and the free dofs"):
        make_linear_solver(A, "auto", dim=dim, memory_limit=1e3)


def test_factor_memory_estimate_grows_with_size_and_dimension():
    """The fill model: PARDISO's Cholesky needs less than SuperLU's LU, 3D
    more per entry of A than 2D, and 1e6 2D dofs fit in a few GB."""
    assert choose(10**4, 14 * 10**4, 2, memory_limit=1e9)[0] in DIRECT
    assert choose(10**6, 14 * 10**6, 2, memory_limit=1e8)[0] == "amg"
    assert factor_bytes(10**5, 1.4e6, 2, "pardiso") < factor_bytes(10**5, 1.4e6, 2, "superlu")
    assert factor_bytes(10**5, 1.4e6, 2, "pardiso") < factor_bytes(10**5, 1.4e6, 3, "pardiso")
    assert 1e9 < factor_bytes(10**6, 14e6, 2, "pardiso") < 4e9


def test_bad_input_is_named():
    A, _, mesh, free = elasticity(2)
    with pytest.raises(ValueError, match="method 'lu': allowed are auto, pardiso, superlu, amg"):
        make_linear_solver(A, "lu", dim=2)
    assert METHODS == ("auto", "pardiso", "superlu", "amg")
    with pytest.raises(ValueError, match="dim must be 2 or 3, got 4"):
        choose(10, 10, 4)
    with pytest.raises(ValueError, match=r"A must be a square sparse matrix, got ndarray"):
        SuperLUSolver(np.eye(3))
    solver = SuperLUSolver(A)
    with pytest.raises(ValueError, match=rf"b must have shape \({A.shape[0]},\) or "
                                         rf"\({A.shape[0]}, m\), got \(3,\)"):
        solver.solve(np.ones(3))
    with pytest.raises(ValueError, match=r"points must have shape \(2, npoints\)"):
        make_linear_solver(A, "amg", dim=2, points=mesh.p[:1], dofs=free)


def test_failed_factorisations_raise():
    singular = sp.csr_matrix(np.diag([1.0, 0.0, 2.0]))
    with pytest.raises(LinearSolverError, match="SuperLU factorisation of the 3×3 matrix "
                                                "failed: Factor is exactly singular"):
        SuperLUSolver(singular)
    if pardiso.available():
        A, *_ = elasticity(2)
        with pytest.raises(LinearSolverError, match=r"PARDISO factorisation of the \d+×\d+ "
                                                    r"matrix failed with error -4 .*not SPD"):
            PardisoSolver(-A)


def test_empty_system():
    for method in DIRECT:
        solver = make_linear_solver(sp.csr_matrix((0, 0)), method, dim=2)
        assert solver.solve(np.zeros(0)).shape == (0,)
    solver = AMGSolver(sp.csr_matrix((0, 0)))
    assert solver.solve(np.zeros((0, 2))).shape == (0, 2)


def test_pardiso_is_available_where_mkl_wheels_exist():
    """pyproject installs pypardiso on x86-64 Linux and Windows."""
    if (sys.platform, platform.machine()) in (("linux", "x86_64"), ("win32", "AMD64")):
        assert pardiso.available()
    else:
        assert DIRECT == ["superlu"] or pardiso.available()


def test_pardiso_releases_its_factors():
    """MKL keeps a factorisation until its handle is released (phase −1);
    the solver does that when it is collected."""
    if not pardiso.available():
        assert DIRECT == ["superlu"]
        return
    A, *_ = elasticity(2)
    solver = PardisoSolver(A)
    released = []
    handle = solver.pardiso
    handle.free_memory = lambda everything=False: released.append(everything)
    del solver
    gc.collect()
    assert released == [True]


def test_amg_reaches_round_off_on_a_slender_cantilever():
    """A 4 × 0.5 strip clamped at one end and pulled at the other (10400
    dofs): its condition number puts the round-off of b − A x (ε ‖A‖ ‖x‖,
    7e-10 ‖b‖) above tol ‖b‖ = 1e-10 ‖b‖, where a direct solve also stops
    (2.5e-10 ‖b‖). AMG-CG stops there too instead of raising (pyamg's CG
    restarted from an iterate at round-off diverged, to 1e47), and agrees
    with the direct solve to the conditioning of the problem."""
    from conftest import scene_dict

    from adhesive_contact import build_problem, scene_from_dict

    problem = build_problem(scene_from_dict(scene_dict({
        "mesh.size": [4.0, 0.5], "mesh.cells": [200, 25], "boundary.dirichlet": ["left"],
        "boundary.contact": [], "loads.traction": {"right": ["7*t", "14*t"]}})))
    free = problem.free
    material = problem.scene.material
    A = problem.assembly.stiffness(material.lam, material.mu)[free][:, free].tocsr()
    b = problem.loads(0.05)[free]
    solver = make_linear_solver(A, "amg", dim=2, points=problem.mesh.p, dofs=free)
    x = solver.solve(b)
    direct = spsolve(A.tocsc(), b)
    assert np.linalg.norm(b - A @ direct) > 1e-10 * np.linalg.norm(b)   # the case is one
    assert solver.info["relative_residual"] <= 1e-9
    assert np.linalg.norm(x - direct) <= 1e-6 * np.linalg.norm(direct)
