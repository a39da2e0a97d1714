"""Normal laws p_ν(β, r) of docs/model.md §4, r = u_ν positive towards the
foundation: none, normal compliance, adhesive compliance (the interface
of :mod:`adhesive_contact.laws`)."""

from dataclasses import dataclass

import numpy as np


def separation(r, L):
    """R_ν(r) = min(max(−r, 0), L): the separation, capped at L."""
    return np.minimum(np.maximum(-r, 0.0), L)


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
    :mod:`adhesive_contact.problem.smallness` less conservative.
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
