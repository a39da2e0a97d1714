"""Exponential midpoint rule, the bonding integrator of the second-order
scheme (docs/scheme.md, "The second-order scheme"):

    β_½ = β_{n−1} + (k/2) φ₁((k/2) J(β_{n−1})) f(β_{n−1}),
    β_n = β_{n−1} + k φ₁(k J_½) (f_½ + J_½ (β_{n−1} − β_½)),

f_½ = f(β_½), J_½ = ∂f/∂β(β_½), φ₁(x) = (eˣ − 1)/x: an exponential Euler
half step predicts β at the midpoint, and the step solves exactly the
linearisation β' = f_½ + J_½ (β − β_½) of the rate there. The scheme
freezes the rate at the midpoint t_{n−½} (the displacement
extrapolated there, the source s_β(t_{n−½})), so the integrator sees an
autonomous rate. Second order in k for a smooth rate (the linearisation's
remainder is O((β − β_½)²) = O(k²) over a step; its O(k) part, odd
about the midpoint, integrates to O(k³)); exact for a rate linear in β.

For the Frémond law without a source it keeps β ∈ [0, 1] for every k: the
linearisation at β_½ is J_½ β + e_½ with J_½ ≤ 0 minus the mean of the
stretch s over the points where the glue is loaded at β_½ and e_½ ≥ 0 the
mean of ε_a there, so β_n lies between β_{n−1} and the fixed point
−e_½/J_½ ∈ [0, β_½] (loaded points have β_½ s > ε_a), and β_½ ∈ [0, 1] by
the exponential Euler argument (:mod:`.exponential`).
"""

from .exponential import phi1


def advance(rate, beta, k):
    """β_n (nf,) from β_{n−1} (nf,); ``rate(beta) -> (f, ∂f/∂β)`` at the midpoint."""
    f0, J0 = rate(beta)
    half = beta + 0.5 * k * phi1(0.5 * k * J0) * f0
    f, J = rate(half)
    return beta + k * phi1(k * J) * (f + J * (beta - half))
