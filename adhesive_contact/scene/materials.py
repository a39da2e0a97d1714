"""The readers of ``[material]`` and ``[memory]``: isotropic tensors given
by a Young or a Lamé pair, and the memory kernels built of them."""

from .errors import SceneError
from .reader import Table, choice, expression, positive
from .spec import Isotropic, MemorySpec, PronyTerm


def _isotropic(table, dim):
    """Exactly one pair: (E, nu) or (lam, mu)."""
    young = table.has("E") or table.has("nu")
    lame = table.has("lam") or table.has("mu")
    if young and lame:
        raise SceneError(table.key("E"), "give exactly one pair: E and nu, or lam and mu")
    if lame:
        lam = table.get("lam", "number")
        mu = positive(table.key("mu"), table.get("mu", "number"))
        if not lam + 2.0 * mu / dim > 0:
            raise SceneError(table.key("lam"),
                             f"must give a positive bulk modulus lam + 2 mu/{dim} > 0")
        return Isotropic(lam, mu)
    E = positive(table.key("E"), table.get("E", "number"))
    nu = table.get("nu", "number")
    if not -1.0 < nu < 0.5:
        raise SceneError(table.key("nu"), f"must lie in (-1, 0.5), got {nu:g}")
    lam = E * nu / ((1.0 + nu) * (1.0 - 2.0 * nu))
    mu = E / (2.0 * (1.0 + nu))
    return Isotropic(lam, mu, E, nu)


def read_material(table, dim):
    material = _isotropic(table, dim)
    table.finish()
    return material


def read_memory(table, dim):
    """A MemorySpec, or None without a [memory] table."""
    if table is None:
        return None
    kernel = choice(table.key("kernel"), table.get("kernel", "str"),
                     ("prony", "function", "relaxation"))
    if kernel == "function":
        function = expression(table.key("r"), table.get("r", "expr"), ("t",))
        tensor = _isotropic(table, dim)
        table.finish()
        return MemorySpec("function", function=function, tensor=tensor)
    long_term = None
    if kernel == "relaxation":
        raw = table.get("long_term", "table")
        lt = Table(raw, table.key("long_term"))
        long_term = _isotropic(lt, dim)
        lt.finish()
    terms_raw = table.get("terms", "list")
    if not terms_raw:
        raise SceneError(table.key("terms"), "must list at least one term {E, nu, tau}")
    terms = []
    for i, raw in enumerate(terms_raw):
        t = Table(raw, f"{table.key('terms')}[{i}]")
        if kernel == "relaxation" and long_term.E is not None and t.has("E") \
                and not t.has("nu") and not (t.has("lam") or t.has("mu")):
            t.data = {**t.data, "nu": long_term.nu}   # nu defaults to long_term's
        tensor = _isotropic(t, dim)
        tau = positive(t.key("tau"), t.get("tau", "number"))
        t.finish()
        terms.append(PronyTerm(tensor, tau))
    table.finish()
    return MemorySpec(kernel, terms=tuple(terms), long_term=long_term)


def instantaneous(memory):
    """G(0) = C_∞ + Σ_i C_i of a relaxation kernel, as one Isotropic (its
    (E, ν) when every part has the same ν: E adds up then)."""
    parts = (memory.long_term,) + tuple(t.tensor for t in memory.terms)
    lam, mu = sum(p.lam for p in parts), sum(p.mu for p in parts)
    nus = {p.nu for p in parts}
    if None not in nus and len(nus) == 1:
        return Isotropic(lam, mu, sum(p.E for p in parts), nus.pop())
    return Isotropic(lam, mu)


def check_relaxation_step(memory, dim, k):
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
