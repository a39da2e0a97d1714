"""The readers of ``[contact]``: the wall (a gap expression or a
foundation), the quadrature on Γ_C, and the normal, friction and bonding
laws of :mod:`adhesive_contact.laws`."""

import math
import sys

from ..laws import FRICTION_LAWS
from ..errors import SceneError
from .keys import declared
from .reader import Table, coordinates, show, within
from .spec import ContactSpec, FoundationSpec, LawSpec


def read_contact(table, dim, contact_sides):
    """A ContactSpec; ``ContactSpec()`` without a [contact] table."""
    if table is None:
        return ContactSpec()
    if not contact_sides:
        raise SceneError("contact", "a [contact] table needs boundary.contact to list its sides")
    gap = None
    if table.has("gap"):
        gap = table.read_expression("gap", coordinates(dim) + ("t",))
    foundation = _read_foundation(table.table("foundation"), dim)
    if gap is not None and foundation is not None:
        raise SceneError(table.key("foundation"), "give exactly one of contact.gap (an "
                         "expression) and [contact.foundation] (a geometry)")
    quadrature = table.read("quadrature")
    order = table.read("order")
    normal = _read_normal(table.table("normal"))
    friction = _read_friction(table)
    bonding, beta0, integrator = _read_bonding(table.table("bonding"), dim)
    table.finish()
    if any(f.law == "coulomb" for f in friction) and normal.law not in ("compliance",
                                                                        "adhesive_compliance"):
        raise SceneError(table.key("friction"), "law 'coulomb' has the bound μ p_ν(β, u_ν) "
                         "of the normal law: it needs [contact.normal] law 'compliance' or "
                         f"'adhesive_compliance', got {normal.law!r}")
    cohesive = (normal.law == "cohesive", bonding.law == "cohesive")
    if any(cohesive) and not all(cohesive):
        which = "bonding" if cohesive[0] else "normal"
        raise SceneError(table.key(which) + ".law", "must be 'cohesive' too: the cohesive "
                         "law names [contact.normal] and [contact.bonding] together")
    if bonding.law == "cohesive" and integrator != "explicit":
        raise SceneError(table.key("bonding") + ".integrator", "must be 'explicit' for the "
                         "cohesive law (its damage update is not an ODE)")
    kinked = [f.law for f in friction if FRICTION_LAWS[f.law][0].has_kink]
    if quadrature == "gauss" and kinked:
        smooth = ", ".join(name for name, (cls, _) in FRICTION_LAWS.items()
                           if cls is not None and not cls.has_kink)
        raise SceneError(table.key("quadrature"), f"'gauss' takes smooth friction laws only "
                         f"({smooth}); {kinked[0]!r} needs 'nodal'")
    return ContactSpec(gap, quadrature, order, normal, friction, bonding, beta0, integrator,
                       foundation)


def _read_normal(table):
    """The normal law of ``contact.normal`` (law "none" without the table)."""
    if table is None:
        return LawSpec("none")
    normal = _law(table)
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
        sub = Table(item, key)
        spec = _law(sub)
        sub.finish()
        if spec.law != "none":
            laws.append(spec)
    return tuple(laws)


def _read_bonding(table, dim):
    """(bonding law, β_0 or None, integrator) of ``contact.bonding``."""
    if table is None:
        return LawSpec("none"), None, ContactSpec.integrator
    bonding = _law(table)
    beta0 = None
    if table.has("beta0"):   # absent: None, β_0 at its default 1
        beta0 = table.read_expression("beta0", coordinates(dim))
    integrator = table.read("integrator")
    table.finish()
    return bonding, beta0, integrator


def _law(table):
    """A LawSpec of the registry the table's law key names (law name ->
    (class, {parameter: constraint}), the constraints of
    :mod:`adhesive_contact.laws`)."""
    name = table.read("law")
    registry = declared(table.key("law")).laws
    params = {}
    for pname, constraint in registry[name][1].items():
        if isinstance(constraint, tuple):      # a string among choices
            value = table.get(pname, "str")
            if value not in constraint:
                raise SceneError(table.key(pname), f"must be one of "
                                 f"{', '.join(repr(c) for c in constraint)}, got {show(value)}")
            params[pname] = value
        elif constraint.endswith("?"):         # an optional number
            value = table.get(pname, "number", required=False)
            if value is not None:
                params[pname] = within(table.key(pname), value, constraint[:-1])
        else:
            params[pname] = within(table.key(pname), table.get(pname, "number"), constraint)
    check = getattr(registry[name][0], "check", None)
    problem = check(params) if check else None
    if problem:
        raise SceneError(table.key(problem[0]), problem[1])
    return LawSpec(name, params)


def _point(table, name, dim, nonzero=False):
    value = table.read(name)
    if len(value) != dim or not all(isinstance(c, (int, float)) and not isinstance(c, bool)
                                    and math.isfinite(c) for c in value):
        raise SceneError(table.key(name), f"must be a list of {dim} numbers, got {show(value)}")
    if nonzero and not any(value):
        raise SceneError(table.key(name), "must be a nonzero vector")
    squared = sum(float(c) * float(c) for c in value)
    if nonzero and not sys.float_info.min <= squared <= sys.float_info.max:
        # |v|² under- or overflows: the unit vector v/|v| would be 0 or NaN
        raise SceneError(table.key(name), f"{show(value)} has a length whose square "
                         f"{'underflows' if squared < 1 else 'overflows'} in floating point; "
                         "give the direction with components of moderate size, e.g. [0, 1]")
    return tuple(float(c) for c in value)


#: the largest radius of a foundation (its square and products stay finite)
MAX_LENGTH = 1e100


def _read_foundation(table, dim):
    """A FoundationSpec of ``contact.foundation``, or None without the table."""
    if table is None:
        return None
    shape = table.read("shape", dim)
    point = _point(table, "point", dim)
    if not max(abs(c) for c in point) <= MAX_LENGTH:   # distances to it square it
        raise SceneError(table.key("point"), f"{show(list(point))} is too far out (each "
                         f"coordinate at most {MAX_LENGTH:g} in absolute value)")
    normal = axis = radius = None
    if shape == "plane":
        normal = _point(table, "normal", dim, nonzero=True)
    else:
        radius = table.read("radius")
        if not radius <= MAX_LENGTH:   # the ray-sphere intersection squares it
            raise SceneError(table.key("radius"), f"{radius:g} is too large (at most "
                             f"{MAX_LENGTH:g}: the gap squares it); a plane is the limit of "
                             "a large sphere: use shape = \"plane\"")
    if shape == "cylinder":
        axis = _point(table, "axis", dim, nonzero=True)
    table.finish()
    return FoundationSpec(shape, point, normal, axis, radius)
