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

from .linear import CondensedOperator
from .step_solver import ContactEnergy, minimise_step


class StepFailure(RuntimeError):
    """A step solve that did not converge; carries the step and its result."""

    def __init__(self, n, t, result):
        self.n, self.t, self.result = n, t, result
        super().__init__(
            f"step {n} (t = {t:g}) did not converge: {result.message}; projected "
            f"residual reached {result.residual:.2e} (tolerance {result.tolerance:.1e}) "
            f"after {result.nit} iterations. Try more time steps (smaller k), a larger "
            f"solver.max_iter, or check the smallness condition of the contact laws")


@dataclass
class Solution:
    """The discrete history; arrays are indexed by the time level n = 0..N."""

    problem: object
    t: np.ndarray                 # (N+1,)
    u: np.ndarray                 # (N+1, npoints, d)
    beta: np.ndarray              # (N+1, nf) β per contact facet
    stress: np.ndarray            # (N+1, ncells, d, d) σ_n per cell
    contact_force: np.ndarray     # (N+1, nc, d) force of Γ_C on the body, nodal frames
    normal_displacement: np.ndarray  # (N+1, nc) u_ν at the contact nodes
    on_wall: np.ndarray           # (N+1, nc) bool
    probes: np.ndarray            # (N+1, nprobes, d)
    iterations: np.ndarray        # (N+1,) Newton iterations per step
    residual: np.ndarray          # (N+1,) final relative projected residual
    timings: dict = field(default_factory=dict)

    @property
    def steps(self):
        return self.t.size - 1

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
    """
    scene = problem.scene
    asm = problem.assembly
    free, d = problem.free, problem.dim
    N, k = scene.steps, scene.k
    boundary = problem.boundary
    memory = problem.memory
    t_start = time.perf_counter()

    # the step matrices: A at t = 0, a_n = A + k R(0) for n >= 1
    lam, mu = scene.material.lam, scene.material.mu
    dlam, dmu = memory.instantaneous(k)
    if boundary is not None:
        contact, Q = problem.contact_positions, boundary.rotation()
    else:
        contact, Q = np.zeros(0, dtype=np.int64), None

    def condensed(lam_, mu_):
        A = asm.stiffness(lam_, mu_)[free][:, free]
        return CondensedOperator(A, contact, Q)

    op0 = condensed(lam, mu)
    op = op0 if (dlam, dmu) == (0.0, 0.0) else condensed(lam + dlam, mu + dmu)
    t_factor = time.perf_counter() - t_start

    npoints, ncells = problem.mesh.p.shape[1], problem.mesh.t.shape[1]
    nc = 0 if boundary is None else boundary.nodes.size
    nf = 0 if boundary is None else boundary.facets.size
    nprobes = 0 if problem.probe_map is None else problem.probe_map.shape[0]
    U = np.zeros((N + 1, npoints, d))
    beta = np.empty((N + 1, nf))
    stress = np.empty((N + 1, ncells, d, d))
    force = np.zeros((N + 1, nc, d))
    un = np.zeros((N + 1, nc))
    wall = np.zeros((N + 1, nc), dtype=bool)
    probes = np.zeros((N + 1, nprobes, d))
    iterations = np.zeros(N + 1, dtype=int)
    residual = np.zeros(N + 1)

    memory.begin(k, asm.ndofs)
    z = np.zeros(0 if boundary is None else boundary.n_unknowns)
    beta_n = problem.beta0
    t_loop = time.perf_counter()
    for n, t in enumerate(problem.times):
        step = op0 if n == 0 else op
        f = problem.loads(t)
        history = memory.history(n) if n >= 1 else None
        if history is not None:
            f -= asm.force(*history)
        b = f[free]
        c = step.reduce(b)
        if boundary is not None:
            energy = ContactEnergy(boundary, problem.normal_law, beta_n)
            result = minimise_step(step.S, c, energy, problem.upper_bound(n), z,
                                   scene.solver.tol, scene.solver.max_iter)
            if not result.success:
                raise StepFailure(n, t, result)
            z = result.z
            force[n] = (step.S @ z - c).reshape(nc, d)
            un[n] = z[boundary.normal_unknowns]
            wall[n] = result.on_wall[boundary.normal_unknowns]
            iterations[n], residual[n] = result.nit, result.residual
        u = np.zeros(asm.ndofs)
        u[free] = step.expand(z, b)
        U[n] = u.reshape(npoints, d)
        beta[n] = beta_n

        # σ_n = C ε(u_n) + k R(0) ε(u_n) + history (none at t = 0)
        il, im = (lam, mu) if n == 0 else (lam + dlam, mu + dmu)
        a_lam, a_mu = il * u, im * u
        if history is not None:
            a_lam, a_mu = a_lam + history[0], a_mu + history[1]
        stress[n] = asm.cell_stress(a_lam, a_mu)
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
    return Solution(problem, problem.times.copy(), U, beta, stress, force, un, wall,
                    probes, iterations, residual, timings)
