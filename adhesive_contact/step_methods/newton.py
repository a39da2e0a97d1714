"""Step method "newton" (the default): the globalised projected
semismooth Newton method for the step of (4.1) on the contact unknowns.

With the interior condensed out (:mod:`adhesive_contact.scheme.condensed`), a step
minimises the energy of docs/scheme.md ('What a step solves') over the contact unknowns z,

    E(z) = ½ zᵀ S z − cᵀ z + Φ(z)   subject to  z_ν ≤ g  (the wall),

with Φ the contact terms (:class:`~adhesive_contact.scheme.contact_energy.ContactEnergy`).
Friction laws with a kink at ξ = 0 (Tresca, slip weakening) add, at each
contact node a, a term with Clarke subdifferential B(0, κ_a) at ξ_a = 0.

Each iteration first tries the semismooth Newton step of
:func:`semismooth_step` on the projection form of the optimality
conditions (the min function for the wall, the shrink operator for the
kink), whose sets follow the iterate coordinate by coordinate and whose
slip directions may turn inside a step; its trial points must pass the
same Armijo test. After a full semismooth step whose sets the new iterate
keeps, :func:`chord_step` solves the Newton equations at the new iterate
with the same matrix, its factorisation reused (a simplified Newton
step, part of the same iteration: ``nit`` counts the Newton matrices);
it is kept where it divides the residual by 1/CHORD_GAIN. A solve starts
with the same step on the last Newton system its operator S keeps
(``S.chord_start``, from the previous solve with S). When no
semismooth trial passes, the iteration is the held-direction
one below (and "newton-plain" uses only that one): a projected semismooth
Newton iteration with an Armijo line
search on E, combining Bertsekas' two-metric projection for the wall with
the orthant-wise treatment of the kink (as in OWL-QN):

- the binding set: z_i within ε of the wall and ∂_i E < 0 — moved onto it
  and held there;
- the stick set: |ξ_a| ≤ ε and |h_a| ≤ κ_a, h_a the gradient without the
  kink — ξ_a is set to 0 and held there;
- every other node slips with its direction ê_a = ξ_a/|ξ_a| held for the
  step (or, at ξ_a = 0, ê_a = −(pseudo-gradient), and the Newton step of
  such a node is projected onto the ray along ê_a): a trial ξ_a that turns
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
∂E + normal cone of the wall, :func:`~.base.stationarity`) is below
``tol`` times the force scale of the step, and returns the wall
multipliers λ = −∂_ν E ≥ 0 on the wall.

With ``globalised=False`` (method "newton-plain",
:mod:`.newton_plain`) every step is the full projected Newton step: no
line search and no gradient fallback, what many codes do; it stops as
DIVERGED when the energy or the iterate stops being finite or the iterate
grows past 1e8 times the size of the first one.
"""

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from .base import (
    CONVERGED,
    DIVERGED,
    LINE_SEARCH_FAILED,
    MAX_ITERATIONS,
    MESSAGES,
    Kink,
    StepResult,
    backtrack,
    no_kink,
    stationarity,
)

__all__ = ["minimise", "minimise_step", "ProjectedNewton", "StepResult", "Kink", "CONVERGED",
           "MAX_ITERATIONS", "LINE_SEARCH_FAILED", "DIVERGED"]


def minimise(S, c, energy, upper, z0, options, kink=None):
    """The step method interface (:mod:`adhesive_contact.step_methods`)."""
    return minimise_step(S, c, energy, upper, z0, options.tol, options.max_iter, kink)


def minimise_step(S, c, energy, upper, z0, tol=1e-10, max_iter=50, kink=None, sigma=1e-4,
                  globalised=True, semismooth=None):
    """Minimise ½ zᵀSz − cᵀz + Φ(z) subject to z ≤ upper (see module doc):
    :meth:`ProjectedNewton.minimise` from ``z0``.

    Parameters
    ----------
    S : the condensed step matrix, a
        :class:`~adhesive_contact.scheme.condensed.DenseSchur` or
        :class:`~adhesive_contact.scheme.condensed.ImplicitSchur`, or the
        step matrix on all free dofs,
        :class:`~adhesive_contact.scheme.full_system.FullSystemMatrix`
        (``S @ z``, ``diagonal()``, ``newton_solve``; the contact unknowns
        are then ``energy.unknowns`` among z)
    c : (nz,)
    energy : ContactEnergy
    upper : (nz,) bounds, +inf where there is none
    z0 : (nz,) initial guess
    tol : relative tolerance on the pseudo-gradient
    kink : Kink or None
    globalised : False for the full projected Newton step every iteration
        (no line search, no gradient fallback)
    semismooth : try the semismooth Newton step of :func:`semismooth_step`
        first at every iteration (default: when ``globalised``)
    """
    return ProjectedNewton(S, c, energy, upper, tol, max_iter, kink, sigma, globalised,
                           semismooth).minimise(z0)


class ProjectedNewton:
    """One step solve by the Newton strategies of the module docstring,
    each a method: :meth:`chord` (a chord step on the last Newton matrix),
    :meth:`semismooth` (the semismooth step on the projection form, its
    sets free), :meth:`held_direction` (sets and slip directions held for
    the step, with an Armijo line search or, unglobalised, the full step);
    :meth:`minimise` tries them in that order each iteration."""

    def __init__(self, S, c, energy, upper, tol=1e-10, max_iter=50, kink=None, sigma=1e-4,
                 globalised=True, semismooth=None):
        self.S, self.c, self.energy, self.upper = S, c, energy, upper
        self.tol, self.max_iter, self.sigma, self.globalised = tol, max_iter, sigma, globalised
        self.semismooth_first = globalised if semismooth is None else semismooth
        self.kink = no_kink() if kink is None else kink
        self.bounded = np.isfinite(upper)
        nz = c.size
        self.diag_S = np.maximum(S.diagonal(), 1e-300) if nz else np.zeros(0)
        # the contact unknowns among z (all of z, but for the full system of
        # adhesive_contact.scheme.full_system, whose other entries are interior dofs)
        self.contact = energy.unknowns
        self.here = {}
        self.first_size = None   # the unglobalised method's first iterate size

    # -- the step energy E and its round-off

    def anchor(self, z, E, Sz):
        """Measure trial energies from the iterate z from now on (:meth:`total`)."""
        self.here.update(z=z, E=E, g=Sz - self.c, phi=self.energy.value(z))

    def total(self, trial):
        """E at a trial point as E(z) plus its change from the iterate z,
        (Sz − c)·Δ + ½ Δ·SΔ + Φ(z + Δ) − Φ(z): ½ zᵀSz − cᵀz itself is a
        difference of large terms when the body has moved far (|S||z|² ≫
        |E|), whose round-off would hide the decrease of a last Newton step."""
        S, c, here = self.S, self.c, self.here
        if not here:
            return 0.5 * trial @ (S @ trial) - c @ trial + self.energy.value(trial)
        step = trial - here["z"]
        return (here["E"] + here["g"] @ step + 0.5 * step @ (S @ step)
                + (self.energy.value(trial) - here["phi"]))

    def noise(self, z, Sz):
        """The round-off of E at z: below it an energy comparison says nothing."""
        return 1e-13 * (0.5 * abs(z @ Sz) + abs(self.c @ z) + abs(self.energy.value(z))
                        + 1e-300)

    # -- the iteration

    def minimise(self, z0):
        """The iterations from ``z0`` until the pseudo-gradient is below
        ``tol`` times the force scale: a :class:`StepResult`."""
        S, tol, max_iter = self.S, self.tol, self.max_iter
        z = np.minimum(z0, self.upper)
        E = self.total(z)
        self.inner_failures = 0
        last_residual = None
        it = 0   # Newton iterations (a chord step is part of the one before it)
        # a chord step on the last Newton system of S first (that of the last
        # solve with S: the previous level's, or the previous proximal step's
        # at t = 0), where S keeps one
        chord = getattr(S, "chord_start", None) if self.semismooth_first else None
        before_chord = None
        while True:
            st = stationarity(S, self.c, self.energy, self.upper, z, self.kink)
            if before_chord is not None:
                # a chord step is kept where it cut the residual CHORD_GAIN-fold
                # (the superlinear regime it is for), else its start is
                if st.residual > CHORD_GAIN * before_chord[2].residual >= tol * st.scale:
                    z, E, st = before_chord
                before_chord = None
            self.anchor(z, E, st.Sz)
            residual, scale = st.residual, st.scale
            status = (CONVERGED if residual <= tol * scale else
                      MAX_ITERATIONS if it == max_iter and chord is None else None)
            if status is not None:
                break
            forcing = (min(eisenstat_walker(residual, last_residual), residual / scale)
                       if self.globalised else 1e-12)
            accuracy = (forcing, 0.5 * tol * scale)
            if chord is not None:
                accepted, chord = self.chord(z, E, st, chord, accuracy), None
                if accepted is not None:
                    before_chord = (z, E, st)
                    z, E = accepted
                    continue
                if it == max_iter:
                    status = MAX_ITERATIONS
                    break
            if self.semismooth_first:
                accepted, chord = self.semismooth(z, E, st, accuracy)
                if accepted is not None:
                    z, E = accepted
                    last_residual = residual
                    it += 1
                    continue
            it += 1
            status, z, E = self.held_direction(z, E, st, accuracy, it)
            last_residual = residual
            if status is not None:
                break
        return self.result(z, E, st, status, it)

    def result(self, z, E, st, status, it):
        """The StepResult of the last iterate z: its wall multipliers and sets."""
        message = MESSAGES[status].format(max_iter=self.max_iter, nit=it)
        if self.inner_failures:
            message += f" ({self.inner_failures} Newton systems solved inexactly)"
        return StepResult(z=z, status=status, message=message, nit=it,
                          residual=st.residual / st.scale, tolerance=self.tol, energy=E,
                          inner_failures=self.inner_failures,
                          multiplier=np.where(st.wall, -st.g, 0.0), on_wall=st.wall,
                          stuck=st.at_zero)

    # -- the strategies

    def chord(self, z, E, st, chord, accuracy):
        """A chord step on the last Newton matrix (:func:`chord_step`),
        counted with its iteration: (z, E) or None."""
        return chord_step(self.S, self.upper, z, E, st, self.kink, chord, accuracy,
                          self.total, self.noise(z, st.Sz), self.sigma)

    def semismooth(self, z, E, st, accuracy):
        """The semismooth Newton step, its sets free to change
        (:func:`semismooth_step`): ((z, E) or None when its line search
        fails, the chord data of a full step or None)."""
        S = self.S
        accepted, solved, chord = semismooth_step(S, self.energy, self.upper, z, E, st,
                                                  self.kink, accuracy, self.total,
                                                  self.noise(z, st.Sz), self.sigma)
        self.inner_failures += not solved
        if chord is not None and hasattr(S, "chord_start"):
            S.chord_start = chord   # for the next solve with S too
        return accepted, chord

    def held_direction(self, z, E, st, accuracy, it):
        """One iteration with the sets identified by a projected-gradient
        step length ε and the slip directions held: (status or None, z, E)."""
        d, stuck = self.held_newton_direction(z, st, accuracy)
        ref = self.held_slip_directions(d, st, stuck)
        if not self.globalised:
            return self.full_step(z, E, d, ref, it)
        kink, pg, diag_S = self.kink, st.pg, self.diag_S
        gradient_step = -pg / np.where(diag_S > 0, diag_S, 1.0)
        if kink.tangential.size:
            kink.put(gradient_step, stuck, -st.xi)
        slack = self.noise(z, st.Sz)
        # the Newton direction, else (nonconvex energy, far from the
        # solution) the scaled projected gradient, which always descends
        accepted = backtrack((d, gradient_step),
                             lambda dz, a: self.project(z + a * dz, ref), self.total,
                             lambda dz, trial, a: E + self.sigma * self.slope(trial - z, st)
                             + slack)
        if accepted is None:
            return LINE_SEARCH_FAILED, z, E
        return None, *accepted

    def held_newton_direction(self, z, st, accuracy):
        """The Newton direction with the binding set moved onto the wall and
        the stick set put at ξ = 0 and held: (d, stuck)."""
        S, kink, upper = self.S, self.kink, self.upper
        tan, kappa, contact = kink.tangential, kink.radius, self.contact
        g, xi, s, hn, pg = st.g, st.xi, st.s, st.hn, st.pg
        zc = z[contact]
        width = np.abs(zc - np.minimum(zc - pg[contact] / self.diag_S[contact],
                                       upper[contact])).max(initial=0.0)
        binding = self.bounded & (z >= upper - width) & (g < 0)
        stuck = (s <= width) & (hn <= kappa)
        fixed = binding.copy()
        d = np.zeros(self.c.size)
        if tan.size:
            kink.put(fixed, stuck, True)
            kink.put(d, stuck, -xi)
        zmax = np.abs(zc).max(initial=0.0)
        Hphi = self.energy.hessian(z, s_floor=1e-12 + 1e-8 * zmax)   # sparse, nodal blocks
        d[binding] = upper[binding] - z[binding]   # onto the wall
        free = ~fixed
        if free.any():
            moved = np.where(fixed, d, 0.0)
            rhs = -pg[free] - ((S @ moved)[free] + (Hphi @ moved)[free])
            # inexact directions need the line search: full steps get exact ones
            d[free], converged = S.newton_solve(Hphi, rhs, free, accuracy=accuracy)
            self.inner_failures += not converged
        return d, stuck

    def held_slip_directions(self, d, st, stuck):
        """The slip directions held for this step (the unit slips, and
        −(pseudo-gradient) at a node leaving ξ = 0, whose part of d is
        put along it): ``ref`` (nkink, d − 1)."""
        kink = self.kink
        ref = st.unit.copy()
        if kink.tangential.size:
            start = st.at_zero & ~stuck
            pg_tan = kink.take(st.pg)[start]
            ref[start] = -pg_tan / np.maximum(np.linalg.norm(pg_tan, axis=1), 1e-300)[:, None]
            # a node leaving ξ = 0 moves along its held direction only: the
            # coupled Newton step may point it elsewhere (in 3D), and a slip
            # off the direction of −h meets a friction force of size κ_a in
            # the wrong direction; the next step turns it back to 0, and
            # with a flat energy the two iterates alternate for ever
            along = np.maximum(np.sum(kink.take(d) * ref, axis=1), 0.0)
            kink.put(d, start, along[:, None] * ref)
        return ref

    def project(self, trial, ref):
        """A trial point onto the wall, and a node whose ξ turned against its
        held direction ``ref`` to ξ = 0 (stuck nodes reach 0 at α = 1)."""
        kink = self.kink
        trial = np.minimum(trial, self.upper)
        if kink.tangential.size:
            turned = np.sum(kink.xi(trial) * ref, axis=1) <= 0
            kink.put(trial, turned, 0.0)
        return trial

    def slope(self, step, st):
        """E'(z; step): the kink adds κ |Δξ| at nodes where ξ = 0."""
        kink = self.kink
        out = st.g @ step
        if kink.tangential.size:
            out += kink.radius[st.at_zero] @ np.linalg.norm(kink.take(step)[st.at_zero], axis=1)
        return out

    def full_step(self, z, E, d, ref, it):
        """The unglobalised iteration ("newton-plain"): the full projected
        step, DIVERGED when E or the iterate stops being finite or the
        iterate grows past 1e8 times the size of the first one."""
        trial = self.project(z + d, ref)
        E_trial = self.total(trial)
        size = np.abs(trial).max(initial=0.0)
        if it == 1:
            self.first_size = max(size, np.abs(z).max(initial=0.0), 1e-300)
        if not (np.isfinite(E_trial) and np.all(np.isfinite(trial))
                and size <= 1e8 * self.first_size):
            return DIVERGED, z, E
        return None, trial, E_trial


@dataclass
class ProjectionForm:
    """The semismooth Newton system of :func:`semismooth_step` at one
    iterate: its sets, the moves of the held coordinates, the right-hand
    side and the cone's curvature across ŵ at the slipping nodes (3D)."""

    wall: np.ndarray      # bool per coordinate: put on the wall
    stick: np.ndarray     # bool per node with a kink: put at ξ = 0
    fixed: np.ndarray     # bool per coordinate: wall or stick
    d: np.ndarray         # the held coordinates' moves (0 elsewhere)
    rhs: np.ndarray       # −∇F, and −J⁻¹(h_a + κ_a ŵ_a) at the slipping nodes
    across: object        # sparse curvature κ_a/(|w_a| − γ_aκ_a)(I − ŵŵᵀ), or None


def projection_form(z, st, upper, gamma, kink, floor):
    """The sets and the Newton equations of the projection form at z (see
    :func:`semismooth_step`), with the step lengths ``gamma``."""
    tan, kappa = kink.tangential, kink.radius
    g = st.g
    wall = np.isfinite(upper) & (z - gamma * g >= upper)
    d = np.zeros(z.size)
    d[wall] = upper[wall] - z[wall]
    fixed = wall.copy()
    rhs = -g
    stick = np.zeros(tan.shape[0], dtype=bool)
    across = None
    if tan.size:
        xi, h = st.xi, st.h
        m = tan.shape[1]
        step = gamma[tan].min(axis=1)
        w = xi - step[:, None] * h
        wn = np.linalg.norm(w, axis=1)
        kinked = kappa > 0
        stick = kinked & (wn <= step * kappa)
        slip = kinked & ~stick
        fixed[tan[stick]] = True
        d[tan[stick]] = -xi[stick]
        what = w[slip] / wn[slip][:, None]
        r = h[slip] + kappa[slip, None] * what
        if m > 1:
            # J⁻¹ r and the cone's curvature across ŵ (3D)
            excess = np.maximum(wn[slip] - step[slip] * kappa[slip], floor)
            along = np.sum(r * what, axis=1)[:, None] * what
            r = along + (wn[slip] / excess)[:, None] * (r - along)
            block = (kappa[slip] / excess)[:, None, None] * (
                np.eye(m) - what[:, :, None] * what[:, None, :])
            rows = np.repeat(tan[slip], m, axis=1).ravel()
            cols = np.tile(tan[slip], (1, m)).ravel()
            across = sp.csr_matrix((block.ravel(), (rows, cols)), shape=(z.size, z.size))
        rhs = rhs.copy()
        rhs[tan[slip]] = -r
    return ProjectionForm(wall=wall, stick=stick, fixed=fixed, d=d, rhs=rhs, across=across)


def armijo_along(z, d, form, E, st, kink, upper, total, slack, sigma, halvings):
    """The trial points z + αd, α = 1, ½, … (``halvings`` of them), the
    coordinates ``form`` holds put on the wall or at ξ = 0: the first that
    passes the Armijo test of the module doc, (z, E, α), or None."""
    tan, kappa = kink.tangential, kink.radius
    at_zero = st.at_zero
    alpha = 1.0
    for _ in range(halvings):
        trial = np.minimum(z + alpha * d, upper)
        trial[form.wall] = upper[form.wall]
        if tan.size:
            trial[tan[form.stick]] = 0.0
        change = trial - z
        slope = st.g @ change
        if tan.size:
            slope += kappa[at_zero] @ np.linalg.norm(change[tan[at_zero]], axis=1)
        if slope < 0:
            E_trial = total(trial)
            if E_trial <= E + sigma * slope + slack:
                return trial, E_trial, alpha
        alpha *= 0.5
    return None


def semismooth_step(S, energy, upper, z, E, st, kink, accuracy, total, slack, sigma,
                    halvings=10):
    """One semismooth Newton step on the projection form of the step's
    optimality conditions, with an Armijo line search on E.

    Write E = F + Σ_a κ_a |ξ_a| + (the wall), F the smooth part (the
    contact terms without the kinks' cones: ∇_a F = h_a, the tangential
    gradient without the kink, ∂²F of ``energy.hessian(kink_free=True)``).
    z is stationary when, with a step length γ_i = 1/(S + ∂²F)_ii per
    coordinate (γ_a the smallest of a node's),

        z_ν = min(g_ν, z_ν − γ ∂_ν F)          (the wall, the min function),
        ξ_a = shrink(ξ_a − γ_a h_a, γ_a κ_a)   (the kink, shrink(w, t) = w (1 − t/|w|)₊),

    and ∂_i F = 0 elsewhere. Newton on these piecewise smooth equations
    takes the sets from the current z, each coordinate on its own (not
    from z's distance to the wall or to ξ = 0, as the held-direction
    iteration does): on the wall where z_ν − γ ∂_ν F ≥ g (then
    d_ν = g − z_ν); stuck where |w_a| ≤ γ_a κ_a, w_a = ξ_a − γ_a h_a (then
    d_a = −ξ_a); else the node slips along ŵ_a = w_a/|w_a|, which may turn
    against ξ_a, and its rows are (J the Jacobian of shrink at w_a)

        (∂²F d)_a + κ_a/(|w_a| − γ_a κ_a) (I − ŵ_a ŵ_aᵀ) d_a = −J⁻¹ (h_a + κ_a ŵ_a),

    J⁻¹ = ŵŵᵀ + |w|/(|w| − γκ) (I − ŵŵᵀ): symmetric, and at a slipping
    solution (|w| − γκ = |ξ|) the Hessian of κ|ξ|. Nodes with κ_a = 0 are
    smooth coordinates. The trial points z + αd, with the held
    coordinates put on the wall or at ξ = 0, α = 1, ½, … (``halvings``
    times), are accepted by the Armijo test of the module doc.

    A node with a held tangential component (3D, a vertex on a side that
    holds one tangential direction: ``kink.held``) has no projection form
    here: with such nodes the step is not taken (None, True, None) and the
    held-direction iteration does the work.

    Returns ``(accepted, solved, chord)``: ``accepted`` (z, E) or None when
    no trial passed, ``solved`` False when the Newton system was solved
    inexactly, ``chord`` what :func:`chord_step` needs (the step lengths,
    the sets and the free coordinates) when the full step was taken, else
    None."""
    if kink.held:
        return None, True, None
    zmax = np.abs(z[energy.unknowns]).max(initial=0.0)
    floor = 1e-12 + 1e-8 * zmax
    H = energy.hessian(z, s_floor=floor, kink_free=True).tocsr()
    diagonal = S.diagonal() + H.diagonal()
    gamma = 1.0 / np.where(diagonal > 0, diagonal, np.maximum(S.diagonal(), 1e-300))
    form = projection_form(z, st, upper, gamma, kink, floor)
    if form.across is not None:
        H = H + form.across
    d = form.d
    free = ~form.fixed
    solved = True
    if free.any():
        moved = np.where(form.fixed, d, 0.0)
        right = form.rhs[free] - ((S @ moved)[free] + (H @ moved)[free])
        d[free], solved = S.newton_solve(H, right, free, accuracy=accuracy)
    accepted = armijo_along(z, d, form, E, st, kink, upper, total, slack, sigma, halvings)
    if accepted is None:
        return None, solved, None
    trial, E_trial, alpha = accepted
    chord = ((gamma, form, free, floor, getattr(S, "kept", None))
             if alpha == 1.0 and free.any() else None)
    return (trial, E_trial), solved, chord


def chord_step(S, upper, z, E, st, kink, chord, accuracy, total, slack, sigma):
    """The chord step after a full semismooth step: the Newton equations of
    the projection form at the new z solved with the matrix of the last
    step, its factorisation reused (``S.chord_solve``), when z has the sets
    of that step (then the step is the simplified Newton step of a smooth
    system, and takes the superlinear error e of the last step to about
    ‖∂²F(z) − ∂²F(z_prev)‖ e: of the nonlinearity of the contact terms
    along it, e.g. a newly slipping node's slip weakening). Its full step
    only, by the Armijo test of the module doc: (z, E) or None (no chord
    solve for this matrix, other sets, or no decrease)."""
    solve = getattr(S, "chord_solve", None)
    gamma, last, free, floor, system = chord
    if solve is None:
        return None
    form = projection_form(z, st, upper, gamma, kink, floor)
    if not (np.array_equal(form.fixed, last.fixed) and np.array_equal(form.wall, last.wall)):
        return None
    d = np.zeros(z.size)
    step = solve(form.rhs[free], free, accuracy=accuracy, system=system)
    if step is None:
        return None
    d[free] = step
    accepted = armijo_along(z, d, form, E, st, kink, upper, total, slack, sigma, 1)
    return None if accepted is None else accepted[:2]


#: a chord step is kept when it divides the residual by at least this
CHORD_GAIN = 0.3


def eisenstat_walker(residual, last, gamma=0.9, largest=0.1):
    """The relative residual an iterative solve of a Newton system may stop
    at (Eisenstat and Walker's second choice): η_k = γ (r_k/r_{k−1})², at
    most ``largest``; the first is ``largest``. (Their safeguard, η_k ≥
    γ η_{k−1}² where that exceeds 0.1, cannot act below a cap of 0.1.)
    While the sets move and the residual falls slowly, a rough direction is
    as good as an exact one; once Newton converges, η_k falls with the
    residual and the convergence stays superlinear.
    The caller caps η_k at the relative residual (Dembo, Eisenstat and
    Steihaug's η_k = O(‖F_k‖)), so that a start near the solution (the
    predictor's) is not followed by a rough first step.
    (``largest`` 0.1 against 0.5 on the 3D ladder with AMG: 2.75 against
    3.35 s of stepping at 1e4 dofs frictionless, 12.0 against 14.3 s at
    2.8e4 dofs full model, the same at 1.1e5 dofs.)"""
    if last is None:
        return largest
    return min(gamma * (residual / last) ** 2, largest)
