"""Linear elasticity without and with contact, against independent
computations: a patch test (exact linear field), a plain scikit-fem solve,
and global equilibrium (forces and moment) of a contact run with memory.
"""

import numpy as np
import pytest
from conftest import (
    clamped_dofs,
    law,
    load_vector,
    prony,
    reference_mesh,
    relative_max,
    run,
    same_mesh,
    scene_dict,
    stiffness,
)
from skfem import condense
from skfem import solve as skfem_solve
from skfem.models.elasticity import lame_parameters

E, NU = 1000.0, 0.3
LAM, MU = lame_parameters(E, NU)  # plane strain: λ = Eν/((1+ν)(1−2ν)), μ = E/(2(1+ν))


# --------------------------------------------------------------------------
# P1 patch test
# --------------------------------------------------------------------------

@pytest.mark.parametrize("pattern", ["diagonal", "cross"])
def test_patch_linear_field_is_reproduced(pattern):
    """u = t (e1 x, e2 x) vanishes on x = 0 and has the constant strain
    ε = [[e1, e2/2], [e2/2, 0]]; Hooke (plane strain) gives
    σ_xx = (λ + 2μ) e1, σ_yy = λ e1, σ_xy = μ e2. With the tractions σν on
    right (ν = e_x), top (ν = e_y) and bottom (ν = −e_y) the exact solution
    is in V^h, so the Galerkin solution equals it up to round-off."""
    e1, e2 = 1.0e-3, 2.0e-3
    sxx, syy, sxy = (LAM + 2 * MU) * e1, LAM * e1, MU * e2
    scene = scene_dict({
        "mesh": {"domain": "rectangle", "size": [2.0, 1.0], "cells": [6, 3], "pattern": pattern},
        "boundary": {"dirichlet": ["left"]}, "material": {"E": E, "nu": NU},
        "loads.traction": {"right": [f"{sxx!r}*t", f"{sxy!r}*t"],
                           "top": [f"{sxy!r}*t", f"{syy!r}*t"],
                           "bottom": [f"{-sxy!r}*t", f"{-syy!r}*t"]},
        "time.steps": 2})
    problem, sol = run(scene)
    x = problem.mesh.p[0]
    exact_eps = np.array([[e1, e2 / 2], [e2 / 2, 0.0]])
    exact_sigma = np.array([[sxx, sxy], [sxy, syy]])
    for n, t in enumerate(sol.t):
        exact = t * np.stack([e1 * x, e2 * x], axis=1)
        if t == 0:
            # zero load: zero displacement and stress
            assert np.abs(sol.u[n]).max() == 0.0
            continue
        # Tolerance: the discrete solution is the exact field, so only
        # round-off of a sparse direct solve is left, ε_mach·κ(K) with
        # κ(K) ≈ 1e2 on this 6x3 mesh: 1e-12 relative is ~50x above it.
        assert relative_max(sol.u[n], exact) < 1e-12
        # The library's cell strains/stresses: constant, equal to t ε and t σ.
        assert relative_max(sol.stress[n], np.broadcast_to(t * exact_sigma,
                                                           sol.stress[n].shape)) < 1e-12
        strain = problem.assembly.cell_strain(sol.u[n].ravel())
        assert relative_max(strain, np.broadcast_to(t * exact_eps, strain.shape)) < 1e-12


# --------------------------------------------------------------------------
# Against a plain scikit-fem solve
# --------------------------------------------------------------------------

@pytest.mark.parametrize("pattern", ["diagonal", "cross"])
def test_no_contact_matches_plain_skfem(pattern):
    """No contact, no memory: each u_n solves K u = f(t_n) with u = 0 on the
    left. Reference: scikit-fem's linear_elasticity, LinearForms for the
    loads (exact rule for these polynomial loads), condense + solve."""
    size, cells = (2.0, 1.0), (8, 4)
    scene = scene_dict({
        "mesh": {"domain": "rectangle", "size": list(size), "cells": list(cells),
                 "pattern": pattern},
        "boundary": {"dirichlet": ["left"]}, "material": {"E": E, "nu": NU},
        "loads": {"body": ["t*(3*x*y - 1)", "-t*(1 + x**2 - y)"],
                  "traction": {"right": ["5*t*y", "-2*t*(1 + y**2)"],
                               "top": ["0.5*t*x", "-t*x*(2 - x)"]}},
        "time.steps": 2})
    problem, sol = run(scene)
    mesh = reference_mesh(size, cells, pattern)
    same_mesh(problem, mesh)
    K = stiffness(mesh, E, NU)
    D = clamped_dofs(mesh, ["left"])
    for n, t in enumerate(sol.t):
        f = load_vector(
            mesh,
            body=lambda x, y: (t * (3 * x * y - 1), -t * (1 + x**2 - y)),
            traction={"right": lambda x, y: (5 * t * y + 0 * x, -2 * t * (1 + y**2) + 0 * x),
                      "top": lambda x, y: (0.5 * t * x + 0 * y, -t * x * (2 - x))})
        u_ref = skfem_solve(*condense(K, f, D=D))
        got = sol.u[n].ravel()   # interleaved (u_x, u_y) per node, as scikit-fem
        if t == 0:
            assert np.abs(got).max() == 0.0
            continue
        # Tolerance: both solve the same linear system (the loads are
        # polynomials integrated exactly by both rules), so the difference is
        # round-off of two sparse direct solves, ~ε_mach·κ(K) ≈ 1e-13.
        assert relative_max(got, u_ref) < 1e-10


# --------------------------------------------------------------------------
# Global equilibrium with contact and memory
# --------------------------------------------------------------------------

PRONY = [(200.0, 0.3, 0.5), (100.0, 0.25, 0.1)]   # (E_m, ν_m, τ_m)

EQUILIBRIUM_SCENE = scene_dict({
    "mesh.size": [2.0, 1.0], "mesh.cells": [16, 8], "memory": prony(*PRONY),
    "loads": {"body": ["10*t*y", "-300*t*(1 + 0.5*x)"],
              "traction": {"right": ["-20*t*y", "-10*t"], "left": ["15*t", "5*t*y"]}},
    "contact": {"gap": "0.004 + 0.004*x*(2 - x)", "normal": law("compliance", c=10000.0)},
    "time.steps": 10})


def exact_resultants(t):
    """∫_Ω f_0 + ∫_Γ_N f_N (force) and ∫ x × f (moment about the origin),
    by hand for the loads of EQUILIBRIUM_SCENE on [0, 2] x [0, 1]:

    body (10 t y, −300 t (1 + x/2)):
        ∫ f_x = 10 t · 2 · ½ = 10 t,   ∫ f_y = −300 t (2 + 1) = −900 t,
        ∫ (x f_y − y f_x) = −300 t ∫∫ (x + x²/2) − 10 t ∫∫ y²
                          = −300 t (2 + 4/3) − 10 t · 2/3.
    right (x = 2): (−20 t y, −10 t): ∫ f_x = −10 t, ∫ f_y = −10 t,
        ∫ (2 f_y − y f_x) = −20 t + 20 t/3.
    left (x = 0): (15 t, 5 t y): ∫ f_x = 15 t, ∫ f_y = 2.5 t,
        ∫ (0 − y f_x) = −7.5 t.
    """
    fx = 10 * t - 10 * t + 15 * t
    fy = -900 * t - 10 * t + 2.5 * t
    m = (-300 * t * (2 + 4 / 3) - 10 * t * 2 / 3) + (-20 * t + 20 * t / 3) + (-7.5 * t)
    return np.array([fx, fy]), m


def test_global_equilibrium_with_contact_and_memory():
    """At every t_n: with r = a(u_n) + memory − f_n computed here from
    scikit-fem stiffnesses and a direct sum of the memory,
      - r = 0 at the free dofs off Γ_C, r = contact force at the contact nodes
        (the library's contact_force rotated back with boundary.frame),
      - Σ reactions on Γ_D + Σ contact forces + applied loads = 0 (force and
        moment; the applied resultants integrated by hand),
      - u_ν ≤ g at every contact node (u_ν = u·ν computed here)."""
    problem, sol = run(EQUILIBRIUM_SCENE)
    size, cells = (2.0, 1.0), (16, 8)
    mesh = reference_mesh(size, cells)
    same_mesh(problem, mesh)
    K = stiffness(mesh, E, NU)
    Km = [stiffness(mesh, Em, num) for Em, num, _ in PRONY]
    k = problem.scene.k
    D = clamped_dofs(mesh, ["top"])
    bnd = problem.boundary
    x, y = mesh.p

    # the contact nodes: bottom nodes (y = 0), none clamped (top is clamped)
    bottom = np.flatnonzero(np.isclose(y, 0.0))
    np.testing.assert_array_equal(np.sort(bnd.nodes), bottom)
    cdofs = np.stack([2 * bnd.nodes, 2 * bnd.nodes + 1], axis=1)
    other = np.setdiff1d(np.arange(K.shape[0]), np.concatenate([D, cdofs.ravel()]))
    normals = bnd.frame[:, :, 0]
    # the outward normal of the bottom side
    np.testing.assert_allclose(normals, np.tile([0.0, -1.0], (bnd.nodes.size, 1)), atol=1e-14)

    U = sol.u.reshape(sol.t.size, -1)
    checked_wall = checked_compliance = False
    for n, t in enumerate(sol.t):
        f = load_vector(
            mesh,
            body=lambda x, y: (10 * t * y, -300 * t * (1 + 0.5 * x)),
            traction={"right": lambda x, y: (-20 * t * y, -10 * t + 0 * y),
                      "left": lambda x, y: (15 * t + 0 * y, 5 * t * y)})
        r = K @ U[n] - f
        if n >= 1:
            # right rectangle rule, direct O(n) sum: k Σ_{j=1}^{n} e^{−(t_n−t_j)/τ} C_m ε(u_j)
            for (Em, num, tau), Kmm in zip(PRONY, Km):
                acc = sum(np.exp(-(t - sol.t[j]) / tau) * U[j] for j in range(1, n + 1))
                r += k * (Kmm @ acc)
        force_cart = np.einsum("aij,aj->ai", bnd.frame, sol.contact_force[n])
        fscale = np.abs(f).max() if t > 0 else 1.0
        # Tolerance: the step solver stops at a relative projected residual
        # 1e-10 (solver.tol) of the force scale; 1e-8 leaves a factor 100.
        assert np.abs(r[other]).max() <= 1e-8 * fscale
        assert np.abs(r[cdofs] - force_cart).max() <= 1e-8 * fscale

        F_applied, M_applied = exact_resultants(t)
        RD = np.array([r[D[D % 2 == 0]].sum(), r[D[D % 2 == 1]].sum()])
        FC = force_cart.sum(axis=0)
        MD = np.sum(x[D[D % 2 == 1] // 2] * r[D[D % 2 == 1]]) - \
            np.sum(y[D[D % 2 == 0] // 2] * r[D[D % 2 == 0]])
        MC = np.sum(x[bnd.nodes] * force_cart[:, 1] - y[bnd.nodes] * force_cart[:, 0])
        scale = max(np.abs(F_applied).max(), 1.0)
        # Tolerance: as above (force balance holds exactly for the discrete
        # equations since rigid motions are in the kernel of K; the applied
        # resultants are exact for P1 test functions summing to 1 and x, y
        # interpolated exactly).
        np.testing.assert_allclose(RD + FC + F_applied, 0.0, atol=1e-8 * scale)
        # moments about the origin, scaled by |M| + L |F| (L = 2 the length)
        assert abs(MD + MC + M_applied) <= 1e-8 * (abs(M_applied) + 2.0 * scale)

        # the wall: u_ν ≤ g at every contact node
        u_nodes = sol.u[n][bnd.nodes]
        u_nu = np.sum(u_nodes * normals, axis=1)
        g = sol.gap[n]
        np.testing.assert_allclose(g, 0.004 + 0.004 * x[bnd.nodes] * (2 - x[bnd.nodes]),
                                   rtol=1e-14)
        assert np.all(u_nu <= g + 1e-10)
        checked_wall |= bool(np.any(np.isclose(u_nu, g, rtol=0, atol=1e-12)))
        checked_compliance |= bool(np.any((u_nu > 1e-9) & (u_nu < g - 1e-9)))
    # the run exercised both the wall and the compliance
    assert checked_wall and checked_compliance
