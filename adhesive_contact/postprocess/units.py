"""The unit of a reported quantity, from the units a scene names.

The package has no units: every number is in the scene's own, and
``[output.units]`` only names them (``length``, ``stress``, ``time``,
``force``). A quantity has a *kind* (:data:`KINDS`), and its unit is read
off the names given, in 2D per unit thickness (plane strain): a force is
then a force per length, an energy a force (an energy per length), the
measure of a part of Γ_C a length.

========== =============== =================
kind        3D              2D
========== =============== =================
length      L               L
measure     L²              L
stress      S               S
time        T               T
force       F               F/L
energy      F·L             F
toughness   F/L             F/L
========== =============== =================

F is the force's name, or S·L² where only stress and length are named.
A kind whose names are not all given has no unit (None); ``"1"`` and
``"count"`` never have one.
"""

#: the kinds a quantity may have
KINDS = ("length", "measure", "stress", "time", "force", "energy", "toughness", "1",
         "count")


def _force(units):
    if "force" in units:
        return units["force"]
    if "stress" in units and "length" in units:
        return f"{units['stress']}·{units['length']}²"
    return None


def unit_of(kind, units, dim):
    """The unit name of a quantity of ``kind`` in a scene of dimension
    ``dim`` whose ``[output.units]`` are ``units`` ({quantity: name}), or
    None when it has none (module docstring)."""
    if kind not in KINDS:
        raise ValueError(f"unknown kind of quantity {kind!r}")
    units = units or {}
    L, F = units.get("length"), _force(units)
    if kind in ("length", "stress", "time"):
        return units.get(kind)
    if kind == "measure":
        return None if L is None else (L if dim == 2 else f"{L}²")
    if kind == "force":
        if F is None or (dim == 2 and L is None):
            return None
        return F if dim == 3 else f"{F}/{L}"
    if kind == "energy":
        if F is None or (dim == 3 and L is None):
            return None
        return F if dim == 2 else f"{F}·{L}"
    if kind == "toughness":
        return None if F is None or L is None else f"{F}/{L}"
    return None


def with_unit(name, kind, units, dim):
    """``name`` with its unit in brackets, ``"reaction_right_y [N/mm]"``,
    or ``name`` alone when it has none (the column names of scalars.csv)."""
    unit = unit_of(kind, units, dim)
    return name if unit is None else f"{name} [{unit}]"
