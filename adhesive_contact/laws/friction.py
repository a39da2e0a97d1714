"""Friction potentials j_τ(β, ξ) = φ(β, |ξ|) of docs/model.md §4: Tresca,
slip weakening (nonmonotone), power law, adhesive spring, and their sum
(the interface of :mod:`adhesive_contact.laws`); and a Coulomb-type bound
μ p_ν(β, u_ν)_+ (:class:`Coulomb`), which depends on u_ν and is outside
the paper's theory (docs/model.md, "Coulomb-type friction"): a step
freezes it at a normal pressure (:meth:`FrictionSum.with_pressure`) and
iterates on that pressure (:mod:`adhesive_contact.scheme.state`)."""

from dataclasses import dataclass

import numpy as np


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
class Coulomb:
    """A Coulomb-type bound: j_τ = μ (p_ν)_+ |ξ|, p_ν = p_ν(β, u_ν) the normal
    law's reaction at the same point (docs/model.md, "Coulomb-type friction").

    Not a potential of (β, ξ) alone: it is used frozen at a pressure,
    :meth:`at_pressure`, a :class:`PointBound` κ_q = μ (p_q)_+ per point.
    Calling its φ, φ', φ'' or kink unfrozen is an error. Where the surface
    has separated (p_ν ≤ 0: no compression, or the glue pulling) the bound
    is 0. m_τ and c_1 are those of the frozen law (0, bounded); the
    dependence of the bound on u_ν is what the paper's theorem does not cover.
    """

    mu: float
    has_kink = True
    pressure_dependent = True
    m_tau = 0.0
    c_1 = 0.0

    def at_pressure(self, pressure):
        """The law frozen at the normal pressure p_q (nq,) of each point."""
        return PointBound(self.mu * np.maximum(np.asarray(pressure, dtype=float), 0.0))

    def _unfrozen(self, *args):
        raise ValueError("the Coulomb bound μ p_ν depends on u_ν: freeze it at a normal "
                         "pressure first (FrictionSum.with_pressure)")

    kink = phi = dphi = ddphi = _unfrozen


@dataclass(frozen=True, eq=False)
class PointBound:
    """j_τ = κ_q |ξ| with a given bound κ_q ≥ 0 per quadrature point: Tresca
    with a bound that varies along Γ_C (a frozen :class:`Coulomb`). Its
    arrays have the shape of ``bound`` (nq,): the contact points."""

    bound: np.ndarray
    has_kink = True
    m_tau = 0.0
    c_1 = 0.0

    def kink(self, beta):
        return np.broadcast_to(self.bound, np.shape(beta)).copy()

    def phi(self, beta, s):
        return self.bound * s

    def dphi(self, beta, s):
        return np.broadcast_to(self.bound, np.shape(s)).copy()

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
    def pressure_dependent(self):
        """Whether a law's bound depends on the normal pressure (:class:`Coulomb`)."""
        return any(getattr(law, "pressure_dependent", False) for law in self.laws)

    def with_pressure(self, pressure):
        """The sum with every pressure-dependent law frozen at ``pressure``
        (nq,), p_ν(β_q, u_ν,q) at the contact points."""
        return FrictionSum(tuple(law.at_pressure(pressure)
                                 if getattr(law, "pressure_dependent", False) else law
                                 for law in self.laws))

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
