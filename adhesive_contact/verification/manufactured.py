"""Manufactured solutions: the data an exact solution implies (docs/verification.md).

A scene's ``[exact]`` table gives u*(x, t), β*(x, t) and, where u*_ν = g,
a wall multiplier λ*(x, t) > 0. This module derives, with sympy for the
space and time derivatives and a Gauss–Legendre rule in s for the memory
integral,

    σ*(t)   = C ε(u*(t)) + ∫_0^t R(t−s) ε(u*(s)) ds            (1.1)
    f_0     = −Div σ*                                          (1.2)
    f_N     = σ* n on each Neumann side                        (1.4)
    f_C     = σ*ν + p_ν(β*, u*_ν) ν + λ* ν [u*_ν = g]
              + ∇j_τ(β*, u*_τ) [u*_τ ≠ 0]                      on Γ_C
    s_β     = ∂_t β* − F(u*_ν, u*_τ, β*)                        on Γ_C

so that u*, β* satisfy every condition of the problem with the extra
surface load f_C and bonding source s_β (both zero in ordinary runs): on
Γ_C, σ*ν = f_C − p_ν ν − λ* ν − ∇j_τ, i.e. the contact reaction plus the
load. Where u*_τ = 0 the friction force is taken as 0, strictly inside
∂j_τ(β*, 0) when the law has a kink. All functions returned are numpy
callables f(x, y, z, t) (z None in 2D).
"""

import ast
from functools import partial

import numpy as np

from ..expressions import FUNCTIONS, VARIABLES, Expression, chain

#: relative tolerance of "u*_ν = g" (the contact set of a manufactured solution)
TOLERANCE = 1e-10


def on_wall(r, g):
    """u*_ν = g up to ``TOLERANCE`` · (|u*_ν| + |g|): the contact set, where
    the load gets λ* (and :mod:`~adhesive_contact.verification.admissibility` checks λ* ≥ 0)."""
    return np.abs(r - g) <= TOLERANCE * (np.abs(r) + np.abs(g))

_GAUSS_POINTS = 16   # Gauss–Legendre points in s for the memory integral (exact to
                     # round-off for the smooth integrands of manufactured data)


def _sympy():
    import sympy
    return sympy


#: the largest constant exponent |p| of x**p that sympy is given: with exact
#: integers, 9**9**9 or x**1e308 would make it work without end
MAX_EXPONENT = 64


def _variable_free(node):
    return not any(isinstance(n, ast.Name) and n.id in VARIABLES for n in ast.walk(node))


def _constant(node):
    """The float value of a variable-free subtree."""
    return float(Expression("", node, ())(0.0))


#: the sizes of an expression sympy is given: its derivation (two
#: derivatives, then code for numpy) grows with the square of a product's
#: factors and with the depth of nested functions; at these bounds a scene
#: builds in about 2 s (16 factors x*(x + 1)*...*(x + 14)*t: 2.2 s, 10 nested
#: sin: 1.4 s, of which 1.2 s setting up; 40 factors took 24 s, 40 nested sin
#: 7.5 s, and 199 factors or 98 nested sin did not end in a minute)
MAX_FACTORS = 16
MAX_NESTING = 10
MAX_VARIABLE_NODES = 80


def _size_problem(tree):
    """Why an expression tree is too large for sympy (None when it is not):
    more than MAX_FACTORS factors depending on x, y, z or t in one product,
    functions of them nested deeper than MAX_NESTING, or more than
    MAX_VARIABLE_NODES operations on them."""
    dependent = [n for n in ast.walk(tree) if isinstance(n, ast.expr)
                 and not isinstance(n, ast.Name) and not _variable_free(n)]
    if len(dependent) > MAX_VARIABLE_NODES:
        return (f"it has {len(dependent)} operations on x, y, z, t (at most "
                f"{MAX_VARIABLE_NODES})")
    for node in dependent:
        if isinstance(node, ast.BinOp) and isinstance(node.op, (ast.Mult, ast.Div)):
            factors, left = [], node   # the left-nested chain a*b/c*... of this product
            while isinstance(left, ast.BinOp) and isinstance(left.op, (ast.Mult, ast.Div)):
                factors.append(left.right)
                left = left.left
            count = sum(not _variable_free(f) for f in factors + [left])
            if count > MAX_FACTORS:
                return (f"a product of {count} factors depending on x, y, z, t (at most "
                        f"{MAX_FACTORS})")

    def nesting(node):
        inner = max((nesting(child) for child in ast.iter_child_nodes(node)), default=0)
        return inner + (isinstance(node, ast.Call) and not _variable_free(node))

    depth = nesting(tree)
    if depth > MAX_NESTING:
        return f"functions of x, y, z, t nested {depth} deep (at most {MAX_NESTING})"
    return None


def symbolic_problem(expression):
    """Why sympy must not be given ``expression`` (an Expression), or None.

    Refused: a constant part that is not finite (``1/0``, ``1e308*10``), a
    power with a constant exponent beyond ±MAX_EXPONENT, and an expression
    beyond the sizes above (:func:`_size_problem`), whose derivation would
    not end in reasonable time. Checked on floats and on the tree, before
    sympy sees anything, so the check itself is fast."""
    size = _size_problem(expression._tree)
    if size:
        return f"too large for the symbolic derivation: {size}"
    for node in ast.walk(expression._tree):
        if not isinstance(node, ast.expr) or isinstance(node, (ast.Constant, ast.Name)) \
                or not _variable_free(node):
            pass
        elif not np.isfinite(_constant(node)):
            return f"a constant part is not finite ({_constant(node):g})"
        if isinstance(node, ast.BinOp) and isinstance(node.op, ast.Pow) \
                and _variable_free(node.right):
            p = _constant(node.right)
            if not abs(p) <= MAX_EXPONENT:
                return (f"the exponent {p:g} is too large for the symbolic derivation "
                        f"(at most {MAX_EXPONENT} in absolute value)")
    return None


def to_sympy(expression, symbols):
    """The sympy form of a restricted :class:`~adhesive_contact.expressions.Expression`."""
    sp = _sympy()
    binops = {ast.Add: lambda a, b: a + b, ast.Sub: lambda a, b: a - b,
              ast.Mult: lambda a, b: a * b, ast.Div: lambda a, b: a / b,
              ast.Pow: lambda a, b: a ** b}
    compare = {ast.Lt: sp.Lt, ast.LtE: sp.Le, ast.Gt: sp.Gt, ast.GtE: sp.Ge,
               ast.Eq: sp.Eq, ast.NotEq: sp.Ne}
    names = {**symbols, "pi": sp.pi, "e": sp.E}

    def walk(node):
        if isinstance(node, ast.Constant):
            return sp.Float(node.value) if not float(node.value).is_integer() \
                else sp.Integer(int(node.value))
        if isinstance(node, ast.Name):
            return names[node.id]
        if isinstance(node, ast.BinOp):
            base, links = chain(node)
            value = walk(base)
            for op, right in links:
                value = binops[type(op)](value, walk(right))
            return value
        if isinstance(node, ast.UnaryOp):
            value = walk(node.operand)
            return -value if isinstance(node.op, ast.USub) else value
        if isinstance(node, ast.Compare):
            left, out = walk(node.left), sp.true
            for op, comparator in zip(node.ops, node.comparators):
                right = walk(comparator)
                out = sp.And(out, compare[type(op)](left, right))
                left = right
            return out
        return FUNCTIONS[node.func.id].sympy(sp)(*(walk(a) for a in node.args))

    return walk(expression._tree)


def _lambdify(expr, symbols):
    """A numpy callable f(x, y, z, t) of a sympy expression, broadcast to x."""
    sp = _sympy()
    f = sp.lambdify(symbols, expr, modules="numpy")

    def call(x, y=None, z=None, t=0.0):
        args = [x, y, z, t][:len(symbols) - 1] + [t]
        args = [a if a is not None else 0.0 for a in args]
        shape = np.broadcast_shapes(*(np.shape(a) for a in args))
        with np.errstate(all="ignore"):
            return np.broadcast_to(np.asarray(f(*args), dtype=float), shape)
    return call


class ManufacturedSolution:
    """u*, β*, λ* of a scene and the data they imply (module docstring).

    Parameters
    ----------
    scene : Scene with ``exact`` set
    normal_law, friction, bonding : the scene's law objects
    kernel_terms : list of (kernel(lag) callable, λ, μ) terms of R, or []
        (default: :func:`memory_terms` of the scene)

    Pickles by its arguments: the numpy functions are derived again on
    unpickling (sympy's lambdified functions do not pickle).
    """

    def __init__(self, scene, normal_law, friction, bonding, kernel_terms=None):
        self._arguments = (scene, normal_law, friction, bonding)
        if kernel_terms is None:
            kernel_terms = memory_terms(scene)
        sp = _sympy()
        d = scene.dim
        self.dim = d
        xs = sp.symbols("x y z")[:d]
        t = sp.Symbol("t")
        self.symbols = (*xs, t)
        env = {str(s): s for s in self.symbols}
        u = [to_sympy(e, env) for e in scene.exact.u]
        lam, mu = scene.material.lam, scene.material.mu
        grad = [[sp.diff(u[i], xs[j]) for j in range(d)] for i in range(d)]
        eps = [[(grad[i][j] + grad[j][i]) / 2 for j in range(d)] for i in range(d)]
        div = sum(eps[i][i] for i in range(d))
        # Div(C ε(u)) = λ ∇ div u + μ (Δu + ∇ div u): the λ and μ parts
        grad_div = [sp.diff(div, xs[i]) for i in range(d)]
        div_mu = [sum(sp.diff(2 * eps[i][j], xs[j]) for j in range(d)) for i in range(d)]

        L = lambda e: _lambdify(e, self.symbols)
        self._u = [L(c) for c in u]
        self._eps = [[L(eps[i][j]) for j in range(d)] for i in range(d)]
        self._div = L(div)
        self._grad_div = [L(c) for c in grad_div]
        self._div_mu = [L(c) for c in div_mu]
        self.lam, self.mu = lam, mu
        self.memory = kernel_terms
        self.normal_law, self.friction, self.bonding = normal_law, friction, bonding
        beta = to_sympy(scene.exact.beta, env) if scene.exact.beta is not None else sp.Integer(1)
        self._beta = L(beta)
        self._beta_t = L(sp.diff(beta, t))
        self._multiplier = (L(to_sympy(scene.exact.multiplier, env))
                            if scene.exact.multiplier is not None else None)
        self.gap = scene.contact.gap
        xg, wg = np.polynomial.legendre.leggauss(_GAUSS_POINTS)
        self._gauss = (0.5 * (xg + 1.0), 0.5 * wg)   # on [0, 1]

    def __reduce__(self):
        return (type(self), self._arguments)

    # -- fields ---------------------------------------------------------

    def displacement(self, x, y=None, z=None, t=0.0):
        return np.stack([f(x, y, z, t) for f in self._u])

    def strain(self, x, y=None, z=None, t=0.0):
        d = self.dim
        return np.stack([np.stack([self._eps[i][j](x, y, z, t) for j in range(d)])
                         for i in range(d)])

    def beta(self, x, y=None, z=None, t=0.0):
        return np.asarray(self._beta(x, y, z, t), dtype=float)

    @property
    def has_multiplier(self):
        """Whether the scene gives a wall multiplier λ*."""
        return self._multiplier is not None

    def multiplier(self, x, y=None, z=None, t=0.0):
        """λ*(x, t) (call only if :attr:`has_multiplier`)."""
        return np.asarray(self._multiplier(x, y, z, t), dtype=float)

    # -- memory: ∫_0^t kernel(t − s) g(s) ds by Gauss–Legendre in s ------

    def _history(self, g, x, y, z, t):
        """Σ_m ∫_0^t r_m(t−s) (λ_m g_λ(s) + μ_m g_μ(s)) ds for g returning (gλ, gμ)."""
        if not self.memory or t == 0.0:
            return None
        s_ref, w_ref = self._gauss
        s = t * s_ref
        ex = lambda a: None if a is None else np.asarray(a)[..., None]
        gl, gm = g(ex(x), ex(y), ex(z), s)
        out = 0.0
        for kernel, lam_m, mu_m in self.memory:
            weight = t * w_ref * kernel(t - s)
            out = out + lam_m * (gl @ weight) + mu_m * (gm @ weight)
        return out

    def stress(self, x, y=None, z=None, t=0.0):
        """σ*(x, t) of (1.1), shape (d, d, ...)."""
        d = self.dim
        eye = np.eye(d).reshape(d, d, *([1] * np.ndim(x)))
        sig = self.lam * self._div(x, y, z, t) * eye + 2 * self.mu * self.strain(x, y, z, t)

        def parts(x_, y_, z_, s):
            e = self.strain(x_, y_, z_, s)
            tr = sum(e[i, i] for i in range(d))
            return tr * np.eye(d).reshape(d, d, *([1] * (e.ndim - 2))), 2 * e
        hist = self._history(parts, x, y, z, t)
        return sig if hist is None else sig + hist

    def body_force(self, x, y=None, z=None, t=0.0):
        """f_0 = −Div σ*, shape (d, ...)."""
        d = self.dim
        f = -np.stack([self.lam * self._grad_div[i](x, y, z, t) + self.mu * self._div_mu[i](x, y, z, t)
                       for i in range(d)])

        def parts(x_, y_, z_, s):
            return (np.stack([self._grad_div[i](x_, y_, z_, s) for i in range(d)]),
                    np.stack([self._div_mu[i](x_, y_, z_, s) for i in range(d)]))
        hist = self._history(parts, x, y, z, t)
        return f if hist is None else f - hist

    def traction(self, normal):
        """f_N = σ* n on a side with outward normals n (d, …): a function
        f(x, y, z, t)."""
        return partial(self._traction, normal)

    def _traction(self, normal, x, y=None, z=None, t=0.0):
        sig = self.stress(x, y, z, t)
        return np.einsum("ij...,j...->i...", sig, np.broadcast_to(normal, sig.shape[1:]))

    def _frame(self, x, y, z, t, normal, tangents):
        """u*, u*_ν, u*_τ (…, m) and β* at points with normals (d, …) and
        tangents (m, d, …) (broadcast against the points)."""
        u = self.displacement(x, y, z, t)
        r = np.sum(u * normal, axis=0)
        xi = np.stack([np.sum(u * tt, axis=0) for tt in tangents], axis=-1)
        return u, r, xi, self.beta(x, y, z, t)

    def contact_load(self, normal, tangents):
        """f_C on Γ_C with outward normals ν (d, …) and tangents τ (m, d, …):
        a function f(x, y, z, t)."""
        return partial(self._contact_load, normal, tangents)

    def _contact_load(self, normal, tangents, x, y=None, z=None, t=0.0):
        u, r, xi, beta = self._frame(x, y, z, t, normal, tangents)
        sig_n = np.einsum("ij...,j...->i...", self.stress(x, y, z, t),
                          np.broadcast_to(normal, u.shape))
        push = self.normal_law.value(beta, r)
        if self.gap is not None and self._multiplier is not None:
            g = self.gap(x, y, z, t=t)
            push = push + np.where(on_wall(r, g), self._multiplier(x, y, z, t), 0.0)
        load = sig_n + push * normal
        if self.friction is not None:
            force = self.friction.gradient(beta, xi)    # 0 where ξ = 0
            for k, tt in enumerate(tangents):
                load = load + force[..., k] * tt
        return load

    def beta_source(self, normal, tangents):
        """s_β = ∂_t β* − F(u*_ν, u*_τ, β*) at points of Γ_C: a function
        f(x, y, z, t)."""
        return partial(self._beta_source, normal, tangents)

    def _beta_source(self, normal, tangents, x, y=None, z=None, t=0.0):
        out = np.asarray(self._beta_t(x, y, z, t), dtype=float)
        if self.bonding is None:
            return out
        u, r, xi, beta = self._frame(x, y, z, t, normal, tangents)
        return out - self.bonding.rate(r, xi, beta)


def memory_terms(scene):
    """R as a list of (kernel(lag), λ, μ): Prony terms or r(t) C_0."""
    if scene.memory is None:
        return []
    if scene.memory.kernel in ("prony", "relaxation"):
        return [(lambda lag, tau=term.tau: np.exp(-lag / tau), term.tensor.lam, term.tensor.mu)
                for term in scene.memory.prony_terms]
    r = scene.memory.function
    return [(lambda lag: r(lag, t=lag), scene.memory.tensor.lam, scene.memory.tensor.mu)]
