"""The step methods in 3D: a frictional step against an independent
minimisation of its energy, and a glued block whose slipping nodes turn.

Setting: the box [0, 2] × [0, 0.5] × [0, 1], 4 × 2 × 2 cells (tetrahedra),
top (y = 0.5) clamped, bottom (y = 0) = Γ_C with ν = (0, −1, 0), so that
u_ν = −u_y and u_τ = (u_x, u_z) at the contact nodes. E = 1000, ν = 0.3,
one step, no memory, β ≡ 1. A body force presses the middle of the block
onto a wall behind the gap g = g0 + g1 x, lifts its ends (where the
adhesive pulls back) and shears it in x and z, so that the step has nodes
on the wall, in adhesion (−L < u_ν < 0), sticking and slipping.

With the nodal rule each contact node a carries w_a = Σ_{facets ∋ a} |f|/3
and the step minimises over the free dofs

    J(u) = ½ uᵀ K u − fᵀ u + Σ_a w_a [P_ν(u_ν,a) + μ |u_τ,a|],  u_ν,a ≤ g_a,

P_ν the adhesive-compliance potential (P_ν' = c r_+ + γ clip(r, −L, 0)) and
μ |·| Tresca's friction. K (scikit-fem's linear_elasticity), f, w_a, P_ν
are built here, and J is minimised by FISTA with adaptive restart on the
FULL free-dof vector: a gradient step on the smooth part, then the exact
proximal map of the rest (block soft-thresholding of (u_x, u_z) by t w_a μ,
projection of u_y onto u_y ≥ −g_a). Nothing of the library's frames, Schur
complement or Newton method is used.
"""

import numpy as np
from conftest import glued_contact, law, prony, scene_dict
from skfem import Basis, ElementTetP1, ElementVector, LinearForm, MeshTet, asm
from skfem.models.elasticity import lame_parameters, linear_elasticity

from adhesive_contact import build_problem, scene_from_dict, solve
from adhesive_contact.postprocess import contact_state_counts


E, NU = 1000.0, 0.3
SX, SZ = 60.0, 40.0
SIZE, CELLS = (2.0, 0.5, 1.0), (4, 2, 2)
C, GAMMA, L, MU = 1.0e4, 200.0, 0.01, 10.0
G0, G1 = 0.001, 0.0005
BODY = ("SX*x*z", "-600 + 1000*(x - 1)**2", "SZ*x")   # polynomial: both rules exact


def body(x, y, z):
    return SX * x * z, -600 + 1000 * (x - 1) ** 2, SZ * x


def library_step():
    scene = scene_dict({
        "dim": 3, "mesh": {"domain": "box", "size": list(SIZE), "cells": list(CELLS)},
        "material": {"E": E, "nu": NU}, "loads.body": [b.replace("SX", str(SX)).replace("SZ", str(SZ))
                                          for b in BODY],
        "contact.gap": f"{G0} + {G1}*x",
        "contact.normal": law("adhesive_compliance", c=C, gamma=GAMMA, L=L),
        "contact.friction": [law("tresca", mu=MU)],
        "solver": {"tol": 1e-13}})
    problem = build_problem(scene_from_dict(scene))
    solution = solve(problem)
    assert solution.success
    return problem, solution.u[-1].ravel()


class Reference:
    def __init__(self):
        axes = [np.linspace(0.0, s, n + 1) for s, n in zip(SIZE, CELLS)]
        mesh = MeshTet.init_tensor(*axes)
        self.mesh = mesh
        basis = Basis(mesh, ElementVector(ElementTetP1()), intorder=6)
        K = asm(linear_elasticity(*lame_parameters(E, NU)), basis).toarray()

        @LinearForm
        def load(v, w):
            fx, fy, fz = body(*w.x)
            return fx * v[0] + fy * v[1] + fz * v[2]
        f = asm(load, basis)
        p = mesh.p
        bottom = mesh.facets[:, np.flatnonzero(
            np.all(np.abs(p[1, mesh.facets]) < 1e-12, axis=0))]
        clamped = np.flatnonzero(np.abs(p[1] - SIZE[1]) < 1e-12)
        area = 0.5 * np.linalg.norm(np.cross(p[:, bottom[1]] - p[:, bottom[0]],
                                             p[:, bottom[2]] - p[:, bottom[0]], axis=0), axis=0)
        w = np.zeros(p.shape[1])
        for i in range(3):
            np.add.at(w, bottom[i], area / 3)
        self.nodes = np.setdiff1d(np.unique(bottom), clamped)
        self.w = w[self.nodes]
        self.g = G0 + G1 * p[0, self.nodes]
        free = np.setdiff1d(np.arange(K.shape[0]), np.concatenate([3 * clamped + c
                                                                   for c in range(3)]))
        pos = np.full(K.shape[0], -1)
        pos[free] = np.arange(free.size)
        self.free, self.K, self.f = free, K[np.ix_(free, free)], f[free]
        self.X, self.Y, self.Z = (pos[3 * self.nodes + c] for c in range(3))
        self.lipschitz = np.linalg.eigvalsh(self.K)[-1] + self.w.max() * max(C, GAMMA)

    def smooth_gradient(self, u):
        g = self.K @ u - self.f
        r = -u[self.Y]                                      # u_ν
        g[self.Y] -= self.w * (C * np.maximum(r, 0.0) + GAMMA * np.clip(r, -L, 0.0))
        return g

    def prox(self, v, t):
        u = v.copy()
        tau = np.stack([v[self.X], v[self.Z]])
        norm = np.linalg.norm(tau, axis=0)
        shrink = np.maximum(1.0 - t * self.w * MU / np.where(norm > 0, norm, 1.0), 0.0)
        u[self.X], u[self.Z] = shrink * tau
        u[self.Y] = np.maximum(v[self.Y], -self.g)          # u_ν ≤ g
        return u

    def minimise(self, iterations=10000):
        t = 1.0 / self.lipschitz
        u = y = np.zeros(self.free.size)
        theta = 1.0
        for _ in range(iterations):
            u_new = self.prox(y - t * self.smooth_gradient(y), t)
            if (y - u_new) @ (u_new - u) > 0:               # restart (O'Donoghue–Candès)
                theta, y = 1.0, u
                continue
            theta_new = 0.5 * (1 + np.sqrt(1 + 4 * theta ** 2))
            y = u_new + (theta - 1) / theta_new * (u_new - u)
            u, theta = u_new, theta_new
        full = np.zeros(3 * self.mesh.p.shape[1])
        full[self.free] = u
        return full


def test_3d_frictional_step_equals_independent_minimiser():
    problem, u = library_step()
    ref = Reference()
    np.testing.assert_array_equal(problem.mesh.p, ref.mesh.p)
    u_ref = ref.minimise()
    scale = np.abs(u_ref).max()
    assert np.abs(u - u_ref).max() <= 1e-8 * scale
    # the step has every regime: wall, adhesion, separation beyond L, stick and slip
    un = -u_ref[3 * ref.nodes + 1]
    slip = np.hypot(u_ref[3 * ref.nodes], u_ref[3 * ref.nodes + 2])
    on_wall = np.abs(un - ref.g) <= 1e-12
    glued = (un < 0) & (un > -L)
    assert on_wall.sum() >= 1 and glued.sum() >= 1
    assert (slip == 0).sum() >= 1 and (slip > 1e-6 * scale).sum() >= 1


# ----------------------------------------------------------------
# The step solve in 3D, where a slipping node has two tangential
# components: a glued block with memory, adhesive compliance, slip weakening
# and an adhesive spring, Frémond bonding and a wall, pulled and lifted at
# its free end (the scene of the 3D stall: with the slip direction of a node
# leaving the kink not held, step 16 cycled between two iterates until the
# iteration limit).


BLOCK_3D = scene_dict({
    "dim": 3,
    "mesh": {"domain": "box", "size": [4.0, 1.0, 2.0], "cells": [24, 12, 6]},
    "boundary": {"dirichlet": ["left"], "contact": ["bottom"]},
    "memory": prony((200.0, 0.3, 0.5)),
    "loads": {"traction": {"right": ["7*t", "14*t", "0"]}},
    "contact": glued_contact(),
    "time": {"T": 1.0, "steps": 20},
})


def test_glued_block_in_3d_converges_every_step():
    problem = build_problem(scene_from_dict(BLOCK_3D))
    assert problem.ndofs == 6825 and problem.dim == 3
    sol = solve(problem)
    assert sol.success, sol.message
    assert np.all(sol.residual <= problem.scene.solver.tol)
    # the run does what the scene is for: the glue lets go near the pulled end
    # while stick and slip coexist on Γ_C
    assert sol.beta[-1].min() < 0.5 < sol.beta[-1].max()
    states = contact_state_counts(sol)
    assert states["stick"].max() > 0 and states["slip"].max() > 0
