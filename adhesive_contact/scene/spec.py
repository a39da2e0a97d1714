"""The validated scene: one frozen dataclass per table.

The :class:`Scene` dataclasses are the one stored form of a scene; its
``resolved`` record (every default filled in, written to summary.json and
to the identity of a convergence study) is derived from them on demand
(:mod:`.record`), so ``dataclasses.replace`` gives a consistent scene.
Absent optional tables: ``[memory]`` and ``[exact]`` add a part to the
problem and are None when absent; ``[loads]``, ``[contact]``, ``[solver]``
and ``[output]`` only set values that have defaults and read as those
defaults when absent.
"""

from dataclasses import dataclass, field

from .keys import default
from .record import resolved as resolved_record


@dataclass(frozen=True)
class MeshSpec:
    """The ``[mesh]`` table: a mesh of ``domain`` refined ``refine`` times.

    ``domain`` "rectangle"/"box": a structured mesh of ``size`` and
    ``cells``; "file": the mesh file ``file`` (as the scene gave it) found
    at ``path`` (resolved against the scene file's folder), whose content
    has the SHA-256 ``sha256`` (part of the resolved record, so that a study
    of another mesh is another study).
    """

    domain: str
    size: tuple = ()
    cells: tuple = ()
    pattern: str = default("mesh.pattern")
    refine: int = default("mesh.refine")
    file: str = None
    path: str = None
    sha256: str = None
    dim: int = None               # the space dimension (needed by a file mesh)


@dataclass(frozen=True)
class Isotropic:
    """An isotropic tensor C ε = λ tr(ε) I + 2 μ ε given by its Lamé pair.

    ``E`` and ``nu`` are the Young pair the scene gave, from which λ and μ
    were computed; both None when the scene gave (λ, μ) itself.
    """

    lam: float
    mu: float
    E: float = None
    nu: float = None


@dataclass(frozen=True)
class PronyTerm:
    """One term e^{-t/τ} C of a Prony series R(t) = Σ_m e^{-t/τ_m} C_m."""

    tensor: Isotropic
    tau: float


@dataclass(frozen=True)
class MemorySpec:
    """The memory kernel R of σ = C ε + ∫_0^t R(t − s) ε(s) ds.

    - ``prony``: R(t) = Σ_m e^{−t/τ_m} C_m (``terms``), added to [material]'s C;
    - ``function``: R(t) = r(t) C_0;
    - ``relaxation``: a relaxation modulus G(t) = C_∞ + Σ_i e^{−t/τ_i} C_i
      (``long_term`` C_∞, ``terms`` the C_i with τ_i), σ(t) = ∫_0^t G(t − s) dε(s)
      = G(0) ε(t) + ∫_0^t G'(t − s) ε(s) ds: C = G(0) = C_∞ + Σ_i C_i (the
      scene's ``material``) and R(t) = G'(t) = −Σ_i (1/τ_i) e^{−t/τ_i} C_i
      (:attr:`prony_terms`).
    """

    kernel: str
    terms: tuple = ()
    function: object = None       # Expression r(t) for kernel = "function"
    tensor: Isotropic = None      # C_0 for kernel = "function"
    long_term: Isotropic = None   # C_∞ for kernel = "relaxation"

    @property
    def prony_terms(self):
        """R as Prony terms (tensor, τ): the terms themselves for ``prony``,
        (−C_i/τ_i, τ_i) for ``relaxation``; () for ``function``."""
        if self.kernel == "prony":
            return self.terms
        if self.kernel == "relaxation":
            return tuple(PronyTerm(Isotropic(-t.tensor.lam / t.tau, -t.tensor.mu / t.tau), t.tau)
                         for t in self.terms)
        return ()

    @property
    def shortest_relaxation_time(self):
        """min τ_m of a Prony or relaxation kernel, None for ``function``."""
        terms = self.prony_terms
        return min(t.tau for t in terms) if terms else None


@dataclass(frozen=True)
class LawSpec:
    """A law of the registry in :mod:`adhesive_contact.laws` and its parameters
    (law ``"none"`` for no law)."""

    law: str
    params: dict = field(default_factory=dict)


@dataclass(frozen=True)
class FoundationSpec:
    """A rigid foundation the gap is measured to (``[contact.foundation]``):
    a ``plane`` through ``point`` with unit ``normal`` (out of the
    foundation, towards the body), a ``sphere`` (a disc in 2D) of centre
    ``point`` and ``radius``, or a ``cylinder`` (3D) of ``radius`` around
    the line through ``point`` along ``axis``."""

    shape: str
    point: tuple
    normal: tuple = None
    axis: tuple = None
    radius: float = None


@dataclass(frozen=True)
class ContactSpec:
    """The ``[contact]`` table; ``ContactSpec()`` when the scene has none.

    ``gap`` and ``foundation`` None: no wall (at most one of them is set);
    ``beta0`` None: β_0 = 1; no law is law ``"none"``
    (``friction`` lists the laws whose potentials sum, none of them
    ``"none"``).
    """

    gap: object = None            # Expression, or None for no wall
    quadrature: str = default("contact.quadrature")
    order: int = default("contact.order")   # exactness of the Gauss rule on Γ_C
    normal: LawSpec = LawSpec("none")
    friction: tuple = ()          # LawSpecs whose potentials sum
    bonding: LawSpec = LawSpec("none")
    beta0: object = None          # Expression for β_0, or None for β_0 = 1
    integrator: str = default("contact.bonding.integrator")   # for the bonding ODE
    foundation: FoundationSpec = None  # the wall's geometry, instead of a gap expression

    @property
    def has_wall(self):
        """Whether Γ_C has a rigid wall: a gap expression or a foundation."""
        return self.gap is not None or self.foundation is not None

    @property
    def bonded(self):
        """Whether the scene sets the bonding at all: a law or β_0."""
        return self.bonding.law != "none" or self.beta0 is not None


@dataclass(frozen=True)
class ExactSpec:
    """A manufactured solution (docs/verification.md): u*, β* and the wall multiplier λ*."""

    u: tuple                      # d Expressions in x, y, (z), t
    beta: object = None           # Expression, or None (β* = 1)
    multiplier: object = None     # Expression λ* > 0 where u*_ν = g, or None


@dataclass(frozen=True)
class SolverSpec:
    """The ``[solver]`` table.

    ``method`` the step method (:mod:`adhesive_contact.step_methods`);
    ``linear_tol`` the relative residual ‖b − A x‖ ≤ linear_tol ‖b‖ of each
    solve of the iterative backend (AMG-preconditioned CG; the direct
    backends solve to round-off and ignore it);
    ``penalty`` and ``smoothing`` are read by ``method = "penalty"`` only:
    the wall's penalty stiffness is ρ = penalty · max_i S_ii (the largest
    diagonal entry of the step's condensed matrix), so the wall violation
    it leaves is about 1/penalty of the displacement a unit contact force
    causes; the friction kink is rounded over δ = smoothing · the diameter
    of the body.
    """

    method: str = default("solver.method")
    tol: float = default("solver.tol")
    max_iter: int = default("solver.max_iter")
    linear: str = default("solver.linear")   # the backend (adhesive_contact.linear_solvers)
    penalty: float = default("solver.penalty")       # relative to max diag S
    smoothing: float = default("solver.smoothing")   # relative to the diameter of the body
    linear_tol: float = default("solver.linear_tol")   # AMG's CG: of each linear solve


@dataclass(frozen=True)
class AdaptiveSpec:
    """``[time.adaptive]``: step doubling with steps k_max 2^-j, j = 0..halvings
    (docs/scheme.md, "Adaptive time steps"); k_max = T/N."""

    tol: float
    k_min: float            # k_max 2^-halvings (the given k_min rounded down)
    halvings: int           # J ≥ 1
    rate_floor: float = default("time.adaptive.rate_floor")
    growth: float = default("time.adaptive.growth")
    shrink: float = default("time.adaptive.shrink")
    safety: float = default("time.adaptive.safety")


@dataclass(frozen=True)
class Scene:
    """A validated scene (see the module docstring for absent tables)."""

    title: str
    dim: int
    mesh: MeshSpec
    dirichlet: tuple
    contact_sides: tuple
    material: Isotropic
    memory: MemorySpec            # None: no memory
    body: tuple                   # d Expressions
    traction: dict                # side -> d Expressions
    contact: ContactSpec
    T: float
    steps: int
    solver: SolverSpec
    probes: tuple
    exact: ExactSpec = None       # None: no manufactured solution
    displacement: dict = field(default_factory=dict)  # side -> d Expressions or None ("free")
    units: dict = field(default_factory=dict)  # quantity -> unit name ([output] units)
    plot_times: object = "auto"   # the figures' times: "auto" or a sorted tuple
    scheme: str = default("time.scheme")   # "paper" or "second-order" (docs/scheme.md)
    adaptive: AdaptiveSpec = None   # [time.adaptive], or None: uniform steps k = T/N
    every: int = default("output.every")     # fields at every N-th level (and more)
    fields: tuple = default("output.fields")  # the fields written there

    @property
    def held_sides(self):
        """The sides with a prescribed displacement: Dirichlet (u = 0) sides,
        then the sides of [boundary.displacement], each once."""
        return tuple(self.dirichlet) + tuple(s for s in self.displacement
                                             if s not in self.dirichlet)

    @property
    def k(self):
        """The time step k = T / N."""
        return self.T / self.steps

    @property
    def has_contact_terms(self):
        """Whether Γ_C carries anything: a wall, a normal law or friction."""
        c = self.contact
        return bool(self.contact_sides) and (
            c.has_wall or c.normal.law != "none" or len(c.friction) > 0
            or c.bonding.law != "none")

    @property
    def resolved(self):
        """The scene with every default filled in, as a JSON-able dict of its
        tables (expressions as their text, or as the number given)."""
        return resolved_record(self)
