"""Integrators of the bonding ODE (4.2) on the P0 bonding field,

    β' = P_B F(u_ν, u_τ, β) (+ s_β for a manufactured solution),

one module per integrator behind one call,

    advance(rate, beta, k) -> β_n,

where ``rate(beta) -> (f, dfdb)`` is the facet-wise right-hand side at
frozen displacement (:class:`FacetRate`): f = P_B F(u, β) + s (nf,) and its
derivative ∂f/∂β (nf,), ≤ 0 for the Frémond law. Chosen by the scene's
``contact.bonding.integrator``:

- ``"explicit"`` (:mod:`.explicit`, the paper's): β_n = β + k f(β);
- ``"implicit"`` (:mod:`.implicit`): backward Euler in β, β_n = β + k f(β_n),
  with the displacement of level n − 1 (semi-implicit, see the module);
- ``"exponential"`` (:mod:`.exponential`): exponential Euler,
  β_n = β + k φ₁(k f'(β)) f(β), exact for a linear rate; keeps β in [0, 1];
- ``"midpoint"`` (:mod:`.midpoint`): the exponential midpoint rule, second
  order; the integrator of ``time.scheme = "second-order"``, which freezes
  the rate at the midpoint t_{n−½}; keeps β in [0, 1].

Explicit and implicit Euler are first order in k at frozen displacement;
exponential Euler, with the exact ∂f/∂β, is exact for a linear rate and
second order for a smooth one there, but the paper's scheme freezes the
rate at t_{n−1}, which makes a run first order; the midpoint rule is second
order at frozen displacement (tests/test_integrators.py,
tests/test_second_order.py) and, with the rate frozen at t_{n−½}, in a run.

A rate-independent law (the cohesive one) has no rate: its damage update,
:mod:`.damage`, takes the place of the integrator.
"""

from dataclasses import dataclass

import numpy as np

from . import damage, explicit, exponential, implicit, midpoint

#: contact.bonding.integrator -> module whose ``advance`` it calls
INTEGRATORS = {"explicit": explicit, "implicit": implicit, "exponential": exponential,
               "midpoint": midpoint}


@dataclass
class FacetRate:
    """f(β) = P_B F(r, ξ, β) + P_B s per contact facet, at frozen r, ξ.

    Parameters
    ----------
    law : bonding law (``rate``, ``rate_derivative``)
    r, xi : u_ν (nq,) and u_τ (nq, d−1) or None at the quadrature points
    at_points, facet_mean : β (nf,) -> (nq,) and (nq,) -> (nf,) of the
        contact boundary
    source : (nq,) s_β at the points, or None
    """

    law: object
    r: np.ndarray
    xi: np.ndarray
    at_points: object
    facet_mean: object
    source: np.ndarray = None

    def __call__(self, beta):
        b = self.at_points(beta)
        f = self.law.rate(self.r, self.xi, b)
        if self.source is not None:
            f = f + self.source
        return self.facet_mean(f), self.facet_mean(self.law.rate_derivative(self.r, self.xi, b))


def advance(integrator, rate, beta, k):
    """β_n from β_{n−1} = ``beta`` with ``integrator`` (a key of :data:`INTEGRATORS`)."""
    return INTEGRATORS[integrator].advance(rate, beta, k)


__all__ = ["INTEGRATORS", "FacetRate", "advance"]
