"""Contact laws of MODEL.md §6, one small object per law.

Each normal law is a function of the bonding β and of the normal
displacement r = u_ν (positive towards the foundation) and provides

- ``potential(beta, r)``  P_ν(β, r) with ∂_r P_ν = p_ν,
- ``value(beta, r)``      p_ν(β, r), the normal reaction density,
- ``derivative(beta, r)`` ∂_r p_ν(β, r) (one element of Clarke's
  generalised derivative at a kink),
- ``lipschitz``           m_ν of MODEL.md §2.

All arguments are numpy arrays of one shape (β is the P0 value of the
facet that holds the quadrature point); the methods are vectorised.

``NORMAL_LAWS`` maps a scene's ``contact.normal.law`` to the class and to
the parameters it takes, so that the scene reader validates them without
knowing the laws.
"""

from dataclasses import dataclass

import numpy as np


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
    """Normal compliance p_ν(β, r) = c r_+ (MODEL.md §6), P_ν = c r_+² / 2.

    Independent of β; its Lipschitz constant is m_ν = c.
    """

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


#: law name -> (class, {parameter: constraint}); constraint is one of
#: "positive", "nonnegative" or "number".
NORMAL_LAWS = {
    "none": (NoNormalLaw, {}),
    "compliance": (NormalCompliance, {"c": "positive"}),
}

FRICTION_LAWS = {
    "none": (None, {}),
}

BONDING_LAWS = {
    "none": (None, {}),
}


def make_normal_law(name, params):
    """The normal law object for a validated scene entry."""
    cls, _ = NORMAL_LAWS[name]
    return cls(**params)
