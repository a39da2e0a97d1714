"""Friction (docs/scheme.md ('What a step solves')–§6) against independent computations.

Setting: [0, 2] x [0, 0.5], 16 x 4 cells, top clamped, bottom = Γ_C with
ν = (0, −1), τ = (1, 0), so u_ν = −u_y and u_τ = u_x at the contact nodes.
Plane strain, E = 1000, ν = 0.3. A body force (f_x, f_y) = (s x, −p) presses
the strip onto its foundation and shears it more and more towards x = 2, so
Tresca and slip-weakening friction hold the nodes near x = 0 (stick,
u_τ = 0) and let those near x = 2 slip. One time step, no memory, β ≡ 1.

With the nodal rule each contact node a carries the weight
w_a = Σ_{facets f ∋ a} |f|/2 and the step (docs/scheme.md ('What a step solves')) minimises, over the
free dofs u,

    J(u) = ½ uᵀ K u − fᵀ u + Σ_a w_a [P_ν(−u_{y,a}) + φ(|u_{x,a}|)],

φ the radial friction potential. Here K (scikit-fem's linear_elasticity with
lame_parameters), f, w_a, P_ν and φ are all built in this file (conftest for
K and f), and J is minimised by scipy's L-BFGS-B over the FULL free-dof
vector: nothing of the library's Schur complement, frames or Newton solver
is used.
"""

import numpy as np
import pytest
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
from scipy.sparse.linalg import spsolve

from adhesive_contact import StepFailure, build_problem, scene_from_dict, solve
from adhesive_contact.postprocess import contact_state_counts
from adhesive_contact.scheme import STEP_FAILED, STOPPED
from adhesive_contact.step_methods import MAX_ITERATIONS

E, NU, C = 1000.0, 0.3, 1.0e4
SIZE, CELLS = (2.0, 0.5), (16, 4)


def scene(friction, body, normal=None, steps=1, solver=None):
    """A scene of the setting; ``friction`` a list of law tables."""
    changes = {"mesh.size": list(SIZE), "mesh.cells": list(CELLS),
               "material": {"E": E, "nu": NU}, "loads.body": list(body),
               "contact.normal": normal or law("compliance", c=C),
               "contact.friction": friction, "time.steps": steps}
    if solver:
        changes["solver"] = solver
    return scene_dict(changes)


# --------------------------------------------------------------------------
# The laws, written here from docs/model.md §4 (not imported from the library).
# Each gives h(s), h'(s) and the increment h(s0 + ds) − h(s0) computed
# without forming h(s0) (see Reference._increment): by default the integral
# of h' over [s0, s0 + ds], Gauss–Legendre (8 points, exact to degree 15) on
# the pieces between the breakpoints of h', so exact for the piecewise
# polynomial laws and to ~1e-18 for the exponential of slip weakening.
# --------------------------------------------------------------------------

_XG, _WG = np.polynomial.legendre.leggauss(8)
_XG, _WG = (_XG + 1) / 2, _WG / 2


def _integral(dh, x0, dx, breaks):
    """∫_{x0}^{x0+dx} dh, the pieces written as offsets from x0."""
    x0, dx = np.broadcast_arrays(np.asarray(x0, float), np.asarray(dx, float))
    safe = np.where(dx != 0, dx, 1.0)
    theta = [np.zeros_like(x0), np.ones_like(x0)]
    theta += [np.clip((b - x0) / safe, 0.0, 1.0) for b in breaks]
    theta = np.sort(np.stack(theta), axis=0)
    out = np.zeros_like(x0)
    for lo, hi in zip(theta[:-1], theta[1:]):
        for xg, wg in zip(_XG, _WG):
            out += wg * (hi - lo) * dh(x0 + dx * (lo + (hi - lo) * xg))
    return dx * out


class _Law:
    breaks = ()
    kink = False        # φ'(0+) > 0: a friction bound at ξ = 0
    nonconvexity = 0.0  # m with φ'' ≥ −m

    def diff(self, s0, ds):
        return _integral(self.dh, s0, ds, self.breaks)


class Tresca(_Law):
    kink = True

    def __init__(self, mu):
        self.mu = mu

    def h(self, s):
        return self.mu * s

    def dh(self, s):
        return self.mu + 0.0 * s


class SlipWeakening(_Law):
    kink = True

    def __init__(self, a, b, alpha):
        self.a, self.b, self.alpha = a, b, alpha
        self.nonconvexity = alpha * (a - b)

    def h(self, s):   # ∫_0^s [(a − b) e^{−α t} + b] dt
        return self.b * s + (self.a - self.b) * (1.0 - np.exp(-self.alpha * s)) / self.alpha

    def dh(self, s):
        return (self.a - self.b) * np.exp(-self.alpha * s) + self.b


class Power(_Law):
    def __init__(self, mu, q):
        self.mu, self.q = mu, q

    def h(self, s):
        return self.mu * s ** (1 + self.q) / (1 + self.q)

    def dh(self, s):
        return self.mu * s ** self.q

    def diff(self, s0, ds):
        # h' = μ s^q is not polynomial at 0: the closed form, through
        # expm1/log1p when |ds| < s0 (else h(s0) ≤ h(|ds|) and the plain
        # difference loses nothing)
        e = 1.0 + self.q
        near = (s0 > 0) & (np.abs(ds) < s0)
        rel = np.where(near, ds / np.where(s0 > 0, s0, 1.0), 0.0)
        return np.where(near, self.mu / e * s0 ** e * np.expm1(e * np.log1p(rel)),
                        self.h(s0 + ds) - self.h(s0))


class Spring(_Law):
    """γ s²/2 up to L, then linear: h' = γ min(s, L) (β = 1)."""

    def __init__(self, gamma, L):
        self.gamma, self.L, self.breaks = gamma, L, (L,)

    def h(self, s):
        return self.gamma * np.where(s <= self.L, 0.5 * s * s, self.L * s - 0.5 * self.L ** 2)

    def dh(self, s):
        return self.gamma * np.minimum(s, self.L)


class Sum(_Law):
    def __init__(self, *laws):
        self.laws = laws
        self.kink = any(law.kink for law in laws)
        self.nonconvexity = sum(law.nonconvexity for law in laws)

    def h(self, s):
        return sum(law.h(s) for law in self.laws)

    def dh(self, s):
        return sum(law.dh(s) for law in self.laws)

    def diff(self, s0, ds):
        return sum(law.diff(s0, ds) for law in self.laws)


class Compliance(_Law):
    """P_ν = c r_+²/2."""

    def __init__(self, c):
        self.c, self.breaks = c, (0.0,)

    def h(self, r):
        return 0.5 * self.c * np.maximum(r, 0.0) ** 2

    def dh(self, r):
        return self.c * np.maximum(r, 0.0)


class AdhesiveCompliance(_Law):
    """P_ν with p_ν = c r_+ − γ β² R_ν(r), β = 1: P_ν' = c r_+ + γ clip(r, −L, 0)."""

    def __init__(self, c, gamma, L):
        self.c, self.gamma, self.L, self.breaks = c, gamma, L, (-L, 0.0)

    def h(self, r):
        glue = np.where(r > 0, 0.0, np.where(r >= -self.L, 0.5 * r * r,
                                             -self.L * r - 0.5 * self.L ** 2))
        return 0.5 * self.c * np.maximum(r, 0.0) ** 2 + self.gamma * glue

    def dh(self, r):
        return self.c * np.maximum(r, 0.0) + self.gamma * np.clip(r, -self.L, 0.0)


# --------------------------------------------------------------------------
# The reference minimiser
# --------------------------------------------------------------------------

class Reference:
    """J assembled here and minimised with L-BFGS-B over all free dofs.

    Kinked laws (Tresca, slip weakening): φ(|x|) is not differentiable at
    x = 0, so each contact x-dof is split, u_{x,a} = p_a − m_a with
    p_a, m_a ≥ 0 (bounds), and the friction term is w_a φ(p_a + m_a), which
    is smooth. This is the same problem: for fixed u_{x,a} = p − m,
    p + m ≥ |p − m| with equality iff min(p, m) = 0, and φ is increasing, so
    min over the split of φ(p + m) is φ(|u_{x,a}|); and no KKT point of the
    split problem has p_a, m_a > 0 both (∂_p + ∂_m = 2 w_a φ'(p + m) > 0),
    so its KKT points are exactly the Clarke stationary points of J, and J
    is strictly convex here (checked in the test), so there is one.
    Smooth laws (power, adhesive spring): φ(|x|) is C¹ (φ'(0) = 0), used as
    it is.

    Scaling: unknowns v = √diag(K) u (Jacobi: O(1) curvature per unknown)
    and J divided by an energy scale, so that L-BFGS-B's absolute tests
    mean something. Then two more runs minimise J(y + δ) − J(y) over δ,
    the increment evaluated without forming J(y) (the quadratic part as
    ½ δᵀKδ + (Ky − f)ᵀδ, the contact parts by `diff`), which removes the
    ~1e-16 |J| round-off floor that would otherwise limit u to ~1e-8.
    """

    def __init__(self, body, normal, friction):
        mesh = reference_mesh(SIZE, CELLS)
        self.mesh = mesh
        self.K = stiffness(mesh, E, NU)
        self.f = load_vector(mesh, body=body)
        D = clamped_dofs(mesh, ["top"])
        self.free = np.setdiff1d(np.arange(self.K.shape[0]), D)
        pos = np.full(self.K.shape[0], -1)
        pos[self.free] = np.arange(self.free.size)
        self.Kf = self.K[self.free][:, self.free].tocsr()
        self.ff = self.f[self.free]
        # nodal weights w_a = Σ over the bottom facets at a of |f|/2
        bottom = mesh.facets[:, mesh.boundaries["bottom"]]
        length = np.linalg.norm(mesh.p[:, bottom[1]] - mesh.p[:, bottom[0]], axis=0)
        w = np.zeros(mesh.p.shape[1])
        np.add.at(w, bottom[0], length / 2)
        np.add.at(w, bottom[1], length / 2)
        self.nodes = np.setdiff1d(np.unique(bottom), D // 2)
        self.w = w[self.nodes]
        self.xcol, self.ycol = pos[2 * self.nodes], pos[2 * self.nodes + 1]
        self.normal, self.friction = normal, friction
        self.split = friction.kink
        self.n = self.free.size
        sc = 1.0 / np.sqrt(self.Kf.diagonal())
        self.sc = np.concatenate([sc, sc[self.xcol]]) if self.split else sc
        # energy scale: the elastic energy of the load, fᵀK⁻¹f
        self.E0 = float(self.ff @ spsolve(self.Kf.tocsc(), self.ff))

    def displacement(self, y):
        """Free-dof u of the unknowns y (y = u, or (u with p at the x-dofs, m))."""
        u = y[:self.n].copy()
        if self.split:
            u[self.xcol] = y[self.xcol] - y[self.n:]
        return u

    def _increment(self, y0, d):
        """J(y0 + d) − J(y0) and its gradient in y, without forming J(y0)."""
        X, Y, w = self.xcol, self.ycol, self.w
        u0, du = self.displacement(y0), self.displacement(d)
        Kdu = self.Kf @ du
        r0 = self.Kf @ u0 - self.ff
        J = 0.5 * du @ Kdu + r0 @ du
        g = Kdu + r0
        rn0, drn = -u0[Y], -du[Y]          # u_ν = −u_y
        J += w @ self.normal.diff(rn0, drn)
        g[Y] -= w * self.normal.dh(rn0 + drn)
        if self.split:
            s0, ds = y0[X] + y0[self.n:], d[X] + d[self.n:]
            J += w @ self.friction.diff(s0, ds)
            bound = w * self.friction.dh(s0 + ds)
            gx = g[X].copy()
            g = np.concatenate([g, -gx + bound])
            g[X] = gx + bound
        else:
            x0, x1 = u0[X], u0[X] + du[X]
            # |x1| − |x0| exactly when no sign change; else |dx| > |x0|
            ds = np.where(x0 * x1 > 0, np.sign(x0) * du[X], np.abs(x1) - np.abs(x0))
            J += w @ self.friction.diff(np.abs(x0), ds)
            g[X] += w * np.sign(x1) * self.friction.dh(np.abs(x1))
        return J, g

    def _lbfgsb(self, y0, **tolerances):
        sc = self.sc
        lower = np.full(y0.size, -np.inf)
        if self.split:
            lower[self.xcol] = 0.0
            lower[self.n:] = 0.0

        def fun(v):
            J, g = self._increment(y0, v * sc)
            return J / self.E0, g * sc / self.E0

        res = minimize(fun, np.zeros(y0.size), jac=True, method="L-BFGS-B",
                       bounds=list(zip((lower - y0) / sc, np.full(y0.size, np.inf))),
                       options=dict(maxiter=50000, maxfun=100000, maxcor=50, **tolerances))
        y = y0 + res.x * sc
        if self.split:      # exactly feasible (and exact zeros where the bound is active)
            y[self.xcol] = np.maximum(y[self.xcol], 0.0)
            y[self.n:] = np.maximum(y[self.n:], 0.0)
        return y

    def minimise(self):
        y = self._lbfgsb(np.zeros(self.sc.size), ftol=1e-15, gtol=1e-12)
        for _ in range(2):   # in increments from the current point: full precision
            y = self._lbfgsb(y, ftol=0.0, gtol=0.0)
        u = np.zeros(self.K.shape[0])
        u[self.free] = self.displacement(y)
        return u

    def kkt_residual(self, u):
        """Max violation of the first-order conditions of J at u (force units):
        ∇J = 0 off the contact x-dofs; at a contact x-dof, the smooth part's
        derivative g_a is −w_a φ'(|u_x|) sign(u_x) if u_x ≠ 0 and lies in
        [−w_a φ'(0+), w_a φ'(0+)] if u_x = 0."""
        uf = u[self.free]
        g = self.Kf @ uf - self.ff
        g[self.ycol] -= self.w * self.normal.dh(-uf[self.ycol])
        x = uf[self.xcol]
        gx = g[self.xcol]
        g[self.xcol] = np.where(x != 0, gx + self.w * np.sign(x) * self.friction.dh(np.abs(x)),
                                np.maximum(np.abs(gx) - self.w * self.friction.dh(0.0 * x), 0))
        return np.abs(g).max()

    def min_curvature(self):
        """λ_min of K_ff − m diag(w) on the contact x-dofs, m the friction's
        nonconvexity (φ'' ≥ −m): > 0 makes J strictly convex (the normal
        law and the kink are convex), so its minimiser is unique."""
        H = self.Kf.toarray()
        H[self.xcol, self.xcol] -= self.friction.nonconvexity * self.w
        return np.linalg.eigvalsh(H)[0]


# --------------------------------------------------------------------------
# Cases: (normal law table, [friction law tables], body, normal, friction)
# --------------------------------------------------------------------------

COMPLIANCE = law("compliance", c=C)
ADHESIVE = law("adhesive_compliance", c=C, gamma=5000.0, L=0.0005)
TRESCA = law("tresca", mu=10.0)
WEAKENING = law("nonmonotone", a=10.0, b=8.5, alpha=200.0)
POWER = law("power", mu=100.0, q=0.5)
SPRING = law("adhesive_spring", gamma=1000.0, L=0.01)
# the body force, as the scene's strings and as a function for load_vector
PRESS = (("40*x", "-40"),           # sheared towards x = 2, pressed everywhere
         lambda x, y: (40.0 * x, -40.0 + 0 * x))
LIFT = (("40*x", "-40 + 40*x"),     # ... pressed for x < 1, lifted beyond
        lambda x, y: (40.0 * x, -40.0 + 40.0 * x))

CASES = {
    "tresca": (COMPLIANCE, [TRESCA], PRESS, Compliance(C), Tresca(10.0)),
    # α(a − b) = 300: slip weakening over a slip 1/α = 5e-3 (the largest slip
    # here is ~8e-3), below the curvature of K (checked: min_curvature > 0)
    "nonmonotone": (COMPLIANCE, [WEAKENING], PRESS, Compliance(C),
                    SlipWeakening(10.0, 8.5, 200.0)),
    "power": (COMPLIANCE, [POWER], PRESS, Compliance(C), Power(100.0, 0.5)),
    "adhesive_spring": (COMPLIANCE, [SPRING], PRESS, Compliance(C), Spring(1000.0, 0.01)),
    "tresca+adhesive_spring": (COMPLIANCE, [law("tresca", mu=6.0), SPRING], PRESS,
                               Compliance(C), Sum(Tresca(6.0), Spring(1000.0, 0.01))),
    "adhesive_compliance+tresca": (ADHESIVE, [TRESCA], LIFT,
                                   AdhesiveCompliance(C, 5000.0, 0.0005), Tresca(10.0)),
}


@pytest.mark.parametrize("name", list(CASES))
def test_step_equals_independent_minimiser(name):
    normal_table, friction_tables, body, normal, friction = CASES[name]
    problem, sol = run(scene(friction_tables, body[0], normal_table))
    ref = Reference(body[1], normal, friction)
    same_mesh(problem, ref.mesh)
    np.testing.assert_array_equal(np.sort(problem.boundary.nodes), ref.nodes)
    # the library's nodal weights are the w_a built here
    order = np.argsort(problem.boundary.nodes)
    np.testing.assert_allclose(problem.boundary.node_weights[order], ref.w, rtol=1e-14)
    assert ref.min_curvature() > 0          # J strictly convex: one minimiser

    u_ref = ref.minimise()
    u = sol.u[1].ravel()
    scale = np.abs(ref.ff).max()
    # the reference is a minimiser: its KKT residual is at round-off level
    # (measured 1e-14 .. 5e-14 of the load scale); so is the run's, with
    # this file's K, f and laws (measured ≤ 3e-14)
    assert ref.kkt_residual(u_ref) <= 1e-11 * scale
    assert ref.kkt_residual(u) <= 1e-11 * scale

    err = relative_max(u, u_ref)
    # (the loads are constant: step 0 already solves the step problem and
    # step 1 restarts from its solution, so its iteration count is 0)
    print(f"\n{name}: max|u − u_ref|/max|u_ref| = {err:.2e}, "
          f"Newton iterations (step 0) {sol.iterations[0]}")
    # Tolerance 1e-7 (brief). Both are the unique minimiser to ~1e-14
    # (measured 3e-15 .. 1.3e-14): library Newton to a 1e-10 relative
    # residual with quadratic convergence, reference refined in increments.
    assert err < 1e-7
    e = u - u_ref
    assert np.sqrt(e @ (ref.K @ e)) < 1e-7 * np.sqrt(u_ref @ (ref.K @ u_ref))

    ux, ux_ref = u[2 * ref.nodes], u_ref[2 * ref.nodes]
    if friction.kink:
        # both stick (u_τ = 0, held by the bound) and slip nodes occur, the
        # same ones in the run and in the reference
        assert (ux_ref == 0).any() and (ux_ref != 0).any()
        np.testing.assert_array_equal(ux == 0, ux_ref == 0)
        np.testing.assert_array_equal(sol.stuck[1][order], ux_ref == 0)
    if isinstance(normal, AdhesiveCompliance):
        # every branch of the glue is used: compression, glue spring, capped
        r = -u_ref[2 * ref.nodes + 1]
        assert (r > 0).any() and ((r < 0) & (r > -normal.L)).any() and (r < -normal.L).any()


# --------------------------------------------------------------------------
# Stick and slip under Tresca
# --------------------------------------------------------------------------

def _reaction(ref, u):
    """K u − f at the contact nodes (x, y): the force of Γ_C on the body."""
    r = ref.K @ u - ref.f
    return r[2 * ref.nodes], r[2 * ref.nodes + 1]


def test_stick_under_small_tangential_load():
    """A shear load below the friction bound everywhere: every contact node
    sticks. Reference: the linear problem with u_x = 0 at the contact nodes
    (all pressed, so the compliance is the spring c w_a on u_y), solved
    directly; its tangential reactions are checked to lie inside the bound,
    which makes it the solution of the frictional problem."""
    mu, body = 10.0, ("5*x", "-40")
    problem, sol = run(scene([TRESCA], body))
    ref = Reference(lambda x, y: (5.0 * x, -40.0 + 0 * x), Compliance(C), Tresca(mu))
    order = np.argsort(problem.boundary.nodes)

    A = ref.Kf.tolil()
    A[ref.ycol, ref.ycol] = A[ref.ycol, ref.ycol].toarray().ravel() + C * ref.w
    keep = np.setdiff1d(np.arange(ref.n), ref.xcol)      # u_x = 0 at Γ_C
    uf = np.zeros(ref.n)
    uf[keep] = spsolve(A.tocsr()[keep][:, keep].tocsc(), ref.ff[keep])
    u_ref = np.zeros(ref.K.shape[0])
    u_ref[ref.free] = uf
    assert np.all(-uf[ref.ycol] > 0)                     # all pressed
    fx_ref, _ = _reaction(ref, u_ref)
    ratio = np.abs(fx_ref) / (mu * ref.w)
    print(f"\nstick: max |f_τ|/(μ w_a) = {ratio.max():.3f}")
    assert ratio.max() < 0.9                             # inside the bound

    u = sol.u[1].ravel()
    assert sol.stuck[1].all()
    # exactly zero, not merely small (the solver sets ξ_a = 0 on the stick set)
    assert np.all(sol.frame_displacement[1][:, 1] == 0.0)
    assert np.all(u[2 * ref.nodes] == 0.0)
    # Tolerance: after the stick set is found the problem is linear and the
    # Newton step exact; measured ~1e-15.
    assert relative_max(u, u_ref) < 1e-10
    force_t = sol.contact_force[1][order, 1]
    assert np.all(np.abs(force_t) <= mu * ref.w)
    # the library's tangential force is the reaction K u − f (τ = e_x);
    # residual-level tolerance, measured 1e-15 of the load scale
    assert np.abs(force_t - fx_ref).max() <= 1e-8 * np.abs(ref.ff).max()


def test_slip_under_large_tangential_load():
    """A shear load far above the bound: every contact node slips, each with
    the full Tresca force μ w_a opposing its slip."""
    mu, body = 10.0, ("150*x", "-80")
    problem, sol = run(scene([TRESCA], body))
    ref = Reference(lambda x, y: (150.0 * x, -80.0 + 0 * x), Compliance(C), Tresca(mu))
    order = np.argsort(problem.boundary.nodes)
    u = sol.u[1].ravel()
    ut = sol.frame_displacement[1][order, 1]
    np.testing.assert_array_equal(ut, u[2 * ref.nodes])        # u_τ = u_x
    ft = sol.contact_force[1][order, 1]
    slip = ut != 0
    print(f"\nslip: {slip.sum()} of {slip.size} nodes slip")
    assert slip.all() and not sol.stuck[1].any()
    # |f_τ| = μ w_a, to 1e-10 relative: the Newton iteration on the slip set
    # (a linear problem once the set is known) ends far below its 1e-10
    # stopping tolerance; measured ≲ 1e-14.
    rel = np.abs(np.abs(ft[slip]) - mu * ref.w[slip]) / (mu * ref.w[slip])
    print(f"slip: max ||f_τ| − μ w_a|/(μ w_a) = {rel.max():.1e}")
    assert rel.max() < 1e-10
    assert np.all(np.sign(ft[slip]) == -np.sign(ut[slip]))
    # and that force is the reaction K u − f computed here (measured 4e-15)
    fx, _ = _reaction(ref, u)
    assert np.abs(ft - fx).max() <= 1e-8 * np.abs(ref.ff).max()


# --------------------------------------------------------------------------
# The step solver's iterations
# --------------------------------------------------------------------------

def test_slip_weakening_newton_iterations_bounded():
    """Slip weakening (negative tangent φ'' down to −α(a − b)) over three
    growing load steps: the globalised Newton converges in few iterations
    per step (a count, not a timing)."""
    body = ("40*x*t", "-40*t")
    problem, sol = run(scene([WEAKENING], body, steps=3))
    its = sol.iterations[1:]
    print(f"\nslip weakening: Newton iterations per step {its.tolist()}")
    assert np.all(its >= 1) and np.all(its <= 30)
    assert np.all(sol.residual[1:] <= problem.scene.solver.tol)
    # the last step slips somewhere and sticks somewhere
    states = contact_state_counts(sol)
    assert states["stick"][-1] > 0 and states["slip"][-1] > 0


def test_step_failure_names_the_step():
    """One Newton iteration cannot find the slip set: StepFailure at step 1
    (step 0 has no load and converges at once)."""
    problem = build_problem(scene_from_dict(scene([TRESCA], ("150*x*t", "-80*t"), steps=2,
                                                  solver={"max_iter": 1})))
    with pytest.raises(StepFailure) as info:
        solve(problem, raise_on_failure=True)
    err = info.value
    assert err.n == 1 and err.t == 0.5
    assert str(err).startswith("step 1 (t = 0.5) did not converge")
    assert "1 iterations" in str(err) and not err.result.success
    assert err.result.status == MAX_ITERATIONS


def test_failed_step_is_a_returned_status_with_the_history_before_it():
    """Without raise_on_failure the same run returns: not successful, the
    failure named, and the one level that converged (t = 0) kept."""
    problem = build_problem(scene_from_dict(scene([TRESCA], ("150*x*t", "-80*t"), steps=2,
                                                  solver={"max_iter": 1})))
    sol = solve(problem)
    assert not sol.success and sol.status == STEP_FAILED
    assert sol.failure.n == 1 and sol.message == str(sol.failure)
    assert sol.t.tolist() == [0.0] and sol.u.shape[0] == sol.beta.shape[0] == 1
    complete = solve(problem, raise_on_failure=False, progress=None)
    np.testing.assert_array_equal(complete.u, sol.u)   # the problem was not changed


def test_progress_callback_can_stop_a_run():
    problem = build_problem(scene_from_dict(scene([TRESCA], ("150*x*t", "-80*t"), steps=4)))
    seen = []
    sol = solve(problem, progress=lambda n, N: seen.append(n) or n == 2)
    assert seen == [0, 1, 2] and sol.status == STOPPED and not sol.success
    assert sol.t.size == 3 and sol.message == "stopped after step 2 (t = 0.5)"
    full = solve(problem)
    assert full.success and full.t.size == 5
    np.testing.assert_array_equal(full.u[:3], sol.u)


def test_power_law_near_zero_slip_converges():
    """A smooth convex power law (q = 1/2): the strip is clamped on the left
    and sheared and pressed on top, so the contact node next to the clamp
    barely slides (u_τ ≈ −3e-9). The step energy is strictly convex and
    smooth; the globalised Newton must converge within its default budget
    (50 iterations: it takes 48, the Hessian μ q s^(q−1) unbounded at the
    node that barely slides)."""
    problem, sol = run(scene_dict({
        "boundary.dirichlet": ["left"], "material": {"E": E, "nu": NU},
        "loads.traction.top": ["10", "-20"],
        "contact.normal": COMPLIANCE, "contact.friction": [POWER]}))
    print(f"\npower law near zero slip: Newton iterations {sol.iterations.tolist()}")
    assert sol.success, sol.message
    assert np.all(sol.iterations <= problem.scene.solver.max_iter)
