"""Step methods: ways of solving the step of (4.1) on the contact unknowns,

    min_z  ½ zᵀ S z − cᵀ z + Φ(z)   subject to  z_ν ≤ g

(:mod:`.base`), one module per method behind one call,

    minimise(S, c, energy, upper, z0, options, kink) -> StepResult,

chosen by the scene's ``solver.method``:

- ``"newton"`` (:mod:`.newton`, the default): semismooth Newton on the
  projection form of the step (sets free to move, slip directions free to
  turn), with the held-direction projected Newton step as its fallback,
  globalised by an Armijo line search with a gradient fallback;
- ``"newton-plain"`` (:mod:`.newton_plain`): the held-direction step with
  full steps only;
- ``"penalty"`` (:mod:`.penalty`): the wall as a penalty ρ, the friction
  kink smoothed over δ, Newton on the smooth energy: solves a nearby
  problem and reports the wall violation it leaves;
- ``"optimizer"`` (:mod:`.optimizer`): SciPy's L-BFGS-B on the energy.

"newton", "newton-plain" and "optimizer" solve the same discrete problem
and are judged by the same residual (:func:`.base.stationarity`).
"""

from . import newton, newton_plain, optimizer, penalty
from .base import (
    CONVERGED,
    DIVERGED,
    LINE_SEARCH_FAILED,
    MAX_ITERATIONS,
    OPTIMIZER_STOPPED,
    Kink,
    StepOptions,
    StepResult,
    stationarity,
)

#: solver.method -> the module whose ``minimise`` it calls
METHODS = {"newton": newton, "newton-plain": newton_plain, "penalty": penalty,
           "optimizer": optimizer}

#: the methods that solve the discrete problem itself (the wall exactly)
EXACT = ("newton", "newton-plain", "optimizer")


def minimise(method, S, c, energy, upper, z0, options, kink=None):
    """Solve a step with ``method`` (a key of :data:`METHODS`)."""
    return METHODS[method].minimise(S, c, energy, upper, z0, options, kink)


__all__ = ["METHODS", "EXACT", "minimise", "StepOptions", "StepResult", "Kink",
           "stationarity", "CONVERGED", "MAX_ITERATIONS", "LINE_SEARCH_FAILED", "DIVERGED",
           "OPTIMIZER_STOPPED"]
