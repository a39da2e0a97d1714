"""The state of the scheme and the functions that advance it, one per
equation of the fully discrete Problem 4.1.

A :class:`State` is what level n leaves for level n + 1: β_n, u_n, the
contact unknowns (the next Newton start) and the memory history. It
belongs to one run: the built-once :class:`~adhesive_contact.problem.Problem`
is never changed by a run.
"""

import time
from dataclasses import dataclass, replace

import numpy as np

from ..bonding import FacetRate, advance, damage
from .contact_energy import ContactEnergy
from ..expressions import coordinates
from ..step_methods import MAX_ITERATIONS, Kink, StepOptions, minimise
from ..step_methods.base import stationarity


@dataclass
class State:
    """Level n of a run."""

    n: int
    t: float
    beta: np.ndarray     # (nf,) β_n per contact facet
    z: np.ndarray        # the step's unknowns: contact unknowns (nodal frames) or all free dofs
    u: np.ndarray        # (ndofs,) u_n, Cartesian
    frame_u: np.ndarray  # (nc·d,) all nodal-frame components of u_n at the contact nodes,
                         # held ones included
    memory: object       # the run's memory history (adhesive_contact.scheme.memory)
    z_before: np.ndarray = None   # the step's unknowns of level n − 1 (None before level 1)
    frame_u_before: np.ndarray = None   # frame_u of level n − 1 (None before level 1)
    k_last: float = None   # t_n − t_{n−1}, the step that led here (None at level 0)
    gap: np.ndarray = None   # (nc,) g(x_a, t_n) of the wall, None without one


@dataclass
class Level:
    """What level n computed: the fields a recorder may keep."""

    n: int
    t: float
    u: np.ndarray                 # (npoints, d)
    beta: np.ndarray              # (nf,)
    stress: np.ndarray            # (ncells, d, d)
    stress_zz: np.ndarray         # (ncells,) plane strain σ_zz, or None in 3D
    contact_force: np.ndarray     # (nc, d) force of Γ_C on the body, nodal frames
                                  # (the contact laws' alone at a held component)
    frame_displacement: np.ndarray  # (nc, d)
    on_wall: np.ndarray           # (nc,) bool
    stuck: np.ndarray             # (nc,) bool
    probes: np.ndarray            # (nprobes, d)
    reaction: np.ndarray          # (nD,) force of the support alone on the body per
                                  # held dof (the contact laws' is in contact_force)
    iterations: int
    residual: float
    gap: np.ndarray = None        # (nc,) g(x_a, t_n) of the wall, None without one
    k: float = 0.0                # t_n − t_{n−1}, the step that led here (0 at level 0)


@dataclass(frozen=True)
class StepInput:
    """What the step solve of one level is given: where it is (``index``
    on the run's grid, for the notes; ``t``, the step ``k`` that leads
    there, 0 at level 0, whose t = 0 problem has no memory), its load
    ``b`` on the free dofs in frames and :class:`KnownPart`, β_n, the gap
    of the level and of the level before, and the starts ``z0`` (level
    n − 1's unknowns) and ``z_before`` (level n − 2's, for the predictor;
    None)."""

    index: int
    t: float
    k: float
    b: np.ndarray
    known: object
    beta: np.ndarray
    gap: np.ndarray
    gap_before: np.ndarray
    z0: np.ndarray
    z_before: np.ndarray = None

    @property
    def initial(self):
        """Whether this is level 0, the t = 0 problem without memory."""
        return self.k == 0.0


@dataclass
class StepOutcome:
    """What a step solve returns: the ``level`` (None when the solve
    failed), u_n, its nodal-frame components at the contact nodes, the
    step unknowns z and the step method's ``result`` (None without Γ_C)."""

    level: Level
    u: np.ndarray
    frame_u: np.ndarray
    z: np.ndarray
    result: object


NEWTON = ("newton", "newton-plain")   # the methods that converge quadratically
#: two solutions of a step differ when |Δz|_∞ exceeds this fraction of |z|_∞
#: (each is converged to solver.tol on the forces, 1e-10 by default)
SECOND_START_RTOL = 1e-6


#: a stuck node is moved on with the stick front only where its tangential
#: force is within 10 % of the friction bound, |h_a| > FRONT_NEAR κ_a: on
#: the 2D strip of studies/bench/ratio the iterations a step were 3.74
#: without the front moved on, 3.18 with every candidate, 2.96 at 0.9
#: (3.14 at 0.8, 3.10 at 0.93, 3.40 at 0.97)
FRONT_NEAR = 0.9


class ContactStep:
    """The contact terms Φ of a run's steps and the kinks of its friction
    (:mod:`adhesive_contact.scheme.contact_energy`), solved by the scene's step
    method (:mod:`adhesive_contact.step_methods`).

    ``within = (positions, size)`` when the step unknowns are the free dofs
    (:mod:`.full_system`), the contact unknowns at ``positions`` among
    them; by default they are the contact unknowns alone.

    The held components of the contact nodes enter the contact terms at the
    values of :meth:`hold`; the friction of a node with a free tangential
    component has its kink (``kink_nodes`` the nodes of ``kink``), that of
    a node whose tangential components are all held is part of the
    reaction of its side."""

    def __init__(self, problem, within=None):
        boundary, nc, d = problem.boundary, problem.boundary.nodes.size, problem.dim
        self.problem = problem
        self.energy = ContactEnergy(boundary, problem.columns, problem.normal_law,
                                    problem.friction, problem.beta0, within)
        self.unknowns = self.energy.unknowns
        self.size = self.energy.nz
        self.kink = None
        self.kink_nodes = np.zeros(0, dtype=np.int64)
        self.seconds = 0.0   # spent in the step method, over all levels so far
        # the steps whose Newton matrix at the solution was indefinite, and
        # those of them where a second start reached another solution
        self.indefinite_steps, self.two_solution_steps = set(), {}
        if problem.friction is not None:
            # every friction law gets its slip directions held (κ_a = 0 without a
            # kink): Newton on φ' = μ|ξ|^q, not Lipschitz at 0, would flip ξ.
            # Its nodes: those with a free tangential component (−1 at a held one)
            column = np.full(nc * d, -1)
            column[problem.columns] = np.arange(problem.columns.size)
            tangential = column.reshape(nc, d)[:, 1:]
            self.kink_nodes = np.flatnonzero((tangential >= 0).any(axis=1))
            tangential = tangential[self.kink_nodes]
            index = np.where(tangential >= 0, self.unknowns[np.maximum(tangential, 0)], -1)
            self.kink = Kink(index, np.zeros(self.kink_nodes.size))

    def hold(self, prescribed):
        """Use the held values g_D(t_n) (nD,) of the step from now on."""
        boundary = self.problem.boundary
        if not boundary.has_held:
            return
        values = boundary.held_values(prescribed)
        self.energy.set_held(values)
        if self.kink is not None and np.any(self.kink.tangential < 0):
            self.kink.offset = values.reshape(boundary.held.shape)[self.kink_nodes, 1:]

    def minimise(self, S, c, beta, step, z0, tighter=1.0, before=None, iterations=None):
        """The step solve of (4.1) on the contact unknowns with β_n, by
        ``solver.method``, for the :class:`StepInput` ``step`` (its gap,
        the gap before it and its index for the notes); a Newton method's
        tolerance times ``tighter`` and, with ``iterations``, its
        iterations at most that many. ``z0`` is the last level's solution;
        with ``before``, the one of the level before it, the "newton"
        method starts from the :meth:`predictor` where that lowers the
        step energy."""
        problem = self.problem
        self.energy.set_bonding(beta)
        self.energy.set_pressure(z0)   # a Coulomb bound: at the last level's pressure first
        self.set_radius()
        solver = problem.options.solver
        options = self.options(S)
        if solver.method in NEWTON:
            options = replace(options, tol=max(options.tol * tighter, 1e-14))
            if iterations is not None:
                options = replace(options, max_iter=min(options.max_iter, iterations))
        upper = np.full(self.size, np.inf)
        upper[self.unknowns] = problem.upper_bound(step.gap)
        n = step.index
        start = time.perf_counter()
        if before is not None and solver.method == "newton":
            z0 = self.predictor(S, c, upper, z0, before, step.gap_before)
        S.indefinite, solves_before = False, S.indefinite_solves
        if (self.energy.pressure_dependent and self.problem.held_by_contact
                and not np.any(self.kink.radius > 0)):
            # no bound at the last level's pressure (sheared from zero load):
            # the first solve would slide a body held by contact away
            result = self.stuck_start(S, c, upper, options, z0, None)
        else:
            result = minimise(solver.method, S, c, self.energy, upper, z0, options, self.kink)
            if self.energy.pressure_dependent and not result.success:
                result = self.stuck_start(S, c, upper, options, z0, result)
        if self.energy.pressure_dependent and result.success:
            result = self.pressure_fixed_point(S, c, upper, options, result)
        result.indefinite = bool(S.indefinite and result.nit > 0)
        if result.success:
            if result.indefinite:
                self.indefinite_steps.add(n)
            if S.indefinite_solves > solves_before:   # a nonconvex energy on the way
                self.second_start(S, c, upper, options, n, z0, result)
        self.seconds += time.perf_counter() - start
        return result

    def set_radius(self):
        """κ_a of the kinks from the friction (frozen at its pressure)."""
        if self.kink is not None:
            boundary = self.problem.boundary
            self.kink.radius = self.energy.node_kink(
                boundary.point_node, boundary.nodes.size)[self.kink_nodes]

    def stuck_start(self, S, c, upper, options, z0, failed):
        """A Coulomb step whose bound, frozen at the last level's pressure,
        holds too little (a body held by contact alone, sheared from zero
        load: the bound is 0 at t = 0, so the first solve slides away) is
        started again from Γ_C stuck: the bound frozen at a pressure so large
        that no node slides, solved from ``z0``; its solution's pressure then
        starts the fixed point (:meth:`pressure_fixed_point`). Returns that
        solve's result, or ``failed`` (the first solve's result, or None
        when there was none) when it fails too."""
        scale = max(np.abs(c).max(initial=0.0), 1e-300)
        w = self.energy.w
        large = 1e6 * scale / max(float(w[w > 0].min(initial=1.0)), 1e-300)
        mu = max(float(getattr(law, "mu", 0.0)) for law in self.energy.friction_law.laws)
        self.energy.set_pressure_values(np.full(w.size, large / max(mu, 1e-300)))
        self.set_radius()
        stuck = minimise(self.problem.options.solver.method, S, c, self.energy, upper, z0,
                         options, self.kink)
        before = 0 if failed is None else failed.nit
        if not stuck.success:
            self.energy.set_pressure(z0)
            self.set_radius()
            if failed is None:
                stuck.nit += before
                return stuck
            return failed
        self.energy.set_pressure(stuck.z)
        self.set_radius()
        result = minimise(self.problem.options.solver.method, S, c, self.energy, upper, stuck.z,
                          options, self.kink)
        result.nit += before + stuck.nit
        return result

    def pressure_fixed_point(self, S, c, upper, options, result):
        """A Coulomb bound's fixed point within the step (docs/model.md,
        "Coulomb-type friction"): with the bound frozen at the pressure
        p_ν(β_n, u_ν) of the last solution, solve the step again (a Tresca
        step, from that solution) until the nodal bounds κ_a change by at
        most ``options.tol`` times their largest value; then the step's
        residual with the bound at its own solution is below the tolerance
        too. Not converging in ``max_iter`` passes is the step's failure
        (MAX_ITERATIONS, with the change reached)."""
        passes = max(int(self.problem.options.solver.max_iter), 1)
        nit = result.nit
        for _ in range(passes):
            before = self.kink.radius.copy()
            self.energy.set_pressure(result.z)
            self.set_radius()
            change = float(np.abs(self.kink.radius - before).max(initial=0.0))
            if change <= options.tol * max(self.kink.radius.max(initial=0.0), 1e-300):
                result.nit = nit
                return result
            result = minimise(self.problem.options.solver.method, S, c, self.energy, upper,
                              result.z, options, self.kink)
            nit += result.nit
            if not result.success:
                return result
        result.status = MAX_ITERATIONS
        result.message = (f"the Coulomb bound μ p_ν did not settle in {passes} fixed-point "
                          f"passes on the normal pressure (its nodal bound still changed by "
                          f"{change:.3g}); try smaller steps or a smaller mu")
        result.nit = nit
        return result

    def predictor(self, S, c, upper, last, before, gap_before):
        """The start of step n from the last two levels: z_{n−1} + (z_{n−1}
        − z_{n−2}) (uniform steps), with the sets of level n − 1 kept
        (a node stuck there, ξ = 0, stays stuck; one on the wall of t_{n−1}
        is put on the wall of t_n) and projected onto the wall; z_{n−1}
        itself where the extrapolation does not lower the step energy
        ½ zᵀ S z − cᵀ z + Φ(z) (β_n, the load of level n). Then the stick
        front is moved on as far as it moved in the last step
        (:meth:`front_moved_on`). ``gap_before``: the gap of level n − 1."""
        guess = 2.0 * last - before
        positions = self.unknowns
        wall_before = self.problem.upper_bound(gap_before)
        held = np.isfinite(wall_before) & (last[positions] >= wall_before)
        guess[positions[held]] = upper[positions[held]]
        if self.kink is not None:
            stuck = ~np.any(self.kink.xi(last) != 0, axis=1)
            self.kink.put(guess, stuck, 0.0)
        guess = np.minimum(guess, upper)
        start = np.minimum(last, upper)

        def energy(z):
            return 0.5 * z @ (S @ z) - c @ z + self.energy.value(z)
        z = guess if energy(guess) < energy(start) else start
        return self.front_moved_on(S, c, upper, z, last, before)

    def front_moved_on(self, S, c, upper, z, last, before):
        """z with the stick front moved on: the m nodes that left ξ = 0 in the
        last step (stuck at level n − 2, slipping at n − 1) are matched by
        at most m nodes stuck in z whose tangential force is nearest the
        friction bound, |h_a|/κ_a largest and above FRONT_NEAR, now set
        slipping along −h_a by the median slip |ξ_{n−1}| of the m. Kept
        stuck, they would leave ξ = 0 one a Newton iteration: a stuck node's
        force only passes κ_a once its neighbour on the front slips and
        hands its load on (studies/bench/newton_steps.py, docs/scheme.md,
        "Step methods")."""
        kink = self.kink
        if kink is None or kink.held:
            return z
        rough = kink.radius > 0
        xi_last = kink.xi(last)
        stuck_last = ~np.any(xi_last != 0, axis=1) & rough
        left = ~np.any(kink.xi(before) != 0, axis=1) & ~stuck_last & rough
        m = int(left.sum())
        if m == 0:
            return z
        st = stationarity(S, c, self.energy, upper, z, kink)
        near = np.flatnonzero(st.at_zero & rough & (st.hn > FRONT_NEAR * kink.radius))
        if near.size == 0:
            return z
        chosen = near[np.argsort(-st.hn[near] / kink.radius[near])[:m]]
        slip = float(np.median(np.linalg.norm(xi_last[left], axis=1)))
        rows = np.zeros(kink.radius.size, dtype=bool)
        rows[chosen] = True
        moved = np.zeros(kink.tangential.shape)
        moved[rows] = -slip * st.h[rows] / st.hn[rows, None]
        out = z.copy()
        kink.put(out, rows, moved)
        return out

    def second_start(self, S, c, upper, options, n, z0, result):
        """Solve step n again from z = 0 (Γ_C at rest) when its iterations
        from ``z0`` met an indefinite Newton matrix (a nonconvex energy), and note
        the step (``result.another_start``, :attr:`two_solution_steps`: n ->
        |Δz|_∞ / |z|_∞) when the two converged solutions differ by more than
        SECOND_START_RTOL of the larger. The run goes on with ``result``."""
        if not np.any(z0):
            return
        other = minimise(self.problem.options.solver.method, S, c, self.energy, upper,
                         np.zeros_like(z0), options, self.kink)
        if not other.success:
            return
        size = max(np.abs(result.z).max(initial=0.0), np.abs(other.z).max(initial=0.0))
        gap = float(np.abs(result.z - other.z).max(initial=0.0))
        if gap > SECOND_START_RTOL * size:
            result.another_start = True
            self.two_solution_steps[n] = float(gap / size)

    def options(self, S):
        """The StepOptions of a step with matrix S: the scene's tolerances and,
        for "penalty", ρ = penalty · max_i S_ii and δ = smoothing · diam Ω."""
        solver = self.problem.options.solver
        if solver.method != "penalty":
            return StepOptions(solver.tol, solver.max_iter)
        p = self.problem.mesh.p
        diameter = float(np.linalg.norm(p.max(axis=1) - p.min(axis=1)))
        stiffness = float(np.max(S.diagonal(), initial=0.0))
        return StepOptions(solver.tol, solver.max_iter, solver.penalty * stiffness,
                           solver.smoothing * diameter)


def initial_state(problem, unknowns=None):
    """Level "−1": β_0^h = P_B β_0, zero displacement, no history yet (the
    memory starts from u_0, :func:`~.memory.start_memory`); ``unknowns``
    the size of the step unknowns (default: the contact unknowns)."""
    nc = 0 if problem.boundary is None else problem.boundary.nodes.size
    size = problem.columns.size if unknowns is None else unknowns
    return State(n=-1, t=0.0, beta=problem.beta0.copy(), z=np.zeros(size),
                 u=np.zeros(problem.ndofs), frame_u=np.zeros(nc * problem.dim), memory=None)


def bonding_step(problem, state, k):
    """(4.2): β_n from β_{n−1} and u_{n−1} over the step k = t_n − t_{n−1}
    by the scene's integrator (:mod:`adhesive_contact.bonding`);
    explicit Euler, the paper's, is β_n = β_{n−1} + k P_B F(u_{n−1,ν},
    u_{n−1,τ}, β_{n−1}) (β frozen without a bonding law, and at n = 0); a
    rate-independent law's damage update
    (:mod:`adhesive_contact.bonding.damage`) in its place.

    The second-order scheme freezes the rate at the midpoint t_{n−½}: the
    displacement extrapolated there, u_{n−½} ≈ (3 u_{n−1} − u_{n−2})/2 on
    equal steps, u_{n−1} + (k/(2 k_{n−1})) (u_{n−1} − u_{n−2}) on unequal
    ones (u_0 itself for n = 1: one step's O(k²) error), the source
    s_β(t_{n−½}); its integrator (exponential midpoint) is second order in
    that rate."""
    if problem.bonding is None or state.n < 0:
        return state.beta
    boundary = problem.boundary
    frame_u, t = state.frame_u, state.t
    if problem.options.second_order:
        t = state.t + 0.5 * k
        if state.frame_u_before is not None:
            if state.k_last == k:
                frame_u = 1.5 * state.frame_u - 0.5 * state.frame_u_before
            else:
                frame_u = state.frame_u + (0.5 * k / state.k_last) * (
                    state.frame_u - state.frame_u_before)
    r = boundary.normal_trace @ frame_u
    xi = (np.stack([trace @ frame_u for trace in boundary.tangential_trace], axis=-1)
          if boundary.tangential_trace else None)
    if getattr(problem.bonding, "rate_independent", False):
        return damage.advance(problem.bonding, r, xi, boundary.facet_mean, state.beta)
    source = None
    if problem.beta_source is not None:   # manufactured solutions only
        source = problem.beta_source(*coordinates(boundary.points), t=t)
    rate = FacetRate(problem.bonding, r, xi, boundary.at_points, boundary.facet_mean, source)
    return advance(problem.options.integrator, rate, state.beta, k)


@dataclass
class KnownPart:
    """What level n knows before its solve, besides the free-dof load:
    the memory history's (a_λ, a_μ) fields (None at n = 0 and while the
    history is zero), the held values g_D(t_n) and the load f_D − (history
    force)_D on the held dofs (for the reactions)."""

    history: tuple
    prescribed: np.ndarray
    held_load: np.ndarray


def history_load(problem, operators, initial, t, history):
    """The load of a level on the free dofs in nodal frames: f(t_n) minus
    the force of the memory history (its (a_λ, a_μ), None: zero; the
    rule's Σ_{j<n} w_j R(t_n − t_j) ε(u_j), u_j the whole displacement,
    held part included), minus the force a_FD g_D(t_n) of the held values
    (``initial``: level 0's step matrix); and the :class:`KnownPart` of
    the level."""
    f = problem.loads(t)
    if history is not None:
        f -= problem.assembly.force(*history)
    held = problem.prescribed
    g = held.values(t)
    b = operators.to_frames(f)
    if not held.is_zero:
        b -= operators.lift(initial, g)
    return b, KnownPart(history, g, f[held.fixed])


def step_solve(problem, operators, contact, step):
    """(4.1) at one level (:class:`StepInput` ``step``): the nonsmooth
    problem on the contact unknowns, then the interior by back
    substitution, the held values g_D(t_n) put in, the stress σ_n = C ε(u_n)
    + k R(0) ε(u_n) + history, the contact reactions and the reactions of
    the held dofs; a :class:`StepOutcome`.

    The force of Γ_C at a free component of a contact node is its reaction
    in the frame equations (S z − c). At a held component the contact laws
    act too (at the prescribed value), F_D = −∂Φ/∂z_D: ``contact_force``
    holds it there, and the support's force is what is left of the held
    rows, R = (a_n u)_D − f_D − F_D, so that Σ_sides R + Σ_a R_a F_a + ∫ f = 0."""
    known, initial = step.known, step.initial
    operator = operators.at(initial)
    if contact is not None:
        contact.hold(known.prescribed)
    if initial and operators.shift is not None:
        u_free, z, c, result = proximal_solve(operator, operators.shift, contact, step,
                                              operators.contraction)
    else:
        u_free, z, c, result = free_solve(operator, contact, step, step.b, step.z0,
                                          before=step.z_before)
    if u_free is None:
        return StepOutcome(None, None, None, step.z0, result)
    d = problem.dim
    nc = 0 if problem.boundary is None else problem.boundary.nodes.size
    force, on_wall, stuck, held_force = contact_results(problem, operator, contact, z, c,
                                                        result, nc)
    u_frame = np.zeros(problem.ndofs)
    u_frame[operators.free] = u_free
    u_frame[problem.prescribed.fixed] = operators.held_frames(known.prescribed)
    u = operators.from_frames(u_frame)
    frame_u = problem.boundary.frame_components(u) if nc else np.zeros(0)
    lam, mu = operators.tensor(initial)
    a_lam, a_mu = lam * u, mu * u
    if known.history is not None:
        a_lam, a_mu = a_lam + known.history[0], a_mu + known.history[1]
    stress, zz = problem.assembly.cell_stress(a_lam, a_mu)
    points = u.reshape(-1, d)
    level = Level(
        n=step.index, t=step.t, u=points, beta=step.beta, stress=stress,
        stress_zz=zz if d == 2 else None, contact_force=force,
        frame_displacement=frame_u.reshape(nc, d), on_wall=on_wall, stuck=stuck,
        probes=(problem.probe_map @ points if problem.probe_map is not None
                else np.zeros((0, d))),
        reaction=operators.reaction(initial, u_frame, known.held_load, held_force),
        iterations=0 if result is None else result.nit,
        residual=0.0 if result is None else result.residual, gap=step.gap, k=step.k)
    return StepOutcome(level, u, frame_u, z, result)


def contact_results(problem, operator, contact, z, c, result, nc):
    """(force (nc, d), on_wall (nc,), stuck (nc,), held_force (nD,) or
    None) of a solved step: the force of Γ_C on the body, its reaction in
    the frame equations at the free components, −∂Φ/∂z_D of the laws at
    the held ones (also as the held dofs' share, for the reactions), and
    the wall and stick sets."""
    d = problem.dim
    force = np.zeros((nc, d))
    on_wall = np.zeros(nc, dtype=bool)
    stuck = np.zeros(nc, dtype=bool)
    held_force = None
    if contact is None:
        return force, on_wall, stuck, held_force
    force.reshape(-1)[problem.columns] = (operator.S @ z - c)[contact.unknowns]
    if contact.energy.held.size:
        force.reshape(-1)[contact.energy.held] = -contact.energy.held_gradient(z)
        held_force = problem.boundary.held_forces(force.reshape(-1),
                                                  problem.prescribed.fixed.size)
    normal = problem.normal_columns
    on_wall[problem.columns[normal] // d] = result.on_wall[contact.unknowns][normal]
    if contact.kink is not None and problem.friction.has_kink:
        stuck[contact.kink_nodes] = result.stuck
    return force, on_wall, stuck, held_force


def free_solve(operator, contact, step, b, z0, tighter=1.0, before=None, iterations=None):
    """The free dofs of (4.1) with the condensed step matrix ``operator``
    and the load b (β_n and the gaps of the :class:`StepInput` ``step``):
    the contact problem on z from ``z0``, then the interior by back
    substitution. Returns ``(u_free, z, c, result)``, u_free None when the
    contact solve failed; ``result`` None without Γ_C. With ``iterations``
    the contact solve takes at most that many Newton iterations, and an
    iterate it leaves unconverged (MAX_ITERATIONS) is expanded as well."""
    c = operator.reduce(b)
    result, z = None, z0
    if contact is not None:
        result = contact.minimise(operator.S, c, step.beta, step, z0, tighter, before,
                                  iterations)
        partial = iterations is not None and result.status == MAX_ITERATIONS
        if not (result.success or partial):
            return None, z0, c, result
        z = result.z
    return operator.expand(z, b), z, c, result


def proximal_solve(operator, shift, contact, step, contraction, rtol=1e-13):
    """The t = 0 problem min ½ uᵀ A u − bᵀ u + Φ(u_C) on the free dofs with the
    factorisation of a_n = A + D only (:mod:`adhesive_contact.scheme.operators`):
    u⁽ⁱ⁺¹⁾ solves the step with the load b + D u⁽ⁱ⁾, from u⁽⁰⁾ = 0, until
    ‖u⁽ⁱ⁺¹⁾ − u⁽ⁱ⁾‖ ≤ rtol ‖u⁽ⁱ⁺¹⁾‖ with the step converged (the error is
    then about ρ/(1 − ρ) of that, ρ ≤ ``contraction`` ≤ 0.3).

    Each step solve takes one Newton iteration from u⁽ⁱ⁾ (a proximal
    Newton method): the step energy is the t = 0 energy plus ½‖u − u⁽ⁱ⁾‖²_D,
    so an iteration that lowers it lowers the t = 0 energy, and the contact
    sets settle while the linear part contracts, instead of one after the
    other. A step it leaves unconverged is not one of the ``limit`` step
    solves; more than ``solver.max_iter`` of them are the t = 0 step's
    failure (MAX_ITERATIONS). The returned result counts the Newton
    iterations of all of them; its load c is that of the last, so that
    S z − c is the contact force of the t = 0 problem (a_n u − D u = A u).
    Same returns as :func:`free_solve`."""
    b, z0 = step.b, step.z0
    u = np.zeros(b.size)
    # ρ^i below rtol, with a margin for the contact terms' nonlinearity
    limit = 10 + int(np.log(rtol) / np.log(max(contraction, 1e-3)))
    budget = 0 if contact is None else int(contact.problem.options.solver.max_iter)
    total = settled = unsettled = 0
    while settled < limit:
        u_next, z0, c, result = free_solve(operator, contact, step, b + shift @ u, z0,
                                           tighter=1e-2, iterations=1)
        converged = result is None or result.success
        if result is not None:
            total += result.nit
            result.nit = total
        if u_next is None:
            return None, z0, c, result
        settled += converged
        unsettled += not converged
        if unsettled > budget:
            return None, z0, c, replace(result, message=(
                f"no convergence in {budget} iterations (the Newton steps of the t = 0 "
                f"iteration on the step matrix)"))
        done = converged and np.linalg.norm(u_next - u) <= rtol * np.linalg.norm(u_next)
        u = u_next
        if done:
            return u, z0, c, result
    if result is None:
        # no contact terms: a linear iteration contracting by ρ ≤ 0.3, which
        # only round-off can keep from rtol; its last iterate is as good
        return u, z0, c, result
    result = replace(result, status=MAX_ITERATIONS, message=(
        f"the t = 0 iteration on the step matrix did not settle in {limit} step solves "
        f"(each converged; the contact terms' nonlinearity outweighs the contraction "
        f"{contraction:.2g}); try a smaller time step"))
    return None, z0, c, result
