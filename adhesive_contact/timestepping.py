"""The time loop of the fully discrete scheme (Problem 4.1, MODEL.md §4).

u_0 solves the problem at t = 0 with the elastic stiffness alone (no memory
yet). For n = 1..N, with k = T/N and t_n = n k, u_n minimises the energy of
MODEL.md §5 with the step matrix a_n = A + k R(0), the load f(t_n) minus
the memory history (right rectangle rule, :mod:`adhesive_contact.memory`),
the contact terms with β_n, and the wall u_ν ≤ g(t_n) at the contact nodes.

Both step matrices are factorised and condensed onto the contact unknowns
once (:class:`~adhesive_contact.linear.CondensedOperator`); a step is the
small nonsmooth problem of :mod:`adhesive_contact.step_solver` and two
solves with the factors.
"""

import time
from dataclasses import dataclass, field

import numpy as np
from threadpoolctl import threadpool_limits

from .contact_energy import ContactEnergy
from .expressions import coordinates
from .linear import CondensedOperator
from .step_solver import Kink, minimise_step


class StepFailure(RuntimeError):
    """A step solve that did not converge; carries the step and its result."""

    def __init__(self, n, t, result):
        self.n, self.t, self.result = n, t, result
        super().__init__(
            f"step {n} (t = {t:g}) did not converge: {result.message}; projected "
            f"residual reached {result.residual:.2e} (tolerance {result.tolerance:.1e}) "
            f"after {result.nit} iterations. Try more time steps (smaller k), a larger "
            f"solver.max_iter, or check the smallness condition of the contact laws")

    def __reduce__(self):   # survive pickling back from a worker process
        return (type(self), (self.n, self.t, self.result))


@dataclass
class Solution:
    """The discrete history; arrays are indexed by the time level n = 0..N."""

    problem: object
    t: np.ndarray                 # (N+1,)
    u: np.ndarray                 # (N+1, npoints, d)
    beta: np.ndarray              # (N+1, nf) β per contact facet
    stress: np.ndarray            # (N+1, ncells, d, d) σ_n per cell
    stress_zz: np.ndarray         # (N+1, ncells) plane strain σ_zz (2D), or None
    contact_force: np.ndarray     # (N+1, nc, d) force of Γ_C on the body, nodal frames
    frame_displacement: np.ndarray  # (N+1, nc, d) [u_ν, u_τ] at the contact nodes
    on_wall: np.ndarray           # (N+1, nc) bool
    stuck: np.ndarray             # (N+1, nc) bool: held at ξ = 0 by a friction kink
    probes: np.ndarray            # (N+1, nprobes, d)
    iterations: np.ndarray        # (N+1,) Newton iterations per step
    residual: np.ndarray          # (N+1,) final relative projected residual
    timings: dict = field(default_factory=dict)

    @property
    def steps(self):
        return self.t.size - 1

    @property
    def normal_displacement(self):
        """u_ν at the contact nodes (N+1, nc)."""
        return self.frame_displacement[:, :, 0]

    def contact_states(self):
        """Counts per level of contact nodes that are separated (u_ν < 0),
        on the wall, stuck (ξ = 0 held by friction) and slipping (the rest
        in contact with friction): a dict of (N+1,) int arrays."""
        separated = self.normal_displacement < 0
        touching = ~separated
        out = {"separated": separated.sum(axis=1), "on_wall": self.on_wall.sum(axis=1)}
        if self.problem.friction is not None:
            moving = np.linalg.norm(self.frame_displacement[:, :, 1:], axis=2) > 0
            out["stick"] = (touching & self.stuck).sum(axis=1)
            out["slip"] = (touching & ~self.stuck & moving).sum(axis=1)
        return out

    def total_normal_force(self):
        """Σ_a of the normal force Γ_C exerts, positive in compression (N+1,)."""
        return -self.contact_force[:, :, 0].sum(axis=1)

    def total_tangential_force(self):
        """Σ_a of the tangential forces in the nodal tangent frames (N+1, d−1)."""
        return self.contact_force[:, :, 1:].sum(axis=1)

    def gap_violation(self):
        """max_a (u_ν − g) per level (−inf without a wall or contact nodes)."""
        gap = self.problem.gap
        if gap is None or gap.shape[1] == 0:
            return np.full(self.t.size, -np.inf)
        return (self.normal_displacement - gap).max(axis=1)


def solve(problem, progress=None):
    """Run the scheme on a :class:`~adhesive_contact.problem.Problem`.

    ``progress(n, N)`` is called after each time level. Raises
    :class:`StepFailure` when a step solve does not converge.

    Dense BLAS runs on one thread here: the step solves factorise matrices
    of the size of Γ_C, for which a threaded OpenBLAS on a shared machine
    was 10–100× slower (a 160 × 160 Cholesky: 0.25 ms on one thread, 2.7 ms
    on two, 34 ms with the second core busy).
    """
    with threadpool_limits(limits=1, user_api="blas"):
        return _solve(problem, progress)


def _solve(problem, progress):
    scene = problem.scene
    asm = problem.assembly
    free, d = problem.free, problem.dim
    N, k = scene.steps, scene.k
    boundary, memory, bonding = problem.boundary, problem.memory, problem.bonding
    t_start = time.perf_counter()

    # the system in nodal frames at Γ_C: ũ = Rᵀ u
    R = boundary.rotation(asm.ndofs) if boundary is not None else None

    def condensed(lam_, mu_, approximation=None):
        A = asm.stiffness(lam_, mu_)
        if R is not None:
            A = (R.T @ A @ R).tocsr()
        return CondensedOperator(A[free][:, free], problem.contact_positions,
                                 approximation=approximation)

    # the step matrices: a_n = A + k R(0) for n >= 1, and A at t = 0; the
    # latter serves one step, so its Schur complement is applied, not formed
    lam, mu = scene.material.lam, scene.material.mu
    dlam, dmu = memory.instantaneous(k)
    op = condensed(lam + dlam, mu + dmu)
    op0 = op if (dlam, dmu) == (0.0, 0.0) else condensed(lam, mu, approximation=op.S)
    t_factor = time.perf_counter() - t_start

    npoints, ncells = problem.mesh.p.shape[1], problem.mesh.t.shape[1]
    nc = 0 if boundary is None else boundary.nodes.size
    nf = 0 if boundary is None else boundary.facets.size
    nprobes = 0 if problem.probe_map is None else problem.probe_map.shape[0]
    U = np.zeros((N + 1, npoints, d))
    beta = np.empty((N + 1, nf))
    stress = np.empty((N + 1, ncells, d, d))
    stress_zz = np.empty((N + 1, ncells)) if d == 2 else None
    force = np.zeros((N + 1, nc, d))
    frame_u = np.zeros((N + 1, nc, d))
    wall = np.zeros((N + 1, nc), dtype=bool)
    stuck = np.zeros((N + 1, nc), dtype=bool)
    probes = np.zeros((N + 1, nprobes, d))
    iterations = np.zeros(N + 1, dtype=int)
    residual = np.zeros(N + 1)

    kink = None
    if problem.friction is not None:
        # every friction law gets its slip directions held (κ_a = 0 without a
        # kink): Newton on φ' = μ|ξ|^q, not Lipschitz at 0, would flip ξ
        tangential = np.arange(problem.columns.size).reshape(nc, d)[:, 1:]
        kink = Kink(tangential, np.zeros(nc))
    contact_dofs = None if boundary is None else boundary.dofs.ravel()
    energy = None if boundary is None else ContactEnergy(
        boundary, problem.columns, problem.normal_law, problem.friction, problem.beta0)

    memory.begin(k, asm.ndofs)
    z = np.zeros(problem.columns.size)
    beta_n = problem.beta0.copy()
    t_loop = time.perf_counter()
    for n, t in enumerate(problem.times):
        step = op0 if n == 0 else op
        if n >= 1 and bonding is not None:
            # (4.2): β_n = β_{n−1} + k P_B F(u_{n−1,ν}, u_{n−1,τ}, β_{n−1})
            rate = bonding_rate(boundary, bonding, frame_u[n - 1].ravel(), beta_n)
            if problem.beta_source is not None:   # manufactured solutions only
                rate = rate + problem.beta_source(*coordinates(boundary.points), t=t - k)
            beta_n = beta_n + k * boundary.facet_mean(rate)
        f = problem.loads(t)
        history = memory.history(n) if n >= 1 else None
        if history is not None:
            f -= asm.force(*history)
        if R is not None:
            f = R.T @ f
        b = f[free]
        c = step.reduce(b)
        if boundary is not None:
            energy.set_bonding(beta_n)
            if kink is not None:
                kink.radius = energy.node_kink(boundary.point_node, nc)
            result = minimise_step(step.S, c, energy, problem.upper_bound(n), z,
                                   scene.solver.tol, scene.solver.max_iter, kink)
            if not result.success:
                raise StepFailure(n, t, result)
            z = result.z
            # the force of Γ_C on the body: its reaction in the frame equations
            force[n].reshape(-1)[problem.columns] = step.S @ z - c
            wall[n] = result.on_wall[problem.normal_columns]
            if kink is not None and problem.friction.has_kink:
                stuck[n] = result.stuck
            iterations[n], residual[n] = result.nit, result.residual
        u_frame = np.zeros(asm.ndofs)
        u_frame[free] = step.expand(z, b)
        if boundary is not None:
            frame_u[n] = u_frame[contact_dofs].reshape(nc, d)
        u = R @ u_frame if R is not None else u_frame
        U[n] = u.reshape(npoints, d)
        beta[n] = beta_n

        # σ_n = C ε(u_n) + k R(0) ε(u_n) + history (none at t = 0)
        il, im = (lam, mu) if n == 0 else (lam + dlam, mu + dmu)
        a_lam, a_mu = il * u, im * u
        if history is not None:
            a_lam, a_mu = a_lam + history[0], a_mu + history[1]
        stress[n], zz = asm.cell_stress(a_lam, a_mu)
        if stress_zz is not None:
            stress_zz[n] = zz
        if nprobes:
            probes[n] = problem.probe_map @ U[n]
        if n >= 1:
            memory.advance(n, u)
        if progress is not None:
            progress(n, N)
    t_end = time.perf_counter()

    timings = {
        "assembly": problem.assembly_seconds,
        "factorisation": t_factor,
        "schur": op0.schur_seconds + (op.schur_seconds if op is not op0 else 0.0),
        "stepping": t_end - t_loop,
        "total": problem.assembly_seconds + (t_end - t_start),
    }
    return Solution(problem, problem.times.copy(), U, beta, stress, stress_zz, force, frame_u, wall,
                    stuck, probes, iterations, residual, timings)


def bonding_rate(boundary, bonding, z_full, beta):
    """F(u_ν, u_τ, β) at the quadrature points of Γ_C, from the nodal-frame
    components ``z_full`` (nc·d) of u and the facet values β."""
    r = boundary.normal_trace @ z_full
    xi = (np.stack([t @ z_full for t in boundary.tangential_trace], axis=-1)
          if boundary.tangential_trace else None)
    return bonding.rate(r, xi, boundary.at_points(beta))
