"""The energy balance of a run: work, stored energy and dissipation per level.

Every term has its own formula (docs/model.md §6, "Energy"); the balance

    W_n − S_n − D_n                                                     (6.1)

closes to round-off and the solver's tolerance because the terms follow the
scheme's own discrete energy identity, obtained by testing (4.1) at level n
with Δu_n = u_n − u_{n−1} (u_{−1} = 0, the scheme's initial state):

    (σ_n, ε(Δu_n)) = ⟨f(t_n), Δu_n⟩ + r_n·Δg_D + F_n·Δz_n,

r_n the reactions of the held dofs (the supports' force alone), F_n the
force of Γ_C on the body (the contact laws and the wall), z the nodal-frame
displacements of the contact nodes. At a contact node with a held component
F_n holds the laws' force along it, F = −∇_z Φ there (docs/conventions.md),
so F_n·Δz_n holds every component and r_n·Δg_D the supports' work. Its
terms:

- **work** W_n = Σ_{m≤n} ⟨f(t_m), Δu_m⟩ + r_m·Δg_D,m (+ the work of a
  moving wall, −λ_m·Δg_m): the right rectangle rule of the scheme;
- **body**: with a relaxing modulus G(t) = C_∞ + Σ_i e^{−t/τ_i} C_i the
  rectangle rule's history is σ_n = C ε_n − Σ_i C̃_i y_{i,n} with the
  internal variables y_{i,n} = d_i y_{i,n−1} + (1 − d_i) ε_n (y_{i,0} = 0,
  d_i = e^{−k/τ_i}), C̃_i = C_i/θ_i, θ_i = (1 − d_i)/(k/τ_i), and
  C̃_∞ = C − Σ_i C̃_i. The discrete free energy and the two dissipations

      ψ_n = ½|ε_n|²_{C̃∞} + Σ_i ½|ε_n − y_{i,n}|²_{C̃i}           (stored)
      V_n = Σ_i d_i/(1 − d_i) |Δy_{i,n}|²_{C̃i}                  (viscous)
      N_n = ½|Δε_n|²_{C̃∞} + Σ_i ½|Δε_n − Δy_{i,n}|²_{C̃i}        (numerical)

  satisfy (σ_n, Δε_n) = ψ_n − ψ_{n−1} + V_n + N_n exactly (|a|²_T = ∫ a:T a).
  Elastic: C̃_∞ = C, no terms;
- **contact**: Φ(β, z) = Σ_q w_q [P_ν(β_q, r_q) + j_τ(β_q, ξ_q)] on the
  contact quadrature (the laws' own potentials). It is stored; its change
  splits into the debonding release at the old displacement and a Bregman
  remainder at the new bonding,

      D^b_n = Φ(β_{n−1}, z_{n−1}) − Φ(β_n, z_{n−1})    (debonding, ≥ 0 as β falls)
      B_n   = Φ(β_n, z_{n−1}) − Φ(β_n, z_n) + F_n·(z_{n−1} − z_n) + W^wall_n
                                                      (numerical, with N_n)

  B_n ≥ 0 for convex laws, since −F_n is a subgradient at z_n of Φ(β_n, ·)
  plus the wall's constraint; W^wall_n = −λ_n·(g_n − g_{n−1}) is the work
  of a wall that moves (λ_n its multiplier), 0 for a fixed one.

The stored parts are named by what holds them: ``elastic`` (½|ε|²_{C̃∞}),
``memory`` (the branches), ``layer`` (Φ at β = 0 of the normal law: the
compliant layer), ``glue`` (the β-dependent rest of Φ) and ``friction``
(Φ at β = 0 of the friction laws: the model's friction is a potential of
u_τ, given back when u_τ returns).

A free energy with nonnegative dissipation exists for an elastic body and a
relaxing kernel (every Prony tensor of R negative semidefinite, as
``kernel = "relaxation"`` makes them); not for a ``prony`` kernel with
positive tensors (a modulus that grows with time) nor for a general
``function`` kernel, and not with a manufactured bonding source:
:func:`energy_unavailable` says why.
"""

from dataclasses import dataclass

import numpy as np

from ..threads import one_blas_thread

#: the stored and dissipated parts, in the order of the figure and summary.json
STORED = ("elastic", "memory", "layer", "glue", "friction")
DISSIPATED = ("viscous", "debonding", "numerical")


@dataclass
class EnergyHistory:
    """The energies of every level n = 0..M (each (M+1,) array).

    ``stored`` and ``dissipated`` map the names of :data:`STORED` and
    :data:`DISSIPATED` to their levels; the dissipated parts are cumulative."""

    t: np.ndarray
    external_work: np.ndarray
    stored: dict
    dissipated: dict

    @property
    def stored_total(self):
        return sum(self.stored.values())

    @property
    def dissipated_total(self):
        return sum(self.dissipated.values())

    @property
    def balance(self):
        """W − S − D per level (6.1): round-off and solver tolerance."""
        return self.external_work - self.stored_total - self.dissipated_total


def _negative_semidefinite(lam, mu, dim):
    return mu <= 0.0 and lam + 2.0 * mu / dim <= 0.0


def energy_unavailable(problem):
    """Why a run of ``problem`` has no energy balance (a sentence), or None."""
    memory = problem.scene.memory
    if problem.friction is not None and problem.friction.pressure_dependent:
        return ("a Coulomb-type friction bound mu p_nu(beta, u_nu) is no potential of the "
                "displacement: the contact terms have no stored energy and the balance "
                "does not hold (docs/model.md#coulomb-type-friction)")
    if problem.beta_source is not None:
        return ("a manufactured solution's bonding source makes β grow: the glue's "
                "energy balance does not hold")
    if memory is None:
        return None
    if problem.scene.adaptive is not None:
        return ("the discrete energy balance is that of uniform steps k = T/N; a run with "
                "[time.adaptive] has none here")
    if problem.scene.scheme == "second-order":
        return ("the discrete energy balance is that of the paper's right rectangle rule; "
                "the second-order scheme's trapezoidal memory has none here "
                "(use time.scheme = \"paper\")")
    if memory.kernel == "function":
        return ("a general memory kernel r(t) has no free energy with nonnegative "
                "dissipation (use kernel = \"relaxation\")")
    if not all(_negative_semidefinite(t.tensor.lam, t.tensor.mu, problem.dim)
               for t in memory.prony_terms):
        return ("a prony kernel with positive tensors is a modulus that grows with time: "
                "it has no free energy with nonnegative dissipation (kernel = "
                "\"relaxation\" gives a relaxing one)")
    return None


def branch_tensors(problem):
    """The discrete long-term tensor C̃_∞ and the branches (C̃_i, d_i) of
    the module docstring, as Lamé pairs: ``((lam, mu), [((lam, mu), d), ...])``."""
    material, k = problem.scene.material, problem.scene.k
    memory = problem.scene.memory
    lam_inf, mu_inf = material.lam, material.mu
    branches = []
    for term in (() if memory is None else memory.prony_terms):
        c = k / term.tau
        decay = np.exp(-c)
        theta = -np.expm1(-c) / c
        # C_i = −τ C_m (C_m the Prony tensor of R), C̃_i = C_i / θ
        lam, mu = -term.tau * term.tensor.lam / theta, -term.tau * term.tensor.mu / theta
        branches.append(((lam, mu), decay))
        lam_inf, mu_inf = lam_inf - lam, mu_inf - mu
    return (lam_inf, mu_inf), branches


class _Field:
    """A displacement-like field with its products by K_λ and K_μ."""

    def __init__(self, assembly, v, products=None):
        self.v = v
        self.kl, self.km = products if products is not None else (assembly.K_lam @ v,
                                                                  assembly.K_mu @ v)

    def __sub__(self, other):
        return _Field(None, self.v - other.v, (self.kl - other.kl, self.km - other.km))

    def energy(self, tensor):
        """½ |ε(v)|²_T = ½ (λ vᵀK_λv + μ vᵀK_μv)."""
        lam, mu = tensor
        return 0.5 * (lam * (self.v @ self.kl) + mu * (self.v @ self.km))


def bulk_energies(problem, u_levels):
    """ψ_n split as (elastic, memory), and the increments V_n, N_n of the
    body (module docstring), for the displacements ``u_levels`` (each
    (npoints, d) or (ndofs,)): four (M+1,) arrays."""
    assembly = problem.assembly
    long_term, branches = branch_tensors(problem)
    levels = len(u_levels)
    elastic, memory, viscous, numerical = (np.zeros(levels) for _ in range(4))
    zero = _Field(assembly, np.zeros(problem.ndofs), (np.zeros(problem.ndofs),) * 2)
    u_old = zero
    y_old = [zero] * len(branches)
    for n in range(levels):
        u = _Field(assembly, np.asarray(u_levels[n], dtype=float).reshape(-1))
        du = u - u_old
        if n == 0:   # level 0 has no memory yet: y_0 = 0
            y = [zero] * len(branches)
        else:        # y_n = d y_{n−1} + (1 − d) u_n, by linearity on K_λ y, K_μ y too
            y = [_Field(None, d * p.v + (1 - d) * u.v, (d * p.kl + (1 - d) * u.kl,
                                                        d * p.km + (1 - d) * u.km))
                 for p, (_, d) in zip(y_old, branches)]
        elastic[n] = u.energy(long_term)
        numerical[n] = du.energy(long_term)
        for (tensor, d), yi, pi in zip(branches, y, y_old):
            dy = yi - pi
            memory[n] += (u - yi).energy(tensor)
            numerical[n] += (du - dy).energy(tensor)
            if n > 0:
                viscous[n] += 2.0 * d / (1.0 - d) * dy.energy(tensor)
        u_old, y_old = u, y
    return elastic, memory, viscous, numerical


class ContactPotentials:
    """Φ of the contact laws on a run's contact quadrature, split by part,
    for nodal-frame displacements z (nz, levels) and bonding β (nf, levels)."""

    def __init__(self, problem):
        self.problem = problem
        self.boundary = problem.boundary

    def _traces(self, z):
        b = self.boundary
        r = b.normal_trace @ z                                        # (nq, L)
        xi = (np.stack([t @ z for t in b.tangential_trace], axis=-1)  # (nq, L, d−1)
              if b.tangential_trace else None)
        return r, xi

    def parts(self, beta, z):
        """(layer, glue, friction), each (L,): Σ_q w_q of P_ν(0, r),
        P_ν(β, r) − P_ν(0, r) + j_τ(β, ξ) − j_τ(0, ξ), and j_τ(0, ξ)."""
        problem, w = self.problem, self.boundary.weights
        r, xi = self._traces(z)
        bq = beta[self.boundary.facet_of_point]                        # (nq, L)
        zero = np.zeros_like(bq)
        normal = problem.normal_law
        layer = w @ normal.potential(zero, r)
        glue = w @ normal.potential(bq, r) - layer
        friction = np.zeros(r.shape[1])
        if problem.friction is not None and xi is not None:
            friction = w @ problem.friction.potential(zero, xi)
            glue = glue + w @ problem.friction.potential(bq, xi) - friction
        return layer, glue, friction

    def total(self, beta, z):
        return sum(self.parts(beta, z))

    def law_force(self, beta, z):
        """∇_z Φ(β, z) (nz, L) of the contact laws (friction: the minimal-norm
        subgradient at ξ = 0)."""
        problem, b, w = self.problem, self.boundary, self.boundary.weights
        r, xi = self._traces(z)
        bq = beta[b.facet_of_point]
        g = b.normal_trace.T @ (w[:, None] * problem.normal_law.value(bq, r))
        if problem.friction is not None and xi is not None:
            grad = w[:, None, None] * problem.friction.gradient(bq, xi)
            for i, t in enumerate(b.tangential_trace):
                g = g + t.T @ grad[:, :, i]
        return g


def contact_energies(solution):
    """(layer, glue, friction) stored per level, the increments D^b_n of the
    debonding and B_n of the contact's numerical dissipation and the work of
    a moving wall per level: six (M+1,) arrays (module docstring)."""
    problem = solution.problem
    levels = solution.t.size
    b = problem.boundary
    if b is None or b.facets.size == 0:
        zeros = np.zeros(levels)
        return zeros, zeros, zeros, zeros, zeros.copy(), zeros.copy()
    potentials = ContactPotentials(problem)
    z = solution.frame_displacement.reshape(levels, -1).T                  # (nz, L)
    z_old = np.concatenate([np.zeros((z.shape[0], 1)), z[:, :-1]], axis=1)
    beta = solution.beta.T                                                 # (nf, L)
    beta_old = np.concatenate([beta[:, :1], beta[:, :-1]], axis=1)         # β_{−1} = β_0
    layer, glue, friction = potentials.parts(beta, z)
    at_old = potentials.total(beta, z_old)
    debonding = potentials.total(beta_old, z_old) - at_old
    force = solution.contact_force.reshape(levels, -1).T
    wall = np.zeros(levels)
    gap = solution.gap
    if gap is not None and gap.shape[1]:
        g = gap
        dg = np.diff(g, axis=0, prepend=g[:1])                             # g_{−1} = g_0
        dg = np.where(np.isfinite(dg), dg, 0.0)
        if np.any(dg != 0.0):
            # λ_a = −F_{a,ν} − ∂_{z_{a,ν}} Φ at the nodes the wall holds
            normal = np.arange(0, z.shape[0], problem.dim)
            lam = -(force + potentials.law_force(beta, z))[normal].T * solution.on_wall
            wall = -np.sum(lam * dg, axis=1)
    bregman = at_old - (layer + glue + friction) + np.sum(force * (z_old - z), axis=0) + wall
    return layer, glue, friction, debonding, bregman, wall


def external_work_increments(solution):
    """⟨f(t_n), Δu_n⟩ + r_n·Δg_D,n per level (M+1,), u_{−1} = 0."""
    problem = solution.problem
    fixed = problem.prescribed.fixed
    out = np.zeros(solution.t.size)
    old = np.zeros(problem.ndofs)
    for n, t in enumerate(solution.t):
        u = np.asarray(solution.u[n], dtype=float).reshape(-1)
        du = u - old
        out[n] = problem.loads(t) @ du + solution.reaction[n] @ du[fixed]
        old = u
    return out


def energies(solution):
    """The :class:`EnergyHistory` of a solution, or None where no free
    energy exists (:func:`energy_unavailable`).

    Parameters
    ----------
    solution : Solution (u read one level at a time, so a streamed one works;
        one read back from a folder gives the energies it recorded)

    Returns
    -------
    EnergyHistory or None
    """
    problem = solution.problem
    if energy_unavailable(problem) is not None:
        return None
    recorded = getattr(solution, "scalars", None)
    if recorded is not None and "external_work" in recorded:   # read back from a folder
        return EnergyHistory(
            t=np.asarray(solution.t, dtype=float).copy(),
            external_work=np.asarray(recorded["external_work"][1]),
            stored={part: np.asarray(recorded[f"stored_{part}"][1]) for part in STORED},
            dissipated={part: np.asarray(recorded[f"dissipated_{part}"][1])
                        for part in DISSIPATED})
    with one_blas_thread():   # level-sized products: threads only wait on each other
        elastic, memory, viscous, numerical = bulk_energies(problem, solution.u)
        layer, glue, friction, debonding, bregman, wall = contact_energies(solution)
        work = np.cumsum(external_work_increments(solution) + wall)
    return EnergyHistory(
        t=np.asarray(solution.t, dtype=float).copy(), external_work=work,
        stored={"elastic": elastic, "memory": memory, "layer": layer, "glue": glue,
                "friction": friction},
        dissipated={"viscous": np.cumsum(viscous), "debonding": np.cumsum(debonding),
                    "numerical": np.cumsum(numerical + bregman)})
