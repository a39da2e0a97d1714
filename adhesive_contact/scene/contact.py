"""The readers of ``[contact]``: the wall (a gap expression or a
foundation), the quadrature on Γ_C, and the normal, friction and bonding
laws of :mod:`adhesive_contact.laws`."""

import math

from ..laws import BONDING_LAWS, FRICTION_LAWS, NORMAL_LAWS
from ..scheme.bonding import INTEGRATORS
from .errors import SceneError
from .reader import Table, choice, coordinates, expression, positive, show
from .spec import ContactSpec, FoundationSpec, LawSpec


def read_contact(table, dim, contact_sides):
    """A ContactSpec; ``ContactSpec()`` without a [contact] table."""
    if table is None:
        return ContactSpec()
    if not contact_sides:
        raise SceneError("contact", "a [contact] table needs boundary.contact to list its sides")
    gap = None
    if table.has("gap"):
        source = table.get("gap", "expr")
        gap = expression(table.key("gap"), source, coordinates(dim) + ("t",))
        if gap.is_constant and float(gap(0.0)) < 0:
            raise SceneError(table.key("gap"), f"must be >= 0, got {source}")
    foundation = _read_foundation(table.table("foundation"), dim)
    if gap is not None and foundation is not None:
        raise SceneError(table.key("foundation"), "give exactly one of contact.gap (an "
                         "expression) and [contact.foundation] (a geometry)")
    quadrature = choice(table.key("quadrature"),
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
        sub = Table(item, key)
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
        beta0 = expression(table.key("beta0"), source, coordinates(dim))
        if beta0.is_constant and not 0.0 <= float(beta0(0.0)) <= 1.0:
            raise SceneError(table.key("beta0"), f"must lie in [0, 1], got {source}")
    integrator = choice(table.key("integrator"),
                         table.get("integrator", "str", "explicit"), tuple(INTEGRATORS))
    table.finish()
    return bonding, beta0, integrator


def _law(table, registry):
    """A LawSpec of ``registry`` (law name -> (class, {parameter: constraint}))."""
    name = choice(table.key("law"), table.get("law", "str"), tuple(registry))
    params = {}
    for pname, constraint in registry[name][1].items():
        value = table.get(pname, "number")
        if constraint == "positive":
            positive(table.key(pname), value)
        elif constraint == "nonnegative" and value < 0:
            raise SceneError(table.key(pname), f"must be >= 0, got {value:g}")
        params[pname] = value
    check = getattr(registry[name][0], "check", None)
    problem = check(params) if check else None
    if problem:
        raise SceneError(table.key(problem[0]), problem[1])
    return LawSpec(name, params)


def _point(table, name, dim, nonzero=False):
    value = table.get(name, "list")
    if len(value) != dim or not all(isinstance(c, (int, float)) and not isinstance(c, bool)
                                    and math.isfinite(c) for c in value):
        raise SceneError(table.key(name), f"must be a list of {dim} numbers, got {show(value)}")
    if nonzero and not any(value):
        raise SceneError(table.key(name), "must be a nonzero vector")
    return tuple(float(c) for c in value)


def _read_foundation(table, dim):
    """A FoundationSpec of ``contact.foundation``, or None without the table."""
    if table is None:
        return None
    shapes = ("plane", "sphere") if dim == 2 else ("plane", "sphere", "cylinder")
    shape = choice(table.key("shape"), table.get("shape", "str", "plane"), shapes)
    point = _point(table, "point", dim)
    normal = axis = radius = None
    if shape == "plane":
        normal = _point(table, "normal", dim, nonzero=True)
    else:
        radius = positive(table.key("radius"), table.get("radius", "number"))
    if shape == "cylinder":
        axis = _point(table, "axis", dim, nonzero=True)
    table.finish()
    return FoundationSpec(shape, point, normal, axis, radius)
