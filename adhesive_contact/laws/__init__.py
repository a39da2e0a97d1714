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

One module per kind of law (:mod:`.normal`, :mod:`.friction`,
:mod:`.bonding`). ``NORMAL_LAWS``, ``FRICTION_LAWS`` and ``BONDING_LAWS``
map the scene's law names to the class and the parameters it takes, so
that the scene reader validates a law without knowing it: a new law is a
class in its module and one entry here. A parameter's constraint is
"positive", "nonnegative" or "number" (a required number), the same with
a trailing "?" (an optional number, absent: not passed), or a tuple of
strings (a required choice).

The cohesive law (:mod:`.cohesive`) is a normal law and a bonding law
named together: its bonding law takes the normal law's parameters, and a
mixed-mode one adds its tangential traction to the friction laws.
"""

from .bonding import Fremond, truncate
from .cohesive import SHAPES, CohesiveDamage, CohesiveNormal, CohesiveShear
from .friction import (AdhesiveSpring, Coulomb, FrictionSum, PointBound, PowerLaw,
                       SlipWeakening, Tresca)
from .normal import AdhesiveCompliance, NoNormalLaw, NormalCompliance, separation

__all__ = ["NORMAL_LAWS", "FRICTION_LAWS", "BONDING_LAWS", "make_normal_law", "make_friction",
           "make_bonding", "Fremond", "AdhesiveSpring", "Coulomb", "FrictionSum", "PointBound",
           "PowerLaw", "SlipWeakening", "Tresca", "CohesiveDamage", "CohesiveNormal",
           "CohesiveShear", "AdhesiveCompliance", "NoNormalLaw", "NormalCompliance",
           "separation", "truncate"]

NORMAL_LAWS = {
    "none": (NoNormalLaw, {}),
    "compliance": (NormalCompliance, {"c": "positive"}),
    "adhesive_compliance": (AdhesiveCompliance,
                            {"c": "positive", "gamma": "nonnegative", "L": "positive"}),
    "cohesive": (CohesiveNormal,
                 {"shape": SHAPES, "strength": "positive", "toughness": "positive",
                  "stiffness": "positive?", "toughness_shear": "positive?",
                  "mixity": "positive?"}),
}

FRICTION_LAWS = {
    "none": (None, {}),
    "tresca": (Tresca, {"mu": "positive"}),
    "coulomb": (Coulomb, {"mu": "positive"}),
    "nonmonotone": (SlipWeakening, {"a": "positive", "b": "positive", "alpha": "positive"}),
    "power": (PowerLaw, {"mu": "positive", "q": "positive"}),
    "adhesive_spring": (AdhesiveSpring, {"gamma": "positive", "L": "positive"}),
}

BONDING_LAWS = {
    "none": (None, {}),
    "fremond": (Fremond, {"gamma_nu": "nonnegative", "gamma_tau": "nonnegative",
                          "eps_a": "nonnegative", "L": "positive"}),
    "cohesive": (CohesiveDamage, {}),
}


def make_normal_law(spec):
    """The normal law of a scene (NoNormalLaw for ``law = "none"``)."""
    cls, _ = NORMAL_LAWS[spec.law]
    return cls(**spec.params)


def make_friction(specs, normal=None):
    """A FrictionSum of the scene's friction laws and, for a mixed-mode
    cohesive ``normal`` law, its tangential traction; None without friction."""
    laws = tuple(FRICTION_LAWS[s.law][0](**s.params) for s in specs if s.law != "none")
    if isinstance(normal, CohesiveNormal) and normal.mixed:
        laws += (CohesiveShear(normal.K, normal.L),)
    return FrictionSum(laws) if laws else None


def make_bonding(spec, normal=None):
    """The bonding law, or None when β is frozen; the cohesive one is made
    from the ``normal`` law."""
    if spec.law == "none":
        return None
    if spec.law == "cohesive":
        return CohesiveDamage(normal)
    return BONDING_LAWS[spec.law][0](**spec.params)
