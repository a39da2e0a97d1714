"""Step method "penalty": the wall as a penalty and the friction kink
smoothed, so that the step energy is once differentiable and Newton's
method applies without any projection:

    E_ρ,δ(z) = ½ zᵀ S z − cᵀ z + Σ_q w_q [P_ν(β_q, (N z)_q) + φ(β_q, s_δ(|(T z)_q|))]
               + ½ ρ Σ_i (z_i − g_i)_+²,

    s_δ(s) = √(s² + δ²) − δ   (s_δ(0) = 0, s_δ'(0) = 0, s_δ(s) → s − δ),

with the penalty on the normal unknowns that have a wall. The method
solves a nearby problem: it leaves the wall violation max (z_ν − g)_+ ≈
λ/ρ (reported in the result; the exact methods project onto the wall and
leave none) and replaces the friction bound near ξ = 0 by a steep spring
of stiffness ≈ κ/δ. Newton's direction on the free gradient system
(S + ∂²Φ_δ + ρ D) d = −∇E_ρ,δ, with D the indicator of the violated
bounds and the indefinite case floored as in "newton", is safeguarded by
an Armijo line search on E_ρ,δ (and, should it fail, the scaled gradient).
It stops when |∇E_ρ,δ|_∞ ≤ tol times the force scale of the step.

The caller sets ρ and δ (:class:`~.base.StepOptions`); the scene's
``solver.penalty`` and ``solver.smoothing`` are relative to the stiffness
and to the size of the body (:mod:`adhesive_contact.scheme.state`).
"""

import numpy as np
import scipy.sparse as sp

from .base import (
    CONVERGED,
    LINE_SEARCH_FAILED,
    MAX_ITERATIONS,
    MESSAGES,
    StepResult,
    backtrack,
    no_kink,
)


class SmoothedContact:
    """Φ_δ (the friction kink rounded) plus the wall penalty, as one smooth
    function of z: ``value``, ``gradient``, ``hessian`` (sparse)."""

    def __init__(self, energy, upper, rho, delta):
        self.energy, self.upper, self.rho, self.delta = energy, upper, rho, delta
        self.bounded = np.isfinite(upper)
        self.bound = np.where(self.bounded, upper, 0.0)

    def _violation(self, z):
        return np.where(self.bounded, np.maximum(z - self.bound, 0.0), 0.0)

    def _friction(self, z):
        xi = self.energy.tangential(z)
        s = np.linalg.norm(xi, axis=-1)
        r = np.sqrt(s * s + self.delta * self.delta)
        return xi, s, r, r - self.delta

    def _normal(self, z):
        return self.energy.normal(z)

    def value(self, z):
        e, out = self.energy, 0.0
        if e.normal_law.active:
            out += e.w @ e.normal_law.potential(e.beta, self._normal(z))
        if e.friction is not None:
            _, _, _, sd = self._friction(z)
            out += e.w @ e.friction.phi(e.beta, sd)
        v = self._violation(z)
        return float(out + 0.5 * self.rho * (v @ v))

    def gradient(self, z):
        e = self.energy
        g = self.rho * self._violation(z)
        if e.normal_law.active:
            g += e.N.T @ (e.w * e.normal_law.value(e.beta, self._normal(z)))
        if e.friction is not None:
            xi, _, r, sd = self._friction(z)
            force = (e.w * e.friction.dphi(e.beta, sd) / r)[:, None] * xi
            for i, t in enumerate(e.T):
                g += t.T @ force[:, i]
        return g

    def hessian(self, z):
        """∂²: P_ν'' N ᵀN + Σ Tᵢᵀ [φ''(s_δ) ξξᵀ/r² + φ'(s_δ)(I/r − ξξᵀ/r³)]_ij Tⱼ + ρ D,
        r = √(|ξ|² + δ²)."""
        e = self.energy
        H = sp.diags(self.rho * (self._violation(z) > 0).astype(float))
        if e.normal_law.active:
            H = H + e.N.T @ sp.diags(e.w * e.normal_law.derivative(e.beta, self._normal(z))) @ e.N
        if e.friction is not None:
            xi, _, r, sd = self._friction(z)
            m = xi.shape[1]
            ee = xi[:, :, None] * xi[:, None, :] / (r * r)[:, None, None]
            dphi, ddphi = e.friction.dphi(e.beta, sd), e.friction.ddphi(e.beta, sd)
            blocks = (ddphi[:, None, None] * ee
                      + (dphi / r)[:, None, None] * (np.eye(m) - ee))
            for i, ti in enumerate(e.T):
                for j, tj in enumerate(e.T):
                    H = H + ti.T @ sp.diags(e.w * blocks[:, i, j]) @ tj
        return sp.csr_matrix(H)


def minimise(S, c, energy, upper, z0, options, kink=None, sigma=1e-4):
    """Minimise E_ρ,δ (see module doc) from z0 by Newton with line search;
    ρ = ``options.penalty``, δ = ``options.smoothing``."""
    kink = kink if kink is not None else no_kink()
    nz = c.size
    phi = SmoothedContact(energy, upper, options.penalty, options.smoothing)
    free = np.ones(nz, dtype=bool)
    diag = np.maximum(S.diagonal(), 1e-300) if nz else np.zeros(0)

    def total(z):
        return 0.5 * z @ (S @ z) - c @ z + phi.value(z)

    z = np.array(z0, dtype=float)
    E = total(z)
    inner_failures, status = 0, None
    for it in range(options.max_iter + 1):
        Sz = S @ z
        gphi = phi.gradient(z)
        g = Sz - c + gphi
        scale = max(np.abs(c).max(initial=0.0), np.abs(Sz).max(initial=0.0),
                    np.abs(gphi).max(initial=0.0), kink.radius.max(initial=0.0), 1e-300)
        residual = np.abs(g).max(initial=0.0)
        if residual <= options.tol * scale:
            status = CONVERGED
            break
        if it == options.max_iter:
            status = MAX_ITERATIONS
            break
        d, converged = S.newton_solve(phi.hessian(z), -g, free)
        inner_failures += not converged
        slack = 1e-13 * (abs(E) + 0.5 * abs(z @ Sz) + abs(c @ z) + 1e-300)
        def bound(direction, trial, alpha):
            slope = g @ direction
            return E + sigma * alpha * slope + slack if slope < 0 else None

        accepted = backtrack((d, -g / diag), lambda dz, a: z + a * dz, total, bound)
        if accepted is None:
            status = LINE_SEARCH_FAILED
            break
        z, E = accepted
    violation = phi._violation(z)
    s = np.linalg.norm(kink.xi(z), axis=1) if kink.tangential.size else np.zeros(0)
    message = MESSAGES[status].format(max_iter=options.max_iter, nit=it)
    if inner_failures:
        message += f" ({inner_failures} Newton systems solved inexactly)"
    return StepResult(z=z, status=status, message=message, nit=it,
                      residual=residual / scale, tolerance=options.tol, energy=E,
                      inner_failures=inner_failures, multiplier=options.penalty * violation,
                      on_wall=violation > 0, stuck=s <= options.smoothing,
                      wall_violation=float(violation.max(initial=0.0)))
