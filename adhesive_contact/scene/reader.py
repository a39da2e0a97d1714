"""Reading a TOML table: typed access to its keys by their declarations
(:mod:`.keys`), unknown keys reported with the nearest known one, and the
checks every table reader shares."""

import difflib
import math

from ..expressions import ExpressionError, compile_expression
from ..errors import SceneError
from .keys import declared, offered


class Table:
    """A TOML table being read: typed access, and unknown keys reported.

    Parameters
    ----------
    data : dict
        The table as TOML decodes it.
    path : str
        Its dotted name in the scene (``""``: the document), which names
        its keys in messages and finds their declarations.
    """

    def __init__(self, data, path):
        if not isinstance(data, dict):
            raise SceneError(path, f"must be a table, got {show(data)}")
        self.data = data
        self.path = path
        self.used = set()

    def key(self, name):
        """The dotted name of the key ``name`` of this table."""
        return f"{self.path}.{name}" if self.path else name

    def has(self, name):
        """Whether the table gives the key ``name``."""
        return name in self.data

    def read(self, name, dim=None):
        """The value of the key ``name`` as its declaration says: of its
        kind, its default when absent (None for a key that sets nothing),
        one of its choices (those of ``dim``), a number within its bounds."""
        key = declared(self.key(name))
        value = self.get(name, key.kind, None if key.required else key.default,
                         required=key.required)
        if key.choices is not None:
            choice(self.key(name), value, key.allowed(dim))
        if key.bounds is not None and key.kind in ("number", "int") and value is not None:
            within(self.key(name), value, key.bounds, integer=key.kind == "int",
                   reason=key.reason)
        return value

    def read_expression(self, name, variables):
        """The compiled expression of the key ``name``, which may use only
        ``variables``; a constant one within the key's bounds."""
        source = self.read(name)
        expr = expression(self.key(name), source, variables)
        bounds = declared(self.key(name)).bounds
        if bounds is not None and expr.is_constant:
            within(self.key(name), float(expr(0.0)), bounds, shown=source)
        return expr

    def get(self, name, kind, default=None, required=True):
        """The value of the key ``name``, of ``kind`` (a number as a float);
        ``default`` when absent, which a ``required`` key without a
        default must not be."""
        self.used.add(name)
        if name not in self.data:
            if required and default is None:
                raise SceneError(self.key(name), f"missing; {_describe(kind)} is required")
            return default
        return _check_type(self.key(name), self.data[name], kind)

    def table(self, name):
        """The sub-table ``name`` as a :class:`Table`; None when absent (a
        required one must not be)."""
        self.used.add(name)
        if name not in self.data:
            if declared(self.key(name)).required:
                raise SceneError(self.key(name), "missing table")
            return None
        return Table(self.data[name], self.key(name))

    def finish(self):
        """Refuse the first key (in sorted order) that no reader asked for,
        with the nearest of the keys allowed here."""
        unknown = sorted(set(self.data) - self.used)
        if unknown:
            # a known key given where this table's branch does not take it
            # (the normal of a sphere) is not offered back
            allowed = sorted(self.used | (offered(self.path) - set(self.data)))
            close = difflib.get_close_matches(unknown[0], allowed, n=1, cutoff=0.6)
            hint = f" (did you mean {close[0]!r}?)" if close else ""
            raise SceneError(self.key(unknown[0]), f"unknown key{hint}; allowed here: "
                             f"{', '.join(allowed) or 'none'}")


def show(value):
    """``repr(value)``, cut to fit in a message."""
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
        raise SceneError(key, f"must be {_describe(kind)}, got {show(value)}")
    if kind == "number":
        value = float(value)
        if not math.isfinite(value):
            raise SceneError(key, f"must be a finite number, got {value}")
    return value


def within(key, value, bounds, integer=False, reason=None, shown=None):
    """Refuse ``value`` of the key ``key`` outside ``bounds`` (``"positive"``,
    ``"nonnegative"`` or an :class:`~.keys.Interval`); ``shown`` is how the
    message shows the value (default: ``f"{value:g}"``)."""
    if bounds == "positive":
        if not value > 0:
            raise SceneError(key, f"must be > 0, got {_shown(value, shown)}")
    elif bounds == "nonnegative":
        if value < 0:
            raise SceneError(key, f"must be >= 0, got {_shown(value, shown)}")
    elif value not in bounds:
        raise SceneError(key, _outside(bounds, value, integer, shown)
                         + (f": {reason}" if reason else ""))
    return value


def _shown(value, shown):
    return f"{value:g}" if shown is None else shown


def _outside(interval, value, integer, shown):
    if integer:
        return f"must be an integer in {interval.lo}..{_count(interval.hi)}, got {value}"
    left, right = ("[", "]") if interval.closed else ("(", ")")
    return (f"must lie in {left}{interval.lo:g}, {interval.hi:g}{right}, "
            f"got {_shown(value, shown)}")


def _count(n):
    """An integer bound as a message shows it: 10000, or 1e+08 from a million."""
    return f"{n:.0e}" if n >= 10**6 else str(n)


def choice(key, value, allowed):
    """Refuse ``value`` of the key ``key`` that is not one of ``allowed``."""
    if value not in allowed:
        raise SceneError(key, f"must be one of {', '.join(map(repr, allowed))}, got {show(value)}")
    return value


def expression(key, source, variables):
    """The compiled expression ``source`` of the key ``key``, which may use
    only ``variables`` (besides the constants and functions)."""
    try:
        expr = compile_expression(source)
    except ExpressionError as err:
        raise SceneError(key, f"{err} (in {show(source)})") from None
    extra = sorted(set(expr.uses) - set(variables))
    if extra:
        raise SceneError(key, f"expression uses {extra[0]!r}; allowed variables here: "
                         f"{', '.join(variables)}")
    return expr


def vector_of_expressions(key, value, dim, variables):
    """The ``dim`` compiled expressions of the list ``value``."""
    if not isinstance(value, list) or len(value) != dim:
        raise SceneError(key, f"must be a list of {dim} numbers or expressions, got {show(value)}")
    return tuple(expression(f"{key}[{i}]", v, variables) for i, v in enumerate(value))


def coordinates(dim):
    """The names of the coordinates in dimension ``dim``."""
    return ("x", "y") if dim == 2 else ("x", "y", "z")
