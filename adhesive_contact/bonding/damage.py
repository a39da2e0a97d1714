"""The damage update of a rate-independent bonding law (the cohesive law
of :mod:`adhesive_contact.laws.cohesive`), in place of (4.2):

    β_n = min(β_{n−1}, β*((P_B δ_n²)^½, (P_B δ_τ²)^½)),
    δ_n = (−u_{n−1,ν})_+,  δ_τ = |u_{n−1,τ}|,

from the previous level as the explicit step is, so the scheme keeps its
structure (β_n known before the step solve of level n). β_{n−1} carries
the history: the min makes β nonincreasing (irreversible) and keeps it
in [0, 1] for every k. β is one value per facet, driven by the facet's
root-mean-square openings: the glue of a facet stores β K P_B δ_n²/2
(below the cap), so a fall of β dissipates Δβ K P_B δ_n²/2, and with the
r.m.s. opening these falls sum to exactly the law's G_c as the facet
debonds (with the mean opening, P_B δ² > (P_B δ)² would add the
variance of the opening within a facet: 4 % of G_c in the double
cantilever beam of studies/validation, where near the onset of damage
the opening varies across a facet by more than δ_0).
"""

import numpy as np


def advance(law, r, xi, facet_mean, beta):
    """β_n (nf,) from β_{n−1} = ``beta`` (nf,) and u_ν = r (nq,), u_τ = ξ
    (nq, d−1) or None at the points; ``facet_mean`` (nq,) -> (nf,)."""
    opening_n, opening_t = law.openings(r, xi)
    rms_n = np.sqrt(facet_mean(opening_n * opening_n))
    rms_t = None if opening_t is None else np.sqrt(facet_mean(opening_t * opening_t))
    return np.minimum(beta, law.target(rms_n, rms_t))
