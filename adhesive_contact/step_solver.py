"""The nonsmooth step solve of (4.1) on the contact unknowns.

With the interior condensed out (:mod:`adhesive_contact.linear`), a step
is the minimisation of MODEL.md §5 over the contact unknowns z,

    E(z) = ½ zᵀ S z − cᵀ z + Φ(z)   subject to  z_ν ≤ g  (the wall),

Φ(z) = Σ_q w_q [P_ν(β_q, (N z)_q) + j_τ(β_q, (T z)_q)] the contact terms
(:class:`ContactEnergy`). It is solved by a projected semismooth Newton
method (Bertsekas' two-metric projection for the bounds) with an Armijo
line search on E along the projection arc:

- the binding set A = {i : z_i ≥ g_i − ε_k, ∂_i E < 0} is held on the wall,
- on the rest F a Newton step H_FF d_F = −∇_F E with H = S + ∂²Φ (an
  element of the generalised Hessian at kinks),
- z(α) = min(z + α d, g), halving α until
  E(z(α)) ≤ E(z) + σ ∇E · (z(α) − z).

It stops when the projected gradient (∇E with the wall's pull removed on
the binding set) is below ``tol`` times the force scale of the step. The
wall multiplier λ_i = −∂_i E ≥ 0 on the binding set is the wall's reaction.
"""

from dataclasses import dataclass, field

import numpy as np
import scipy.linalg as la
import scipy.sparse as sp


class ContactEnergy:
    """Φ(z) = Σ_q w_q P_ν(β_q, (N z)_q) for the normal law of a step.

    Parameters
    ----------
    boundary : ContactBoundary
    normal_law : a law of :mod:`adhesive_contact.laws`
    beta : (nf,) the bonding β_n per contact facet
    """

    def __init__(self, boundary, normal_law, beta):
        self.N = boundary.normal_trace
        self.w = boundary.weights
        self.law = normal_law
        self.beta = boundary.at_points(beta)
        self.active = normal_law.active

    def value(self, z):
        if not self.active:
            return 0.0
        return float(self.w @ self.law.potential(self.beta, self.N @ z))

    def gradient(self, z):
        if not self.active:
            return np.zeros_like(z)
        return self.N.T @ (self.w * self.law.value(self.beta, self.N @ z))

    def hessian(self, z):
        """An element of the generalised Hessian, sparse (nz, nz)."""
        if not self.active:
            return None
        d = self.w * self.law.derivative(self.beta, self.N @ z)
        return (self.N.T @ sp.diags(d) @ self.N).tocsr()

    def normal_force(self, z):
        """Σ_q w_q p_ν at each contact unknown (the compliance reaction)."""
        return self.gradient(z)


@dataclass
class StepResult:
    """How a step solve ended (cf. scipy.optimize.OptimizeResult)."""

    z: np.ndarray
    success: bool
    message: str
    nit: int
    residual: float
    tolerance: float
    energy: float
    multiplier: np.ndarray = field(repr=False)   # wall reaction λ ≥ 0 per unknown
    on_wall: np.ndarray = field(repr=False)      # bool per unknown


def _newton_direction(H, g, free):
    """Solve H_FF d = −g_F; a modified Cholesky (eigenvalue floor) if H_FF
    is not positive definite."""
    HF = H[np.ix_(free, free)]
    try:
        return la.cho_solve(la.cho_factor(HF, check_finite=False), -g[free],
                            check_finite=False)
    except la.LinAlgError:
        vals, vecs = la.eigh(HF)
        floor = 1e-8 * max(np.abs(vals).max(), 1e-300)
        return vecs @ ((vecs.T @ -g[free]) / np.maximum(np.abs(vals), floor))


def minimise_step(S, c, energy, upper, z0, tol=1e-10, max_iter=50, sigma=1e-4):
    """Minimise ½ zᵀSz − cᵀz + Φ(z) subject to z ≤ upper.

    Parameters
    ----------
    S : (nz, nz) dense symmetric positive definite
    c : (nz,)
    energy : ContactEnergy (value, gradient, hessian)
    upper : (nz,) bounds, +inf where there is none
    z0 : (nz,) initial guess (projected onto the bounds)
    tol : relative tolerance on the projected gradient
    """
    z = np.minimum(z0, upper)
    bounded = np.isfinite(upper)

    def total(z):
        return 0.5 * z @ (S @ z) - c @ z + energy.value(z)

    E = total(z)
    residual, scale = np.inf, 1.0
    diag_S = np.maximum(np.diag(S), 1e-300) if S.size else np.zeros(0)
    for it in range(max_iter + 1):
        Sz = S @ z
        gphi = energy.gradient(z)
        g = Sz - c + gphi
        scale = max(np.abs(c).max(initial=0.0), np.abs(Sz).max(initial=0.0),
                    np.abs(gphi).max(initial=0.0), 1e-300)
        # projected-gradient step length in displacement units
        width = np.abs(z - np.minimum(z - g / diag_S, upper)).max(initial=0.0)
        binding = bounded & (z >= upper - width) & (g < 0)
        # only a coordinate exactly on the wall and pulled into it is stationary
        pg = np.where(bounded & (z >= upper) & (g < 0), 0.0, g)
        residual = np.abs(pg).max(initial=0.0)
        if residual <= tol * scale:
            on_wall = bounded & (z >= upper) & (g < 0)
            return StepResult(z, True, "converged", it, residual / scale, tol, E,
                              np.where(on_wall, -g, 0.0), on_wall)
        if it == max_iter:
            break
        H = S.copy()
        Hphi = energy.hessian(z)
        if Hphi is not None:
            H += Hphi.toarray()
        free = ~binding
        d = np.zeros_like(z)
        if free.any():
            d[free] = _newton_direction(H, g, free)
        d[binding] = -g[binding] / np.diag(H)[binding]
        alpha = 1.0
        for _ in range(60):
            trial = np.minimum(z + alpha * d, upper)
            E_trial = total(trial)
            if E_trial <= E + sigma * (g @ (trial - z)):
                break
            alpha *= 0.5
        else:
            return StepResult(z, False, "line search failed: no decrease of the energy "
                              "along the Newton direction", it, residual / scale, tol, E,
                              np.zeros_like(z), np.zeros_like(z, dtype=bool))
        z, E = trial, E_trial
    return StepResult(z, False, f"no convergence in {max_iter} iterations", max_iter,
                      residual / scale, tol, E, np.zeros_like(z),
                      np.zeros_like(z, dtype=bool))
