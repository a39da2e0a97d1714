"""The step solver against an independent minimisation of the same discrete
energy (docs/scheme.md ('What a step solves')) with scipy's L-BFGS-B, and the sign and
complementarity of the wall multiplier.

Setting: [0, 2] x [0, 0.5], 16 x 8 cells, top (or left) clamped, bottom = Γ_C with
outward normal ν = (0, −1), so u_ν = −u_y and the wall u_ν ≤ g is the box
bound u_y ≥ −g. A frictionless normal compliance p_ν = c (u_ν)_+ and one
time step (T = 1, N = 1; u_1 solves the problem at t = 1 with no memory).
The load pushes part of Γ_C onto the wall and lifts another part, so the
contact nodes fall into all three sets: on the wall, in compliance
(0 < u_ν < g) and separated (u_ν ≤ 0); the tests assert that each is
non-empty.

Reference energy, assembled here from scikit-fem alone, over the free dofs:

    J(u) = ½ uᵀ K u − fᵀ u + (c/2) Σ_q W_q ((N u)_q)_+²,   u_y ≥ −g at Γ_C,

with (N u)_q = u_ν at the quadrature point q: the contact nodes with the
lumped weights W_a = ∫_Γ_C φ_a (nodal rule), or the 3-point Gauss–Legendre
points of each facet with u_ν the P1 interpolant (Gauss rule).
"""

import numpy as np
import pytest
import scipy.sparse as sp
from conftest import (
    clamped_dofs,
    law,
    load_vector,
    reference_mesh,
    relative_max,
    run,
    same_mesh,
    scene_dict,
    stiffness,
)
from scipy.optimize import minimize
from skfem import ElementTriP1, FacetBasis, LinearForm, asm

E, NU, C = 1000.0, 0.3, 2000.0
SIZE, CELLS = (2.0, 0.5), (16, 8)
# name -> (gap expression, gap(x), clamped side, body f_y expression, f_y(x))
# "constant"/"varying": top clamped, the middle pressed, the ends lifted;
# "corner": a cantilever clamped on the left, so the corner (0, 0) is both
# clamped and on Γ_C (a contact node with no unknowns, u = 0, whose
# contact force, p_ν(β, 0) = 0, is in the reaction; the Gauss rule
# integrates over its facet with u = 0 there).
PRESS = ("-400*t*(1.2 - 2.5*(x - 1)**2)", lambda x: -400.0 * (1.2 - 2.5 * (x - 1) ** 2))
CASES = {
    "constant": ("0.01", lambda x: 0.01 + 0 * x, "top") + PRESS,
    "varying": ("0.005 + 0.01*x", lambda x: 0.005 + 0.01 * x, "top") + PRESS,
    "corner": ("0.01", lambda x: 0.01 + 0 * x, "left",
               "-100*t*(x - 0.6)", lambda x: -100.0 * (x - 0.6)),
}


def scene(case, quadrature):
    # The body loads are polynomials (degree ≤ 2), integrated exactly by the
    # library's rule and by ours, so both minimise the same energy.
    gap, _, clamped, load, _ = CASES[case]
    return scene_dict({
        "mesh.size": list(SIZE), "mesh.cells": list(CELLS), "boundary.dirichlet": [clamped],
        "material": {"E": E, "nu": NU}, "loads.body": ["0", load],
        "contact": {"gap": gap, "quadrature": quadrature, "order": 4,
                    "normal": law("compliance", c=C)}})


def _sq_diff(s, q):
    """max(s + q, 0)² − max(s, 0)², without the cancellation of the naive
    difference (needed for the energy of small corrections)."""
    sq = s + q
    return np.where(s > 0, np.where(sq > 0, q * (2 * s + q), -s * s),
                    np.where(sq > 0, sq * sq, 0.0))


class Reference:
    """The discrete problem assembled here, and its L-BFGS-B minimiser."""

    def __init__(self, case, quadrature):
        _, gap_func, clamped, _, load = CASES[case]
        mesh = reference_mesh(SIZE, CELLS)
        self.mesh = mesh
        self.K = stiffness(mesh, E, NU)
        self.f = load_vector(mesh, body=lambda x, y: (0 * x, load(x)))
        D = clamped_dofs(mesh, [clamped])
        self.free = np.setdiff1d(np.arange(self.K.shape[0]), D)
        pos = np.full(self.K.shape[0], -1)
        pos[self.free] = np.arange(self.free.size)
        self.Kf = self.K[self.free][:, self.free].tocsr()
        self.ff = self.f[self.free]
        x, y = mesh.p
        self.nodes = np.setdiff1d(np.flatnonzero(np.isclose(y, 0.0)), D // 2)
        self.ycol = pos[2 * self.nodes + 1]          # u_y of the contact nodes
        self.gap = gap_func(x[self.nodes])
        nfree = self.free.size
        if quadrature == "nodal":
            # lumped weights W_a = ∫_Γ_C φ_a (scalar P1 facet basis)
            w = asm(LinearForm(lambda v, w: v),
                    FacetBasis(mesh, ElementTriP1(), facets=mesh.boundaries["bottom"]))
            self.W = w[self.nodes]
            self.N = sp.csr_matrix((-np.ones(self.nodes.size),
                                    (np.arange(self.nodes.size), self.ycol)),
                                   shape=(self.nodes.size, nfree))
        else:
            # 3-point Gauss–Legendre on each bottom facet (exact to degree 5,
            # the rule of exactness 4), u_ν = −(φ_0 u_y,a + φ_1 u_y,b)
            X, Wg = np.polynomial.legendre.leggauss(3)
            X, Wg = (X + 1) / 2, Wg / 2
            facets = mesh.facets[:, mesh.boundaries["bottom"]]
            length = np.abs(x[facets[1]] - x[facets[0]])
            rows, cols, vals, W = [], [], [], []
            q = 0
            for a, b, h in zip(facets[0], facets[1], length):
                for xi, wq in zip(X, Wg):
                    for node, phi in ((a, 1 - xi), (b, xi)):
                        if pos[2 * node + 1] >= 0:
                            rows.append(q)
                            cols.append(pos[2 * node + 1])
                            vals.append(-phi)
                    W.append(wq * h)
                    q += 1
            self.W = np.array(W)
            self.N = sp.csr_matrix((vals, (rows, cols)), shape=(q, nfree))
        # Jacobi scaling v = √diag(K) u keeps the bounds a box and helps L-BFGS-B
        self.sc = 1.0 / np.sqrt(self.Kf.diagonal())

    def energy(self, uf):
        p = np.maximum(self.N @ uf, 0.0)
        return 0.5 * uf @ (self.Kf @ uf) - self.ff @ uf + 0.5 * C * self.W @ p**2

    def gradient(self, uf):
        return self.Kf @ uf - self.ff + C * (self.N.T @ (self.W * np.maximum(self.N @ uf, 0.0)))

    def _lbfgsb(self, u0, **options):
        """Minimise J(u0 + δ) − J(u0) over δ with L-BFGS-B. Written as an
        increment so that energy differences keep full precision near the
        minimum (the plain energy is resolved only to ~1e-16 |J|, which
        caps the accuracy of u at ~√ε_mach ≈ 1e-8)."""
        sc, N = self.sc, self.N
        r0 = self.Kf @ u0 - self.ff
        s0 = N @ u0

        def fun(v):
            d = v * sc
            Kd = self.Kf @ d
            Nd = N @ d
            J = 0.5 * d @ Kd + r0 @ d + 0.5 * C * self.W @ _sq_diff(s0, Nd)
            g = Kd + r0 + C * (N.T @ (self.W * np.maximum(s0 + Nd, 0.0)))
            return J, g * sc

        lower = np.full(u0.size, -np.inf)
        lower[self.ycol] = (-self.gap - u0[self.ycol]) / sc[self.ycol]
        bounds = list(zip(lower, np.full(u0.size, np.inf)))
        res = minimize(fun, np.zeros(u0.size), jac=True, method="L-BFGS-B", bounds=bounds,
                       options=dict(maxiter=100000, maxfun=200000, maxcor=50, **options))
        u = u0 + res.x * sc
        u[self.ycol] = np.maximum(u[self.ycol], -self.gap)  # exactly feasible
        return u

    def minimise(self):
        u = self._lbfgsb(np.zeros(self.free.size), ftol=1e-16, gtol=1e-14)
        for _ in range(2):   # increments from the current point: full precision
            u = self._lbfgsb(u, ftol=0.0, gtol=0.0)
        full = np.zeros(self.K.shape[0])
        full[self.free] = u
        return full


@pytest.fixture(scope="module")
def cases():
    """Library runs and reference minimisers, computed once per case."""
    out = {}
    for quadrature in ("nodal", "gauss"):
        for case in CASES:
            problem, sol = run(scene(case, quadrature))
            ref = Reference(case, quadrature)
            out[quadrature, case] = (problem, sol, ref, ref.minimise())
    return out


def _sets(u_nu, gap):
    on_wall = np.isclose(u_nu, gap, rtol=0, atol=1e-12)
    compliance = (u_nu > 0) & ~on_wall
    separated = u_nu <= 0
    return on_wall, compliance, separated


@pytest.mark.parametrize("quadrature, tol", [("nodal", 1e-8), ("gauss", 1e-7)])
@pytest.mark.parametrize("case", list(CASES))
def test_step_equals_independent_minimiser(cases, quadrature, tol, case):
    problem, sol, ref, u_ref = cases[quadrature, case]
    same_mesh(problem, ref.mesh)
    unheld = ~problem.boundary.held.all(axis=1)   # the clamped corner has no unknowns
    np.testing.assert_array_equal(np.sort(problem.boundary.nodes[unheld]), ref.nodes)
    assert unheld.sum() == unheld.size - (case == "corner")
    np.testing.assert_allclose(sol.gap[1][unheld], ref.gap, rtol=1e-14)
    u = sol.u[1].ravel()

    # all three contact states occur (in the reference and in the run)
    for uu in (u_ref, u):
        wall, comp, sep = _sets(-uu[2 * ref.nodes + 1], ref.gap)
        assert wall.any() and comp.any() and sep.any()
        assert np.all(-uu[2 * ref.nodes + 1] <= ref.gap + 1e-12)

    # Tolerance: the brief's 1e-8 (nodal) / 1e-7 (Gauss), in the max norm
    # and in the energy norm. Both solutions are KKT points of one strongly
    # convex problem, to ~1e-14 (library: Newton to a 1e-10 relative
    # residual, finite termination on this piecewise quadratic energy;
    # reference: L-BFGS-B refined in increments), so the margin is wide.
    assert relative_max(u, u_ref) < tol
    e = u - u_ref
    assert np.sqrt(e @ (ref.K @ e)) < tol * np.sqrt(u_ref @ (ref.K @ u_ref))
    # u minimises J: its energy is not above the reference's (round-off
    # of J: 1e-14 |J|)
    J, J_ref = ref.energy(u[ref.free]), ref.energy(u_ref[ref.free])
    assert J <= J_ref + 1e-14 * abs(J_ref)


@pytest.mark.parametrize("quadrature", ["nodal", "gauss"])
@pytest.mark.parametrize("case", list(CASES))
def test_wall_multiplier(cases, quadrature, case):
    """λ_a = −(force of Γ_C on the body)_ν − (compliance reaction)_a is the
    wall's reaction: λ ≥ 0, λ = 0 off the wall, u_ν = g on it."""
    problem, sol, ref, _ = cases[quadrature, case]
    bnd = problem.boundary
    unheld = ~bnd.held.all(axis=1)   # the clamped corner: its force is in the reaction
    assert np.all(sol.contact_force[1][~unheld] == 0) and not sol.on_wall[1][~unheld].any()
    order = np.flatnonzero(unheld)[np.argsort(bnd.nodes[unheld])]
    u = sol.u[1].ravel()
    uf = u[ref.free]
    # residual of the discrete equations at the contact nodes, from our K:
    # K u − f = force of Γ_C on the body (zero at the other free dofs)
    r = ref.K @ u - ref.f
    scale = np.abs(ref.f).max()
    # Tolerance: the solver stops at a 1e-10 relative projected residual.
    other = np.setdiff1d(ref.free, np.concatenate([2 * ref.nodes, 2 * ref.nodes + 1]))
    assert np.abs(r[other]).max() <= 1e-8 * scale
    force = np.stack([r[2 * ref.nodes], r[2 * ref.nodes + 1]], axis=1)
    # the library's contact force (nodal frames) agrees once rotated back
    lib_force = np.einsum("aij,aj->ai", bnd.frame, sol.contact_force[1])[order]
    assert np.abs(lib_force - force).max() <= 1e-8 * scale
    # frictionless: no tangential force (τ = ±e_x on the bottom)
    assert np.abs(sol.contact_force[1][:, 1]).max() <= 1e-8 * scale

    nu = np.array([0.0, -1.0])
    u_nu = -u[2 * ref.nodes + 1]
    # compliance reaction per node, ∂/∂u_ν of (c/2) Σ_q W_q (u_ν)_+² (the
    # nodal ν component of the gradient; N has −φ_a in the u_y columns)
    compliance = -(C * (ref.N.T @ (ref.W * np.maximum(ref.N @ uf, 0.0))))[
        ref.ycol]
    lam = -(force @ nu) - compliance
    wall = sol.on_wall[1][order]
    # u_ν = g exactly on the wall (the projection sets it), ≤ g elsewhere
    assert wall.any()
    assert np.abs(u_nu[wall] - ref.gap[wall]).max() <= 1e-12
    assert np.all(u_nu[~wall] < ref.gap[~wall])
    # Tolerance for λ: residual level, 1e-8 of the force scale.
    assert np.all(lam >= -1e-8 * scale)
    assert np.abs(lam[~wall]).max() <= 1e-8 * scale
    assert lam[wall].max() > 1e-3 * scale      # the wall really pushes
