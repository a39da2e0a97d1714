"""Scenes: the validated description of one problem (SPEC.md, scene file).

A scene is read from a TOML document (``parse_scene(text)``) or from the
dictionary it decodes to (``scene_from_dict``). Every key is checked: a
missing, unknown or wrongly typed key, or a value outside its range, raises
:class:`SceneError` whose message is one line that names the key and says
what is allowed. Nothing is computed here; geometry-dependent checks (a
probe outside the mesh, a negative gap) are made when the problem is built.
"""

import math
import tomllib
from dataclasses import dataclass, field

from .expressions import ExpressionError, compile_expression
from .laws import BONDING_LAWS, FRICTION_LAWS, NORMAL_LAWS


class SceneError(ValueError):
    """A scene that cannot be run; ``str(err)`` is ``"key: what is allowed"``."""

    def __init__(self, key, message):
        self.key = key
        super().__init__(f"{key}: {message}" if key else message)


SIDES = {2: ("left", "right", "bottom", "top"),
         3: ("left", "right", "bottom", "top", "front", "back")}


@dataclass(frozen=True)
class MeshSpec:
    domain: str
    size: tuple
    cells: tuple
    pattern: str = "diagonal"
    refine: int = 0


@dataclass(frozen=True)
class Isotropic:
    """An isotropic tensor C ε = λ tr(ε) I + 2 μ ε given by its Lamé pair."""

    lam: float
    mu: float


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
    law: str
    params: dict = field(default_factory=dict)


@dataclass(frozen=True)
class ContactSpec:
    gap: object = None            # Expression, or None for no wall
    quadrature: str = "nodal"
    order: int = 4                # exactness of the Gauss rule on Γ_C
    normal: LawSpec = LawSpec("none")
    friction: tuple = ()          # LawSpecs whose potentials sum
    bonding: LawSpec = LawSpec("none")
    beta0: object = None          # Expression for β_0


@dataclass(frozen=True)
class ExactSpec:
    """A manufactured solution (MODEL.md §7): u*, β* and the wall multiplier λ*."""

    u: tuple                      # d Expressions in x, y, (z), t
    beta: object = None           # Expression, or None (β* = 1)
    multiplier: object = None     # Expression λ* > 0 where u*_ν = g


@dataclass(frozen=True)
class SolverSpec:
    method: str = "newton"
    tol: float = 1e-10
    max_iter: int = 50


@dataclass(frozen=True)
class Scene:
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
    exact: ExactSpec = None
    resolved: dict = field(default_factory=dict, compare=False, repr=False)

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
        return Isotropic(lam, mu), {"lam": lam, "mu": mu}
    E = _positive(table.key("E"), table.get("E", "number"))
    nu = table.get("nu", "number")
    if not -1.0 < nu < 0.5:
        raise SceneError(table.key("nu"), f"must lie in (-1, 0.5), got {nu:g}")
    lam = E * nu / ((1.0 + nu) * (1.0 - 2.0 * nu))
    mu = E / (2.0 * (1.0 + nu))
    return Isotropic(lam, mu), {"E": E, "nu": nu}


def _vector_of_expressions(key, value, dim, variables):
    if not isinstance(value, list) or len(value) != dim:
        raise SceneError(key, f"must be a list of {dim} numbers or expressions, got {_show(value)}")
    return tuple(_expression(f"{key}[{i}]", v, variables) for i, v in enumerate(value))


def _law(table, registry, variables):
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
    table.finish()
    return MeshSpec(domain, tuple(float(s) for s in size), tuple(cells), pattern, refine)


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


def _read_memory(table, dim):
    kernel = _choice(table.key("kernel"), table.get("kernel", "str"), ("prony", "function"))
    if kernel == "prony":
        terms_raw = table.get("terms", "list")
        if not terms_raw:
            raise SceneError(table.key("terms"), "must list at least one term {E, nu, tau}")
        terms, resolved = [], []
        for i, raw in enumerate(terms_raw):
            t = _Table(raw, f"{table.key('terms')}[{i}]")
            tensor, pair = _isotropic(t, dim)
            tau = _positive(t.key("tau"), t.get("tau", "number"))
            t.finish()
            terms.append(PronyTerm(tensor, tau))
            resolved.append({**pair, "tau": tau})
        table.finish()
        return MemorySpec("prony", terms=tuple(terms)), {"kernel": "prony", "terms": resolved}
    source = table.get("r", "expr")
    function = _expression(table.key("r"), source, ("t",))
    tensor, pair = _isotropic(table, dim)
    table.finish()
    return (MemorySpec("function", function=function, tensor=tensor),
            {"kernel": "function", "r": str(source), **pair})


def _read_contact(table, dim, coords):
    if table is None:
        return ContactSpec(), {}
    resolved = {}
    gap = None
    if table.has("gap"):
        source = table.get("gap", "expr")
        gap = _expression(table.key("gap"), source, coords + ("t",))
        if gap.is_constant and float(gap(0.0)) < 0:
            raise SceneError(table.key("gap"), f"must be >= 0, got {source}")
        resolved["gap"] = source
    quadrature = _choice(table.key("quadrature"),
                         table.get("quadrature", "str", "nodal"), ("nodal", "gauss"))
    order = table.get("order", "int", 4, required=False)
    if not 1 <= order <= 10:
        raise SceneError(table.key("order"), f"must be an integer in 1..10, got {order}")
    resolved.update(quadrature=quadrature, order=order)

    normal_table = table.table("normal")
    normal = LawSpec("none") if normal_table is None else _law(normal_table, NORMAL_LAWS, coords)
    if normal_table is not None:
        normal_table.finish()
    resolved["normal"] = {"law": normal.law, **normal.params}

    friction = []
    raw = table.data.get("friction")
    table.used.add("friction")
    if raw is not None:
        items = raw if isinstance(raw, list) else [raw]
        for i, item in enumerate(items):
            key = table.key("friction") + (f"[{i}]" if isinstance(raw, list) else "")
            sub = _Table(item, key)
            spec = _law(sub, FRICTION_LAWS, coords)
            sub.finish()
            if spec.law != "none":
                friction.append(spec)
    resolved["friction"] = [{"law": f.law, **f.params} for f in friction]

    bonding_table = table.table("bonding")
    beta0 = None
    bonding = LawSpec("none")
    if bonding_table is not None:
        bonding = _law(bonding_table, BONDING_LAWS, coords)
        if bonding_table.has("beta0"):
            source = bonding_table.get("beta0", "expr")
            beta0 = _expression(bonding_table.key("beta0"), source, coords)
            if beta0.is_constant and not 0.0 <= float(beta0(0.0)) <= 1.0:
                raise SceneError(bonding_table.key("beta0"), f"must lie in [0, 1], got {source}")
            resolved["beta0"] = source
        integrator = _choice(bonding_table.key("integrator"),
                             bonding_table.get("integrator", "str", "explicit"), ("explicit",))
        resolved["integrator"] = integrator
        bonding_table.finish()
    resolved["bonding"] = {"law": bonding.law, **bonding.params}
    table.finish()
    kinked = [f.law for f in friction if FRICTION_LAWS[f.law][0].has_kink]
    if quadrature == "gauss" and kinked:
        smooth = ", ".join(name for name, (cls, _) in FRICTION_LAWS.items()
                           if cls is not None and not cls.has_kink)
        raise SceneError(table.key("quadrature"), f"'gauss' takes smooth friction laws only "
                         f"({smooth}); {kinked[0]!r} needs 'nodal'")
    return ContactSpec(gap, quadrature, order, normal, tuple(friction), bonding, beta0), resolved


def scene_from_dict(data):
    """Validate a decoded scene document and return a :class:`Scene`."""
    top = _Table(data, "")
    title = top.get("title", "str", "untitled", required=False)
    dim = top.get("dim", "int")
    if dim not in (2, 3):
        raise SceneError("dim", f"must be 2 (plane strain) or 3, got {dim}")
    coords = ("x", "y") if dim == 2 else ("x", "y", "z")
    mesh = _read_mesh(top.table("mesh", required=True), dim)

    boundary = top.table("boundary", required=True)
    dirichlet = _read_sides(boundary, "dirichlet", dim)
    contact_sides = _read_sides(boundary, "contact", dim)
    boundary.finish()
    if not dirichlet:
        raise SceneError("boundary.dirichlet", "must list at least one side (|Γ_D| > 0)")
    both = set(dirichlet) & set(contact_sides)
    if both:
        raise SceneError("boundary.contact", f"side {sorted(both)[0]!r} is also Dirichlet; "
                         "the parts of the boundary must be disjoint")

    material_table = top.table("material", required=True)
    material, material_resolved = _isotropic(material_table, dim)
    material_table.finish()

    memory_table = top.table("memory")
    memory, memory_resolved = (None, None) if memory_table is None else \
        _read_memory(memory_table, dim)

    loads = top.table("loads")
    body = tuple(compile_expression(0.0) for _ in range(dim))
    traction = {}
    loads_resolved = {"body": ["0"] * dim, "traction": {}}
    if loads is not None:
        if loads.has("body"):
            raw = loads.get("body", "list")
            body = _vector_of_expressions(loads.key("body"), raw, dim, coords + ("t",))
            loads_resolved["body"] = [str(v) for v in raw]
        tt = loads.table("traction")
        if tt is not None:
            for side, raw in tt.data.items():
                key = tt.key(side)
                tt.used.add(side)
                if side not in SIDES[dim]:
                    raise SceneError(key, f"unknown side; sides are {', '.join(SIDES[dim])}")
                if side in dirichlet or side in contact_sides:
                    raise SceneError(key, "a traction acts on a Neumann side only; "
                                     f"{side!r} is a {'Dirichlet' if side in dirichlet else 'contact'} side")
                traction[side] = _vector_of_expressions(key, raw, dim, coords + ("t",))
                loads_resolved["traction"][side] = [str(v) for v in raw]
            tt.finish()
        loads.finish()

    contact_table = top.table("contact")
    if contact_table is not None and not contact_sides:
        raise SceneError("contact", "a [contact] table needs boundary.contact to list its sides")
    contact, contact_resolved = _read_contact(contact_table, dim, coords)

    time = top.table("time", required=True)
    T = _positive("time.T", time.get("T", "number"))
    steps = time.get("steps", "int")
    if steps < 1:
        raise SceneError("time.steps", f"must be an integer >= 1, got {steps}")
    time.finish()

    solver_table = top.table("solver")
    solver = SolverSpec()
    if solver_table is not None:
        method = _choice("solver.method", solver_table.get("method", "str", "newton"),
                         ("newton",))
        tol = _positive("solver.tol", solver_table.get("tol", "number", 1e-10))
        max_iter = solver_table.get("max_iter", "int", 50)
        if max_iter < 1:
            raise SceneError("solver.max_iter", f"must be an integer >= 1, got {max_iter}")
        solver = SolverSpec(method, tol, max_iter)
        solver_table.finish()

    output = top.table("output")
    probes = ()
    if output is not None:
        raw = output.get("probes", "list", [], required=False)
        for i, p in enumerate(raw):
            if not (isinstance(p, list) and len(p) == dim and all(
                    isinstance(c, (int, float)) and not isinstance(c, bool) for c in p)):
                raise SceneError(f"output.probes[{i}]", f"must be a point of {dim} numbers, "
                                 f"got {_show(p)}")
        probes = tuple(tuple(float(c) for c in p) for p in raw)
        output.finish()
    exact, exact_resolved = None, None
    exact_table = top.table("exact")
    if exact_table is not None:
        if loads is not None:
            raise SceneError("loads", "a scene with [exact] derives its loads from the exact "
                             "solution; remove [loads]")
        variables = coords + ("t",)
        raw_u = exact_table.get("u", "list")
        u = _vector_of_expressions("exact.u", raw_u, dim, variables)
        beta = multiplier = None
        exact_resolved = {"u": [str(v) for v in raw_u]}
        if exact_table.has("beta"):
            raw = exact_table.get("beta", "expr")
            beta = _expression("exact.beta", raw, variables)
            exact_resolved["beta"] = str(raw)
            if beta.depends_on_time and contact.bonding.law == "none":
                raise SceneError("exact.beta", "depends on t, but contact.bonding.law is "
                                 "'none' (β frozen); use a bonding law")
        if exact_table.has("multiplier"):
            raw = exact_table.get("multiplier", "expr")
            multiplier = _expression("exact.multiplier", raw, variables)
            exact_resolved["multiplier"] = str(raw)
        exact_table.finish()
        if contact.beta0 is not None:
            raise SceneError("contact.bonding.beta0", "a scene with [exact] takes β_0 from "
                             "exact.beta; remove beta0")
        exact = ExactSpec(u, beta, multiplier)
    top.finish()

    resolved = {
        "title": title, "dim": dim,
        "mesh": {"domain": mesh.domain, "size": list(mesh.size), "cells": list(mesh.cells),
                 "pattern": mesh.pattern, "refine": mesh.refine},
        "boundary": {"dirichlet": list(dirichlet), "contact": list(contact_sides)},
        "material": {**material_resolved, "lam": material.lam, "mu": material.mu},
        "memory": memory_resolved,
        "loads": loads_resolved,
        "contact": contact_resolved,
        "time": {"T": T, "steps": steps, "k": T / steps},
        "solver": {"method": solver.method, "tol": solver.tol, "max_iter": solver.max_iter},
        "output": {"probes": [list(p) for p in probes]},
        "exact": exact_resolved,
    }
    return Scene(title, dim, mesh, dirichlet, contact_sides, material, memory, body,
                 traction, contact, T, steps, solver, probes, exact, resolved)


def parse_scene(text):
    """Parse a TOML scene document; TOML syntax errors become SceneError."""
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as err:
        raise SceneError("", f"not valid TOML: {err}") from None
    return scene_from_dict(data)
