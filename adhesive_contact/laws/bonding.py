"""Bonding laws: F(r, ξ, β) of (1.7), the rate of β (the interface of
:mod:`adhesive_contact.laws`)."""

from dataclasses import dataclass

import numpy as np

from .normal import separation

#: what the integrators that keep β in [0, 1] at any k cost at a step beyond
#: the law's time scale 1/((γ_ν + γ_τ) L²) (:meth:`Fremond.stable_step`),
#: measured by studies/stability/time_accuracy.py (docs/scheme.md): (4.2)
#: finds β_n from the displacement of the level before whatever the
#: integrator, so the glue debonds a level late
BEYOND_TIME_SCALE = (
    "contact.bonding.integrator 'implicit', 'exponential' and 'midpoint' keep beta in "
    "[0, 1] at any k, but beta_n follows the displacement of the level before, so at k "
    "beyond that bound, the bonding law's time scale, the debonding front lags and the "
    "force the glue carries is overstated (studies/scenes/peel.toml: "
    "peak peel force +40 to +43 % at 1.5 times that scale, +100 to +112 % at 3 times, "
    "against +8 % for explicit Euler at it)")


def truncate(xi, L):
    """R_τ(ξ) = ξ if |ξ| ≤ L else L ξ/|ξ|, for ξ of shape (..., d−1)."""
    s = np.linalg.norm(xi, axis=-1, keepdims=True)
    return xi * np.minimum(1.0, L / np.maximum(s, 1e-300))


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
        k (γ_ν + γ_τ) L² ≤ 1 (β_n ≥ β_{n−1}(1 − k max stretch)); the law's
        time scale, the shortest time the glue takes to debond (beyond it
        every integrator lags: :data:`BEYOND_TIME_SCALE`)."""
        worst = self.gamma_nu * (self.L * self.L) + self.gamma_tau * (self.L * self.L)
        return np.inf if worst == 0 else 1.0 / worst


#: law name -> (class, {parameter: constraint}); a constraint is
#: "positive", "nonnegative" or "number"; a class may add ``check(params)``
#: returning (parameter, message) for a cross-parameter rule.
