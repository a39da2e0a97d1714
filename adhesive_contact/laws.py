"""Contact laws of docs/model.md §4, one small object per law.

Normal laws are functions of the bonding β and of the normal displacement
r = u_ν (positive towards the foundation):

- ``potential(beta, r)``  P_ν(β, r), with ∂_r P_ν = p_ν,
- ``value(beta, r)``      p_ν(β, r), the normal reaction density,
- ``derivative(beta, r)`` ∂_r p_ν (one element of the generalised
  derivative at a kink),
- ``lipschitz``           m_ν, the (sharp) constant of
  |p_ν(β₁, r₁) − p_ν(β₂, r₂)| ≤ m_ν (|β₁ − β₂| + |r₁ − r₂|), β ∈ [0, 1].

Friction potentials are radial, j_τ(β, ξ) = φ(β, |ξ|) with φ(β, 0) = 0,
and give φ, φ' = ∂_s φ, φ'' and ``kink(beta)`` = φ'(β, 0+) ≥ 0: the Clarke
subdifferential of j_τ(β, ·) at ξ = 0 is the ball of that radius (the
friction bound), and ∇j_τ = φ'(|ξ|) ξ/|ξ| elsewhere. The class attribute
``has_kink`` says whether φ'(β, 0+) can be > 0 (a law with a kink needs the
nodal rule on Γ_C); ``c_1`` is c_1τ of the growth bound |∂j_τ| ≤ c_0 +
c_1 (|β| + |ξ|) (0 for a bounded ∂j_τ); ``m_tau`` is m_τ, the constant of the relaxed
monotonicity (∇j_τ(β₁, ξ₁) − ∇j_τ(β₂, ξ₂))·(ξ₁ − ξ₂) ≥ −m_τ (|β₁ − β₂| +
|ξ₁ − ξ₂|) |ξ₁ − ξ₂|.

The bonding law gives F(r, ξ, β) of (1.7) and its Lipschitz constant L_F.

All methods are vectorised over numpy arrays of one shape (β is the P0
value of the facet holding the quadrature point).

``NORMAL_LAWS``, ``FRICTION_LAWS`` and ``BONDING_LAWS`` map the scene's law
names to the class and the parameters it takes, so that the scene reader
validates a law without knowing it.
"""

from dataclasses import dataclass

import numpy as np


def separation(r, L):
    """R_ν(r) = min(max(−r, 0), L): the separation, capped at L."""
    return np.minimum(np.maximum(-r, 0.0), L)


def truncate(xi, L):
    """R_τ(ξ) = ξ if |ξ| ≤ L else L ξ/|ξ|, for ξ of shape (..., d−1)."""
    s = np.linalg.norm(xi, axis=-1, keepdims=True)
    return xi * np.minimum(1.0, L / np.maximum(s, 1e-300))


# --------------------------------------------------------------------------
# normal laws


@dataclass(frozen=True)
class NoNormalLaw:
    """No normal reaction: p_ν ≡ 0 (only a wall, if any, acts)."""

    active = False
    lipschitz = 0.0

    def potential(self, beta, r):
        return np.zeros_like(r)

    def value(self, beta, r):
        return np.zeros_like(r)

    def derivative(self, beta, r):
        return np.zeros_like(r)


@dataclass(frozen=True)
class NormalCompliance:
    """p_ν(β, r) = c r_+, P_ν = c r_+²/2; m_ν = c."""

    c: float
    active = True

    @property
    def lipschitz(self):
        return self.c

    def potential(self, beta, r):
        rp = np.maximum(r, 0.0)
        return 0.5 * self.c * rp * rp

    def value(self, beta, r):
        return self.c * np.maximum(r, 0.0)

    def derivative(self, beta, r):
        return np.where(r > 0.0, self.c, 0.0)


@dataclass(frozen=True)
class AdhesiveCompliance:
    """p_ν(β, r) = c r_+ − γ β² R_ν(r) (docs/model.md §4).

    Compression pushes back with stiffness c; a bonded, separated surface
    is pulled back by the glue up to a separation L. The potential is
    P_ν = c r_+²/2 + γ β² Ψ(r) with Ψ(r) = r²/2 on [−L, 0], 0 for r > 0
    and −L r − L²/2 for r < −L (Ψ' = −R_ν).

    m_ν = max(c, γ, 2 γ L): the slopes in r (c, or γβ² ≤ γ) and in β
    (2 γ β R_ν ≤ 2 γ L) never act together, so this is the sharp constant
    for |Δp| ≤ m_ν (|Δβ| + |Δr|), β ∈ [0, 1]. Being below the plain sum of
    the slopes, max(c + γ, 2 γ L), it keeps the smallness estimate of
    :mod:`adhesive_contact.smallness` less conservative.
    """

    c: float
    gamma: float
    L: float
    active = True

    @property
    def lipschitz(self):
        return max(self.c, self.gamma, 2.0 * self.gamma * self.L)

    def potential(self, beta, r):
        rp = np.maximum(r, 0.0)
        rm = np.clip(r, -self.L, 0.0)
        psi = 0.5 * rm * rm - self.L * (np.minimum(r, -self.L) + self.L)
        return 0.5 * self.c * rp * rp + self.gamma * beta * beta * psi

    def value(self, beta, r):
        return self.c * np.maximum(r, 0.0) - self.gamma * beta * beta * separation(r, self.L)

    def derivative(self, beta, r):
        glue = (r < 0.0) & (r > -self.L)
        return np.where(r > 0.0, self.c, 0.0) + np.where(glue, self.gamma * beta * beta, 0.0)


# --------------------------------------------------------------------------
# friction potentials j_τ(β, ξ) = φ(β, |ξ|)


@dataclass(frozen=True)
class Tresca:
    """j_τ = μ |ξ|: a constant friction bound μ; convex, m_τ = 0."""

    mu: float
    has_kink = True
    m_tau = 0.0
    c_1 = 0.0          # |∂j_τ| ≤ μ: bounded

    def kink(self, beta):
        return np.full(np.shape(beta), float(self.mu))

    def phi(self, beta, s):
        return self.mu * s

    def dphi(self, beta, s):
        return np.full(np.shape(s), float(self.mu))

    def ddphi(self, beta, s):
        return np.zeros_like(s)


@dataclass(frozen=True)
class SlipWeakening:
    """Nonmonotone friction j_τ = ∫_0^{|ξ|} μ(s) ds, μ(s) = (a−b) e^{−αs} + b.

    The bound falls from a at rest to b in slip: not convex; m_τ = α (a − b).
    """

    a: float
    b: float
    alpha: float
    has_kink = True
    c_1 = 0.0          # |∂j_τ| ≤ a: bounded

    @property
    def m_tau(self):
        return self.alpha * (self.a - self.b)

    @property
    def nonconvexity(self):
        """−min φ'' = α (a − b): j_τ + ½ α (a−b) |ξ|² is convex."""
        return self.alpha * (self.a - self.b)

    @staticmethod
    def check(params):
        if not params["a"] > params["b"]:
            return "a", "must be > b (the bound weakens from a to b)"
        return None

    def kink(self, beta):
        return np.full(np.shape(beta), float(self.a))

    def phi(self, beta, s):
        return self.b * s + (self.a - self.b) * (-np.expm1(-self.alpha * s)) / self.alpha

    def dphi(self, beta, s):
        return (self.a - self.b) * np.exp(-self.alpha * s) + self.b

    def ddphi(self, beta, s):
        return -self.alpha * (self.a - self.b) * np.exp(-self.alpha * s)


@dataclass(frozen=True)
class PowerLaw:
    """j_τ = μ |ξ|^{1+q} / (1+q), 0 < q ≤ 1: convex, smooth, m_τ = 0."""

    mu: float
    q: float
    has_kink = False
    m_tau = 0.0

    @property
    def c_1(self):
        """|∂j_τ| = μ s^q ≤ μ (1 + s): c_0 = c_1 = μ."""
        return self.mu

    @staticmethod
    def check(params):
        if not 0.0 < params["q"] <= 1.0:
            return "q", f"must lie in (0, 1], got {params['q']:g}"
        return None

    def kink(self, beta):
        return np.zeros_like(beta)

    def phi(self, beta, s):
        return self.mu * s ** (1.0 + self.q) / (1.0 + self.q)

    def dphi(self, beta, s):
        return self.mu * s ** self.q

    def ddphi(self, beta, s):
        # unbounded at s = 0 when q < 1; callers floor s
        return self.mu * self.q * np.maximum(s, 1e-300) ** (self.q - 1.0)


@dataclass(frozen=True)
class AdhesiveSpring:
    """The glue's tangential spring: ∇j_τ = γ β² R_τ(ξ) (docs/model.md §4).

    φ(β, s) = γ β² s²/2 for s ≤ L and γ β² (L s − L²/2) beyond, so the
    tangential traction is capped at γ β² L; convex in ξ. The constant of
    the relaxed monotonicity comes from the β dependence: m_τ = 2 γ L.
    """

    gamma: float
    L: float
    has_kink = False
    c_1 = 0.0          # |∂j_τ| ≤ γ L: bounded

    @property
    def m_tau(self):
        return 2.0 * self.gamma * self.L

    def kink(self, beta):
        return np.zeros_like(beta)

    def phi(self, beta, s):
        sm = np.minimum(s, self.L)
        return self.gamma * beta * beta * (0.5 * sm * sm + self.L * (s - sm))

    def dphi(self, beta, s):
        return self.gamma * beta * beta * np.minimum(s, self.L)

    def ddphi(self, beta, s):
        return np.where(s < self.L, self.gamma * beta * beta, 0.0)


@dataclass(frozen=True)
class FrictionSum:
    """A sum of friction potentials: φ = Σ_i φ_i, kink = Σ_i kink_i."""

    laws: tuple

    @property
    def m_tau(self):
        """m_τ of the sum: the sum of the m_τ of its laws."""
        return sum(law.m_tau for law in self.laws)

    @property
    def c_1(self):
        """c_1 of the growth bound |∂j_τ| ≤ c_0 + c_1 (|β| + |ξ|) of the sum."""
        return sum(law.c_1 for law in self.laws)

    @property
    def nonconvexity(self):
        """m with j_τ + ½ m |ξ|² convex (0 for convex potentials)."""
        return sum(getattr(law, "nonconvexity", 0.0) for law in self.laws)

    @property
    def has_kink(self):
        return any(law.has_kink for law in self.laws)

    def kink(self, beta):
        return sum(law.kink(beta) for law in self.laws)

    def phi(self, beta, s):
        return sum(law.phi(beta, s) for law in self.laws)

    def dphi(self, beta, s):
        return sum(law.dphi(beta, s) for law in self.laws)

    def ddphi(self, beta, s):
        return sum(law.ddphi(beta, s) for law in self.laws)

    def potential(self, beta, xi):
        """j_τ(β, ξ) for ξ of shape (..., d−1)."""
        return self.phi(beta, np.linalg.norm(xi, axis=-1))

    def gradient(self, beta, xi):
        """∇_ξ j_τ for ξ ≠ 0 (the minimal-norm subgradient, 0, at ξ = 0)."""
        s = np.linalg.norm(xi, axis=-1)
        scale = np.where(s > 0, self.dphi(beta, s) / np.where(s > 0, s, 1.0), 0.0)
        return xi * scale[..., None]


# --------------------------------------------------------------------------
# bonding


@dataclass(frozen=True)
class Fremond:
    """F(r, ξ, β) = −(β (γ_ν R_ν(r)² + γ_τ |R_τ(ξ)|²) − ε_a)_+ (docs/model.md §4).

    β is clamped to [0, 1] inside F, so F is globally Lipschitz, F(·,·,0) = 0
    (ε_a ≥ 0), F ≤ 0 always (so F ≤ 0 for β ≥ 1 and β never increases) and
    F = 0 for β ≤ 0.
    """

    gamma_nu: float
    gamma_tau: float
    eps_a: float
    L: float

    @property
    def lipschitz(self):
        """L_F for |ΔF| ≤ L_F (|Δr| + |Δξ| + |Δβ|): the sum of the partial bounds."""
        g, L = self.gamma_nu + self.gamma_tau, self.L
        return g * L * L + 2.0 * self.gamma_nu * L + 2.0 * self.gamma_tau * L

    def stretch(self, r, xi):
        """γ_ν R_ν(r)² + γ_τ |R_τ(ξ)|², bounded by (γ_ν + γ_τ) L²."""
        rn = separation(r, self.L)
        out = self.gamma_nu * (rn * rn)
        if xi is not None and self.gamma_tau:
            rt = truncate(xi, self.L)
            # |R_τ|² ≤ L² also in floating point, so k = stable_step() is safe
            out = out + self.gamma_tau * np.minimum(np.sum(rt * rt, axis=-1), self.L * self.L)
        return out

    def rate(self, r, xi, beta):
        """F(r, ξ, β)."""
        b = np.clip(beta, 0.0, 1.0)
        return -np.maximum(b * self.stretch(r, xi) - self.eps_a, 0.0)

    def rate_derivative(self, r, xi, beta):
        """∂F/∂β = −stretch where the glue is loaded (β stretch > ε_a) and
        0 ≤ β ≤ 1, else 0 (one element of the generalised derivative)."""
        stretch = self.stretch(r, xi)
        b = np.clip(beta, 0.0, 1.0)
        loaded = (b * stretch > self.eps_a) & (beta >= 0.0) & (beta <= 1.0)
        return np.where(loaded, -stretch, 0.0)

    def stable_step(self):
        """The largest k with β_n ≥ 0 guaranteed for explicit Euler:
        k (γ_ν + γ_τ) L² ≤ 1 (β_n ≥ β_{n−1}(1 − k max stretch))."""
        worst = self.gamma_nu * (self.L * self.L) + self.gamma_tau * (self.L * self.L)
        return np.inf if worst == 0 else 1.0 / worst


#: law name -> (class, {parameter: constraint}); a constraint is
#: "positive", "nonnegative" or "number"; a class may add ``check(params)``
#: returning (parameter, message) for a cross-parameter rule.
NORMAL_LAWS = {
    "none": (NoNormalLaw, {}),
    "compliance": (NormalCompliance, {"c": "positive"}),
    "adhesive_compliance": (AdhesiveCompliance,
                            {"c": "positive", "gamma": "nonnegative", "L": "positive"}),
}

FRICTION_LAWS = {
    "none": (None, {}),
    "tresca": (Tresca, {"mu": "positive"}),
    "nonmonotone": (SlipWeakening, {"a": "positive", "b": "positive", "alpha": "positive"}),
    "power": (PowerLaw, {"mu": "positive", "q": "positive"}),
    "adhesive_spring": (AdhesiveSpring, {"gamma": "positive", "L": "positive"}),
}

BONDING_LAWS = {
    "none": (None, {}),
    "fremond": (Fremond, {"gamma_nu": "nonnegative", "gamma_tau": "nonnegative",
                          "eps_a": "nonnegative", "L": "positive"}),
}


def make_normal_law(spec):
    cls, _ = NORMAL_LAWS[spec.law]
    return cls(**spec.params)


def make_friction(specs):
    """A FrictionSum of the scene's friction laws, or None without friction."""
    laws = tuple(FRICTION_LAWS[s.law][0](**s.params) for s in specs if s.law != "none")
    return FrictionSum(laws) if laws else None


def make_bonding(spec):
    """The bonding law, or None when β is frozen."""
    if spec.law == "none":
        return None
    return BONDING_LAWS[spec.law][0](**spec.params)
