"""Exponential Euler:

    β_n = β_{n−1} + k φ₁(k J) f(β_{n−1}),   J = ∂f/∂β(β_{n−1}) ≤ 0,
    φ₁(x) = (eˣ − 1)/x  (φ₁(0) = 1),

exact for a rate linear in β (so for the Frémond law at frozen
displacement while no point crosses the threshold β s = ε_a) and first
order in k otherwise. For the Frémond law without a source it keeps
β ∈ [0, 1] by construction, for every k: f(β) = J β + e with e ≥ 0 the
mean of ε_a over the points where the glue is loaded, so
β_n = e^{kJ} β_{n−1} + k φ₁(kJ) e ≥ 0, and β_n ≤ β_{n−1} since f ≤ 0.
"""

import numpy as np


def phi1(x):
    """(eˣ − 1)/x, 1 at x = 0, accurate for small |x|."""
    x = np.asarray(x, dtype=float)
    small = np.abs(x) < 1e-8
    return np.where(small, 1.0 + 0.5 * x, np.expm1(x) / np.where(small, 1.0, x))


def advance(rate, beta, k):
    """β_n (nf,) from β_{n−1} (nf,); ``rate(beta) -> (f, ∂f/∂β)``."""
    f, J = rate(beta)
    return beta + k * phi1(k * J) * f
