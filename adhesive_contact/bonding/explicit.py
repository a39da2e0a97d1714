"""Explicit Euler (4.2), the paper's integrator:

    β_n = β_{n−1} + k f(β_{n−1}).

First order. For the Frémond law it keeps β ≥ 0 only while
k (γ_ν + γ_τ) L² ≤ 1 (β_n ≥ β_{n−1} (1 − k max stretch)); beyond it β
can leave [0, 1] and β² revives the glue.
"""


def advance(rate, beta, k):
    """β_n (nf,) from β_{n−1} (nf,); ``rate(beta) -> (f, ∂f/∂β)``."""
    f, _ = rate(beta)
    return beta + k * f
