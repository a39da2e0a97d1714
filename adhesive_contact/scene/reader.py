"""Reading a TOML table: typed access to its keys, unknown keys reported
with the nearest known one, and the checks every table reader shares."""

import difflib
import math

from ..expressions import ExpressionError, compile_expression
from .errors import SceneError
from .keys import KNOWN_KEYS


class Table:
    """A TOML table being read: typed access, and unknown keys reported."""

    def __init__(self, data, path):
        if not isinstance(data, dict):
            raise SceneError(path, f"must be a table, got {show(data)}")
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
        return Table(self.data[name], self.key(name))

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


def show(value):
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


def positive(key, value):
    if not value > 0:
        raise SceneError(key, f"must be > 0, got {value:g}")
    return value


def choice(key, value, allowed):
    if value not in allowed:
        raise SceneError(key, f"must be one of {', '.join(map(repr, allowed))}, got {show(value)}")
    return value


def expression(key, source, variables):
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
    if not isinstance(value, list) or len(value) != dim:
        raise SceneError(key, f"must be a list of {dim} numbers or expressions, got {show(value)}")
    return tuple(expression(f"{key}[{i}]", v, variables) for i, v in enumerate(value))


def coordinates(dim):
    return ("x", "y") if dim == 2 else ("x", "y", "z")
