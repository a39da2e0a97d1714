"""Scenes: the validated description of one problem (docs/scenes.md).

A scene is read from a file (``load_scene(path)``), a TOML document
(``parse_scene(text, base_dir)``) or the dictionary it decodes to
(``scene_from_dict``); ``base_dir`` is where a relative ``mesh.file`` is
found. Every key is checked: a missing, unknown or wrongly typed key, or a
value outside its range, raises :class:`SceneError` whose message is one
line that names the key and says what is allowed. Nothing is computed
here; geometry-dependent checks (a probe outside the mesh, a negative gap,
side names that a mesh file does not have) are made when the problem is
built.

The :class:`Scene` dataclasses are the one stored form of a scene; its
``resolved`` record (every default filled in, written to summary.json and
to the identity of a convergence study) is derived from them on demand, so
``dataclasses.replace`` gives a consistent scene. Absent optional tables:
``[memory]`` and ``[exact]`` add a part to the problem and are None when
absent; ``[loads]``, ``[contact]``, ``[solver]`` and ``[output]`` only
set values that have defaults and read as those defaults when absent.
"""

import difflib
import hashlib
import math
import tomllib
from dataclasses import dataclass, field
from pathlib import Path

from .scheme.bonding import INTEGRATORS
from .expressions import ExpressionError, compile_expression
from .laws import BONDING_LAWS, FRICTION_LAWS, NORMAL_LAWS
from .linear_solvers import METHODS
from .linear_solvers.pardiso import available as pardiso_available
from .verification.manufactured import symbolic_problem
from .step_methods import METHODS as STEP_METHODS


class SceneError(ValueError):
    """A scene that cannot be run; ``str(err)`` is ``"key: what is allowed"``."""

    def __init__(self, key, message):
        self.key = key
        super().__init__(f"{key}: {message}" if key else message)


#: the ranges every scene must keep (see the readers that use them for why)
MAX_TITLE = 500             # characters of the title (it heads every plot)
LINEAR_TOL_RANGE = (1e-14, 1e-2)   # below: round-off; above: a solve that barely acts
LENGTHS = (1e-6, 1e6)       # each length of the domain; rescale the units outside
MAX_CELL_ASPECT = 1e3       # longest over shortest edge of the structured cells
MAX_NODES = 10**8           # nodes of the refined mesh
MAX_STEPS = 10**8           # time steps
TOL_RANGE = (1e-14, 1e-3)   # solver.tol, relative to the force scale of a step
MAX_ITER = 10_000           # solver.max_iter
MAX_UNIT = 16               # characters of a unit name in output.units

#: the quantities ``output.units`` may name (labels of the plots only)
UNIT_KEYS = ("length", "stress", "time", "force")

SIDES = {2: ("left", "right", "bottom", "top"),
         3: ("left", "right", "bottom", "top", "front", "back")}


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
    pattern: str = "diagonal"
    refine: int = 0
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
    quadrature: str = "nodal"
    order: int = 4                # exactness of the Gauss rule on Γ_C
    normal: LawSpec = LawSpec("none")
    friction: tuple = ()          # LawSpecs whose potentials sum
    bonding: LawSpec = LawSpec("none")
    beta0: object = None          # Expression for β_0, or None for β_0 = 1
    integrator: str = "explicit"  # for the bonding ODE
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

    method: str = "newton"
    tol: float = 1e-10
    max_iter: int = 50
    linear: str = "auto"          # the linear backend (adhesive_contact.linear_solvers)
    penalty: float = 1e4          # relative to max diag S
    smoothing: float = 1e-6       # relative to the diameter of the body
    linear_tol: float = 1e-10     # AMG's CG: relative residual of each linear solve


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
        return {
            "title": self.title, "dim": self.dim,
            "mesh": _mesh_record(self.mesh),
            "boundary": {"dirichlet": list(self.dirichlet), "contact": list(self.contact_sides),
                         **({"displacement": {
                             side: [e.source if e is not None else "free" for e in exprs]
                             for side, exprs in self.displacement.items()}}
                            if self.displacement else {})},
            "material": {**_young(self.material), "lam": self.material.lam,
                         "mu": self.material.mu},
            "memory": _memory_record(self.memory),
            "loads": {"body": _texts(self.body),
                      "traction": {side: _texts(v) for side, v in self.traction.items()}},
            "contact": _contact_record(self.contact),
            "time": {"T": self.T, "steps": self.steps, "k": self.k},
            "solver": _solver_record(self.solver),
            "output": {"probes": [list(p) for p in self.probes],
                       **({"units": dict(self.units)} if self.units else {})},
            "exact": _exact_record(self.exact),
        }


# ---------------------------------------------------------------- the resolved record


def _mesh_record(mesh):
    """A file mesh is recorded by its name and content (not its folder), so
    that a study's identity does not depend on where the files live."""
    if mesh.domain == "file":
        return {"domain": "file", "file": Path(mesh.file).name, "sha256": mesh.sha256,
                "refine": mesh.refine}
    return {"domain": mesh.domain, "size": list(mesh.size), "cells": list(mesh.cells),
            "pattern": mesh.pattern, "refine": mesh.refine}


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
    if memory.kernel == "relaxation":
        return {"kernel": "relaxation", "long_term": _pair(memory.long_term),
                "terms": [{**_pair(t.tensor), "tau": t.tau} for t in memory.terms]}
    return {"kernel": "function", "r": memory.function.source, **_pair(memory.tensor)}


def _contact_record(contact):
    """{} for a scene without contact settings."""
    if contact == ContactSpec():
        return {}
    record = {} if contact.gap is None else {"gap": contact.gap.given}
    if contact.foundation is not None:
        f = contact.foundation
        record["foundation"] = {"shape": f.shape, "point": list(f.point),
                                **({"normal": list(f.normal)} if f.normal else {}),
                                **({"axis": list(f.axis)} if f.axis else {}),
                                **({"radius": f.radius} if f.radius is not None else {})}
    record.update(quadrature=contact.quadrature, order=contact.order,
                  normal=_law_record(contact.normal),
                  friction=[_law_record(f) for f in contact.friction])
    if contact.beta0 is not None:
        record["beta0"] = contact.beta0.given
    if contact.bonded:
        record["integrator"] = contact.integrator
    record["bonding"] = _law_record(contact.bonding)
    return record


def _solver_record(solver):
    record = {"method": solver.method, "tol": solver.tol, "max_iter": solver.max_iter,
              "linear": solver.linear}
    if solver.linear_tol != SolverSpec.linear_tol:   # recorded when set: study identities keep
        record["linear_tol"] = solver.linear_tol
    if solver.method == "penalty":
        record.update(penalty=solver.penalty, smoothing=solver.smoothing)
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


#: every key of a table whose reader asks for some only in some branches
#: (a law's parameters are named by the law's reader; [mesh] and [memory]
#: are read whole for their domain or kernel)
KNOWN_KEYS = {
    "": {"title", "dim", "mesh", "boundary", "material", "memory", "loads", "contact",
         "time", "solver", "output", "exact"},
    "boundary": {"dirichlet", "contact", "displacement"},
    "material": {"E", "nu", "lam", "mu"},
    "loads": {"body", "traction"},
    "contact": {"gap", "foundation", "quadrature", "order", "normal", "friction", "bonding"},
    "contact.foundation": {"shape", "point", "normal", "radius", "axis"},
    "contact.bonding": {"law", "beta0", "integrator", "gamma_nu", "gamma_tau", "eps_a", "L"},
    "time": {"T", "steps"},
    "solver": {"method", "tol", "max_iter", "linear", "linear_tol", "penalty", "smoothing"},
    "output": {"probes", "units"},
    "output.units": set(UNIT_KEYS),
    "exact": {"u", "beta", "multiplier"},
}


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
            # a known key given where this table's branch does not take it
            # (penalty without the penalty method) is not offered back
            allowed = sorted(self.used | (KNOWN_KEYS.get(self.path, set()) - set(self.data)))
            close = difflib.get_close_matches(unknown[0], allowed, n=1, cutoff=0.6)
            hint = f" (did you mean {close[0]!r}?)" if close else ""
            raise SceneError(self.key(unknown[0]), f"unknown key{hint}; allowed here: "
                             f"{', '.join(allowed) or 'none'}")


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


def _read_mesh(table, dim, base_dir):
    domains = {2: ("rectangle", "file"), 3: ("box", "file")}[dim]
    domain = _choice(table.key("domain"), table.get("domain", "str"), domains)
    refine = table.get("refine", "int", 0, required=False)
    if refine < 0 or refine > 12:
        raise SceneError(table.key("refine"), f"must be an integer in 0..12, got {refine}")
    if domain == "file":
        return _read_mesh_file(table, dim, base_dir, refine)
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
    _cell_counts(table.key("cells"), size, cells, refine, pattern)
    table.finish()
    return MeshSpec(domain, tuple(float(s) for s in size), tuple(cells), pattern, refine,
                    dim=dim)


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


def _read_mesh_file(table, dim, base_dir, refine):
    """A file mesh: ``file`` is relative to ``base_dir`` (the scene file's
    folder; the working directory when None). Its content is hashed here;
    it is read when the problem is built."""
    given = table.get("file", "str")
    table.finish()
    path = Path(given).expanduser()
    if not path.is_absolute():
        path = Path(base_dir if base_dir is not None else Path.cwd()) / path
    try:
        digest = hashlib.sha256(path.read_bytes()).hexdigest()
    except FileNotFoundError:
        raise SceneError(table.key("file"), f"no such file {str(path)!r} (a path relative "
                         "to the scene file's folder)") from None
    except OSError as err:
        raise SceneError(table.key("file"), f"cannot read {str(path)!r}: "
                         f"{err.strerror or err}") from None
    return MeshSpec("file", refine=refine, file=given, path=str(path.resolve()),
                    sha256=digest, dim=dim)


def _read_sides(table, name, dim, named_by_file):
    """The sides listed under ``name``: built-in side names, or (for a file
    mesh) any names, checked against the file's groups when the mesh is built."""
    value = table.get(name, "list", [], required=False)
    sides = SIDES[dim]
    for i, side in enumerate(value):
        if named_by_file and not isinstance(side, str):
            raise SceneError(f"{table.key(name)}[{i}]", f"must be a group name (a string), "
                             f"got {_show(side)}")
        if not named_by_file and side not in sides:
            raise SceneError(f"{table.key(name)}[{i}]",
                             f"unknown side {_show(side)}; sides are {', '.join(sides)}")
    if len(set(value)) != len(value):
        raise SceneError(table.key(name), "lists a side twice")
    return tuple(value)


def _read_boundary(table, dim, named_by_file=False):
    """(Dirichlet sides, contact sides, {side: prescribed displacement}):
    the Dirichlet, displacement and contact sides are disjoint; at least
    one side holds the body (whether it holds it against every rigid motion
    is checked with the geometry, when the problem is built)."""
    dirichlet = _read_sides(table, "dirichlet", dim, named_by_file)
    contact_sides = _read_sides(table, "contact", dim, named_by_file)
    displacement = _read_displacement(table.table("displacement"), dim, named_by_file)
    table.finish()
    if not dirichlet and not displacement:
        raise SceneError("boundary.dirichlet", _nothing_holds(contact_sides, dim,
                                                              named_by_file))
    both = set(dirichlet) & set(contact_sides)
    if both:
        raise SceneError("boundary.contact", f"side {sorted(both)[0]!r} is also Dirichlet; "
                         "the parts of the boundary must be disjoint")
    for side in displacement:
        if side in dirichlet or side in contact_sides:
            raise SceneError(f"boundary.displacement.{side}", "is also a "
                             f"{'Dirichlet' if side in dirichlet else 'contact'} side; the "
                             "parts of the boundary must be disjoint")
    return dirichlet, contact_sides, displacement


def _nothing_holds(contact_sides, dim, named_by_file):
    """The message for a body no side holds: the model needs |Γ_D| > 0, and
    glue (boundary.contact) alone does not hold a body; what to write instead."""
    free = [s for s in SIDES[dim] if s not in contact_sides]
    side = "SIDE" if named_by_file or not free else free[0]
    glue = (f"; the glue of boundary.contact ({', '.join(contact_sides)}) cannot hold it "
            "alone" if contact_sides else "")
    held = ", ".join(['"0"'] * (dim - 1) + ['"0.01*t"'])
    rollers = ", ".join(['"0"'] + ['"free"'] * (dim - 1))
    return (f"must list at least one side: nothing holds the body{glue} (the model needs "
            f"|Γ_D| > 0); clamp a side with boundary.dirichlet = [\"{side}\"], or "
            f"prescribe one in [boundary.displacement], e.g. {side} = [{held}] (\"free\" "
            f"leaves a component free, as rollers {side} = [{rollers}] do; the held "
            "components must stop every rigid motion)")


def _read_displacement(table, dim, named_by_file):
    """{side: d entries}: per component an Expression in x, y, (z), t, or
    None for "free"; a side must prescribe at least one component."""
    if table is None:
        return {}
    variables = _coordinates(dim) + ("t",)
    out = {}
    for side, raw in table.data.items():
        key = table.key(side)
        table.used.add(side)
        if not named_by_file and side not in SIDES[dim]:
            raise SceneError(key, f"unknown side; sides are {', '.join(SIDES[dim])}")
        if not isinstance(raw, list) or len(raw) != dim:
            raise SceneError(key, f"must be a list of {dim} entries (a number, an expression "
                             f"or \"free\" per component), got {_show(raw)}")
        for i, v in enumerate(raw):
            if isinstance(v, bool) or not isinstance(v, (int, float, str)):
                raise SceneError(f"{key}[{i}]", "must be a number, an expression or "
                                 f"\"free\", got {_show(v)}")
        entries = tuple(None if v == "free" else _expression(f"{key}[{i}]", v, variables)
                        for i, v in enumerate(raw))
        if all(e is None for e in entries):
            raise SceneError(key, "prescribes no component; give an expression for at "
                             "least one, or remove the side")
        out[side] = entries
    table.finish()
    return out


def _read_material(table, dim):
    material = _isotropic(table, dim)
    table.finish()
    return material


def _read_memory(table, dim):
    """A MemorySpec, or None without a [memory] table."""
    if table is None:
        return None
    kernel = _choice(table.key("kernel"), table.get("kernel", "str"),
                     ("prony", "function", "relaxation"))
    if kernel == "function":
        function = _expression(table.key("r"), table.get("r", "expr"), ("t",))
        tensor = _isotropic(table, dim)
        table.finish()
        return MemorySpec("function", function=function, tensor=tensor)
    long_term = None
    if kernel == "relaxation":
        raw = table.get("long_term", "table")
        lt = _Table(raw, table.key("long_term"))
        long_term = _isotropic(lt, dim)
        lt.finish()
    terms_raw = table.get("terms", "list")
    if not terms_raw:
        raise SceneError(table.key("terms"), "must list at least one term {E, nu, tau}")
    terms = []
    for i, raw in enumerate(terms_raw):
        t = _Table(raw, f"{table.key('terms')}[{i}]")
        if kernel == "relaxation" and long_term.E is not None and t.has("E") \
                and not t.has("nu") and not (t.has("lam") or t.has("mu")):
            t.data = {**t.data, "nu": long_term.nu}   # nu defaults to long_term's
        tensor = _isotropic(t, dim)
        tau = _positive(t.key("tau"), t.get("tau", "number"))
        t.finish()
        terms.append(PronyTerm(tensor, tau))
    table.finish()
    return MemorySpec(kernel, terms=tuple(terms), long_term=long_term)


def _instantaneous(memory):
    """G(0) = C_∞ + Σ_i C_i of a relaxation kernel, as one Isotropic (its
    (E, ν) when every part has the same ν: E adds up then)."""
    parts = (memory.long_term,) + tuple(t.tensor for t in memory.terms)
    lam, mu = sum(p.lam for p in parts), sum(p.mu for p in parts)
    nus = {p.nu for p in parts}
    if None not in nus and len(nus) == 1:
        return Isotropic(lam, mu, sum(p.E for p in parts), nus.pop())
    return Isotropic(lam, mu)


def _check_relaxation_step(memory, dim, k):
    """The step tensor G(0) + k R(0) = C_∞ + Σ_i (1 − k/τ_i) C_i must be
    positive definite (else the step matrix is indefinite)."""
    parts = [(memory.long_term, 1.0)] + [(t.tensor, 1.0 - k / t.tau) for t in memory.terms]
    lam = sum(p.lam * w for p, w in parts)
    mu = sum(p.mu * w for p, w in parts)
    if not (mu > 0 and lam + 2.0 * mu / dim > 0):
        tau = min(t.tau for t in memory.terms)
        raise SceneError("time.steps", f"the time step k = {k:g} is too large for the "
                         f"relaxation time tau = {tau:g}: the step tensor C_inf + "
                         "sum (1 - k/tau_i) C_i is not positive definite; use more steps "
                         f"(k well below {tau:g})")


def _read_loads(table, dim, dirichlet, contact_sides, named_by_file=False):
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
            if not named_by_file and side not in SIDES[dim]:
                raise SceneError(key, f"unknown side; sides are {', '.join(SIDES[dim])}")
            if side in dirichlet or side in contact_sides:
                raise SceneError(key, "a traction acts on a Neumann side only (or on the "
                                 "free components of a displacement side); "
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
                         table.get("integrator", "str", "explicit"), tuple(INTEGRATORS))
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
    foundation = _read_foundation(table.table("foundation"), dim)
    if gap is not None and foundation is not None:
        raise SceneError(table.key("foundation"), "give exactly one of contact.gap (an "
                         "expression) and [contact.foundation] (a geometry)")
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
    return ContactSpec(gap, quadrature, order, normal, friction, bonding, beta0, integrator,
                       foundation)


def _point(table, name, dim, nonzero=False):
    value = table.get(name, "list")
    if len(value) != dim or not all(isinstance(c, (int, float)) and not isinstance(c, bool)
                                    and math.isfinite(c) for c in value):
        raise SceneError(table.key(name), f"must be a list of {dim} numbers, got {_show(value)}")
    if nonzero and not any(value):
        raise SceneError(table.key(name), "must be a nonzero vector")
    return tuple(float(c) for c in value)


def _read_foundation(table, dim):
    """A FoundationSpec of ``contact.foundation``, or None without the table."""
    if table is None:
        return None
    shapes = ("plane", "sphere") if dim == 2 else ("plane", "sphere", "cylinder")
    shape = _choice(table.key("shape"), table.get("shape", "str", "plane"), shapes)
    point = _point(table, "point", dim)
    normal = axis = radius = None
    if shape == "plane":
        normal = _point(table, "normal", dim, nonzero=True)
    else:
        radius = _positive(table.key("radius"), table.get("radius", "number"))
    if shape == "cylinder":
        axis = _point(table, "axis", dim, nonzero=True)
    table.finish()
    return FoundationSpec(shape, point, normal, axis, radius)


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
    method = _choice("solver.method", table.get("method", "str", "newton"), tuple(STEP_METHODS))
    tol = _tolerance("solver.tol", table.get("tol", "number", 1e-10))
    max_iter = table.get("max_iter", "int", 50)
    if not 1 <= max_iter <= MAX_ITER:
        raise SceneError("solver.max_iter", f"must be an integer in 1..{MAX_ITER}, "
                         f"got {max_iter}")
    linear = _choice("solver.linear", table.get("linear", "str", "auto"), METHODS)
    if linear == "pardiso" and not pardiso_available():
        raise SceneError("solver.linear", "'pardiso' needs pypardiso and MKL, which are not "
                         "installed here; allowed are auto, superlu, amg")
    penalty = _positive("solver.penalty", table.get("penalty", "number", SolverSpec.penalty))
    smoothing = _positive("solver.smoothing",
                          table.get("smoothing", "number", SolverSpec.smoothing))
    linear_tol = table.get("linear_tol", "number", SolverSpec.linear_tol)
    lo, hi = LINEAR_TOL_RANGE
    if not lo <= linear_tol <= hi:
        raise SceneError("solver.linear_tol", f"must lie in [{lo:g}, {hi:g}], got "
                         f"{linear_tol:g}: the relative residual of each iterative linear solve")
    table.finish()
    return SolverSpec(method, tol, max_iter, linear, penalty, smoothing, linear_tol)


def _read_output(table, dim):
    """(probes, units) of the [output] table: none of either without it."""
    if table is None:
        return (), {}
    units = _read_units(table.table("units"))
    return _read_probes(table, dim), units


def _read_units(table):
    """{quantity: unit name} of ``output.units``: names the plots' axes use
    instead of "units of length" etc.; they change no number."""
    if table is None:
        return {}
    units = {}
    for name in UNIT_KEYS:
        if not table.has(name):
            table.used.add(name)
            continue
        value = table.get(name, "str")
        if not 1 <= len(value) <= MAX_UNIT or not value.isprintable() or value != value.strip():
            raise SceneError(table.key(name), f"must be a unit name of 1 to {MAX_UNIT} "
                             f"printable characters without outer spaces, got {_show(value)}")
        units[name] = value
    table.finish()
    return units


def _read_probes(table, dim):
    """The probe points of ``output.probes``."""
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
        if contact.foundation is not None:
            raise SceneError("exact.multiplier", "a manufactured wall needs contact.gap as "
                             "an expression, not [contact.foundation]")
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


def scene_from_dict(data, base_dir=None):
    """Validate a decoded scene document and return a :class:`Scene`;
    ``base_dir`` is the folder a relative ``mesh.file`` is taken in
    (default: the working directory)."""
    top = _Table(data, "")
    title = top.get("title", "str", "untitled", required=False)
    if len(title) > MAX_TITLE:
        raise SceneError("title", f"must have at most {MAX_TITLE} characters, got {len(title)}")
    dim = top.get("dim", "int")
    if dim not in (2, 3):
        raise SceneError("dim", f"must be 2 (plane strain) or 3, got {dim}")
    mesh = _read_mesh(top.table("mesh", required=True), dim, base_dir)
    by_file = mesh.domain == "file"
    dirichlet, contact_sides, displacement = _read_boundary(
        top.table("boundary", required=True), dim, by_file)
    memory = _read_memory(top.table("memory"), dim)
    if memory is not None and memory.kernel == "relaxation":
        if top.has("material"):
            raise SceneError("material", "a relaxation kernel ([memory] kernel = "
                             "\"relaxation\") gives the material; remove [material]")
        top.used.add("material")
        material = _instantaneous(memory)
    else:
        material = _read_material(top.table("material", required=True), dim)
    body, traction = _read_loads(top.table("loads"), dim, dirichlet, contact_sides, by_file)
    contact = _read_contact(top.table("contact"), dim, contact_sides)
    T, steps = _read_time(top.table("time", required=True))
    solver = _read_solver(top.table("solver"))
    probes, units = _read_output(top.table("output"), dim)
    exact = _read_exact(top.table("exact"), dim, contact, top.has("loads"))
    top.finish()
    if memory is not None and memory.kernel == "relaxation":
        _check_relaxation_step(memory, dim, T / steps)
    return Scene(title, dim, mesh, dirichlet, contact_sides, material, memory, body,
                 traction, contact, T, steps, solver, probes, exact, displacement, units)


def parse_scene(text, base_dir=None):
    """Parse a TOML scene document; TOML syntax errors become SceneError.
    ``base_dir``: the folder a relative ``mesh.file`` is taken in."""
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as err:
        raise SceneError("", f"not valid TOML: {err}") from None
    except RecursionError:
        raise SceneError("", "not a usable TOML document: arrays or tables nested too "
                         "deeply") from None
    return scene_from_dict(data, base_dir)


def load_scene(path):
    """Read and parse the scene file ``path``; a relative ``mesh.file`` is
    taken in the scene file's folder. OSError if the file cannot be read."""
    path = Path(path)
    return parse_scene(path.read_text(encoding="utf-8"), base_dir=path.parent)
