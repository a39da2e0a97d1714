"""The readers of ``[material]`` and ``[memory]``: isotropic tensors given
by a Young or a Lamé pair, and the memory kernels built of them."""

from ..errors import SceneError
from .keys import MAX_MODULUS, MIN_MODULUS
from .reader import Table
from .spec import Isotropic, MemorySpec, PronyTerm


def _moderate(key, lam, mu, what="the tensor"):
    """Refuse Lamé parameters beyond MAX_MODULUS: the stiffness matrix sums
    them times the squared gradients of the shape functions, and overflows
    to inf or NaN (E = 1e308 failed in the step solve)."""
    if not (abs(lam) <= MAX_MODULUS and mu <= MAX_MODULUS):
        raise SceneError(key, f"gives {what} lam = {lam:.3g}, mu = {mu:.3g}, beyond "
                         f"{MAX_MODULUS:g}, where the stiffness matrix overflows; give the "
                         "moduli in other units (e.g. MPa or GPa)")


def _isotropic(table, dim):
    """Exactly one pair: (E, nu) or (lam, mu)."""
    young = table.has("E") or table.has("nu")
    lame = table.has("lam") or table.has("mu")
    if young and lame:
        raise SceneError(table.key("E"), "give exactly one pair: E and nu, or lam and mu")
    if lame:
        lam = table.read("lam")
        mu = table.read("mu")
        if not lam + 2.0 * mu / dim > 0:
            raise SceneError(table.key("lam"),
                             f"must give a positive bulk modulus lam + 2 mu/{dim} > 0")
        _moderate(table.key("lam"), lam, mu)
        return Isotropic(lam, mu)
    E = table.read("E")
    nu = table.read("nu")
    lam = E * nu / ((1.0 + nu) * (1.0 - 2.0 * nu))
    mu = E / (2.0 * (1.0 + nu))
    _moderate(table.key("E"), lam, mu)
    return Isotropic(lam, mu, E, nu)


def check_elastic(key, tensor, dim, what="the elastic tensor"):
    """Refuse an elastic tensor whose μ or bulk modulus λ + 2μ/d is below
    MIN_MODULUS: its stiffness matrix underflows (E = 5e-324 gave a
    singular factorisation in the first step)."""
    bulk = tensor.lam + 2.0 * tensor.mu / dim
    if not (tensor.mu >= MIN_MODULUS and bulk >= MIN_MODULUS):
        raise SceneError(key, f"gives {what} mu = {tensor.mu:.3g}, bulk modulus "
                         f"{bulk:.3g}, below {MIN_MODULUS:g}, where the stiffness matrix "
                         "underflows; give the moduli in other units (e.g. Pa or kPa)")


def read_material(table, dim):
    material = _isotropic(table, dim)
    check_elastic(table.key("E" if material.E is not None else "mu"), material, dim)
    table.finish()
    return material


def read_memory(table, dim):
    """A MemorySpec, or None without a [memory] table."""
    if table is None:
        return None
    kernel = table.read("kernel")
    if kernel == "function":
        function = table.read_expression("r", ("t",))
        tensor = _isotropic(table, dim)
        table.finish()
        return MemorySpec("function", function=function, tensor=tensor)
    long_term = None
    if kernel == "relaxation":
        raw = table.read("long_term")
        lt = Table(raw, table.key("long_term"))
        long_term = _isotropic(lt, dim)
        lt.finish()
    terms_raw = table.read("terms")
    if not terms_raw:
        raise SceneError(table.key("terms"), "must list at least one term {E, nu, tau}")
    terms = []
    for i, raw in enumerate(terms_raw):
        t = Table(raw, f"{table.key('terms')}[{i}]")
        if kernel == "relaxation" and long_term.E is not None and t.has("E") \
                and not t.has("nu") and not (t.has("lam") or t.has("mu")):
            t.data = {**t.data, "nu": long_term.nu}   # nu defaults to long_term's
        tensor = _isotropic(t, dim)
        tau = t.read("tau")
        t.finish()
        terms.append(PronyTerm(tensor, tau))
    table.finish()
    parts = [t.tensor for t in terms] + ([long_term] if long_term is not None else [])
    _moderate(table.key("terms"), sum(p.lam for p in parts), sum(p.mu for p in parts),
              "summed over its terms")
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


def relaxation_step_definite(memory, dim, k):
    """Whether the step tensor G(0) + k R(0) = C_∞ + Σ_i (1 − k/τ_i) C_i of
    a relaxation kernel is positive definite (μ > 0, λ + 2μ/d > 0)."""
    parts = [(memory.long_term, 1.0)] + [(t.tensor, 1.0 - k / t.tau) for t in memory.terms]
    lam = sum(p.lam * w for p, w in parts)
    mu = sum(p.mu * w for p, w in parts)
    return mu > 0 and lam + 2.0 * mu / dim > 0


def check_relaxation_step(memory, dim, k):
    """The step tensor G(0) + k R(0) = C_∞ + Σ_i (1 − k/τ_i) C_i must be
    positive definite (else the step matrix is indefinite)."""
    if not relaxation_step_definite(memory, dim, k):
        tau = min(t.tau for t in memory.terms)
        raise SceneError("time.steps", f"the time step k = {k:g} is too large for the "
                         f"relaxation time tau = {tau:g}: the step tensor C_inf + "
                         "sum (1 - k/tau_i) C_i is not positive definite; use more steps "
                         f"(k well below {tau:g})")
