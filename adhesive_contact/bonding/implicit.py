"""Backward Euler in β:

    β_n = β_{n−1} + k f(β_n),   f(β) = P_B F(u_{n−1,ν}, u_{n−1,τ}, β) (+ P_B s_β(t_{n−1})).

Semi-implicit: the displacement is that of level n − 1, as in (4.2), so
β_n is found before the step solve of level n and the two stay decoupled;
only the β dependence of F is implicit (the coupled scheme, with u_n in F,
would need the step solve and the bonding solve together).

Per facet, G(β) = β − β_{n−1} − k f(β) is continuous, piecewise linear
for the Frémond law and strictly increasing (f is nonincreasing in β:
F = −(β s − ε_a)_+ with s ≥ 0, clamped outside [0, 1]), so it has one
root; it is found by Newton's method safeguarded by bisection on a
bracket, all facets at once. Without a source the root lies in
[0, β_{n−1}] (G(0) = −β_{n−1} ≤ 0 ≤ G(β_{n−1})): β stays in [0, 1] for
every k. First order in k.
"""

import numpy as np

#: iterations of the safeguarded Newton method (bisection alone halves the
#: bracket each time, so this bounds the error by 2^-100 of it)
MAX_ITER = 100


def advance(rate, beta, k):
    """β_n (nf,) from β_{n−1} (nf,); ``rate(beta) -> (f, ∂f/∂β)``."""
    f0, _ = rate(beta)
    # a bracket: f is nonincreasing, so G(b) ≥ b − β − k f(β) for b ≥ β and
    # G(b) ≤ b − β − k f(β) for b ≤ β; the explicit step bounds the root
    explicit = beta + k * f0
    lo, hi = np.minimum(beta, explicit), np.maximum(beta, explicit)
    x = explicit.copy()
    for _ in range(MAX_ITER):
        f, df = rate(x)
        G = x - beta - k * f
        lo = np.where(G < 0, x, lo)
        hi = np.where(G > 0, x, hi)
        if np.all((G == 0) | (hi - lo <= 1e-15 * np.maximum(1.0, np.abs(x)))):
            break
        newton = x - G / (1.0 - k * df)
        x = np.where((newton > lo) & (newton < hi), newton, 0.5 * (lo + hi))
    return x
