"""A rate-independent cohesive law set by a strength and a toughness
(docs/model.md#44-the-cohesive-law), beside the paper's laws.

The bonding β is the intact fraction, β = 1 − D with D the damage. With
δ_n = R(r) = (−r)_+ the normal opening (r = u_ν positive towards the
foundation), δ_τ = |ξ| the tangential opening and δ_m = (δ_n² + δ_τ²)^½
the effective opening, the tractions are the damaged secant ones,

    p_ν(β, r) = K r_+ − β K min(δ_n, L),        (compression: the layer K)
    p_τ(β, ξ) = β K min(δ_τ, L) ξ/|ξ|           (with a shear toughness only),

and the damage is a function of the largest effective opening reached,
β = min over the history of β*(δ_n, δ_τ) with

- bilinear:     β* = 1 − δ_f (δ_m − δ_0)_+ / (δ_m (δ_f − δ_0)), clipped to [0, 1],
                δ_0 = σ_max/K, δ_f = 2 G_c(B)/σ_max;
- exponential:  β* = exp(−δ_m/δ_c),  δ_c = (G_c(B)/K)^½,  K = e² σ_max²/G_Ic,

so that under a monotone opening t(δ) is the triangle of peak σ_max, or
the Xu–Needleman curve σ_max (δ/δ_c) e^{1 − δ/δ_c} in mode I, and the
work of separation ∫ t dδ is G_c(B) for every mode mixity
B = δ_τ²/δ_m² (= G_II/(G_I + G_II) with one stiffness K in both modes):
the Benzeggagh–Kenane criterion G_c(B) = G_Ic + (G_IIc − G_Ic) B^η.
The shear strength is σ_max too. Without ``toughness_shear`` the law is
mode I: β* depends on δ_n alone and there is no tangential traction.

L caps the opening the traction sees, so that p_ν is globally Lipschitz
(as the paper's laws are): L = 2 max(G_Ic, G_IIc)/σ_max, beyond which a
bilinear point is broken for every B, and 20 δ_c for the exponential
shape (the work left beyond it, (1 + 20) e^{−20} G_c < 10⁻⁷ G_c, is
ignored). The potential is P_ν = K r_+²/2 + β K Ψ(r) with Ψ' = −min(R, L),
so the glue stores β K δ_n²/2 and a fall of β at fixed opening dissipates
(β_{n−1} − β_n) K δ_n²/2: summed over the debonding of a point this is
G_c (tests/test_cohesive.py).
"""

import math
from dataclasses import dataclass

import numpy as np

#: openings beyond CUTOFF δ_c count as broken for the exponential shape
CUTOFF = 20.0
SHAPES = ("bilinear", "exponential")
#: the largest initial stiffness K (as log10) a cohesive law may have: the
#: step matrix adds K times the facets' measure to the body's stiffness
MAX_STIFFNESS_LOG10 = 100


@dataclass(frozen=True)
class CohesiveNormal:
    """The normal law of the cohesive zone (the interface of
    :mod:`adhesive_contact.laws.normal`), and the damage function β* of
    its openings.

    Parameters
    ----------
    shape : "bilinear" or "exponential"
    strength : σ_max > 0, the peak traction
    toughness : G_Ic > 0, the work of separation in mode I
    stiffness : K > 0, the initial stiffness (bilinear only; the exponential
        shape's is e² σ_max²/G_Ic)
    toughness_shear : G_IIc > 0 or None (mode I only)
    mixity : η > 0, the Benzeggagh–Kenane exponent (with ``toughness_shear``)
    """

    shape: str
    strength: float
    toughness: float
    stiffness: float = None
    toughness_shear: float = None
    mixity: float = None
    active = True

    @staticmethod
    def check(params):
        """(parameter, message) of a rule between parameters, or None."""
        shape, K = params["shape"], params.get("stiffness")
        if shape == "bilinear" and K is None:
            return "stiffness", "is required for shape = 'bilinear' (the initial stiffness)"
        if shape == "exponential" and K is not None:
            return "stiffness", ("is for shape = 'bilinear' only: the exponential shape's "
                                 "initial stiffness is e^2 strength^2 / toughness")
        if (params.get("toughness_shear") is None) != (params.get("mixity") is None):
            given = "toughness_shear" if params.get("mixity") is None else "mixity"
            other = "mixity" if given == "toughness_shear" else "toughness_shear"
            return other, f"is required with {given} (the mixed-mode criterion needs both)"
        sigma, G = params["strength"], params["toughness"]
        # the initial stiffness in logarithms: e² σ²/G overflowed (strength 1e200,
        # or 1e160 with toughness 1e-10: OverflowError in every command)
        log_K = (math.log10(K) if shape == "bilinear"
                 else 2.0 * (math.log10(math.e) + math.log10(sigma)) - math.log10(G))
        if log_K > MAX_STIFFNESS_LOG10:
            return ("stiffness" if shape == "bilinear" else "strength"), (
                f"gives the initial stiffness about 1e{round(log_K)}"
                + ("" if shape == "bilinear" else " = e^2 strength^2 / toughness")
                + f", beyond 1e{MAX_STIFFNESS_LOG10}, where the step matrix overflows; "
                "give the law in other units")
        if shape == "bilinear" and not 2.0 * G * K > sigma * sigma:
            return "toughness", (f"must exceed strength^2/(2 stiffness) = "
                                 f"{sigma * sigma / (2 * K):.4g} so that the softening "
                                 f"branch exists (delta_f > delta_0)")
        return None

    # ------------------------------------------------------------------ constants

    @property
    def K(self):
        """The initial stiffness K."""
        if self.shape == "bilinear":
            return float(self.stiffness)
        return float(np.e ** 2 * self.strength ** 2 / self.toughness)

    @property
    def mixed(self):
        """Whether the law has a shear toughness (mixed mode)."""
        return self.toughness_shear is not None

    @property
    def L(self):
        """The cap of the opening the tractions see."""
        G = max(self.toughness, self.toughness_shear or 0.0)
        if self.shape == "bilinear":
            return 2.0 * G / self.strength
        return CUTOFF * np.sqrt(G / self.K)

    @property
    def lipschitz(self):
        """m_ν = max(K, K L): slope K in r, K min(δ_n, L) ≤ K L in β."""
        return max(self.K, self.K * self.L)

    # ------------------------------------------------------------------ p_ν

    def potential(self, beta, r):
        rp = np.maximum(r, 0.0)
        rm = np.clip(r, -self.L, 0.0)
        psi = 0.5 * rm * rm - self.L * (np.minimum(r, -self.L) + self.L)
        return 0.5 * self.K * rp * rp + self.K * beta * psi

    def value(self, beta, r):
        return self.K * (np.maximum(r, 0.0) - beta * np.minimum(np.maximum(-r, 0.0), self.L))

    def derivative(self, beta, r):
        glue = (r < 0.0) & (r > -self.L)
        return self.K * (np.where(r > 0.0, 1.0, 0.0) + np.where(glue, beta, 0.0))

    # ------------------------------------------------------------------ damage

    def critical_energy(self, mix):
        """G_c(B) = G_Ic + (G_IIc − G_Ic) B^η (Benzeggagh–Kenane); G_Ic in mode I."""
        if not self.mixed:
            return np.full(np.shape(mix), float(self.toughness))
        return self.toughness + (self.toughness_shear - self.toughness) * np.power(mix, self.mixity)

    def intact(self, opening_n, opening_t=None):
        """β*(δ_n, δ_τ) ∈ [0, 1], the intact fraction at the openings δ_n ≥ 0
        and δ_τ ≥ 0 (arrays of one shape; δ_τ ignored in mode I)."""
        dn = np.maximum(opening_n, 0.0)
        dt = np.zeros_like(dn) if (opening_t is None or not self.mixed) else opening_t
        dm = np.sqrt(dn * dn + dt * dt)
        mix = np.where(dm > 0.0, dt * dt / np.where(dm > 0.0, dm * dm, 1.0), 0.0)
        G = self.critical_energy(mix)
        if self.shape == "exponential":
            return np.exp(-dm / np.sqrt(G / self.K))
        d0 = self.strength / self.K
        df = 2.0 * G / self.strength
        damage = df * np.maximum(dm - d0, 0.0) / (np.maximum(dm, d0) * (df - d0))
        return np.clip(1.0 - damage, 0.0, 1.0)


@dataclass(frozen=True)
class CohesiveShear:
    """The tangential traction of a mixed-mode cohesive law as a friction
    potential (the interface of :mod:`adhesive_contact.laws.friction`):
    φ(β, s) = β K Ψ_τ(s), Ψ_τ = s²/2 for s ≤ L, L s − L²/2 beyond; convex
    in ξ, smooth, m_τ = K L (the β dependence)."""

    K: float
    L: float
    has_kink = False
    c_1 = 0.0          # |∂j_τ| ≤ K L: bounded

    @property
    def m_tau(self):
        return self.K * self.L

    def kink(self, beta):
        return np.zeros_like(beta)

    def phi(self, beta, s):
        sm = np.minimum(s, self.L)
        return self.K * beta * (0.5 * sm * sm + self.L * (s - sm))

    def dphi(self, beta, s):
        return self.K * beta * np.minimum(s, self.L)

    def ddphi(self, beta, s):
        return np.where(s < self.L, self.K * beta, 0.0)


@dataclass(frozen=True)
class CohesiveDamage:
    """The bonding law of the cohesive zone: β as irreversible damage,
    updated from the previous level as the explicit step (4.2) is,

        β_n = min(β_{n−1}, β*((P_B δ_n²)^½, (P_B δ_τ²)^½)) at u_{n−1},

    β* of the normal law (:meth:`CohesiveNormal.intact`) at the facet's
    root-mean-square openings (one damage per facet; see
    :mod:`adhesive_contact.bonding.damage` for why r.m.s.). β_{n−1} is the
    history variable: β* decreases with the effective opening, so at a
    fixed mixity β_n = P_B β*(max_{j<n} δ_m,j) and unloading follows the
    damaged secant β K. β stays in [0, 1] for every k (no bound like the
    Frémond one: :meth:`stable_step` is ∞); the lag of one level makes the
    traction overshoot the envelope by at most β K Δδ per level, read from a
    finished run (:mod:`adhesive_contact.problem.damage_lag`).
    """

    normal: CohesiveNormal
    rate_independent = True

    @property
    def lipschitz(self):
        """L_F of the paper's F does not apply: the update is not a rate."""
        return np.inf

    @staticmethod
    def openings(r, xi):
        """(δ_n, δ_τ) = ((−u_ν)_+, |u_τ|) at the points: r (nq,), ξ (nq, d−1) or None
        (δ_τ None)."""
        return np.maximum(-r, 0.0), (None if xi is None else np.linalg.norm(xi, axis=-1))

    def target(self, opening_n, opening_t):
        """β*(δ_n, δ_τ) (:meth:`CohesiveNormal.intact`)."""
        return self.normal.intact(opening_n, opening_t)

    def stable_step(self):
        """∞: β_n ∈ [0, 1] for every k (the update is a min of values in [0, 1])."""
        return np.inf
