"""The damage update of a rate-independent bonding law (the cohesive law
of :mod:`adhesive_contact.laws.cohesive`), in place of (4.2):

    β_n = min(β_{n−1}, β*(P_B δ_n, P_B δ_τ)),   δ_n = (−u_{n−1,ν})_+, δ_τ = |u_{n−1,τ}|,

from the previous level as the explicit step is, so the scheme keeps its
structure (β_n known before the step solve of level n). β_{n−1} carries
the history: the min makes β nonincreasing (irreversible) and keeps it
in [0, 1] for every k. The openings are averaged over each facet (P_B),
as β is one value per facet.
"""

import numpy as np


def advance(law, r, xi, facet_mean, beta):
    """β_n (nf,) from β_{n−1} = ``beta`` (nf,) and u_ν = r (nq,), u_τ = ξ
    (nq, d−1) or None at the points; ``facet_mean`` (nq,) -> (nf,)."""
    opening_n, opening_t = law.openings(r, xi)
    if opening_t is not None:
        opening_t = facet_mean(opening_t)
    return np.minimum(beta, law.target(facet_mean(opening_n), opening_t))
