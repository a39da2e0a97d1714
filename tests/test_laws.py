"""The contact laws of docs/model.md §4 against independent computations.

Every check compares a law's method with something computed here without
that method: finite differences of another method, quadrature of the law's
formula as docs/model.md states it, random sampling of the hypotheses of
docs/model.md §3, or a hand-derived constant.

Tolerances. A central difference (f(x+h) − f(x−h))/(2h) differs from f'(x)
by at most h²/6 · sup|f'''| on [x−h, x+h] (Taylor), plus the rounding of
the two evaluations and of x ± h, at most about 2 ε (|f| + |x| |f'|)/h with
ε the machine epsilon; ``fd_tol`` is twice the sum of the two bounds, with
sup|f'''| bounded by hand for each law (0 on the pieces of a piecewise
quadratic potential, so there only rounding is left). A forward difference
(φ(h) − φ(0))/h differs from φ'(0+) by at most h/2 · sup|φ''| on [0, h].
Sampled inequalities get a relative slack of 1e-12 (rounding only).
"""

import warnings
from types import SimpleNamespace

import numpy as np
import pytest

from adhesive_contact.laws import (
    BONDING_LAWS,
    FRICTION_LAWS,
    NORMAL_LAWS,
    AdhesiveCompliance,
    AdhesiveSpring,
    Coulomb,
    Fremond,
    FrictionSum,
    NoNormalLaw,
    NormalCompliance,
    PowerLaw,
    SlipWeakening,
    Tresca,
    make_bonding,
    make_friction,
    make_normal_law,
    separation,
    truncate,
)

EPS = np.finfo(float).eps
SLACK = 1e-12


def central(f, x, h):
    return (f(x + h) - f(x - h)) / (2.0 * h)


def fd_tol(h, third, fmax, dfmax, xmax):
    """Bound on |central difference − f'|: truncation + rounding, times 2."""
    return 2.0 * (h * h / 6.0 * third + 2.0 * EPS * (fmax + xmax * dfmax) / h)


def away_from(x, kinks, dist):
    """The points of x farther than dist from every kink."""
    keep = np.ones(x.shape, bool)
    for k in kinks:
        keep &= np.abs(x - k) > dist
    return x[keep]


# --------------------------------------------------------------------------
# the truncations R_ν and R_τ


def test_separation_matches_its_definition():
    L = 0.7
    r = np.linspace(-3.0, 2.0, 1001)
    expected = np.array([min(max(-ri, 0.0), L) for ri in r])
    got = separation(r, L)
    assert np.array_equal(got, expected)
    assert got.min() == 0.0 and got.max() == L
    # 1-Lipschitz (a composition of 1-Lipschitz maps)
    rng = np.random.default_rng(0)
    r1, r2 = rng.uniform(-3, 2, (2, 2000))
    assert np.all(np.abs(separation(r1, L) - separation(r2, L)) <= np.abs(r1 - r2) * (1 + SLACK))


@pytest.mark.parametrize("d1", [1, 2])
def test_truncate_is_the_projection_onto_the_ball(d1):
    L = 0.6
    rng = np.random.default_rng(1)
    xi = rng.normal(size=(500, d1)) * rng.uniform(0.0, 3.0 * L, (500, 1))
    out = truncate(xi, L)
    assert out.shape == xi.shape
    s = np.linalg.norm(xi, axis=-1)
    inside = s <= L
    assert inside.any() and (~inside).any()
    assert np.array_equal(out[inside], xi[inside])
    # outside: on the sphere of radius L, in the direction of ξ
    assert np.allclose(np.linalg.norm(out[~inside], axis=-1), L, rtol=4 * EPS, atol=0)
    assert np.allclose(out[~inside], L * xi[~inside] / s[~inside, None], rtol=4 * EPS, atol=0)
    # a projection onto a convex set is nonexpansive
    xi2 = rng.normal(size=(500, d1)) * 2 * L
    d_out = np.linalg.norm(out - truncate(xi2, L), axis=-1)
    assert np.all(d_out <= np.linalg.norm(xi - xi2, axis=-1) * (1 + SLACK))
    # ξ = 0 maps to 0, without a warning
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        zero = truncate(np.zeros((3, d1)), L)
    assert np.array_equal(zero, np.zeros((3, d1)))


# --------------------------------------------------------------------------
# normal laws


NORMAL = [
    NormalCompliance(c=2.5),
    AdhesiveCompliance(c=2.0, gamma=3.0, L=0.4),
    AdhesiveCompliance(c=1.0, gamma=0.5, L=2.0),
]
BETAS = [0.0, 0.3, 0.77, 1.0]


def kinks(law):
    return [0.0, -law.L] if isinstance(law, AdhesiveCompliance) else [0.0]


@pytest.mark.parametrize("law", NORMAL, ids=repr)
@pytest.mark.parametrize("beta", BETAS)
def test_normal_value_is_the_derivative_of_the_potential(law, beta):
    # P_ν is piecewise quadratic in r, so away from the kinks the central
    # difference has no truncation error (P''' = 0): only rounding is left.
    h = 1e-4
    r = away_from(np.linspace(-3.0, 2.0, 401), kinks(law), 2 * h)
    b = np.full_like(r, beta)
    P = lambda x: law.potential(b, x)
    fd = central(P, r, h)
    p = law.value(b, r)
    tol = fd_tol(h, 0.0, np.abs(P(r)).max() + 1, np.abs(p).max() + 1, 3.0)
    assert np.max(np.abs(fd - p)) <= tol


@pytest.mark.parametrize("law", NORMAL, ids=repr)
@pytest.mark.parametrize("beta", BETAS)
def test_normal_derivative_is_the_derivative_of_the_value(law, beta):
    # p_ν is piecewise linear in r: again rounding only.
    h = 1e-4
    r = away_from(np.linspace(-3.0, 2.0, 401), kinks(law), 2 * h)
    b = np.full_like(r, beta)
    p = lambda x: law.value(b, x)
    fd = central(p, r, h)
    dp = law.derivative(b, r)
    tol = fd_tol(h, 0.0, np.abs(p(r)).max() + 1, np.abs(dp).max() + 1, 3.0)
    assert np.max(np.abs(fd - dp)) <= tol


@pytest.mark.parametrize("law", NORMAL, ids=repr)
def test_normal_value_matches_model_formula(law):
    # docs/model.md §4: p_ν = c r_+ − γ β² R_ν(r), written here scalar by scalar.
    rng = np.random.default_rng(2)
    r = rng.uniform(-3, 2, 300)
    beta = rng.uniform(0, 1, 300)
    gamma = getattr(law, "gamma", 0.0)
    L = getattr(law, "L", 1.0)
    expected = [law.c * max(ri, 0.0) - gamma * bi ** 2 * min(max(-ri, 0.0), L)
                for ri, bi in zip(r, beta)]
    assert np.allclose(law.value(beta, r), expected, rtol=8 * EPS, atol=8 * EPS)


@pytest.mark.parametrize("law", [NoNormalLaw()] + NORMAL, ids=repr)
def test_normal_value_vanishes_at_zero(law):
    # H(p_ν)(d): p_ν(β, 0) = 0 exactly, for every β in [0, 1]
    beta = np.linspace(0.0, 1.0, 101)
    assert np.all(law.value(beta, np.zeros_like(beta)) == 0.0)
    assert np.all(law.potential(beta, np.zeros_like(beta)) == 0.0)


def test_normal_compliance_lipschitz_is_c():
    law = NormalCompliance(c=2.5)
    rng = np.random.default_rng(3)
    r1, r2 = rng.uniform(-2, 2, (2, 5000))
    b1, b2 = rng.uniform(0, 1, (2, 5000))
    p1, p2 = law.value(b1, r1), law.value(b2, r2)
    rounding = 8 * EPS * (np.abs(p1) + np.abs(p2))
    assert np.all(np.abs(p1 - p2) <= law.lipschitz * (np.abs(b1 - b2) + np.abs(r1 - r2)) * (1 + SLACK)
                  + rounding)
    # attained by two compressions
    assert law.value(0.5, 1.5) - law.value(0.5, 0.5) == pytest.approx(law.lipschitz, rel=1e-14)


ADHESIVE_REGIMES = [
    dict(c=1.0, gamma=2.0, L=1.0),    # 2γL dominates (the β dependence)
    dict(c=10.0, gamma=1.0, L=0.5),   # c dominates
    dict(c=1.0, gamma=1.0, L=0.25),   # c = γ: the compression and glue slopes tie
]


def lipschitz_pairs(law, rng):
    """Random pairs in [0, 1] × [−3L, 2] plus pairs at the steepest places."""
    n = 20000
    b1, b2 = rng.uniform(0, 1, (2, n))
    r1, r2 = rng.uniform(-3 * law.L, 2.0, (2, n))
    d = 1e-6
    # the compression slope c, the glue slope γ at β = 1, the β slope 2γL at r = −L
    tb1 = np.array([0.3, 1.0, 1.0, 1.0])
    tb2 = np.array([0.3, 1.0, 1.0 - d, 1.0 - d])
    tr1 = np.array([0.5, -law.L / 2, -law.L, -2 * law.L])
    tr2 = np.array([0.5 + d, -law.L / 2 + d, -law.L, -2 * law.L])
    return (np.concatenate([b1, tb1]), np.concatenate([b2, tb2]),
            np.concatenate([r1, tr1]), np.concatenate([r2, tr2]))


def lipschitz_ratios(law, seed):
    """|Δp| / (m_ν (|Δβ| + |Δr|)) and the rounding of |Δp| relative to its bound."""
    b1, b2, r1, r2 = lipschitz_pairs(law, np.random.default_rng(seed))
    p1, p2 = law.value(b1, r1), law.value(b2, r2)
    bound = (np.abs(b1 - b2) + np.abs(r1 - r2)) * law.lipschitz
    return np.abs(p1 - p2) / bound, 8 * EPS * (np.abs(p1) + np.abs(p2) + 1) / bound


@pytest.mark.parametrize("params", ADHESIVE_REGIMES, ids=str)
def test_adhesive_compliance_is_lipschitz_with_m_nu(params):
    # H(p_ν)(b) with the law's m_ν = max(c, γ, 2γL), which cannot exceed the
    # plain sum of the slopes max(c + γ, 2γL) (also a valid bound)
    law = AdhesiveCompliance(**params)
    assert law.lipschitz <= max(law.c + law.gamma, 2 * law.gamma * law.L)
    ratio, rounding = lipschitz_ratios(law, 4)
    assert np.all(ratio <= 1 + SLACK + rounding)


@pytest.mark.parametrize("params", ADHESIVE_REGIMES, ids=str)
def test_adhesive_compliance_lipschitz_constant_is_not_loose(params):
    # |Δp| / (m_ν (|Δβ| + |Δr|)) must come close to 1 for some pair. The
    # partial slopes are c (r > 0), γβ² ≤ γ (−L < r < 0) and 2γβ R_ν ≤ 2γL
    # (in β): they never add, so the sharp constant is max(c, γ, 2γL).
    law = AdhesiveCompliance(**params)
    best = lipschitz_ratios(law, 5)[0].max()
    sharp = max(law.c, law.gamma, 2 * law.gamma * law.L)
    assert best == pytest.approx(sharp / law.lipschitz, rel=1e-5)
    assert best > 0.9, (f"m_nu = {law.lipschitz:g} is loose: the sharp constant is "
                        f"max(c, gamma, 2 gamma L) = {sharp:g}")


@pytest.mark.parametrize("params", ADHESIVE_REGIMES, ids=str)
@pytest.mark.parametrize("beta", BETAS)
def test_adhesive_potential_convex_continuous_and_integral_of_value(params, beta):
    law = AdhesiveCompliance(**params)
    L = law.L
    # convexity in r: second differences on a uniform grid through both kinks
    # (step L/500, so −L and 0 are grid points up to rounding)
    r = (L / 500) * np.arange(-1500, int(2.0 / (L / 500)) + 1)
    P = law.potential(np.full_like(r, beta), r)
    assert np.all(P[2:] - 2 * P[1:-1] + P[:-2] >= -1e-12)
    # continuity at r = −L and r = 0: |P(x ± δ) − P(x)| ≤ max|p| δ
    delta = 1e-9
    pmax = law.c * 2.0 + law.gamma * L
    for x in (-L, 0.0):
        jumps = law.potential(beta, np.array([x - delta, x + delta])) - law.potential(beta, x)
        assert np.all(np.abs(jumps) <= pmax * delta * (1 + 1e-6) + 4 * EPS * (1 + abs(P).max()))
    # P(β, r) = ∫_0^r p_ν(β, t) dt: p is piecewise linear, so the trapezoid
    # rule with the kinks as nodes is exact
    for x in (-3 * L, -1.5 * L, -L, -0.5 * L, 0.0, 0.7, 2.0):
        nodes = np.unique(np.concatenate([[0.0, x], [k for k in (0.0, -L) if min(0, x) < k < max(0, x)]]))
        vals = law.value(np.full_like(nodes, beta), nodes)
        integral = np.sum(0.5 * (vals[1:] + vals[:-1]) * np.diff(nodes))
        integral = integral if x >= 0 else -integral   # nodes are ascending
        assert law.potential(beta, x) == pytest.approx(integral, rel=1e-13, abs=1e-14)
    # P(β, −L) = γ β² L²/2 by hand
    assert law.potential(beta, -L) == pytest.approx(0.5 * law.gamma * beta ** 2 * L ** 2, abs=1e-15)


# --------------------------------------------------------------------------
# friction potentials


def bounds(law, beta_max, s_lo, s_hi):
    """Hand bounds of sup |φ|, |φ'|, |φ''|, |φ'''|, |φ''''| over s in [s_lo, s_hi]."""
    if isinstance(law, FrictionSum):
        return tuple(map(sum, zip(*(bounds(l, beta_max, s_lo, s_hi) for l in law.laws))))
    if isinstance(law, Tresca):
        return (law.mu * s_hi, law.mu, 0.0, 0.0, 0.0)
    if isinstance(law, SlipWeakening):
        w = law.a - law.b
        return (law.a * s_hi, law.a, law.alpha * w, law.alpha ** 2 * w, law.alpha ** 3 * w)
    if isinstance(law, PowerLaw):
        mu, q = law.mu, law.q
        if q == 1.0:
            return (mu * s_hi ** 2 / 2, mu * s_hi, mu, 0.0, 0.0)
        if s_lo == 0.0:
            return (mu * s_hi ** (1 + q), mu * s_hi ** q, np.inf, np.inf, np.inf)
        return (mu * s_hi ** (1 + q), mu * s_hi ** q, mu * q * s_lo ** (q - 1),
                mu * q * (1 - q) * s_lo ** (q - 2), mu * q * (1 - q) * (2 - q) * s_lo ** (q - 3))
    if isinstance(law, AdhesiveSpring):
        g = law.gamma * beta_max ** 2
        return (g * law.L * s_hi, g * law.L, g, 0.0, 0.0)   # φ''', φ'''' = 0 off s = L
    raise TypeError(law)


def smooth_kinks(law):
    """The s > 0 where φ'' jumps."""
    if isinstance(law, FrictionSum):
        return [k for l in law.laws for k in smooth_kinks(l)]
    return [law.L] if isinstance(law, AdhesiveSpring) else []


FRICTION = [
    Tresca(mu=0.3),
    SlipWeakening(a=0.8, b=0.3, alpha=4.0),
    PowerLaw(mu=1.5, q=0.5),
    PowerLaw(mu=0.7, q=1.0),
    AdhesiveSpring(gamma=2.0, L=0.8),
    FrictionSum((Tresca(mu=0.3), SlipWeakening(a=0.8, b=0.3, alpha=4.0))),
    FrictionSum((SlipWeakening(a=0.8, b=0.3, alpha=4.0), AdhesiveSpring(gamma=2.0, L=0.8),
                 PowerLaw(mu=1.5, q=0.5))),
]


@pytest.mark.parametrize("law", FRICTION, ids=repr)
@pytest.mark.parametrize("beta", [0.0, 0.6, 1.0])
def test_dphi_and_ddphi_are_derivatives(law, beta):
    h = 1e-5
    s = away_from(np.linspace(0.2, 3.0, 281), smooth_kinks(law), 2 * h)
    b = np.full_like(s, beta)
    f0, f1, f2, f3, f4 = bounds(law, beta, 0.2 - h, 3.0 + h)
    fd1 = central(lambda x: law.phi(b, x), s, h)
    assert np.max(np.abs(fd1 - law.dphi(b, s))) <= fd_tol(h, f3, f0, f1, 3.0)
    fd2 = central(lambda x: law.dphi(b, x), s, h)
    assert np.max(np.abs(fd2 - law.ddphi(b, s))) <= fd_tol(h, f4, f1, f2, 3.0)


def test_phi_matches_model_formulas():
    # φ(s) = ∫_0^s μ(t) dt with μ(t) = (a − b) e^{−αt} + b (docs/model.md §4),
    # by Gauss-Legendre with 30 nodes (exact to rounding for this entire integrand)
    law = SlipWeakening(a=0.8, b=0.3, alpha=4.0)
    x, w = np.polynomial.legendre.leggauss(30)
    for s in (0.01, 0.3, 1.0, 5.0):
        t = 0.5 * s * (x + 1)
        integral = 0.5 * s * np.sum(w * ((law.a - law.b) * np.exp(-law.alpha * t) + law.b))
        assert law.phi(0.5, s) == pytest.approx(integral, rel=1e-13)
    # spring: ∫_0^s γβ² min(t, L) dt, piecewise by hand
    spring = AdhesiveSpring(gamma=2.0, L=0.8)
    for s in (0.3, 0.8, 2.0):
        by_hand = 0.5 * s * s if s <= 0.8 else 0.5 * 0.64 + 0.8 * (s - 0.8)
        assert spring.phi(0.5, s) == pytest.approx(2.0 * 0.25 * by_hand, rel=1e-14)
    # Tresca μ s
    assert Tresca(mu=0.3).phi(1.0, 2.0) == pytest.approx(0.6, rel=1e-15)


@pytest.mark.parametrize("q", [0.5, 1.0, 0.25])
def test_power_law_potential_at_one(q):
    law = PowerLaw(mu=1.7, q=q)
    assert law.phi(0.4, 1.0) == pytest.approx(1.7 / (1 + q), rel=2 * EPS)


KINKS = [
    (Tresca(mu=0.3), 0.3),
    (SlipWeakening(a=0.8, b=0.3, alpha=4.0), 0.8),
    (PowerLaw(mu=1.5, q=0.5), 0.0),
    (PowerLaw(mu=0.7, q=1.0), 0.0),
    (AdhesiveSpring(gamma=2.0, L=0.8), 0.0),
    (FrictionSum((Tresca(mu=0.3), SlipWeakening(a=0.8, b=0.3, alpha=4.0))), 1.1),
]


@pytest.mark.parametrize("law,expected", KINKS, ids=lambda x: repr(x))
def test_kink_is_the_one_sided_derivative_at_zero(law, expected):
    beta = np.array([0.0, 0.5, 1.0])
    kink = law.kink(beta)
    assert kink.shape == beta.shape
    assert np.allclose(kink, expected, rtol=4 * EPS, atol=0)
    h = 1e-7
    fwd = (law.phi(beta, np.full(3, h)) - law.phi(beta, np.zeros(3))) / h
    f0, f1, f2, _, _ = bounds(law, 1.0, 0.0, h)
    components = law.laws if isinstance(law, FrictionSum) else (law,)
    if any(isinstance(l, PowerLaw) and l.q < 1 for l in components):
        # φ'' is unbounded at 0: the forward difference is exactly μ h^q/(1+q) off
        tol = 1.01 * sum(l.mu * h ** l.q / (1 + l.q) for l in components if isinstance(l, PowerLaw))
    else:
        tol = 0.5 * h * f2 + 4 * EPS * f1
    assert np.max(np.abs(fwd - kink)) <= tol


def test_friction_sum_kink_and_constants_are_sums():
    t, sw = Tresca(mu=0.3), SlipWeakening(a=0.8, b=0.3, alpha=4.0)
    p, sp = PowerLaw(mu=1.5, q=0.5), AdhesiveSpring(gamma=2.0, L=0.8)
    beta = np.linspace(0, 1, 5)
    both = FrictionSum((t, sw))
    assert np.allclose(both.kink(beta), 0.3 + 0.8, rtol=4 * EPS, atol=0)
    assert both.has_kink and FrictionSum((sw,)).has_kink
    assert not FrictionSum((p, sp)).has_kink
    assert FrictionSum((t, sw, p, sp)).m_tau == pytest.approx(4.0 * 0.5 + 2 * 2.0 * 0.8)


@pytest.mark.parametrize("law", FRICTION[:5], ids=repr)
def test_has_kink_says_whether_the_friction_bound_is_positive(law):
    beta = np.linspace(0.0, 1.0, 5)
    assert type(law).has_kink == bool(np.all(law.kink(beta[1:]) > 0))
    assert np.all(law.kink(beta) >= 0)
    assert type(law) in {cls for cls, _ in FRICTION_LAWS.values()}


def test_every_registered_friction_law_says_whether_it_has_a_kink():
    classes = {cls for cls, _ in FRICTION_LAWS.values() if cls is not None}
    # each one tested above, but the Coulomb bound, which needs a pressure
    # (tests/test_coulomb.py): frozen at one it has the kink it says
    assert classes - {Coulomb} == {type(law) for law in FRICTION[:5]}
    assert all(isinstance(cls.has_kink, bool) for cls in classes)
    frozen = Coulomb(0.5).at_pressure(np.array([1.0, 2.0]))
    assert Coulomb.has_kink and np.all(frozen.kink(np.ones(2)) > 0)


@pytest.mark.parametrize("law", FRICTION[:5], ids=repr)
def test_kink_and_dphi_keep_floats_for_integer_input(law):
    # β = 1 given as a Python or numpy integer must not truncate the bound
    # (np.full_like copies the dtype of its template)
    expected = law.kink(np.ones(3))
    assert np.allclose(law.kink(np.ones(3, dtype=int)), expected)
    assert np.allclose(law.kink(1), expected[0])
    assert np.allclose(law.dphi(np.ones(2), np.array([1, 2])), law.dphi(np.ones(2), np.array([1.0, 2.0])))


def as_sum(law):
    return law if isinstance(law, FrictionSum) else FrictionSum((law,))


@pytest.mark.parametrize("law", FRICTION, ids=repr)
@pytest.mark.parametrize("d1", [1, 2])
def test_friction_gradient_is_the_gradient_of_the_potential(law, d1):
    # j(ξ) = φ(|ξ|): a third directional derivative is φ''' s'³ + 3 φ'' s' s''
    # + φ' s''' with |s'| ≤ 1, |s''| ≤ 1/s, |s'''| ≤ 3/s², so it is bounded
    # by |φ'''| + 3|φ''|/s + 3|φ'|/s²; |ξ| stays in [0.2, 3].
    fs = as_sum(law)
    rng = np.random.default_rng(6)
    n = 400
    direction = rng.normal(size=(n, d1))
    direction /= np.linalg.norm(direction, axis=-1, keepdims=True)
    radius = away_from(rng.uniform(0.2, 3.0, 3 * n), smooth_kinks(fs), 1e-3)[:n]
    xi = direction * radius[:, None]
    beta = rng.uniform(0, 1, n)
    h = 1e-5
    f0, f1, f2, f3, _ = bounds(fs, 1.0, 0.2 - h, 3.0 + h)
    s_lo = 0.2 - h
    third = f3 + 3 * f2 / s_lo + 3 * f1 / s_lo ** 2
    grad = fs.gradient(beta, xi)
    assert grad.shape == xi.shape
    for i in range(d1):
        e = np.zeros(d1)
        e[i] = h
        fd = (fs.potential(beta, xi + e) - fs.potential(beta, xi - e)) / (2 * h)
        assert np.max(np.abs(fd - grad[:, i])) <= fd_tol(h, third, f0, f1, 3.0)
    # and the gradient is φ'(|ξ|) ξ/|ξ| (direction and length)
    assert np.allclose(np.linalg.norm(grad, axis=-1), fs.dphi(beta, radius), rtol=1e-13, atol=1e-15)


@pytest.mark.parametrize("law", FRICTION, ids=repr)
@pytest.mark.parametrize("d1", [1, 2])
def test_friction_gradient_at_zero_is_exactly_zero(law, d1):
    fs = as_sum(law)
    xi = np.zeros((4, d1))
    xi[1] = 0.5
    xi[3] = -0.25
    beta = np.array([1.0, 1.0, 0.3, 0.3])
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        grad = fs.gradient(beta, xi)
    assert np.all(grad[[0, 2]] == 0.0)
    assert np.all(np.isfinite(grad))


def gradient_1d(law, xi):
    return as_sum(law).gradient(np.ones_like(xi), xi[:, None])[:, 0]


def test_slip_weakening_is_relaxed_monotone_with_sharp_constant():
    law = SlipWeakening(a=0.8, b=0.3, alpha=4.0)
    m = law.m_tau
    assert m == pytest.approx(4.0 * 0.5)
    rng = np.random.default_rng(7)
    x1, x2 = rng.uniform(-2, 2, (2, 20000))
    x1, x2 = x1[(x1 != 0) & (x2 != 0)], x2[(x1 != 0) & (x2 != 0)]
    lhs = (gradient_1d(law, x1) - gradient_1d(law, x2)) * (x1 - x2)
    assert np.all(lhs >= -m * (x1 - x2) ** 2 * (1 + SLACK) - 4 * EPS * law.a * np.abs(x1 - x2))
    # sharp: small slips on the same side of 0 weaken at the rate α(a − b)
    y1 = np.array([1e-4, -1e-4, 2e-4])
    y2 = np.array([2e-4, -3e-4, 2.5e-4])
    ratio = -(gradient_1d(law, y1) - gradient_1d(law, y2)) * (y1 - y2) / (y1 - y2) ** 2
    assert ratio.max() > 0.99 * m
    assert ratio.max() <= m * (1 + 1e-8)


def test_adhesive_spring_is_relaxed_monotone_in_beta_and_xi():
    # docs/model.md §3 with the β dependence: (∇j(β1, ξ1) − ∇j(β2, ξ2))·(ξ1 − ξ2)
    # ≥ −m_τ (|β1 − β2| + |ξ1 − ξ2|) |ξ1 − ξ2|, m_τ = 2γL
    law = AdhesiveSpring(gamma=2.0, L=0.8)
    fs = FrictionSum((law,))
    rng = np.random.default_rng(8)
    n = 20000
    b1, b2 = rng.uniform(0, 1, (2, n))
    x1, x2 = rng.uniform(-2, 2, (2, n, 2))
    dxi = np.linalg.norm(x1 - x2, axis=-1)
    g1, g2 = fs.gradient(b1, x1), fs.gradient(b2, x2)
    lhs = np.sum((g1 - g2) * (x1 - x2), axis=-1)
    rhs = -law.m_tau * (np.abs(b1 - b2) + dxi) * dxi
    rounding = 8 * EPS * (np.linalg.norm(g1, axis=-1) + np.linalg.norm(g2, axis=-1)) * dxi
    assert np.all(lhs >= rhs * (1 + SLACK) - rounding)


def test_nonconvexity_of_slip_weakening_and_convex_laws():
    sw = SlipWeakening(a=0.8, b=0.3, alpha=4.0)
    m = sw.nonconvexity
    assert m == pytest.approx(4.0 * 0.5)
    # −min φ'' over s ≥ 0, on a grid (the minimum is at s = 0)
    s = np.linspace(0, 3, 3001)
    assert -sw.ddphi(1.0, s).min() == pytest.approx(m, rel=1e-14)
    # j + ½ m ξ² is convex in 1D (second differences through 0), and not
    # with 0.9 m: the constant is sharp
    h = 1e-3
    x = np.linspace(-2, 2, 4001)
    j = lambda y: FrictionSum((sw,)).potential(np.ones_like(y), y[:, None])
    second = (j(x + h) - 2 * j(x) + j(x - h)) / h ** 2
    tol = 8 * EPS * 2.0 / h ** 2   # rounding of three values of size ≤ 2
    assert np.all(second + m >= -tol)
    assert np.any(second + 0.9 * m < -tol)
    assert FrictionSum((sw,)).nonconvexity == m
    for law in (Tresca(mu=0.3), PowerLaw(mu=1.5, q=0.5), AdhesiveSpring(gamma=2.0, L=0.8)):
        fs = FrictionSum((law,))
        assert fs.nonconvexity == 0.0
        jl = lambda y: fs.potential(np.ones_like(y), y[:, None])
        assert np.all(jl(x + h) - 2 * jl(x) + jl(x - h) >= -8 * EPS * 5.0)
    mix = FrictionSum((sw, Tresca(mu=0.3), SlipWeakening(a=2.0, b=1.0, alpha=1.0)))
    assert mix.nonconvexity == pytest.approx(m + 1.0)


# --------------------------------------------------------------------------
# bonding


FREMOND = [
    Fremond(gamma_nu=1.5, gamma_tau=0.7, eps_a=0.05, L=0.6),
    Fremond(gamma_nu=3.0, gamma_tau=0.0, eps_a=0.0, L=1.3),
    Fremond(gamma_nu=0.4, gamma_tau=2.5, eps_a=0.0, L=0.9),
]


def fremond_samples(law, rng, n, d1):
    r = rng.uniform(-2 * law.L, law.L, n)
    xi = rng.normal(size=(n, d1)) * rng.uniform(0, 2 * law.L, (n, 1))
    beta = rng.uniform(-0.5, 1.5, n)
    return r, xi, beta


@pytest.mark.parametrize("law", FREMOND, ids=repr)
@pytest.mark.parametrize("d1", [1, 2])
def test_fremond_rate_signs_and_formula(law, d1):
    rng = np.random.default_rng(9)
    r, xi, beta = fremond_samples(law, rng, 3000, d1)
    F = law.rate(r, xi, beta)
    # F(r, ξ, β) of docs/model.md §4, scalar by scalar, β clamped to [0, 1]
    expected = []
    for ri, xii, bi in zip(r, xi, beta):
        sn = min(max(-ri, 0.0), law.L)
        st = min(float(np.sqrt(np.sum(xii ** 2))), law.L)
        bc = min(max(bi, 0.0), 1.0)
        expected.append(-max(bc * (law.gamma_nu * sn ** 2 + law.gamma_tau * st ** 2) - law.eps_a, 0.0))
    assert np.allclose(F, expected, rtol=1e-14, atol=1e-15)
    assert np.all(F <= 0.0)
    assert np.all(law.rate(r, xi, np.zeros_like(r)) == 0.0)           # F(·, ·, 0) = 0
    assert np.all(law.rate(r, xi, -np.abs(beta) - 1e-3) == 0.0)        # F = 0 for β ≤ 0
    big = 1.0 + np.abs(beta)
    assert np.all(law.rate(r, xi, big) <= 0.0)                          # F ≤ 0 for β ≥ 1
    assert np.array_equal(law.rate(r, xi, big), law.rate(r, xi, np.ones_like(r)))
    # the stretch is bounded by (γ_ν + γ_τ) L² and reaches it at maximal stretch
    smax = (law.gamma_nu + law.gamma_tau) * law.L ** 2
    assert np.all(law.stretch(r, xi) <= smax * (1 + SLACK))
    xi_far = np.zeros((1, d1))
    xi_far[0, 0] = -2 * law.L
    assert law.stretch(np.array([-3 * law.L]), xi_far)[0] == pytest.approx(smax, rel=1e-15)


@pytest.mark.parametrize("law", FREMOND, ids=repr)
@pytest.mark.parametrize("d1", [1, 2])
def test_fremond_is_globally_lipschitz(law, d1):
    rng = np.random.default_rng(10)
    n = 20000
    r1, x1, b1 = fremond_samples(law, rng, n, d1)
    r2, x2, b2 = fremond_samples(law, rng, n, d1)
    # plus nearby pairs at maximal stretch, where each partial derivative peaks
    r2[:1000] = r1[:1000] + rng.normal(scale=1e-4, size=1000)
    b2[1000:2000] = b1[1000:2000] + rng.normal(scale=1e-4, size=1000)
    F1, F2 = law.rate(r1, x1, b1), law.rate(r2, x2, b2)
    dist = np.abs(r1 - r2) + np.linalg.norm(x1 - x2, axis=-1) + np.abs(b1 - b2)
    rounding = 8 * EPS * (np.abs(F1) + np.abs(F2) + law.eps_a)
    assert np.all(np.abs(F1 - F2) <= law.lipschitz * dist * (1 + SLACK) + rounding)
    g, L = law.gamma_nu + law.gamma_tau, law.L
    assert law.lipschitz == pytest.approx(g * L * L + 2 * law.gamma_nu * L + 2 * law.gamma_tau * L)


@pytest.mark.parametrize("law", FREMOND, ids=repr)
@pytest.mark.parametrize("d1", [1, 2])
def test_fremond_explicit_euler_stability_limit(law, d1):
    k_max = law.stable_step()
    assert k_max == pytest.approx(1.0 / ((law.gamma_nu + law.gamma_tau) * law.L ** 2), rel=1e-15)
    # maximal stretch: r ≤ −L, |ξ| ≥ L
    r = np.array([-law.L, -2 * law.L, -law.L, -5 * law.L])
    xi = np.zeros((4, d1))
    xi[:, 0] = [law.L, -3 * law.L, 2 * law.L, law.L]
    if d1 == 2:
        xi[2] = [law.L, law.L]

    def euler(k, steps=20):
        beta = np.ones(4)
        low = beta.copy()
        for _ in range(steps):
            beta = beta + k * law.rate(r, xi, beta)
            low = np.minimum(low, beta)
        return low

    assert np.all(euler(k_max) >= 0.0)
    assert np.all(euler(0.5 * k_max) >= 0.0)
    low = euler(1.5 * k_max, steps=1)
    # one step: β_1 = 1 − 1.5 (1 − ε_a k_max)
    assert np.all(low < 0.0)
    assert np.allclose(low, 1 - 1.5 * (1 - law.eps_a * k_max), rtol=1e-12, atol=1e-14)


@pytest.mark.parametrize("law", FREMOND, ids=repr)
def test_fremond_stable_step_holds_for_every_tangent_direction(law):
    # 3D: ξ ∈ R² at maximal stretch in random directions. The guarantee
    # β_n ≥ 0 of stable_step() must survive rounding (no β = −1e-16): the
    # computed stretch may not exceed the (γ_ν + γ_τ) L² behind k.
    rng = np.random.default_rng(11)
    n = 5000
    xi = rng.normal(size=(n, 2))
    xi *= law.L * rng.uniform(1.0, 3.0, (n, 1)) / np.linalg.norm(xi, axis=-1, keepdims=True)
    r = -law.L * rng.uniform(1.0, 3.0, n)
    beta = np.ones(n)
    for _ in range(3):
        beta = beta + law.stable_step() * law.rate(r, xi, beta)
        assert beta.min() >= 0.0, f"beta = {beta.min():.3g} < 0 at k = stable_step()"


def test_fremond_without_bonding_stiffness_has_no_step_limit():
    assert Fremond(gamma_nu=0.0, gamma_tau=0.0, eps_a=0.0, L=1.0).stable_step() == np.inf


# --------------------------------------------------------------------------
# the scene registry


SPECIAL = {"nonmonotone": {"a": 2.0, "b": 1.0}, "power": {"q": 0.5},
           "cohesive": {"shape": "bilinear", "stiffness": 10.0}}


def registry_entries():
    for table in (NORMAL_LAWS, FRICTION_LAWS, BONDING_LAWS):
        for name, (cls, params) in table.items():
            # the cohesive bonding law is made from the normal law (test_cohesive.py)
            if name != "none" and not (table is BONDING_LAWS and name == "cohesive"):
                yield name, cls, params


@pytest.mark.parametrize("name,cls,params", list(registry_entries()), ids=lambda x: str(x)[:20])
def test_registry_laws_construct_with_their_parameters(name, cls, params):
    assert all(isinstance(c, tuple) and all(isinstance(x, str) for x in c)
               or c.rstrip("?") in ("positive", "nonnegative", "number")
               for c in params.values())
    values = {p: 1.0 for p in params}
    values.update(SPECIAL.get(name, {}))
    law = cls(**values)
    for p, v in values.items():
        assert getattr(law, p) == v
    if hasattr(cls, "check"):
        assert cls.check(values) is None


def test_registry_none_entries():
    assert NORMAL_LAWS["none"][0] is NoNormalLaw
    assert FRICTION_LAWS["none"][0] is None and BONDING_LAWS["none"][0] is None


def test_cross_parameter_checks():
    key, msg = SlipWeakening.check({"a": 1.0, "b": 2.0, "alpha": 1.0})
    assert key == "a" and isinstance(msg, str) and msg
    assert SlipWeakening.check({"a": 1.0, "b": 1.0, "alpha": 1.0})[0] == "a"
    key, msg = PowerLaw.check({"mu": 1.0, "q": 1.5})
    assert key == "q" and "1.5" in msg
    assert PowerLaw.check({"mu": 1.0, "q": 1.0}) is None
    assert PowerLaw.check({"mu": 1.0, "q": 0.0})[0] == "q"


def test_factories():
    spec = lambda law, **params: SimpleNamespace(law=law, params=params)
    assert make_normal_law(spec("adhesive_compliance", c=1.0, gamma=2.0, L=0.5)) == \
        AdhesiveCompliance(c=1.0, gamma=2.0, L=0.5)
    assert isinstance(make_normal_law(spec("none")), NoNormalLaw)
    fr = make_friction([spec("tresca", mu=0.3), spec("none"),
                        spec("nonmonotone", a=2.0, b=1.0, alpha=3.0)])
    assert fr == FrictionSum((Tresca(mu=0.3), SlipWeakening(a=2.0, b=1.0, alpha=3.0)))
    assert make_friction([spec("none")]) is None and make_friction([]) is None
    assert make_bonding(spec("none")) is None
    assert make_bonding(spec("fremond", gamma_nu=1.0, gamma_tau=1.0, eps_a=0.0, L=1.0)) == \
        Fremond(gamma_nu=1.0, gamma_tau=1.0, eps_a=0.0, L=1.0)
