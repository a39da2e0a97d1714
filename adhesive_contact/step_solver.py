"""The nonsmooth step solve of (4.1) on the contact unknowns.

With the interior condensed out (:mod:`adhesive_contact.linear`), a step
minimises the energy of MODEL.md §5 over the contact unknowns z,

    E(z) = ½ zᵀ S z − cᵀ z + Φ(z)   subject to  z_ν ≤ g  (the wall),

with Φ the contact terms (:class:`~adhesive_contact.contact_energy.ContactEnergy`).
Friction laws with a kink at ξ = 0 (Tresca, slip weakening) add, at each
contact node a, a term with Clarke subdifferential B(0, κ_a) at ξ_a = 0.

The method is a projected semismooth Newton iteration with an Armijo line
search on E, combining Bertsekas' two-metric projection for the wall with
the orthant-wise treatment of the kink (as in OWL-QN):

- the binding set: z_i within ε of the wall and ∂_i E < 0 — moved onto it
  and held there;
- the stick set: |ξ_a| ≤ ε and |h_a| ≤ κ_a, h_a the gradient without the
  kink — ξ_a is set to 0 and held there;
- every other node slips with its direction ê_a = ξ_a/|ξ_a| held for the
  step (or, at ξ_a = 0, ê_a = −(pseudo-gradient)): a trial ξ_a that turns
  against ê_a is put to 0, so the sign of ξ/|ξ| cannot flip inside a step;
- on the free coordinates a Newton step with H = S + ∂²Φ (a modified
  Cholesky when H is indefinite, e.g. under strong slip weakening),
  coupled to the fixed coordinates' moves; should its line search fail
  (a nonconvex energy far from the solution), the scaled projected
  gradient instead;
- z(α) projected as above, α halved until
  E(z(α)) ≤ E(z) + σ E'(z; z(α) − z) (up to the round-off of E, so that
  the full step is taken once the decrease is below what E can resolve).

It stops when the pseudo-gradient (the minimal-norm element of
∂E + normal cone of the wall) is below ``tol`` times the force scale of
the step, and returns the wall multipliers λ = −∂_ν E ≥ 0 on the wall.
"""

from dataclasses import dataclass, field

import numpy as np
import scipy.linalg as la


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
    stuck: np.ndarray = field(repr=False)        # bool per node with a kink (ξ_a = 0)


@dataclass
class Kink:
    """The nodes whose friction has a kink: their tangential unknowns and κ_a."""

    tangential: np.ndarray   # (na, m) indices into z
    radius: np.ndarray       # (na,) κ_a ≥ 0


def _solve_free(H, rhs, free):
    """Solve H_FF d = rhs; a modified Cholesky (|eigenvalues|, floored) when
    H_FF is not positive definite."""
    return _factor(H[np.ix_(free, free)])(rhs)


def _factor(HF):
    """A solver for the dense symmetric HF: Cholesky, or |eigenvalues| floored."""
    try:
        factor = la.cho_factor(HF, check_finite=False)
        return lambda rhs: la.cho_solve(factor, rhs, check_finite=False)
    except la.LinAlgError:
        vals, vecs = la.eigh(HF)
        vals = np.maximum(np.abs(vals), 1e-8 * max(np.abs(vals).max(), 1e-300))
        return lambda rhs: vecs @ ((vecs.T @ rhs) / vals)


def _solve_free_implicit(S, Hphi, rhs, free, tol=1e-12, max_iter=100):
    """Solve (S + Hphi)_FF d = rhs by CG with S applied (ImplicitSchur),
    preconditioned by (S.approximation + Hphi)_FF."""
    Hphi_FF = Hphi[np.ix_(free, free)]
    precondition = _factor(S.approximation[np.ix_(free, free)] + Hphi_FF)
    full = np.zeros(S.shape[0])

    def apply(v):
        full[free] = v
        return (S @ full)[free] + Hphi_FF @ v

    d = np.zeros(rhs.size)
    r = rhs.copy()
    z = precondition(r)
    p = z.copy()
    rz = r @ z
    stop = tol * np.linalg.norm(rhs)
    for _ in range(max_iter):
        if np.linalg.norm(r) <= stop:
            break
        Ap = apply(p)
        alpha = rz / (p @ Ap)
        d += alpha * p
        r -= alpha * Ap
        z = precondition(r)
        rz, rz_old = r @ z, rz
        p = z + (rz / rz_old) * p
    return d


def _blocks(v, idx):
    return v[idx] if idx.size else np.zeros((0, 0))


def minimise_step(S, c, energy, upper, z0, tol=1e-10, max_iter=50, kink=None, sigma=1e-4):
    """Minimise ½ zᵀSz − cᵀz + Φ(z) subject to z ≤ upper (see module doc).

    Parameters
    ----------
    S : (nz, nz) dense symmetric positive definite, or an ImplicitSchur
        (applied only; Newton systems then by CG preconditioned with its
        dense approximation)
    c : (nz,)
    energy : ContactEnergy
    upper : (nz,) bounds, +inf where there is none
    z0 : (nz,) initial guess
    tol : relative tolerance on the pseudo-gradient
    kink : Kink or None
    """
    nz = c.size
    bounded = np.isfinite(upper)
    if kink is None:
        kink = Kink(np.zeros((0, 1), dtype=np.int64), np.zeros(0))
    tan, kappa = kink.tangential, kink.radius

    def total(z):
        return 0.5 * z @ (S @ z) - c @ z + energy.value(z)

    def noise(z):
        # round-off of E: below it an energy comparison says nothing
        return 1e-13 * (0.5 * abs(z @ (S @ z)) + abs(c @ z) + abs(energy.value(z)) + 1e-300)

    z = np.minimum(z0, upper)
    E = total(z)
    implicit = hasattr(S, "approximation")
    dense_S = S.approximation if implicit else S
    diag_S = np.maximum(np.diag(dense_S), 1e-300) if nz else np.zeros(0)
    residual, scale = np.inf, 1.0
    stuck = np.zeros(kappa.size, dtype=bool)
    for it in range(max_iter + 1):
        Sz = S @ z
        gphi = energy.gradient(z)
        g = Sz - c + gphi                     # ∇E where E is differentiable
        xi = _blocks(z, tan)
        s = np.linalg.norm(xi, axis=1)
        at_zero = s == 0
        unit = np.where(at_zero[:, None], 0.0, xi / np.where(at_zero, 1.0, s)[:, None])
        h = _blocks(g, tan) - kappa[:, None] * unit   # gradient without the kink
        hn = np.linalg.norm(h, axis=1)

        # pseudo-gradient: minimal-norm element of ∂E + N_wall
        pg = g.copy()
        wall = bounded & (z >= upper) & (g < 0)
        pg[wall] = 0.0
        if tan.size:
            slide = np.where(hn > kappa, 1.0 - kappa / np.where(hn > 0, hn, 1.0), 0.0)
            pg[tan[at_zero]] = (h * slide[:, None])[at_zero]
        scale = max(np.abs(c).max(initial=0.0), np.abs(Sz).max(initial=0.0),
                    np.abs(gphi).max(initial=0.0), kappa.max(initial=0.0), 1e-300)
        residual = np.abs(pg).max(initial=0.0)
        if residual <= tol * scale:
            return StepResult(z, True, "converged", it, residual / scale, tol, E,
                              np.where(wall, -g, 0.0), wall, at_zero)
        if it == max_iter:
            break

        # identify the sets with a projected-gradient step length ε
        width = np.abs(z - np.minimum(z - pg / np.where(diag_S > 0, diag_S, 1.0),
                                      upper)).max(initial=0.0)
        binding = bounded & (z >= upper - width) & (g < 0)
        stuck = (s <= width) & (hn <= kappa) if tan.size else stuck
        fixed = binding.copy()
        d = np.zeros(nz)
        if tan.size:
            fixed[tan[stuck]] = True
            d[tan[stuck]] = -xi[stuck]
        zmax = np.abs(z).max(initial=0.0)
        Hphi = energy.hessian(z, s_floor=1e-12 + 1e-8 * zmax).toarray()
        d[binding] = upper[binding] - z[binding]   # onto the wall
        free = ~fixed
        if free.any() and implicit:
            rhs = -pg[free] - ((S @ np.where(fixed, d, 0.0))[free]
                               + Hphi[np.ix_(free, fixed)] @ d[fixed])
            d[free] = _solve_free_implicit(S, Hphi, rhs, np.flatnonzero(free))
        elif free.any():
            H = S + Hphi
            rhs = -pg[free] - H[np.ix_(free, fixed)] @ d[fixed]
            d[free] = _solve_free(H, rhs, free)

        # slipping directions held for this step
        ref = unit.copy()
        if tan.size:
            start = at_zero & ~stuck
            ref[start] = -pg[tan[start]] / np.maximum(
                np.linalg.norm(pg[tan[start]], axis=1), 1e-300)[:, None]

        def project(trial):
            trial = np.minimum(trial, upper)
            if tan.size:
                txi = trial[tan]
                turned = np.sum(txi * ref, axis=1) <= 0   # stuck nodes reach 0 at α = 1
                txi[turned] = 0.0
                trial[tan] = txi
            return trial

        def slope(step):
            # E'(z; step): the kink adds κ |Δξ| at nodes where ξ = 0
            out = g @ step
            if tan.size:
                out += kappa[at_zero] @ np.linalg.norm(step[tan[at_zero]], axis=1)
            return out

        # the Newton direction, else (nonconvex energy, far from the
        # solution) the scaled projected gradient, which always descends
        slack = noise(z)
        gradient_step = -pg / np.where(diag_S > 0, diag_S, 1.0)
        if tan.size:
            gradient_step[tan[stuck]] = -xi[stuck]
        found = False
        for direction in (d, gradient_step):
            alpha = 1.0
            for _ in range(60):
                trial = project(z + alpha * direction)
                E_trial = total(trial)
                if E_trial <= E + sigma * slope(trial - z) + slack:
                    found = True
                    break
                alpha *= 0.5
            if found:
                break
        if not found:
            return StepResult(z, False, "line search failed: no decrease of the energy "
                              "along the Newton or the gradient direction", it,
                              residual / scale, tol, E, np.zeros(nz),
                              np.zeros(nz, dtype=bool), stuck)
        z, E = trial, E_trial
    return StepResult(z, False, f"no convergence in {max_iter} iterations", max_iter,
                      residual / scale, tol, E, np.zeros(nz), np.zeros(nz, dtype=bool), stuck)
