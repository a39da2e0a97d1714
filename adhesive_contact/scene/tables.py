"""The readers of the tables other than ``[material]``, ``[memory]`` and
``[contact]``: the mesh, the boundary, the loads, the time grid, the
solver, the outputs and a manufactured solution."""

import hashlib
import math
import os
import stat
from pathlib import Path

from ..expressions import compile_expression
from ..fem.meshes.builtin import SIDES, nodes_of
from ..linear_solvers.pardiso import available as pardiso_available
from ..verification.manufactured import symbolic_problem
from ..errors import SceneError
from .keys import (MAX_CELL_ASPECT, MAX_HALVINGS, MAX_NODES, MAX_UNIT, MIN_STEP, OUTPUT_FIELDS,
                   declared, default, keys_in)
from .reader import coordinates, expression, show, vector_of_expressions
from .spec import AdaptiveSpec, ExactSpec, MeshSpec, SolverSpec


def read_mesh(table, dim, base_dir):
    domain = table.read("domain", dim)
    refine = table.read("refine")
    if domain == "file":
        return _read_mesh_file(table, dim, base_dir, refine)
    size = table.read("size")
    if len(size) != dim or not all(isinstance(s, (int, float)) and not isinstance(s, bool)
                                   and s > 0 for s in size):
        raise SceneError(table.key("size"), f"must be a list of {dim} positive lengths, "
                         f"got {show(size)}")
    _lengths(table.key("size"), size, declared(table.key("size")).bounds)
    cells = table.read("cells")
    if len(cells) != dim or not all(isinstance(c, int) and not isinstance(c, bool)
                                    and c >= 1 for c in cells):
        raise SceneError(table.key("cells"), f"must be a list of {dim} integers >= 1, "
                         f"got {show(cells)}")
    pattern = table.read("pattern", dim)
    _cell_counts(table.key("cells"), size, cells, refine, pattern)
    table.finish()
    return MeshSpec(domain, tuple(float(s) for s in size), tuple(cells), pattern, refine,
                    dim=dim)


def _lengths(key, size, lengths):
    """Each length finite and within the interval ``lengths``: outside, the
    element volumes (h^d, refined up to 4096 times) underflow or the
    stiffness overflows, and the factorisation meets zero pivots."""
    for i, s in enumerate(size):
        if s not in lengths:   # False for inf and nan
            raise SceneError(f"{key}[{i}]", f"must be a finite length in [{lengths.lo:g}, "
                             f"{lengths.hi:g}] (rescale the units), got {s!r}")


def _cell_counts(key, size, cells, refine, pattern):
    """At most MAX_NODES nodes after refinement (numpy cannot index more
    anyway, and the memory check needs a count it can estimate from), and
    cells no more elongated than MAX_CELL_ASPECT (their stiffness would be
    nearly singular)."""
    nodes = nodes_of(cells, refine, pattern)   # a Python int: exact, however large
    if nodes > MAX_NODES:
        shown = f"{nodes:.3g}" if nodes < 10**300 else f"about 1e+{len(str(nodes)) - 1}"
        raise SceneError(key, f"gives {shown} nodes after {refine} refinements; at most "
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
    given = table.read("file")
    table.finish()
    if "\0" in given:
        raise SceneError(table.key("file"), "the path holds a NUL character")
    try:
        path = Path(given).expanduser()
    except RuntimeError:   # ~user of no such user
        raise SceneError(table.key("file"), f"{given!r}: no such user's home folder "
                         f"({given.split('/')[0]})") from None
    if not path.is_absolute():
        path = Path(base_dir if base_dir is not None else Path.cwd()) / path
    try:
        digest = _file_sha256(table.key("file"), path)
    except FileNotFoundError:
        raise SceneError(table.key("file"), f"no such file {str(path)!r} (a path relative "
                         "to the scene file's folder)") from None
    except OSError as err:
        raise SceneError(table.key("file"), f"cannot read {str(path)!r}: "
                         f"{err.strerror or err}") from None
    return MeshSpec("file", refine=refine, file=given, path=str(path.resolve()),
                    sha256=digest, dim=dim)


def _file_sha256(key, path):
    """The sha256 of a regular file, read in blocks. Anything else (a FIFO,
    which would block the read, a device such as /dev/zero, which never
    ends, a folder) is refused before it is opened."""
    mode = os.stat(path).st_mode
    if not stat.S_ISREG(mode):
        kind = ("a folder" if stat.S_ISDIR(mode) else "a named pipe (FIFO)"
                if stat.S_ISFIFO(mode) else "a device" if stat.S_ISCHR(mode) or
                stat.S_ISBLK(mode) else "a socket" if stat.S_ISSOCK(mode) else "not a file")
        raise SceneError(key, f"{str(path)!r} is {kind}, not a regular file; give a mesh "
                         "file")
    digest = hashlib.sha256()
    with open(path, "rb") as f:
        for block in iter(lambda: f.read(1 << 20), b""):
            digest.update(block)
    return digest.hexdigest()


def read_boundary(table, dim, named_by_file=False):
    """(Dirichlet sides, contact sides, {side: prescribed displacement}):
    the Dirichlet, displacement and contact sides are disjoint. Whether
    something holds the body is checked once [contact] is read
    (:func:`check_something_holds`), and whether it holds it against every
    rigid motion with the geometry, when the problem is built."""
    dirichlet = _read_sides(table, "dirichlet", dim, named_by_file)
    contact_sides = _read_sides(table, "contact", dim, named_by_file)
    displacement = _read_displacement(table.table("displacement"), dim, named_by_file)
    table.finish()
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


def check_something_holds(scene, named_by_file=False):
    """A body with no held side must be held by its contact terms (a wall,
    a normal law, friction on Γ_C): refuse one that has neither."""
    if scene.dirichlet or scene.displacement or scene.has_contact_terms:
        return
    raise SceneError("boundary.dirichlet", _nothing_holds(scene.contact_sides, scene.dim,
                                                          named_by_file))


def _read_sides(table, name, dim, named_by_file):
    """The sides listed under ``name``: built-in side names, or (for a file
    mesh) any names, checked against the file's groups when the mesh is built."""
    value = table.read(name)
    sides = SIDES[dim]
    for i, side in enumerate(value):
        if named_by_file and not isinstance(side, str):
            raise SceneError(f"{table.key(name)}[{i}]", f"must be a group name (a string), "
                             f"got {show(side)}")
        if not named_by_file and side not in sides:
            raise SceneError(f"{table.key(name)}[{i}]",
                             f"unknown side {show(side)}; sides are {', '.join(sides)}")
    if len(set(value)) != len(value):
        raise SceneError(table.key(name), "lists a side twice")
    return tuple(value)


def _nothing_holds(contact_sides, dim, named_by_file):
    """The message for a body that no side and no contact term holds; what
    to write instead."""
    free = [s for s in SIDES[dim] if s not in contact_sides]
    side = "SIDE" if named_by_file or not free else free[0]
    glue = (f"; boundary.contact ({', '.join(contact_sides)}) carries no contact terms "
            "([contact] sets no wall, normal law or friction)" if contact_sides else "")
    held = ", ".join(['"0"'] * (dim - 1) + ['"0.01*t"'])
    rollers = ", ".join(['"0"'] + ['"free"'] * (dim - 1))
    return (f"must list at least one side: nothing holds the body{glue}; clamp a side "
            f"with boundary.dirichlet = [\"{side}\"], or prescribe one in "
            f"[boundary.displacement], e.g. {side} = [{held}] (\"free\" leaves a component free, as rollers {side} = [{rollers}] do; the held "
            "components must stop every rigid motion)")


def _read_displacement(table, dim, named_by_file):
    """{side: d entries}: per component an Expression in x, y, (z), t, or
    None for "free"; a side must prescribe at least one component."""
    if table is None:
        return {}
    variables = coordinates(dim) + ("t",)
    out = {}
    for side, raw in table.data.items():
        key = table.key(side)
        table.used.add(side)
        if not named_by_file and side not in SIDES[dim]:
            raise SceneError(key, f"unknown side; sides are {', '.join(SIDES[dim])}")
        if not isinstance(raw, list) or len(raw) != dim:
            raise SceneError(key, f"must be a list of {dim} entries (a number, an expression "
                             f"or \"free\" per component), got {show(raw)}")
        for i, v in enumerate(raw):
            if isinstance(v, bool) or not isinstance(v, (int, float, str)):
                raise SceneError(f"{key}[{i}]", "must be a number, an expression or "
                                 f"\"free\", got {show(v)}")
        entries = tuple(None if v == "free" else expression(f"{key}[{i}]", v, variables)
                        for i, v in enumerate(raw))
        if all(e is None for e in entries):
            raise SceneError(key, "prescribes no component; give an expression for at "
                             "least one, or remove the side")
        out[side] = entries
    table.finish()
    return out


def read_loads(table, dim, dirichlet, contact_sides, named_by_file=False):
    """(body, traction): d expressions of f_0 (zero by default) and
    {side: d expressions of f_N} on Neumann sides (neither Dirichlet nor contact)."""
    body = tuple(compile_expression("0") for _ in range(dim))
    traction = {}
    if table is None:
        return body, traction
    variables = coordinates(dim) + ("t",)
    if table.has("body"):
        body = vector_of_expressions(table.key("body"), table.read("body"), dim, variables)
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
            traction[side] = vector_of_expressions(key, raw, dim, variables)
        tt.finish()
    table.finish()
    return body, traction


def read_time(table):
    """(T, steps, scheme, adaptive): ``adaptive`` the AdaptiveSpec of
    ``[time.adaptive]``, or None."""
    T = table.read("T")
    steps = table.read("steps")
    if not T / steps >= MIN_STEP:
        raise SceneError(table.key("T"), f"gives the time step k = T/steps = {T / steps:.3g}, "
                         f"below {MIN_STEP:g}, where the time levels n k lose their "
                         "precision; give the time in other units (e.g. ms or µs)")
    scheme = table.read("scheme")
    sub = table.table("adaptive")
    adaptive = None if sub is None else read_adaptive(sub, T / steps)
    table.finish()
    return T, steps, scheme, adaptive


def read_adaptive(table, k_max):
    """``[time.adaptive]`` with k_max = T/N: k_min (default k_max/1024)
    rounded down to k_max 2^-J, 1 ≤ J ≤ MAX_HALVINGS."""
    tol = table.read("tol")
    rate_floor = table.read("rate_floor")
    k_min = table.read("k_min")
    growth, shrink, safety = table.read("growth"), table.read("shrink"), table.read("safety")
    table.finish()
    if k_min is None:
        halvings = 10
    else:
        if not k_min <= 0.5 * k_max:
            raise SceneError(table.key("k_min"), f"must be at most k_max/2 = {0.5 * k_max:g} "
                             f"(k_max = T/steps), got {k_min:g}")
        halvings = int(math.ceil(math.log2(k_max / k_min) - 1e-12))
        if halvings > MAX_HALVINGS:
            raise SceneError(table.key("k_min"), f"must be at least k_max 2^-{MAX_HALVINGS} = "
                             f"{k_max * 2.0 ** -MAX_HALVINGS:g}, got {k_min:g}")
    return AdaptiveSpec(tol, k_max * 2.0 ** -halvings, halvings, rate_floor, growth, shrink,
                        safety)


def read_solver(table):
    """A SolverSpec; ``SolverSpec()`` without a [solver] table."""
    if table is None:
        return SolverSpec()
    method = table.read("method")
    tol = table.read("tol")
    max_iter = table.read("max_iter")
    linear = table.read("linear")
    if linear == "pardiso" and not pardiso_available():
        others = ", ".join(m for m in declared("solver.linear").choices if m != "pardiso")
        raise SceneError("solver.linear", "'pardiso' needs pypardiso and MKL, which are not "
                         f"installed here; allowed are {others}")
    penalty = table.read("penalty")
    smoothing = table.read("smoothing")
    linear_tol = table.read("linear_tol")
    table.finish()
    return SolverSpec(method, tol, max_iter, linear, penalty, smoothing, linear_tol)


#: the most times ``output.plot_times`` may list (a figure stays readable)
MAX_PLOT_TIMES = 12


def read_output(table, dim, T):
    """(probes, units, plot times, every, fields) of the [output] table:
    none of the first two, "auto", 1 and every field without it."""
    if table is None:
        return (), {}, "auto", default("output.every"), default("output.fields")
    units = _read_units(table.table("units"))
    times = _read_plot_times(table, T)
    every = table.read("every")
    fields = _read_fields(table)
    return _read_probes(table, dim), units, times, every, fields


def _read_fields(table):
    """``output.fields``: a list of distinct names of OUTPUT_FIELDS (in that order)."""
    raw = table.read("fields")
    key = table.key("fields")
    allowed = OUTPUT_FIELDS
    if not all(isinstance(name, str) for name in raw):
        raise SceneError(key, f"must be a list of field names out of "
                         f"{', '.join(allowed)}, got {show(raw)}")
    for name in raw:
        if name not in allowed:
            raise SceneError(key, f"{show(name)} is no field; allowed: "
                             f"{', '.join(allowed)} (an empty list writes the scalars only)")
    if len(set(raw)) != len(raw):
        raise SceneError(key, f"names a field twice: {show(raw)}")
    return tuple(name for name in allowed if name in raw)


def _read_plot_times(table, T):
    """``output.plot_times``: "auto", or a sorted tuple of distinct times in [0, T]."""
    table.used.add("plot_times")
    raw = table.data.get("plot_times", "auto")
    if raw == "auto":
        return "auto"
    key = table.key("plot_times")
    if not (isinstance(raw, list) and 1 <= len(raw) <= MAX_PLOT_TIMES and all(
            isinstance(t, (int, float)) and not isinstance(t, bool) for t in raw)):
        raise SceneError(key, f"must be \"auto\" or a list of 1 to {MAX_PLOT_TIMES} times "
                         f"(numbers), got {show(raw)}")
    for t in raw:
        if not 0.0 <= t <= T:
            raise SceneError(key, f"every time must lie in [0, T] = [0, {T:g}], got {t:g}")
    return tuple(sorted({float(t) for t in raw}))


def _read_units(table):
    """{quantity: unit name} of ``output.units``: names the plots' axes use
    instead of "units of length" etc.; they change no number."""
    if table is None:
        return {}
    units = {}
    for name in keys_in("output.units"):
        if not table.has(name):
            table.used.add(name)
            continue
        value = table.read(name)
        if not 1 <= len(value) <= MAX_UNIT or not value.isprintable() or value != value.strip():
            raise SceneError(table.key(name), f"must be a unit name of 1 to {MAX_UNIT} "
                             f"printable characters without outer spaces, got {show(value)}")
        units[name] = value
    table.finish()
    return units


def _read_probes(table, dim):
    """The probe points of ``output.probes``."""
    raw = table.read("probes")
    for i, p in enumerate(raw):
        if not (isinstance(p, list) and len(p) == dim and all(
                isinstance(c, (int, float)) and not isinstance(c, bool) for c in p)):
            raise SceneError(f"output.probes[{i}]", f"must be a point of {dim} numbers, "
                             f"got {show(p)}")
    table.finish()
    return tuple(tuple(float(c) for c in p) for p in raw)


def read_exact(table, dim, contact, has_loads):
    """An ExactSpec, or None without an [exact] table. The loads and β_0 of a
    scene with [exact] come from the exact solution."""
    if table is None:
        return None
    if has_loads:
        raise SceneError("loads", "a scene with [exact] derives its loads from the exact "
                         "solution; remove [loads]")
    variables = coordinates(dim) + ("t",)
    u = vector_of_expressions("exact.u", table.read("u"), dim, variables)
    beta = multiplier = None
    if table.has("beta"):
        beta = table.read_expression("beta", variables)
        if beta.depends_on_time and contact.bonding.law == "none":
            raise SceneError("exact.beta", "depends on t, but contact.bonding.law is "
                             "'none' (β frozen); use a bonding law")
    if table.has("multiplier"):
        multiplier = table.read_expression("multiplier", variables)
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
    for key, expr in zip(keys, expressions):
        problem = None if expr is None else symbolic_problem(expr)
        if problem:
            raise SceneError(key, f"{problem} (in {show(expr.source)})")
