"""Step method "optimizer": the approach of the hemivariational literature,
a general-purpose bound-constrained minimiser applied to the condensed
step energy

    E(z) = ½ zᵀ S z − cᵀ z + Φ(z)   subject to  z_ν ≤ g,

here SciPy's L-BFGS-B (bounds handled by its projected quasi-Newton
iteration). It is handed E and ∇E where E is differentiable; at a node
with ξ_a = 0 exactly, the minimal-norm subgradient of the kink. L-BFGS-B
assumes a smooth energy: at a node that sticks (ξ_a = 0 at the solution)
its iterates hover around the kink and its line search usually gives up.
Whatever L-BFGS-B says, the result is judged by the same pseudo-gradient
as "newton" (:func:`~.base.stationarity`): converged only if it is below
``tol`` times the force scale of the step, else OPTIMIZER_STOPPED with
L-BFGS-B's own message. L-BFGS-B itself stops when its projected gradient
is below ``tol`` times the force scale of the starting point. It runs at most ``OPTIMIZER_ITERATIONS ·
max_iter`` iterations (one energy and gradient evaluation each, plus the
line search's).
"""

import numpy as np
from scipy.optimize import minimize

from .base import (
    CONVERGED,
    MESSAGES,
    OPTIMIZER_ITERATIONS,
    OPTIMIZER_STOPPED,
    StepResult,
    kink_subgradient,
    no_kink,
    stationarity,
)


def minimise(S, c, energy, upper, z0, options, kink=None):
    """The step method interface (:mod:`adhesive_contact.step_methods`)."""
    kink = kink if kink is not None else no_kink()
    tan = kink.tangential

    def fun(z):
        Sz = S @ z
        E = 0.5 * z @ Sz - c @ z + energy.value(z)
        g = Sz - c + energy.gradient(z)
        if tan.size:
            # the kink's subgradient of minimal norm where ξ_a = 0
            xi = kink.xi(z)
            zero = ~np.any(xi != 0, axis=1)
            if zero.any():
                kink.put(g, zero, kink_subgradient(kink.take(g), kink.radius))
        return E, g

    bounds = [(None, None if not np.isfinite(b) else float(b)) for b in upper]
    z_start = np.minimum(z0, upper)
    # L-BFGS-B's own stop: its projected gradient below tol times the force
    # scale of the start (the pseudo-gradient judges the result afterwards)
    start = stationarity(S, c, energy, upper, z_start, kink)
    out = minimize(fun, z_start, jac=True, method="L-BFGS-B", bounds=bounds,
                   options={"maxiter": OPTIMIZER_ITERATIONS * options.max_iter,
                            "maxfun": 2 * OPTIMIZER_ITERATIONS * options.max_iter,
                            "ftol": 0.0, "gtol": options.tol * start.scale, "maxcor": 20})
    z = np.minimum(out.x, upper)
    st = stationarity(S, c, energy, upper, z, kink)
    if st.residual <= options.tol * st.scale:
        status, message = CONVERGED, MESSAGES[CONVERGED]
    else:
        detail = out.message if isinstance(out.message, str) else out.message.decode()
        status = OPTIMIZER_STOPPED
        message = MESSAGES[OPTIMIZER_STOPPED].format(detail=f"L-BFGS-B: {detail}")
    return StepResult(z=z, status=status, message=message, nit=int(out.nit),
                      residual=st.residual / st.scale, tolerance=options.tol,
                      energy=float(out.fun), multiplier=np.where(st.wall, -st.g, 0.0),
                      on_wall=st.wall, stuck=st.at_zero)
