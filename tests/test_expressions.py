"""Tests for the restricted expression evaluator."""

import ast
import inspect

import numpy as np
import pytest
from conftest import COMPLIANT_BLOCK, assert_refused, scene_dict, solve_scene

from adhesive_contact import expressions
from adhesive_contact.expressions import Expression, ExpressionError, compile_expression


X = np.linspace(0.0, 2.0, 11)
Y = np.linspace(-1.0, 1.0, 11)
Z = np.linspace(3.0, 4.0, 11)


@pytest.mark.parametrize("source, expected", [
    ("0.02 + 0.01*sin(pi*x)", 0.02 + 0.01 * np.sin(np.pi * X)),
    ("-40*t", np.full_like(X, -40 * 0.5)),
    ("x**2 - 3*y/2 + z", X**2 - 3 * Y / 2 + Z),
    ("exp(-x)*cos(e*y)", np.exp(-X) * np.cos(np.e * Y)),
    ("arctan2(y, x + 1)", np.arctan2(Y, X + 1)),
    ("hypot(x, y)", np.hypot(X, Y)),
    ("minimum(x, 1) + maximum(y, 0)", np.minimum(X, 1) + np.maximum(Y, 0)),
    ("clip(x, 0.5, 1.5)", np.clip(X, 0.5, 1.5)),
    ("heaviside(x - 1, 0.5)", np.heaviside(X - 1, 0.5)),
    ("sqrt(abs(y)) * sign(y)", np.sqrt(np.abs(Y)) * np.sign(Y)),
    ("floor(3*x) + ceil(3*y) + log10(z) + log(z)",
     np.floor(3 * X) + np.ceil(3 * Y) + np.log10(Z) + np.log(Z)),
    ("tanh(x) + sinh(y) - cosh(y) + tan(y) + arcsin(y) + arccos(y)"
     " + arctan(x)",
     np.tanh(X) + np.sinh(Y) - np.cosh(Y) + np.tan(Y) + np.arcsin(Y)
     + np.arccos(Y) + np.arctan(X)),
    ("where(x < 1, 1.0, 0.0)", np.where(X < 1, 1.0, 0.0)),
    ("where(x >= 1, x, -x)", np.where(X >= 1, X, -X)),
    ("where(0.5 < x <= 1.5, 2, 0)",
     np.where((X > 0.5) & (X <= 1.5), 2.0, 0.0)),
    ("where(y == 0, 7, where(y != 0, 1, 2))", np.where(Y == 0, 7.0, 1.0)),
    ("(x < 1)*3 - (x > 1)", (X < 1) * 3.0 - (X > 1)),
    ("+x - -y", X + Y),
    ("2**-1 * x", 0.5 * X),
])
def test_values_match_numpy(source, expected):
    out = compile_expression(source)(X, Y, Z, t=0.5)
    assert out.dtype == float
    assert out.shape == X.shape
    np.testing.assert_allclose(out, expected, rtol=1e-14, atol=1e-15)


@pytest.mark.parametrize("source", ["3", "pi/2", "-40*t", 2.5, 7])
def test_constant_and_time_only_broadcast_to_shape_of_x(source):
    x = np.zeros((4, 3))
    out = compile_expression(source)(x, t=2.0)
    assert isinstance(out, np.ndarray)
    assert out.shape == (4, 3)
    assert out.dtype == float
    assert np.all(out == out.flat[0])
    out[0, 0] = 123.0  # the result is writeable, not a broadcast view
    assert out[1, 1] != 123.0


def test_number_input():
    expr = compile_expression(2.5)
    np.testing.assert_array_equal(expr(X), np.full_like(X, 2.5))
    assert expr.is_constant and not expr.depends_on_time
    assert compile_expression(3)(X).dtype == float
    with pytest.raises(ExpressionError):
        compile_expression(True)
    with pytest.raises(ExpressionError):
        compile_expression(None)


def test_an_expression_keeps_what_it_was_given():
    text = compile_expression(" 2*x ")
    assert (text.source, text.number, text.given) == (" 2*x ", None, " 2*x ")
    for number, source in ((0.02, "0.02"), (-40, "-40"), (np.float64(1.5), "1.5")):
        expr = compile_expression(number)
        assert expr.source == source and expr.given is number
        assert compile_expression(expr.source)(X)[0] == number   # the text reads back


def test_uses_and_flags():
    expr = compile_expression("0.02 + 0.01*sin(pi*x) * t")
    assert isinstance(expr, Expression)
    assert expr.source == "0.02 + 0.01*sin(pi*x) * t"
    assert expr.uses == frozenset({'x', 't'})
    assert not expr.is_constant and expr.depends_on_time
    expr = compile_expression("hypot(y, z)")
    assert expr.uses == frozenset({'y', 'z'})
    assert not expr.depends_on_time
    expr = compile_expression("2*pi + e")
    assert expr.uses == frozenset() and expr.is_constant
    assert compile_expression("-40*t").uses == frozenset({'t'})


def test_time_argument():
    expr = compile_expression("-40*t + x")
    np.testing.assert_allclose(expr(X, t=0.25), X - 10.0)
    np.testing.assert_allclose(expr(X), X)  # t defaults to 0


def test_missing_coordinate():
    with pytest.raises(ExpressionError,
                       match="uses 'z' but the problem is 2D"):
        compile_expression("x + z")(X, Y)
    with pytest.raises(ExpressionError, match="uses 'y'"):
        compile_expression("y")(X)
    # unused coordinates may be None
    np.testing.assert_allclose(compile_expression("2*x")(X, None, None), 2 * X)


def test_numpy_semantics_for_division_by_zero():
    with np.errstate(all='raise'):  # warnings must be silenced inside
        inv = compile_expression("1/x")(X)
        big = compile_expression("9**9**9")(X)
        log0 = compile_expression("log(x - x)")(X)
        nan = compile_expression("0/x")(X)
    assert inv[0] == np.inf and np.isfinite(inv[1:]).all()
    assert np.all(big == np.inf)
    assert np.all(log0 == -np.inf)
    assert np.isnan(nan[0]) and np.all(nan[1:] == 0.0)


@pytest.mark.parametrize("source, name, nargs", [
    ("where(x < 1, 1)", "where", 3),
    ("minimum(x)", "minimum", 2),
    ("clip(x, 1)", "clip", 3),
    ("sin(x, y)", "sin", 1),
    ("hypot(x)", "hypot", 2),
])
def test_arity(source, name, nargs):
    with pytest.raises(ExpressionError,
                       match=r"'{}' takes {} argument".format(name, nargs)):
        compile_expression(source)


@pytest.mark.parametrize("source, message", [
    ("__import__('os').system('ls')", "attribute access"),
    ("__import__('os')", "function '__import__' is not allowed"),
    ("x.__class__", "attribute access"),
    ("().__class__", "attribute access"),
    ("[1,2][0]", "subscript"),
    ("x[0]", "subscript"),
    ("lambda: 1", "lambda"),
    ("(lambda: 1)()", "named functions"),
    ("[x for x in y]", "comprehension"),
    ("'a'", "string"),
    ("f'{x}'", "string"),
    ("q + 1", "name 'q' is not allowed; use x, y, z, t, pi, e"),
    ("os", "name 'os' is not allowed"),
    ("sin(x, y)", "'sin' takes 1 argument"),
    ("sin(x=1)", "keyword arguments"),
    ("sin(*x)", "star"),
    ("x if t else y", "conditional expression"),
    ("x and y", "boolean operators"),
    ("not x", "operator Not"),
    ("x // 2", "operator FloorDiv"),
    ("x in y", "comparison In"),
    ("True", "constant True"),
    ("1j", "constant 1j"),
    ("(x, y)", "tuple"),
    ("sin", "function 'sin' must be called"),
    ("open('f')", "function 'open' is not allowed"),
    ("np.sin(x)", "attribute access"),
    ("(y := 1)", "assignment"),
    ("", "empty"),
    ("   ", "empty"),
    ("1 +", "invalid syntax"),
    ("import os", "invalid syntax"),
    ("(" * 200 + "x" + ")" * 200, "nested too deeply"),
    ("-" * 1999 + "x", "nested too deeply"),
    ("sin(" * 300 + "x" + ")" * 300, "nested too deeply"),
    ("-" * 150 + "x", "nested too deeply"),
    ("sin(" * 120 + "x" + ")" * 120, "nested too deeply"),
    ("x" + "+x" * 1000, "too long"),
])
def test_rejected(source, message):
    with pytest.raises(ExpressionError, match=message) as info:
        compile_expression(source)
    assert isinstance(info.value, ValueError)
    assert "\n" not in str(info.value)


def test_no_builtin_eval_exec_compile_in_module():
    tree = ast.parse(inspect.getsource(expressions))
    for node in ast.walk(tree):
        if isinstance(node, ast.Call) and isinstance(node.func, ast.Name):
            assert node.func.id not in {"eval", "exec", "compile",
                                        "__import__"}, node.func.id
    assert "builtins" not in inspect.getsource(expressions)


def _call(name):
    """A call of ``name`` with its arity, arguments in the domain of every function."""
    return {1: f"{name}(0.3 + 0.4*x)", 2: f"{name}(0.3 + 0.4*x, 0.5 - 0.2*x)",
            3: f"{name}(x < 0.5, 0.3 + x, 0.2*x)" if name == "where"
            else f"{name}(x, 0.3, 0.6)"}[expressions.FUNCTIONS[name].arity]


@pytest.mark.parametrize("name", list(expressions.FUNCTIONS))
def test_numpy_and_sympy_forms_of_each_function_agree(name):
    # the one function table gives both forms; manufactured solutions
    # differentiate the sympy one, the time loop evaluates the NumPy one
    import sympy

    from adhesive_contact.verification.manufactured import to_sympy
    x = np.linspace(0.05, 0.95, 13)
    expr = compile_expression(_call(name))
    symbol = sympy.Symbol("x")
    exact = sympy.lambdify(symbol, to_sympy(expr, {"x": symbol}), modules="numpy")
    np.testing.assert_allclose(expr(x), exact(x) + 0 * x, rtol=1e-14, atol=0)


# ----------------------------------------------------------------
# The evaluator as the scene meets it: refused expressions are exit 2, huge
# results are refused where they are used, comparisons and flat sums evaluate
# in float64 and in order.


@pytest.mark.parametrize("source, message", [
    ("x.real", "attribute access is not allowed"),
    ("().__class__.__bases__", "attribute access is not allowed"),
    ("__import__('os').system('true')", "attribute access is not allowed"),
    ("__import__('os')", "function '__import__' is not allowed"),
    ("open('/etc/passwd')", "function 'open' is not allowed"),
    ("(lambda: 1)()", "only calls to named functions"),
    ("lambda: 1", "lambda is not allowed"),
    ("[i for i in (1, 2)]", "comprehensions are not allowed"),
    ("sum(i for i in (1, 2))", "function 'sum' is not allowed"),
    ("'abc'", "string literals are not allowed"),
    ("sin('x')", "string literals are not allowed"),
    ("os", "name 'os' is not allowed"),
    ("x" * 2001, "too long"),
    ("(" * 101 + "x" + ")" * 101, "nested too deeply"),
    ("-" * 200 + "x", "nested too deeply"),
    ("1" * 400, "number literal is too large"),
])
def test_evaluator_refuses_with_exit_2(tmp_path, source, message):
    with pytest.raises(Exception, match=message):
        compile_expression(source)
    result, out = solve_scene(tmp_path, scene_dict({"loads.body": [source, "0"]}, COMPLIANT_BLOCK))
    assert_refused(result, out, message)
    assert result.stderr.startswith("error: loads.body[0]: ")


@pytest.mark.parametrize("source", ["9**9**9", "10**10**10", "x**1e308 + 2", "exp(1e5*x)",
                                    "1e308*10*x", "2**2**2**2**2**2"])
def test_huge_results_are_refused_where_used(tmp_path, source):
    result, out = solve_scene(tmp_path, scene_dict({"loads.body": ["0", source]}, COMPLIANT_BLOCK))
    assert_refused(result, out, "loads.body[1]: is not finite: inf at (")


def test_a_function_of_a_comparison_is_computed_in_float64():
    value = compile_expression("exp(x > 1)")(np.array([2.0, 0.0]))
    assert value.dtype == np.float64
    assert value.tolist() == [np.exp(1.0), 1.0]   # was 2.71875 (float16)


def test_a_flat_sum_is_not_nested_and_evaluates_in_order():
    terms = [f"{i}*x" for i in range(1, 300)]    # 299 terms, 1700 characters
    x = np.array([0.5, 3.0])
    expected = np.zeros(2)
    for i in range(1, 300):
        expected = expected + i * x
    assert compile_expression("+".join(terms))(x).tolist() == expected.tolist()
    assert compile_expression("-".join(["x"] * 900))(x).tolist() == (-898 * x).tolist()


@pytest.mark.parametrize("source, char, position", [
    ("ｘ + 1", "'ｘ' (U+FF58 FULLWIDTH LATIN SMALL LETTER X)", 1),   # NFKC: x
    ("2*ｓｉｎ(x)", "'ｓ' (U+FF53 FULLWIDTH LATIN SMALL LETTER S)", 3),   # NFKC: sin
    ("х*2", "'х' (U+0445 CYRILLIC SMALL LETTER HA)", 1),   # looks like x
    ("1 − t", "'−' (U+2212 MINUS SIGN)", 3),
])
def test_non_ascii_names_are_refused_and_said_to_be(source, char, position):
    # Python normalised ｘ to x and ｓｉｎ to sin; х was "name 'х' is not allowed"
    with pytest.raises(ExpressionError) as info:
        compile_expression(source)
    assert str(info.value) == (f"non-ASCII character {char} at position {position}: "
                               "expressions are written in ASCII (names such as x, y, z, t, "
                               "sin, exp; operators + - * / **)")
