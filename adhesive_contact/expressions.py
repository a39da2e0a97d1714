"""Restricted evaluation of scalar field expressions.

Scene files give loads, gaps and initial fields as short formulas in the
coordinates and time, e.g. ``"-40*t"`` or ``"0.02 + 0.01*sin(pi*x)"``.  Such
strings come from input files and must never reach Python's ``eval``: this
module parses them with :func:`ast.parse` and accepts only a small arithmetic
language (numbers, ``x y z t pi e``, ``+ - * / **``, comparisons and a
whitelist of elementwise NumPy functions).  Everything else -- attribute
access, subscripts, strings, lambdas, keyword arguments, other names -- is
rejected when the expression is compiled, so a scene file cannot run code.
The validated tree is then evaluated by walking it with NumPy arrays.

"""
import ast
import numbers
import unicodedata
from typing import Callable, NamedTuple

import numpy as np

__all__ = ['ExpressionError', 'Expression', 'chain', 'compile_expression', 'coordinates']

MAX_LENGTH = 2000
MAX_DEPTH = 100
VARIABLES = ('x', 'y', 'z', 't')
CONSTANTS = {'pi': np.pi, 'e': np.e}


class Function(NamedTuple):
    """A function an expression may call: its NumPy form, its number of
    arguments and its sympy form (``sympy(module)`` returns a callable of
    sympy expressions; sympy is imported only for manufactured solutions)."""

    numpy: Callable
    arity: int
    sympy: Callable


def _unary(numpy, sympy_name):
    return Function(numpy, 1, lambda sp: getattr(sp, sympy_name))


FUNCTIONS = {
    'sin': _unary(np.sin, 'sin'), 'cos': _unary(np.cos, 'cos'),
    'tan': _unary(np.tan, 'tan'), 'arcsin': _unary(np.arcsin, 'asin'),
    'arccos': _unary(np.arccos, 'acos'), 'arctan': _unary(np.arctan, 'atan'),
    'arctan2': Function(np.arctan2, 2, lambda sp: sp.atan2),
    'sinh': _unary(np.sinh, 'sinh'), 'cosh': _unary(np.cosh, 'cosh'),
    'tanh': _unary(np.tanh, 'tanh'), 'exp': _unary(np.exp, 'exp'),
    'log': _unary(np.log, 'log'),
    'log10': Function(np.log10, 1, lambda sp: lambda a: sp.log(a, 10)),
    'sqrt': _unary(np.sqrt, 'sqrt'), 'abs': _unary(np.abs, 'Abs'),
    'minimum': Function(np.minimum, 2, lambda sp: sp.Min),
    'maximum': Function(np.maximum, 2, lambda sp: sp.Max),
    'where': Function(np.where, 3,
                      lambda sp: lambda c, a, b: sp.Piecewise((a, c), (b, True))),
    'sign': _unary(np.sign, 'sign'), 'floor': _unary(np.floor, 'floor'),
    'ceil': _unary(np.ceil, 'ceiling'),
    'heaviside': Function(np.heaviside, 2, lambda sp: sp.Heaviside),
    'hypot': Function(np.hypot, 2, lambda sp: lambda a, b: sp.sqrt(a * a + b * b)),
    'clip': Function(np.clip, 3, lambda sp: lambda a, lo, hi: sp.Min(sp.Max(a, lo), hi)),
}
BINOPS = {ast.Add: np.add, ast.Sub: np.subtract, ast.Mult: np.multiply,
          ast.Div: np.true_divide, ast.Pow: np.power}
UNARYOPS = {ast.UAdd: np.positive, ast.USub: np.negative}
COMPAREOPS = {ast.Lt: np.less, ast.LtE: np.less_equal, ast.Gt: np.greater,
              ast.GtE: np.greater_equal, ast.Eq: np.equal,
              ast.NotEq: np.not_equal}
ALLOWED_NAMES = "use x, y, z, t, pi, e or a function (sin, cos, ...)"
REJECTED = {
    ast.Attribute: "attribute access is not allowed",
    ast.Subscript: "subscripts/indexing are not allowed",
    ast.Lambda: "lambda is not allowed",
    ast.IfExp: "conditional expressions are not allowed; "
               "use where(cond, a, b)",
    ast.BoolOp: "boolean operators (and/or) are not allowed; "
                "use where(...) with comparisons",
    ast.Starred: "star arguments are not allowed",
    ast.NamedExpr: "assignment expressions are not allowed",
    ast.JoinedStr: "string literals are not allowed",
}
for _node in (ast.ListComp, ast.SetComp, ast.DictComp, ast.GeneratorExp):
    REJECTED[_node] = "comprehensions are not allowed"
for _node in (ast.Tuple, ast.List, ast.Set, ast.Dict):
    REJECTED[_node] = "tuple, list, set and dict literals are not allowed"


class ExpressionError(ValueError):
    """Invalid, disallowed or inapplicable field expression."""


def _opname(op):
    return type(op).__name__


def chain(node):
    """A left-nested chain of binary operations ``((a op1 b) op2 c) ...`` as
    ``(a, [(op1, b), (op2, c), ...])``, found without recursion.

    A flat sum of many terms parses into such a chain, as deep as it is
    long; checking and evaluating it link by link keeps its depth one level
    (and Python's recursion short), while the result is the same, operation
    for operation, as the nested form's."""
    links = []
    while isinstance(node, ast.BinOp):
        links.append((node.op, node.right))
        node = node.left
    return node, links[::-1]


def _check(node, uses, depth=0):
    """Validate ``node`` recursively and collect the variables it uses."""
    if depth > MAX_DEPTH:
        raise ExpressionError("expression is nested too deeply "
                              "(more than {} levels)".format(MAX_DEPTH))
    if type(node) in REJECTED:
        raise ExpressionError(REJECTED[type(node)])
    if isinstance(node, ast.Constant):
        if isinstance(node.value, str):
            raise ExpressionError("string literals are not allowed")
        if (isinstance(node.value, bool)
                or not isinstance(node.value, (int, float))):
            raise ExpressionError("constant {!r} is not allowed; only real "
                                  "numbers".format(node.value))
        try:
            node.value = float(node.value)  # float math: 9**9**9 -> inf
        except OverflowError:
            raise ExpressionError("number literal is too large") from None
        return
    if isinstance(node, ast.Name):
        if node.id in VARIABLES:
            uses.add(node.id)
        elif node.id in FUNCTIONS:
            raise ExpressionError("function '{}' must be called, e.g. {}(x)"
                                  .format(node.id, node.id))
        elif node.id not in CONSTANTS:
            raise ExpressionError("name '{}' is not allowed; {}"
                                  .format(node.id, ALLOWED_NAMES))
        return
    if isinstance(node, ast.BinOp):
        # a chain a + b - c ... is one level, however long (see chain())
        base, links = chain(node)
        for op, _ in links:
            if type(op) not in BINOPS:
                raise ExpressionError("operator {} is not allowed; use + - * / **"
                                      .format(_opname(op)))
        children = [base] + [right for _, right in links]
    elif isinstance(node, ast.UnaryOp):
        if type(node.op) not in UNARYOPS:
            raise ExpressionError("operator {} is not allowed; use unary + -"
                                  .format(_opname(node.op)))
        children = [node.operand]
    elif isinstance(node, ast.Compare):
        for op in node.ops:
            if type(op) not in COMPAREOPS:
                raise ExpressionError("comparison {} is not allowed; use "
                                      "< <= > >= == !=".format(_opname(op)))
        children = [node.left] + node.comparators
    elif isinstance(node, ast.Call):
        if isinstance(node.func, ast.Attribute):
            raise ExpressionError("attribute access is not allowed; "
                                  "call functions by bare name, e.g. sin(x)")
        if not isinstance(node.func, ast.Name):
            raise ExpressionError("only calls to named functions are allowed,"
                                  " e.g. sin(x)")
        if node.func.id not in FUNCTIONS:
            raise ExpressionError("function '{}' is not allowed; allowed: {}"
                                  .format(node.func.id, ', '.join(FUNCTIONS)))
        name = node.func.id
        if node.keywords:
            raise ExpressionError("keyword arguments are not allowed "
                                  "(in call to '{}')".format(name))
        if len(node.args) != FUNCTIONS[name].arity:
            raise ExpressionError("function '{}' takes {} argument(s), got {}"
                                  .format(name, FUNCTIONS[name].arity, len(node.args)))
        children = node.args
    else:
        raise ExpressionError("{} is not allowed in expressions"
                              .format(type(node).__name__))
    for child in children:
        _check(child, uses, depth + 1)


def _float(value):
    return np.asarray(value, dtype=float)  # booleans take part as 0/1


def _eval(node, env):
    """Evaluate a validated tree with the arrays in ``env``."""
    if isinstance(node, ast.Constant):
        return np.float64(node.value)
    if isinstance(node, ast.Name):
        return env[node.id]
    if isinstance(node, ast.BinOp):
        base, links = chain(node)
        value = _float(_eval(base, env))
        for op, right in links:
            value = BINOPS[type(op)](value, _float(_eval(right, env)))
        return value
    if isinstance(node, ast.UnaryOp):
        return UNARYOPS[type(node.op)](_float(_eval(node.operand, env)))
    if isinstance(node, ast.Compare):
        left, out = _eval(node.left, env), True
        for op, comparator in zip(node.ops, node.comparators):
            right = _eval(comparator, env)
            out = np.logical_and(out, COMPAREOPS[type(op)](left, right))
            left = right
        return out
    # arguments as float64: a comparison's booleans would make NumPy
    # compute in float16 (exp(x > 1) = 2.71875)
    return FUNCTIONS[node.func.id].numpy(*(_float(_eval(arg, env)) for arg in node.args))


class Expression:
    """A compiled restricted expression f(x, y, z, t).

    Attributes
    ----------
    source : str
        The original text (``str(number)`` for a number).
    number : int, float or None
        The number the expression was compiled from, as given; None when it
        was compiled from text.
    uses : frozenset
        Which of ``'x', 'y', 'z', 't'`` the expression references.

    """

    def __init__(self, source, tree, uses, number=None):
        self.source = source
        self.number = number
        self.uses = frozenset(uses)
        self._tree = tree

    @property
    def given(self):
        """What the expression was compiled from: the number, or the text."""
        return self.source if self.number is None else self.number

    @property
    def is_constant(self):
        """True if the expression uses none of x, y, z, t."""
        return not self.uses

    @property
    def depends_on_time(self):
        """True if the expression uses t."""
        return 't' in self.uses

    @property
    def depends_on_space(self):
        """True if the expression uses x, y or z."""
        return bool(self.uses & {'x', 'y', 'z'})

    def __call__(self, x, y=None, z=None, t=0.0):
        """Evaluate at points ``(x, y, z)`` and time ``t``.

        Parameters
        ----------
        x, y, z : ndarray
            Coordinates of one common shape; ``y`` and ``z`` may be None if
            the expression does not use them.
        t : float or ndarray
            Time (an array broadcastable to the shape of ``x`` is allowed).

        Returns
        -------
        ndarray
            Float array of the shape of ``x``.  Division by zero and the like
            follow NumPy and may give inf or nan.

        """
        x = np.asarray(x, dtype=float)
        env = dict(CONSTANTS, x=x, t=np.asarray(t, dtype=float))
        for name, value, dim in (('y', y, '1D'), ('z', z, '2D')):
            if value is None:
                if name in self.uses:
                    raise ExpressionError("expression uses '{}' but the "
                                          "problem is {}".format(name, dim))
            else:
                env[name] = np.asarray(value, dtype=float)
        with np.errstate(all='ignore'):
            value = _eval(self._tree, env)
        return np.array(np.broadcast_to(value, x.shape), dtype=float)

    def __repr__(self):
        return "Expression({!r})".format(self.source)


def compile_expression(source):
    """Parse and validate an expression without evaluating it.

    Parameters
    ----------
    source : str, int or float
        Expression text, or a plain number for a constant expression.

    Returns
    -------
    Expression
        The compiled expression.

    Raises
    ------
    ExpressionError
        If the text is empty, too long, nested too deeply, syntactically
        invalid or uses anything outside the allowed language.

    """
    if isinstance(source, Expression):
        return source
    if isinstance(source, numbers.Real) and not isinstance(source,
                                                           (bool, np.bool_)):
        return Expression(str(source), ast.Constant(float(source)), (),
                          number=source)
    if not isinstance(source, str):
        raise ExpressionError("expression must be a string or a number, "
                              "not {}".format(type(source).__name__))
    if not source.strip():
        raise ExpressionError("expression is empty")
    if len(source) > MAX_LENGTH:
        raise ExpressionError("expression is too long (more than {} "
                              "characters)".format(MAX_LENGTH))
    if not source.isascii():
        # Python reads identifiers in NFKC form: a full-width "ｓｉｎ" would be
        # taken as sin, while a Cyrillic "х" looks like x and is another name
        index, char = next((i, c) for i, c in enumerate(source) if not c.isascii())
        raise ExpressionError(
            "non-ASCII character {!r} ({}) at position {}: expressions are written in "
            "ASCII (names such as x, y, z, t, sin, exp; operators + - * / **)".format(
                char, "U+{:04X} {}".format(ord(char), unicodedata.name(char, "unnamed")),
                index + 1))
    level = 0
    for char in source:  # protect the parser from deep bracket nesting
        level += (char in '([{') - (char in ')]}')
        if level > MAX_DEPTH:
            raise ExpressionError("expression is nested too deeply (more "
                                  "than {} levels)".format(MAX_DEPTH))
    try:
        tree = ast.parse(source.strip(), mode="eval").body
    except SyntaxError as err:
        raise ExpressionError("invalid syntax in expression {!r}: {}".format(
            source[:60], err.msg)) from None
    except (RecursionError, MemoryError):
        raise ExpressionError("expression is nested too deeply") from None
    uses = set()
    _check(tree, uses)
    return Expression(source, tree, uses)


def coordinates(points):
    """Split points (d, ...) into the arguments ``x, y, z`` of an expression
    (``None`` for the coordinates a 2D problem does not have)."""
    return [points[i] if i < points.shape[0] else None for i in range(3)]
