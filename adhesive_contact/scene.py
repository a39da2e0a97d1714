"""Scenes: the validated description of one problem (SPEC.md, scene file).

A scene is read from a TOML document (``parse_scene(text)``) or from the
dictionary it decodes to (``scene_from_dict``). Every key is checked: a
missing, unknown or wrongly typed key, or a value outside its range, raises
:class:`SceneError` whose message is one line that names the key and says
what is allowed. Nothing is computed here; geometry-dependent checks (a
probe outside the mesh, a negative gap) are made when the problem is built.

The :class:`Scene` dataclasses are the one stored form of a scene; its
``resolved`` record (every default filled in, written to summary.json and
to the identity of a convergence study) is derived from them on demand, so
``dataclasses.replace`` gives a consistent scene. Absent optional tables:
``[memory]`` and ``[exact]`` add a part to the problem and are None when
absent; ``[loads]``, ``[contact]``, ``[solver]`` and ``[output]`` only
set values that have defaults and read as those defaults when absent.
"""

import math
import tomllib
from dataclasses import dataclass, field

from .expressions import ExpressionError, compile_expression
from .laws import BONDING_LAWS, FRICTION_LAWS, NORMAL_LAWS
from .linear_solvers import METHODS
from .manufactured import symbolic_problem
from .linear_solvers.pardiso import available as pardiso_available


class SceneError(ValueError):
    """A scene that cannot be run; ``str(err)`` is ``"key: what is allowed"``."""

    def __init__(self, key, message):
        self.key = key
        super().__init__(f"{key}: {message}" if key else message)


#: the ranges every scene must keep (see the readers that use them for why)
MAX_TITLE = 500             # characters of the title (it heads every plot)
LENGTHS = (1e-6, 1e6)       # each length of the domain; rescale the units outside
MAX_CELL_ASPECT = 1e3       # longest over shortest edge of the structured cells
MAX_NODES = 10**8           # nodes of the refined mesh
MAX_STEPS = 10**8           # time steps
TOL_RANGE = (1e-14, 1e-3)   # solver.tol, relative to the force scale of a step
MAX_ITER = 10_000           # solver.max_iter

SIDES = {2: ("left", "right", "bottom", "top"),
         3: ("left", "right", "bottom", "top", "front", "back")}


@dataclass(frozen=True)
class MeshSpec:
    """The ``[mesh]`` table: a structured mesh of ``domain`` refined ``refine`` times."""

    domain: str
    size: tuple
    cells: tuple
    pattern: str = "diagonal"
    refine: int = 0


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
    """Relaxation kernel R: ``prony`` (terms) or ``function`` (r(t) C_0)."""

    kernel: str
    terms: tuple = ()
    function: object = None       # Expression r(t) for kernel = "function"
    tensor: Isotropic = None      # C_0 for kernel = "function"


@dataclass(frozen=True)
class LawSpec:
    """A law of the registry in :mod:`adhesive_contact.laws` and its parameters
    (law ``"none"`` for no law)."""

    law: str
    params: dict = field(default_factory=dict)


@dataclass(frozen=True)
class ContactSpec:
    """The ``[contact]`` table; ``ContactSpec()`` when the scene has none.

    ``gap`` None: no wall; ``beta0`` None: β_0 = 1; no law is law ``"none"``
    (``friction`` lists the laws whose potentials sum, none of them
    ``"none"``).
    """

    gap: object = None            # Expression, or None for no wall
    quadrature: str = "nodal"
    order: int = 4                # exactness of the Gauss rule on Γ_C
    normal: LawSpec = LawSpec("none")
    friction: tuple = ()          # LawSpecs whose potentials sum
    bonding: LawSpec = LawSpec("none")
    beta0: object = None          # Expression for β_0, or None for β_0 = 1
    integrator: str = "explicit"  # for the bonding ODE

    @property
    def bonded(self):
        """Whether the scene sets the bonding at all: a law or β_0."""
        return self.bonding.law != "none" or self.beta0 is not None


@dataclass(frozen=True)
class ExactSpec:
    """A manufactured solution (MODEL.md §7): u*, β* and the wall multiplier λ*."""

    u: tuple                      # d Expressions in x, y, (z), t
    beta: object = None           # Expression, or None (β* = 1)
    multiplier: object = None     # Expression λ* > 0 where u*_ν = g, or None


@dataclass(frozen=True)
class SolverSpec:
    method: str = "newton"
    tol: float = 1e-10
    max_iter: int = 50
    linear: str = "auto"          # the linear backend (adhesive_contact.linear_solvers)


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

    @property
    def k(self):
        """The time step k = T / N."""
        return self.T / self.steps

    @property
    def has_contact_terms(self):
        """Whether Γ_C carries anything: a wall, a normal law or friction."""
        c = self.contact
        return bool(self.contact_sides) and (
            c.gap is not None or c.normal.law != "none" or len(c.friction) > 0
            or c.bonding.law != "none")

    @property
    def resolved(self):
        """The scene with every default filled in, as a JSON-able dict of its
        tables (expressions as their text, or as the number given)."""
        return {
            "title": self.title, "dim": self.dim,
            "mesh": {"domain": self.mesh.domain, "size": list(self.mesh.size),
                     "cells": list(self.mesh.cells), "pattern": self.mesh.pattern,
                     "refine": self.mesh.refine},
            "boundary": {"dirichlet": list(self.dirichlet), "contact": list(self.contact_sides)},
            "material": {**_young(self.material), "lam": self.material.lam,
                         "mu": self.material.mu},
            "memory": _memory_record(self.memory),
            "loads": {"body": _texts(self.body),
                      "traction": {side: _texts(v) for side, v in self.traction.items()}},
            "contact": _contact_record(self.contact),
            "time": {"T": self.T, "steps": self.steps, "k": self.k},
            "solver": {"method": self.solver.method, "tol": self.solver.tol,
                       "max_iter": self.solver.max_iter, "linear": self.solver.linear},
            "output": {"probes": [list(p) for p in self.probes]},
            "exact": _exact_record(self.exact),
        }


# ---------------------------------------------------------------- the resolved record


def _texts(expressions):
    return [e.source for e in expressions]


def _young(tensor):
    return {} if tensor.E is None else {"E": tensor.E, "nu": tensor.nu}


def _pair(tensor):
    """The pair the scene gave: (E, nu) or (lam, mu)."""
    return _young(tensor) or {"lam": tensor.lam, "mu": tensor.mu}


def _law_record(spec):
    return {"law": spec.law, **spec.params}


def _memory_record(memory):
    if memory is None:
        return None
    if memory.kernel == "prony":
        return {"kernel": "prony",
                "terms": [{**_pair(t.tensor), "tau": t.tau} for t in memory.terms]}
    return {"kernel": "function", "r": memory.function.source, **_pair(memory.tensor)}


def _contact_record(contact):
    """{} for a scene without contact settings."""
    if contact == ContactSpec():
        return {}
    record = {} if contact.gap is None else {"gap": contact.gap.given}
    record.update(quadrature=contact.quadrature, order=contact.order,
                  normal=_law_record(contact.normal),
                  friction=[_law_record(f) for f in contact.friction])
    if contact.beta0 is not None:
        record["beta0"] = contact.beta0.given
    if contact.bonded:
        record["integrator"] = contact.integrator
    record["bonding"] = _law_record(contact.bonding)
    return record


def _exact_record(exact):
    if exact is None:
        return None
    record = {"u": _texts(exact.u)}
    if exact.beta is not None:
        record["beta"] = exact.beta.source
    if exact.multiplier is not None:
        record["multiplier"] = exact.multiplier.source
    return record


# ---------------------------------------------------------------- reading tables


class _Table:
    """A TOML table being read: typed access, and unknown keys reported."""

    def __init__(self, data, path):
        if not isinstance(data, dict):
            raise SceneError(path, f"must be a table, got {_show(data)}")
        self.data = data
        self.path = path
        self.used = set()

    def key(self, name):
        return f"{self.path}.{name}" if self.path else name

    def has(self, name):
        return name in self.data

    def get(self, name, kind, default=None, required=True):
        self.used.add(name)
        if name not in self.data:
            if required and default is None:
                raise SceneError(self.key(name), f"missing; {_describe(kind)} is required")
            return default
        return _check_type(self.key(name), self.data[name], kind)

    def table(self, name, required=False):
        self.used.add(name)
        if name not in self.data:
            if required:
                raise SceneError(self.key(name), "missing table")
            return None
        return _Table(self.data[name], self.key(name))

    def finish(self):
        unknown = sorted(set(self.data) - self.used)
        if unknown:
            allowed = ", ".join(sorted(self.used)) or "none"
            raise SceneError(self.key(unknown[0]),
                             f"unknown key; allowed here: {allowed}")


def _show(value):
    text = repr(value)
    return text if len(text) < 40 else text[:37] + "..."


def _describe(kind):
    return {"number": "a number", "int": "an integer", "str": "a string",
            "list": "a list", "expr": "a number or an expression string",
            "table": "a table"}[kind]


def _check_type(key, value, kind):
    ok = {
        "number": isinstance(value, (int, float)) and not isinstance(value, bool),
        "int": isinstance(value, int) and not isinstance(value, bool),
        "str": isinstance(value, str),
        "list": isinstance(value, list),
        "expr": isinstance(value, (int, float, str)) and not isinstance(value, bool),
        "table": isinstance(value, dict),
    }[kind]
    if not ok:
        raise SceneError(key, f"must be {_describe(kind)}, got {_show(value)}")
    if kind == "number":
        value = float(value)
        if not math.isfinite(value):
            raise SceneError(key, f"must be a finite number, got {value}")
    return value


def _positive(key, value):
    if not value > 0:
        raise SceneError(key, f"must be > 0, got {value:g}")
    return value


def _choice(key, value, allowed):
    if value not in allowed:
        raise SceneError(key, f"must be one of {', '.join(map(repr, allowed))}, got {_show(value)}")
    return value


def _expression(key, source, variables):
    try:
        expr = compile_expression(source)
    except ExpressionError as err:
        raise SceneError(key, f"{err} (in {_show(source)})") from None
    extra = sorted(set(expr.uses) - set(variables))
    if extra:
        raise SceneError(key, f"expression uses {extra[0]!r}; allowed variables here: "
                         f"{', '.join(variables)}")
    return expr


def _isotropic(table, dim):
    """Exactly one pair: (E, nu) or (lam, mu)."""
    young = table.has("E") or table.has("nu")
    lame = table.has("lam") or table.has("mu")
    if young and lame:
        raise SceneError(table.key("E"), "give exactly one pair: E and nu, or lam and mu")
    if lame:
        lam = table.get("lam", "number")
        mu = _positive(table.key("mu"), table.get("mu", "number"))
        if not lam + 2.0 * mu / dim > 0:
            raise SceneError(table.key("lam"),
                             f"must give a positive bulk modulus lam + 2 mu/{dim} > 0")
        return Isotropic(lam, mu)
    E = _positive(table.key("E"), table.get("E", "number"))
    nu = table.get("nu", "number")
    if not -1.0 < nu < 0.5:
        raise SceneError(table.key("nu"), f"must lie in (-1, 0.5), got {nu:g}")
    lam = E * nu / ((1.0 + nu) * (1.0 - 2.0 * nu))
    mu = E / (2.0 * (1.0 + nu))
    return Isotropic(lam, mu, E, nu)


def _vector_of_expressions(key, value, dim, variables):
    if not isinstance(value, list) or len(value) != dim:
        raise SceneError(key, f"must be a list of {dim} numbers or expressions, got {_show(value)}")
    return tuple(_expression(f"{key}[{i}]", v, variables) for i, v in enumerate(value))


def _law(table, registry):
    """A LawSpec of ``registry`` (law name -> (class, {parameter: constraint}))."""
    name = _choice(table.key("law"), table.get("law", "str"), tuple(registry))
    params = {}
    for pname, constraint in registry[name][1].items():
        value = table.get(pname, "number")
        if constraint == "positive":
            _positive(table.key(pname), value)
        elif constraint == "nonnegative" and value < 0:
            raise SceneError(table.key(pname), f"must be >= 0, got {value:g}")
        params[pname] = value
    check = getattr(registry[name][0], "check", None)
    problem = check(params) if check else None
    if problem:
        raise SceneError(table.key(problem[0]), problem[1])
    return LawSpec(name, params)


def _read_mesh(table, dim):
    domains = {2: ("rectangle",), 3: ("box",)}[dim]
    domain = _choice(table.key("domain"), table.get("domain", "str"), domains)
    size = table.get("size", "list")
    if len(size) != dim or not all(isinstance(s, (int, float)) and not isinstance(s, bool)
                                   and s > 0 for s in size):
        raise SceneError(table.key("size"), f"must be a list of {dim} positive lengths, "
                         f"got {_show(size)}")
    _lengths(table.key("size"), size)
    cells = table.get("cells", "list")
    if len(cells) != dim or not all(isinstance(c, int) and not isinstance(c, bool)
                                    and c >= 1 for c in cells):
        raise SceneError(table.key("cells"), f"must be a list of {dim} integers >= 1, "
                         f"got {_show(cells)}")
    patterns = ("diagonal", "cross") if dim == 2 else ("diagonal",)
    pattern = _choice(table.key("pattern"), table.get("pattern", "str", "diagonal"), patterns)
    refine = table.get("refine", "int", 0, required=False)
    if refine < 0 or refine > 12:
        raise SceneError(table.key("refine"), f"must be an integer in 0..12, got {refine}")
    _cell_counts(table.key("cells"), size, cells, refine, pattern)
    table.finish()
    return MeshSpec(domain, tuple(float(s) for s in size), tuple(cells), pattern, refine)


def _lengths(key, size):
    """Each length finite and within LENGTHS: outside, the element volumes
    (h^d, refined up to 4096 times) underflow or the stiffness overflows,
    and the factorisation meets zero pivots."""
    lo, hi = LENGTHS
    for i, s in enumerate(size):
        if not lo <= s <= hi:   # False for inf and nan
            raise SceneError(f"{key}[{i}]", f"must be a finite length in [{lo:g}, {hi:g}] "
                             f"(rescale the units), got {s!r}")


def nodes_of(size_cells, refine, pattern="diagonal"):
    """The number of nodes of the structured mesh of ``cells`` refined
    ``refine`` times (exact, in Python integers: no overflow)."""
    n = [c * 2**refine for c in size_cells]
    nodes = math.prod(c + 1 for c in n)
    if pattern == "cross":   # a centre node per quadrilateral of the unrefined mesh,
        nodes += math.prod(size_cells) * 4**refine   # refined with the rest
    return nodes


def _cell_counts(key, size, cells, refine, pattern):
    """At most MAX_NODES nodes after refinement (numpy cannot index more
    anyway, and the memory check needs a count it can estimate from), and
    cells no more elongated than MAX_CELL_ASPECT (their stiffness would be
    nearly singular)."""
    nodes = nodes_of(cells, refine, pattern)
    if nodes > MAX_NODES:
        raise SceneError(key, f"gives {nodes:.3g} nodes after {refine} refinements; at most "
                         f"{MAX_NODES:.0e} are allowed")
    edges = [s / c for s, c in zip(size, cells)]
    if max(edges) > MAX_CELL_ASPECT * min(edges):
        raise SceneError(key, f"cells of {' x '.join(f'{e:.3g}' for e in edges)} are "
                         f"elongated more than {MAX_CELL_ASPECT:g}:1; choose cells "
                         "closer to the proportions of mesh.size")


def _read_sides(table, name, dim):
    value = table.get(name, "list", [], required=False)
    sides = SIDES[dim]
    for i, side in enumerate(value):
        if side not in sides:
            raise SceneError(f"{table.key(name)}[{i}]",
                             f"unknown side {_show(side)}; sides are {', '.join(sides)}")
    if len(set(value)) != len(value):
        raise SceneError(table.key(name), "lists a side twice")
    return tuple(value)


def _read_boundary(table, dim):
    """(Dirichlet sides, contact sides): disjoint, at least one Dirichlet side."""
    dirichlet = _read_sides(table, "dirichlet", dim)
    contact_sides = _read_sides(table, "contact", dim)
    table.finish()
    if not dirichlet:
        raise SceneError("boundary.dirichlet", "must list at least one side (|Γ_D| > 0)")
    both = set(dirichlet) & set(contact_sides)
    if both:
        raise SceneError("boundary.contact", f"side {sorted(both)[0]!r} is also Dirichlet; "
                         "the parts of the boundary must be disjoint")
    return dirichlet, contact_sides


def _read_material(table, dim):
    material = _isotropic(table, dim)
    table.finish()
    return material


def _read_memory(table, dim):
    """A MemorySpec, or None without a [memory] table."""
    if table is None:
        return None
    kernel = _choice(table.key("kernel"), table.get("kernel", "str"), ("prony", "function"))
    if kernel == "prony":
        terms_raw = table.get("terms", "list")
        if not terms_raw:
            raise SceneError(table.key("terms"), "must list at least one term {E, nu, tau}")
        terms = []
        for i, raw in enumerate(terms_raw):
            t = _Table(raw, f"{table.key('terms')}[{i}]")
            tensor = _isotropic(t, dim)
            tau = _positive(t.key("tau"), t.get("tau", "number"))
            t.finish()
            terms.append(PronyTerm(tensor, tau))
        table.finish()
        return MemorySpec("prony", terms=tuple(terms))
    function = _expression(table.key("r"), table.get("r", "expr"), ("t",))
    tensor = _isotropic(table, dim)
    table.finish()
    return MemorySpec("function", function=function, tensor=tensor)


def _read_loads(table, dim, dirichlet, contact_sides):
    """(body, traction): d expressions of f_0 (zero by default) and
    {side: d expressions of f_N} on Neumann sides (neither Dirichlet nor contact)."""
    body = tuple(compile_expression("0") for _ in range(dim))
    traction = {}
    if table is None:
        return body, traction
    variables = _coordinates(dim) + ("t",)
    if table.has("body"):
        body = _vector_of_expressions(table.key("body"), table.get("body", "list"), dim,
                                      variables)
    tt = table.table("traction")
    if tt is not None:
        for side, raw in tt.data.items():
            key = tt.key(side)
            tt.used.add(side)
            if side not in SIDES[dim]:
                raise SceneError(key, f"unknown side; sides are {', '.join(SIDES[dim])}")
            if side in dirichlet or side in contact_sides:
                raise SceneError(key, "a traction acts on a Neumann side only; "
                                 f"{side!r} is a {'Dirichlet' if side in dirichlet else 'contact'} side")
            traction[side] = _vector_of_expressions(key, raw, dim, variables)
        tt.finish()
    table.finish()
    return body, traction


def _read_normal(table):
    """The normal law of ``contact.normal`` (law "none" without the table)."""
    if table is None:
        return LawSpec("none")
    normal = _law(table, NORMAL_LAWS)
    table.finish()
    return normal


def _read_friction(table):
    """The friction laws of ``contact.friction``: one table or a list of them."""
    raw = table.data.get("friction")
    table.used.add("friction")
    if raw is None:
        return ()
    items = raw if isinstance(raw, list) else [raw]
    laws = []
    for i, item in enumerate(items):
        key = table.key("friction") + (f"[{i}]" if isinstance(raw, list) else "")
        sub = _Table(item, key)
        spec = _law(sub, FRICTION_LAWS)
        sub.finish()
        if spec.law != "none":
            laws.append(spec)
    return tuple(laws)


def _read_bonding(table, dim):
    """(bonding law, β_0 or None, integrator) of ``contact.bonding``."""
    if table is None:
        return LawSpec("none"), None, ContactSpec.integrator
    bonding = _law(table, BONDING_LAWS)
    beta0 = None
    if table.has("beta0"):
        source = table.get("beta0", "expr")
        beta0 = _expression(table.key("beta0"), source, _coordinates(dim))
        if beta0.is_constant and not 0.0 <= float(beta0(0.0)) <= 1.0:
            raise SceneError(table.key("beta0"), f"must lie in [0, 1], got {source}")
    integrator = _choice(table.key("integrator"),
                         table.get("integrator", "str", "explicit"), ("explicit",))
    table.finish()
    return bonding, beta0, integrator


def _read_contact(table, dim, contact_sides):
    """A ContactSpec; ``ContactSpec()`` without a [contact] table."""
    if table is None:
        return ContactSpec()
    if not contact_sides:
        raise SceneError("contact", "a [contact] table needs boundary.contact to list its sides")
    gap = None
    if table.has("gap"):
        source = table.get("gap", "expr")
        gap = _expression(table.key("gap"), source, _coordinates(dim) + ("t",))
        if gap.is_constant and float(gap(0.0)) < 0:
            raise SceneError(table.key("gap"), f"must be >= 0, got {source}")
    quadrature = _choice(table.key("quadrature"),
                         table.get("quadrature", "str", "nodal"), ("nodal", "gauss"))
    order = table.get("order", "int", 4, required=False)
    if not 1 <= order <= 10:
        raise SceneError(table.key("order"), f"must be an integer in 1..10, got {order}")
    normal = _read_normal(table.table("normal"))
    friction = _read_friction(table)
    bonding, beta0, integrator = _read_bonding(table.table("bonding"), dim)
    table.finish()
    kinked = [f.law for f in friction if FRICTION_LAWS[f.law][0].has_kink]
    if quadrature == "gauss" and kinked:
        smooth = ", ".join(name for name, (cls, _) in FRICTION_LAWS.items()
                           if cls is not None and not cls.has_kink)
        raise SceneError(table.key("quadrature"), f"'gauss' takes smooth friction laws only "
                         f"({smooth}); {kinked[0]!r} needs 'nodal'")
    return ContactSpec(gap, quadrature, order, normal, friction, bonding, beta0, integrator)


def _read_time(table):
    """(T, steps)."""
    T = _positive("time.T", table.get("T", "number"))
    steps = table.get("steps", "int")
    if not 1 <= steps <= MAX_STEPS:
        raise SceneError("time.steps", f"must be an integer in 1..{MAX_STEPS:.0e}, got {steps}")
    table.finish()
    return T, steps


def _tolerance(key, tol):
    """tol within TOL_RANGE: the residual is relative to the step's force
    scale, so a tol near 1 accepts the starting point as the solution (no
    Newton iteration, a quiet wrong answer), and below 1e-14 round-off
    keeps the residual from reaching it."""
    lo, hi = TOL_RANGE
    if not lo <= tol <= hi:
        raise SceneError(key, f"must lie in [{lo:g}, {hi:g}], got {tol:g}: it is relative to "
                         "the force scale of a step, so a larger tol accepts the start as the "
                         "solution and a smaller one is below round-off")
    return tol


def _read_solver(table):
    """A SolverSpec; ``SolverSpec()`` without a [solver] table."""
    if table is None:
        return SolverSpec()
    method = _choice("solver.method", table.get("method", "str", "newton"), ("newton",))
    tol = _tolerance("solver.tol", table.get("tol", "number", 1e-10))
    max_iter = table.get("max_iter", "int", 50)
    if not 1 <= max_iter <= MAX_ITER:
        raise SceneError("solver.max_iter", f"must be an integer in 1..{MAX_ITER}, "
                         f"got {max_iter}")
    linear = _choice("solver.linear", table.get("linear", "str", "auto"), METHODS)
    if linear == "pardiso" and not pardiso_available():
        raise SceneError("solver.linear", "'pardiso' needs pypardiso and MKL, which are not "
                         "installed here; allowed are auto, superlu, amg")
    table.finish()
    return SolverSpec(method, tol, max_iter, linear)


def _read_probes(table, dim):
    """The probe points of ``output.probes`` (none without an [output] table)."""
    if table is None:
        return ()
    raw = table.get("probes", "list", [], required=False)
    for i, p in enumerate(raw):
        if not (isinstance(p, list) and len(p) == dim and all(
                isinstance(c, (int, float)) and not isinstance(c, bool) for c in p)):
            raise SceneError(f"output.probes[{i}]", f"must be a point of {dim} numbers, "
                             f"got {_show(p)}")
    table.finish()
    return tuple(tuple(float(c) for c in p) for p in raw)


def _read_exact(table, dim, contact, has_loads):
    """An ExactSpec, or None without an [exact] table. The loads and β_0 of a
    scene with [exact] come from the exact solution."""
    if table is None:
        return None
    if has_loads:
        raise SceneError("loads", "a scene with [exact] derives its loads from the exact "
                         "solution; remove [loads]")
    variables = _coordinates(dim) + ("t",)
    u = _vector_of_expressions("exact.u", table.get("u", "list"), dim, variables)
    beta = multiplier = None
    if table.has("beta"):
        beta = _expression("exact.beta", table.get("beta", "expr"), variables)
        if beta.depends_on_time and contact.bonding.law == "none":
            raise SceneError("exact.beta", "depends on t, but contact.bonding.law is "
                             "'none' (β frozen); use a bonding law")
    if table.has("multiplier"):
        multiplier = _expression("exact.multiplier", table.get("multiplier", "expr"), variables)
    table.finish()
    if contact.beta0 is not None:
        raise SceneError("contact.bonding.beta0", "a scene with [exact] takes β_0 from "
                         "exact.beta; remove beta0")
    _symbolic(("exact.u[0]", "exact.u[1]", "exact.u[2]")[:dim] + ("exact.beta",
              "exact.multiplier"), u + (beta, multiplier))
    return ExactSpec(u, beta, multiplier)


def _symbolic(keys, expressions):
    """Expressions sympy can differentiate without overflowing or hanging."""
    for key, expression in zip(keys, expressions):
        problem = None if expression is None else symbolic_problem(expression)
        if problem:
            raise SceneError(key, f"{problem} (in {_show(expression.source)})")


def _coordinates(dim):
    return ("x", "y") if dim == 2 else ("x", "y", "z")


def scene_from_dict(data):
    """Validate a decoded scene document and return a :class:`Scene`."""
    top = _Table(data, "")
    title = top.get("title", "str", "untitled", required=False)
    if len(title) > MAX_TITLE:
        raise SceneError("title", f"must have at most {MAX_TITLE} characters, got {len(title)}")
    dim = top.get("dim", "int")
    if dim not in (2, 3):
        raise SceneError("dim", f"must be 2 (plane strain) or 3, got {dim}")
    mesh = _read_mesh(top.table("mesh", required=True), dim)
    dirichlet, contact_sides = _read_boundary(top.table("boundary", required=True), dim)
    material = _read_material(top.table("material", required=True), dim)
    memory = _read_memory(top.table("memory"), dim)
    body, traction = _read_loads(top.table("loads"), dim, dirichlet, contact_sides)
    contact = _read_contact(top.table("contact"), dim, contact_sides)
    T, steps = _read_time(top.table("time", required=True))
    solver = _read_solver(top.table("solver"))
    probes = _read_probes(top.table("output"), dim)
    exact = _read_exact(top.table("exact"), dim, contact, top.has("loads"))
    top.finish()
    return Scene(title, dim, mesh, dirichlet, contact_sides, material, memory, body,
                 traction, contact, T, steps, solver, probes, exact)


def parse_scene(text):
    """Parse a TOML scene document; TOML syntax errors become SceneError."""
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as err:
        raise SceneError("", f"not valid TOML: {err}") from None
    except RecursionError:
        raise SceneError("", "not a usable TOML document: arrays or tables nested too "
                         "deeply") from None
    return scene_from_dict(data)
