"""The vertices of Γ_C where a side holds some (or all) components.

Every vertex of Γ_C is a contact node: it enters the bonding step (4.2)
with its actual displacement u_{n−1}; the contact laws act there, their
force along its free components in the equations (the wall where u_ν is
free, friction with the same stick and slip conditions as elsewhere where
a u_τ is free) and their force along its held components in its contact
force, −∂Φ/∂z_D, so that a side's reaction is the support's force alone,
what a load cell in the grip reads (docs/outputs.md).

The references are computed here: the Frémond update by hand from the
solution's Cartesian u at the facet's vertices, the normal forces of the
laws by hand from u and β, the residual of the discrete equations from
scikit-fem's stiffness (conftest), the friction conditions from the Tresca
bound μ |f|/2 of the nodal rule.
"""

import tomllib
from pathlib import Path

import numpy as np
import pytest
from conftest import law, load_vector, reference_mesh, run, same_mesh, scene_dict, stiffness

from adhesive_contact import build_problem, load_scene, reaction_sides, reactions, solve
from adhesive_contact.postprocess import total_contact_force

ROOT = Path(__file__).resolve().parents[1]
DEFAULT = ROOT / "cli" / "default_scene.toml"


@pytest.fixture(scope="module")
def default():
    """The built-in scene: a strip on rollers at the left (u_x = 0), lifted
    at the right (u_y = 0.15 t, u_x free), glued along the bottom; both
    bottom corners are vertices of Γ_C with a held component."""
    solution = solve(build_problem(load_scene(DEFAULT)))
    assert solution.success
    return solution, tomllib.loads(DEFAULT.read_text())


def fremond(r, xi, beta, p):
    """F(r, ξ, β) of docs/model.md §4.3, written out here."""
    R_nu = np.minimum(np.maximum(-r, 0.0), p["L"])
    R_tau = np.minimum(np.abs(xi), p["L"])
    stretch = p["gamma_nu"] * R_nu ** 2 + p["gamma_tau"] * R_tau ** 2
    return -np.maximum(np.clip(beta, 0.0, 1.0) * stretch - p["eps_a"], 0.0)


def normal_pressure(r, beta, p):
    """p_ν(β, r) = c r_+ − γ β² R_ν(r) of the adhesive compliance."""
    return p["c"] * np.maximum(r, 0.0) - p["gamma"] * beta ** 2 * np.minimum(
        np.maximum(-r, 0.0), p["L"])


def bottom_facets(solution):
    """(left vertex, right vertex, length) of every facet of Γ_C (the bottom)."""
    mesh, b = solution.problem.mesh, solution.problem.boundary
    v = b.facet_nodes
    left = np.where(mesh.p[0, v[0]] < mesh.p[0, v[1]], v[0], v[1])
    right = np.where(mesh.p[0, v[0]] < mesh.p[0, v[1]], v[1], v[0])
    assert np.all(mesh.p[1, v] == 0.0)
    return left, right, mesh.p[0, right] - mesh.p[0, left]


def test_beta_at_the_corners_is_the_explicit_euler_step_of_their_vertices(default):
    """(4.2) on every facet, the two at the held corners included: β_n =
    β_{n−1} + k · ½ Σ_{v = a, b} F(u_ν(x_v), u_τ(x_v), β_{n−1}) with u_{n−1}
    the solution's displacement at the facet's two vertices (ν = −e_y,
    τ = e_x on the bottom). The corner vertices used to read u = 0."""
    solution, data = default
    params = data["contact"]["bonding"]
    left, right, _ = bottom_facets(solution)
    x = solution.problem.mesh.p[0]
    k = data["time"]["T"] / data["time"]["steps"]
    corners = np.isclose(x[left], 0.0) | np.isclose(x[right], 4.0)
    assert corners.sum() == 2
    for n in range(1, solution.t.size):
        u = solution.u[n - 1]
        beta = solution.beta[n - 1]
        rate = 0.5 * sum(fremond(-u[v, 1], u[v, 0], beta, params) for v in (left, right))
        np.testing.assert_allclose(solution.beta[n], beta + k * rate, rtol=0, atol=1e-12)
    # the lifted corner's facet does debond (its vertex is pulled off at once)
    lifted = np.flatnonzero(np.isclose(x[right], 4.0))[0]
    assert solution.beta[-1][lifted] < 0.5


def test_the_body_balances_the_reactions_and_the_contact_forces(default):
    """Σ_sides R + Σ_a R_a F_a = 0 (no loads) at every level, with F_a the
    force of Γ_C at every component of every vertex, held ones included."""
    solution, _ = default
    total = reactions(solution).sum(axis=1) + total_contact_force(solution)
    scale = np.abs(reactions(solution)).max()
    np.testing.assert_allclose(total, 0.0, atol=1e-10 * scale)


def test_the_grip_at_the_lifted_corner_pulls_against_the_glue_there(default):
    """The normal forces of the laws by hand at every vertex, F_y,a =
    Σ_{f ∋ a} |f|/2 p_ν(β_f, u_ν,a): they are the solution's contact forces
    at every vertex, the lifted corner (u_ν held) included, and the vertical
    balance of the body makes the lifted side's reaction the grip's force
    alone, R_right,y = −Σ_a F_y,a (the left side holds u_x only): it pulls
    against the glue at its own corner too."""
    solution, data = default
    problem = solution.problem
    b = problem.boundary
    normal = dict(data["contact"]["normal"])
    left, right, length = bottom_facets(solution)
    x = problem.mesh.p[0, b.nodes]
    local = np.full(problem.mesh.p.shape[1], -1)
    local[b.nodes] = np.arange(b.nodes.size)
    corner = int(np.flatnonzero(np.isclose(x, 4.0))[0])
    roller = int(np.flatnonzero(np.isclose(x, 0.0))[0])
    # the lifted corner holds u_ν (= −u_y), the roller u_τ (= u_x)
    assert b.held[corner].tolist() == [True, False] and b.held[roller].tolist() == [False, True]
    R = reactions(solution)
    sides = reaction_sides(problem)
    pulls = []
    for n in range(solution.t.size):
        u, beta = solution.u[n], solution.beta[n]
        F_y = np.zeros(b.nodes.size)
        for v in (left, right):
            np.add.at(F_y, local[v], 0.5 * length * normal_pressure(-u[v, 1], beta, normal))
        # the solution's normal forces at every vertex: F_ν = −F_y
        np.testing.assert_allclose(-solution.contact_force[n, :, 0], F_y,
                                   rtol=0, atol=1e-9 * max(np.abs(F_y).max(), 1.0))
        np.testing.assert_allclose(R[n, sides.index("right"), 1], -F_y.sum(),
                                   rtol=1e-10, atol=1e-10)
        assert R[n, sides.index("left"), 1] == 0.0
        pulls.append(F_y[corner])
    pulls = np.array(pulls)
    # the glue pulls the lifted corner down while the peel starts: 0.47 of
    # the grip's 1.58 at t = k (the half facet's γ β² |u_ν|)
    lift = R[:, sides.index("right"), 1]
    assert pulls[1] == pytest.approx(-0.5 * 0.05 * normal["gamma"] * 0.15 * solution.t[1],
                                     rel=1e-12)
    assert np.all(-pulls[1:4] > 0.2 * lift[1:4])


# ---------------------------------------------------------------- the grip's force


#: a 1 × 0.2 body of 2 × 1 cells glued along its bottom (adhesive
#: compliance γ, adhesive spring γ_τ, β = 1 for good), held at both ends by
#: grips that lift it by δ_y = 1e-3 t and slide it by δ_x = 2e-3 t: both
#: ends of Γ_C are held in both components, its middle vertex is free
GRIP = {"c": 1e4, "gamma": 5e3, "gamma_tau": 2e3, "L": 0.01}
GRIPPED = scene_dict({
    "mesh": {"domain": "rectangle", "size": [1.0, 0.2], "cells": [2, 1]},
    "boundary": {"dirichlet": [], "contact": ["bottom"],
                 "displacement": {side: ["0.002*t", "0.001*t"] for side in ("left", "right")}},
    "contact.normal": law("adhesive_compliance", c=GRIP["c"], gamma=GRIP["gamma"], L=GRIP["L"]),
    "contact.friction": law("adhesive_spring", gamma=GRIP["gamma_tau"], L=GRIP["L"]),
    "time.steps": 2,
})


def test_a_grip_holding_a_glued_vertex_pulls_against_the_glue_there():
    """The grip's force is the support's force alone, what a load cell reads:
    R_D = (K u)_D − F_D, K scikit-fem's stiffness and F the glue's force on
    the body at the held vertices by hand, F_a = w_a (−γ_τ u_x, −γ u_y)
    (nodal rule, w_a = |f|/2 at the ends; both displacements below L). The
    two grips hold the whole body, so together they balance the glue all
    along Γ_C: Σ R = −Σ_a F_a. The reactions used to be (K u)_D, which left
    out the glue at the grips' own vertices (here nine tenths of the pull)."""
    problem, solution = run(GRIPPED)
    assert solution.success
    mesh = reference_mesh((1.0, 0.2), (2, 1))
    same_mesh(problem, mesh)
    K = stiffness(mesh, 1000.0, 0.3)
    b = problem.boundary
    bottom = b.nodes                                  # (0, 0), (0.5, 0), (1, 0)
    x = mesh.p[0, bottom]
    w = b.node_weights
    np.testing.assert_allclose(w, [0.25, 0.5, 0.25], rtol=1e-14)
    sides = reaction_sides(problem)
    R = reactions(solution)
    for n in range(solution.t.size):
        u = solution.u[n]
        glue = -w[:, None] * np.stack([GRIP["gamma_tau"] * u[bottom, 0],
                                       GRIP["gamma"] * u[bottom, 1]], axis=1)
        assert np.all(np.abs(u[bottom]) < GRIP["L"])
        Ku = (K @ u.reshape(-1)).reshape(-1, 2)
        for side, end in (("left", 0.0), ("right", 1.0)):
            nodes = np.flatnonzero(np.isclose(mesh.p[0], end))
            at = int(np.flatnonzero(np.isclose(x, end))[0])
            expected = Ku[nodes].sum(axis=0) - glue[at]
            np.testing.assert_allclose(R[n, sides.index(side)], expected,
                                       rtol=1e-9, atol=1e-12)
        np.testing.assert_allclose(R[n].sum(axis=0), -glue.sum(axis=0), rtol=1e-9, atol=1e-12)
        # the solution's contact forces are the glue's at every vertex, in the
        # nodal frame [ν, τ] = [−e_y, e_x]: (F_ν, F_τ) = (−F_y, F_x)
        np.testing.assert_allclose(solution.contact_force[n],
                                   np.stack([-glue[:, 1], glue[:, 0]], axis=1),
                                   rtol=1e-9, atol=1e-12)
    # at T the glue at the grips' own vertices (held at u_y = 1e-3) pulls with
    # 2 w γ u_y = 2.5 of the grips' 2.76; (K u)_D alone read 0.26
    assert R[-1].sum(axis=0)[1] == pytest.approx(2.5 + GRIP["gamma"] * 0.5 * solution.u[-1][
        bottom[1], 1], rel=1e-9)
    assert R[-1].sum(axis=0)[1] > 2.5


# ---------------------------------------------------------------- friction at a held normal

TRESCA = 1.0
#: a strip clamped on the left, its right side on rollers (u_y = 0), glued
#: frictionally along the bottom (Tresca) and pulled along x at the right:
#: the corner (2, 0) holds u_ν = −u_y = 0 and leaves u_τ = u_x free
PULLED = scene_dict({
    "mesh.cells": [8, 2], "boundary.dirichlet": ["left"],
    "boundary.displacement": {"right": ["free", "0"]},
    "contact.normal": law("compliance", c=1000.0),
    "contact.friction": law("tresca", mu=TRESCA),
})


@pytest.mark.parametrize("pull, state", [(0.05, "stick"), (20.0, "slip")])
def test_friction_on_the_free_tangential_dof_of_a_held_normal(pull, state):
    """At the corner, K u − f at its u_x (the force of Γ_C, scikit-fem's
    stiffness here) satisfies the Tresca conditions of the nodal rule with
    the bound κ = μ |f|/2: stuck (u_x = 0, |r| ≤ κ) under a small pull,
    sliding (u_x > 0, r = −κ) under a large one, like every other node."""
    data = scene_dict({"loads.traction.right": [f"{pull}*t", "0"]}, PULLED)
    problem, sol = run(data)
    assert sol.success
    mesh = reference_mesh((2.0, 0.5), (8, 2))
    same_mesh(problem, mesh)
    K = stiffness(mesh, 1000.0, 0.3)
    f = load_vector(mesh, traction={"right": lambda x, y: (pull + 0 * x, 0 * x)})
    u = sol.u[1].ravel()
    r = K @ u - f
    corner = int(np.flatnonzero((mesh.p[0] == 2.0) & (mesh.p[1] == 0.0))[0])
    kappa = TRESCA * 0.25 / 2
    b = problem.boundary
    a = int(np.flatnonzero(b.nodes == corner)[0])
    assert b.held[a].tolist() == [True, False]
    scale = np.abs(f).max()
    bottom = b.nodes[~b.held.all(axis=1)]          # the clamped vertex (0, 0) aside
    if state == "stick":
        assert u[2 * corner] == 0.0 and abs(r[2 * corner]) <= kappa
        assert abs(r[2 * corner]) > 1e-3 * kappa     # friction holds it, not nothing
        assert sol.stuck[1][a]
        assert np.all(u[2 * bottom] == 0.0)
    else:
        assert u[2 * corner] > 0.0 and not sol.stuck[1][a]
        np.testing.assert_allclose(r[2 * corner], -kappa, rtol=0, atol=1e-8 * scale)
    # the library's force at the corner's free component is that residual
    np.testing.assert_allclose(sol.contact_force[1][a, 1], r[2 * corner], rtol=0,
                               atol=1e-8 * scale)
    assert sol.contact_force[1][a, 0] == 0.0


# ---------------------------------------------------------------- the wall at a held tangential

def test_the_wall_holds_a_roller_corner():
    """A strip on rollers at the left (u_x = 0) pressed down by its top
    (u_y = −0.01 t) onto a soft layer 0.002 thick: the corner (0, 0) holds
    u_τ = u_x and leaves u_ν = −u_y free, which the wall bounds like every
    other contact node (it used to go through it with the body)."""
    data = scene_dict({
        "mesh.cells": [8, 2], "boundary.dirichlet": [],
        "boundary.displacement": {"left": ["0", "free"], "top": ["free", "-0.01*t"]},
        "contact": {"gap": 0.002, "normal": law("compliance", c=10.0)}})
    problem, sol = run(data)
    assert sol.success
    b = problem.boundary
    corner = int(np.flatnonzero(problem.mesh.p[0, b.nodes] == 0.0)[0])
    assert b.held[corner].tolist() == [False, True]
    u = sol.u[1]
    u_nu = -u[b.nodes, 1]
    assert u_nu[corner] == pytest.approx(0.002, abs=1e-15) and sol.on_wall[1][corner]
    assert np.all(u_nu <= 0.002 + 1e-15) and sol.on_wall[1].all()
    # the wall pushes the corner up: its multiplier is in its normal force
    assert sol.contact_force[1][corner, 0] < 0.0


# ---------------------------------------------------------------- a moving clamped vertex

def test_a_vertex_held_in_every_component_enters_the_bonding_step_with_its_values():
    """The right end lifted and pulled, u = (0.004 t, 0.006 t), every
    component held: its vertex on Γ_C reads those values in (4.2) (it used
    to read 0), has no unknowns, and the laws' force there is its contact
    force."""
    data = scene_dict({
        "mesh.cells": [8, 2], "boundary.dirichlet": ["left"], "time.steps": 4,
        "boundary.displacement": {"right": ["0.004*t", "0.006*t"]},
        "contact": {"normal": law("adhesive_compliance", c=1e4, gamma=100.0, L=0.01),
                    "friction": law("adhesive_spring", gamma=100.0, L=0.01),
                    "bonding": {"law": "fremond", "gamma_nu": 1e4, "gamma_tau": 5e3,
                                "eps_a": 0.0, "L": 0.01}}})
    problem, sol = run(data)
    assert sol.success
    params = data["contact"]["bonding"]
    left, right, _ = bottom_facets(sol)
    x = problem.mesh.p[0]
    b = problem.boundary
    corner = int(np.flatnonzero(x[b.nodes] == 2.0)[0])
    assert b.held[corner].all() and not b.rotated[corner]
    np.testing.assert_allclose(sol.frame_displacement[:, corner],
                               np.stack([-0.006 * sol.t, 0.004 * sol.t], axis=1), atol=1e-15)
    # its contact force is the laws' at the held values, by hand: w = |f|/2,
    # F_ν = −w p_ν = w γ β² 0.006 t, F_τ = −w γ_τ β² 0.004 t (β of its facet)
    last = np.flatnonzero(x[right] == 2.0)[0]
    beta_corner = sol.beta[:, last]
    w = 0.5 * 2.0 / 8
    np.testing.assert_allclose(
        sol.contact_force[:, corner],
        np.stack([w * 100.0 * beta_corner ** 2 * 0.006 * sol.t,
                  -w * 100.0 * beta_corner ** 2 * 0.004 * sol.t], axis=1), rtol=1e-12, atol=1e-15)
    for n in range(1, sol.t.size):
        u, beta = sol.u[n - 1], sol.beta[n - 1]
        rate = 0.5 * sum(fremond(-u[v, 1], u[v, 0], beta, params) for v in (left, right))
        np.testing.assert_allclose(sol.beta[n], beta + 0.25 * rate, rtol=0, atol=1e-12)
    assert sol.beta[-1][last] < sol.beta[-1][last - 1] < 1.0


# ---------------------------------------------------------------- a frame not along the axes

def test_a_held_axis_off_the_nodal_frame_gets_the_nearest_frame_along_it(tmp_path):
    """A parallelogram, x' = x + 0.3 y, pressed by a body force onto a layer
    along its slanted left side; the bottom is on rollers (u_y = 0). At the
    corner (0, 0) the averaged normal is that of its facet, ∝ (−1, 0.3),
    not along the held axis y: the corner gets ν = −e_x (ν projected off
    e_y, nearer to it than ±e_y), τ = −e_y, held. The other vertices of
    the side keep their normal. K u − f at the corner's u_x (scikit-fem)
    is then the compliance force of its half facet, read at u_ν = −u_x."""
    from skfem import MeshTri
    from test_geometry import write_msh

    xs, ys = np.linspace(0.0, 2.0, 9), np.linspace(0.0, 1.0, 5)
    mesh = MeshTri.init_tensor(xs, ys)
    mesh = MeshTri(np.array([mesh.p[0] + 0.3 * mesh.p[1], mesh.p[1]]), mesh.t)
    mesh = mesh.with_boundaries({"left": lambda x: np.isclose(x[0], 0.3 * x[1]),
                                 "right": lambda x: np.isclose(x[0], 2.0 + 0.3 * x[1]),
                                 "bottom": lambda x: np.isclose(x[1], 0.0)})
    path = tmp_path / "slanted.msh"
    write_msh(path, mesh, ["left", "right", "bottom"])
    c = 1000.0
    data = scene_dict({
        "mesh": {"domain": "file", "file": str(path)}, "boundary.dirichlet": [],
        "boundary.contact": ["left"],
        "boundary.displacement": {"bottom": ["free", "0"], "right": ["0", "free"]},
        "loads.body": ["-200*t", "0"], "contact.normal": law("compliance", c=c)})
    problem, sol = run(data)
    assert sol.success
    b = problem.boundary
    xy = problem.mesh.p[:, b.nodes]
    corner = int(np.flatnonzero((xy[0] == 0.0) & (xy[1] == 0.0))[0])
    assert b.frame[corner].tolist() == [[-1.0, 0.0], [0.0, -1.0]]
    assert b.held[corner].tolist() == [False, True]
    slanted = np.array([-1.0, 0.3]) / np.hypot(1.0, 0.3)
    others = np.arange(b.nodes.size) != corner
    np.testing.assert_allclose(b.frame[others, :, 0], np.tile(slanted, (others.sum(), 1)),
                               atol=1e-14)
    # the step: u_ν = −u_x at the corner, and its equation holds the layer's force
    K = stiffness(problem.mesh, 1000.0, 0.3)
    f = load_vector(problem.mesh, body=lambda x, y: (-200.0 + 0 * x, 0 * x))
    u = sol.u[1].ravel()
    node = b.nodes[corner]
    u_nu = -u[2 * node]
    assert u_nu > 0 and sol.frame_displacement[1][corner].tolist() == [u_nu, 0.0]
    half = 0.5 * np.hypot(0.3, 1.0) * 0.25
    r = K @ u - f
    np.testing.assert_allclose(r[2 * node], half * c * u_nu, rtol=1e-8)
    np.testing.assert_allclose(sol.contact_force[1][corner], [-half * c * u_nu, 0.0], rtol=1e-8)


# ---------------------------------------------------------------- 3D: one tangential held

def test_friction_in_3d_where_one_tangential_component_is_held():
    """A box clamped on top (y = 0.5), on a symmetry plane at x = 0 (u_x = 0),
    Γ_C its bottom (ν = −e_y, τ = e_z, τ' = −e_x) with Tresca friction, and
    pulled along z at its back: on the line x = 0 of Γ_C, u_τ' is held at 0
    and u_τ free, whose friction is the one-dimensional Tresca law. Every
    node satisfies the conditions of the nodal rule with κ_a = μ Σ |f|/3:
    stuck, ξ_a = 0 and |F_τ| ≤ κ_a; sliding, F_τ = −κ_a ξ_a/|ξ_a|; some of
    those on the line stick, some slide."""
    mu = 0.5
    data = scene_dict({
        "dim": 3, "mesh": {"domain": "box", "size": [1.0, 0.5, 1.0], "cells": [3, 2, 4]},
        "boundary.dirichlet": ["top"], "boundary.displacement": {"left": ["0", "free", "free"]},
        "loads.traction.back": ["0", "0", "1*t"],
        "contact.normal": law("compliance", c=1000.0), "contact.friction": law("tresca", mu=mu)})
    problem, sol = run(data)
    assert sol.success
    b = problem.boundary
    mesh = problem.mesh
    np.testing.assert_array_equal(b.frame[0], [[0, 0, -1], [-1, 0, 0], [0, 1, 0]])
    line = (mesh.p[0, b.nodes] == 0.0) & (mesh.p[1, b.nodes] == 0.0)
    line &= ~b.held.all(axis=1)
    assert line.sum() == 5
    assert np.all(b.held[line] == [False, False, True])
    # κ_a by hand: a third of each bottom triangle's area at each of its vertices
    v = b.facet_nodes
    p = mesh.p
    area = 0.5 * np.linalg.norm(np.cross((p[:, v[1]] - p[:, v[0]]).T, (p[:, v[2]] - p[:, v[0]]).T),
                                axis=1)
    local = np.full(p.shape[1], -1)
    local[b.nodes] = np.arange(b.nodes.size)
    kappa = np.zeros(b.nodes.size)
    for i in range(3):
        np.add.at(kappa, local[v[i]], mu * area / 3)
    F = sol.contact_force[1][:, 1:]
    xi = sol.frame_displacement[1][:, 1:]
    s = np.linalg.norm(xi, axis=1)
    unheld = ~b.held.all(axis=1)   # the clamped vertices aside (none on the bottom)
    stuck = (s == 0) & unheld
    slid = (s > 0) & unheld
    scale = np.abs(F).max()
    assert np.all(np.linalg.norm(F[stuck], axis=1) <= kappa[stuck] * (1 + 1e-9))
    np.testing.assert_allclose(F[slid], -kappa[slid, None] * xi[slid] / s[slid, None],
                               rtol=0, atol=1e-8 * scale)
    assert np.all(F[line, 1] == 0.0) and np.all(xi[line, 1] == 0.0)   # τ' held at 0
    assert (line & stuck).any() and (line & slid).any()
    np.testing.assert_array_equal(sol.stuck[1][unheld], stuck[unheld])


@pytest.mark.parametrize("linear", ["amg", "pardiso"])
def test_the_linear_backends_agree_on_the_held_corners(default, linear):
    """The default scene's held corners through every route: with AMG the
    step runs on all free dofs, with PARDISO on its Schur complement."""
    if linear == "pardiso":
        pytest.importorskip("pypardiso")
    solution, data = default
    scene = load_scene(DEFAULT)
    from dataclasses import replace
    other = solve(build_problem(replace(scene, solver=replace(scene.solver, linear=linear))))
    assert other.success
    scale = np.abs(solution.u).max()
    np.testing.assert_allclose(other.u, solution.u, rtol=0, atol=1e-7 * scale)
    np.testing.assert_allclose(other.beta, solution.beta, rtol=0, atol=1e-7)
    np.testing.assert_allclose(reactions(other), reactions(solution), rtol=0,
                               atol=1e-6 * np.abs(reactions(solution)).max())


@pytest.mark.parametrize("dim", [2, 3])
def test_held_frames_put_every_held_axis_in_the_frame_and_keep_the_nearest_normal(dim):
    """For random normals and held sets: the frames are orthonormal, each held
    axis is ±1 times one frame column (held, at the dof of that axis), and
    ν is the nearer of ν off the held axes and the nearest held axis."""
    from adhesive_contact.fem.contact_boundary import held_frames, tangent_frame

    rng = np.random.default_rng(7)
    n = 400
    nu = rng.standard_normal((dim, n))
    nu[:, :50] = np.eye(dim)[:, rng.integers(0, dim, 50)] * rng.choice([-1, 1], 50)
    nu /= np.linalg.norm(nu, axis=0)
    held_axes = rng.random((n, dim)) < 0.4
    held_axes[:20] = True                       # clamped
    held_axes[20:40] = False                    # free
    dofs = dim * np.arange(n)[:, None] + np.arange(dim)
    frame0 = tangent_frame(nu)
    frame, held, frame_dofs = held_frames(frame0, held_axes, dofs)
    eye = np.einsum("aji,ajk->aik", frame, frame)
    np.testing.assert_allclose(eye, np.broadcast_to(np.eye(dim), eye.shape), atol=1e-14)
    for a in range(n):
        H = np.flatnonzero(held_axes[a])
        if H.size in (0, dim):
            np.testing.assert_array_equal(frame[a], frame0[a])
            assert held[a].tolist() == [H.size == dim] * dim
            np.testing.assert_array_equal(frame_dofs[a], dofs[a])
            continue
        assert held[a].sum() == H.size
        for h in H:
            c = int(np.flatnonzero(np.abs(frame[a][h]) == 1.0)[0])
            assert held[a, c] and frame_dofs[a, c] == dofs[a, h]
            assert np.count_nonzero(frame[a][h]) == 1 and np.count_nonzero(frame[a][:, c]) == 1
        assert sorted(frame_dofs[a].tolist()) == dofs[a].tolist()
        off = np.where(held_axes[a], 0.0, nu[:, a])
        best = max(np.linalg.norm(off), np.abs(nu[H, a]).max())
        assert frame[a][:, 0] @ nu[:, a] == pytest.approx(best, abs=1e-12)


@pytest.mark.parametrize("linear", ["superlu", "amg"])
def test_reactions_contact_forces_and_loads_balance_at_every_level(linear):
    """Σ_sides R + Σ_a R_a F_a + ∫ f = 0 on the body at every level, to
    round-off: the built-in scene's rollers and lifted corner (both vertices
    of Γ_C, the glue and friction acting along their held components), with
    a body load and a traction on top added, memory on. The memory's
    history force sums to zero over the dofs (a stress does no net work on
    a translation), so the balance holds with it."""
    data = tomllib.loads(DEFAULT.read_text())
    data["loads"] = {"body": ["3*t", "-20*t"], "traction": {"top": ["1 + x*t", "-5*t"]}}
    data["solver"] = {"linear": linear}
    problem, solution = run(data)
    assert solution.success
    loads = np.array([problem.loads(t).reshape(-1, 2).sum(axis=0) for t in solution.t])
    R = reactions(solution)
    total = R.sum(axis=1) + total_contact_force(solution) + loads
    scale = max(np.abs(R).max(), np.abs(loads).max())
    np.testing.assert_allclose(total, 0.0, atol=1e-9 * scale)
    # the held corners do carry the laws' force (else this would test nothing new)
    b = problem.boundary
    held = np.flatnonzero(b.held.any(axis=1))
    assert np.abs(solution.contact_force[1:, held][b.held[held][None].repeat(
        solution.t.size - 1, axis=0)]).max() > 1e-3 * scale
