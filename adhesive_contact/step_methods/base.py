"""The interface of the step methods: their options, what they return,
and the one measure of stationarity they are all judged by.

A step of (4.1), with the interior condensed out, minimises

    E(z) = ½ zᵀ S z − cᵀ z + Φ(z)   subject to  z ≤ upper  (the wall),

Φ the contact terms (:class:`~adhesive_contact.scheme.contact_energy.ContactEnergy`),
whose friction adds at each node a with a kink the Clarke subdifferential
B(0, κ_a) at ξ_a = 0. z is stationary when 0 ∈ ∂E(z) + N_wall(z): the
*pseudo-gradient* (the minimal-norm element of that set, :func:`stationarity`)
vanishes. Its sup norm over the force scale of the step is the residual
every exact method reports.
"""

from dataclasses import dataclass, field

import numpy as np

#: StepResult.status: how a step solve ended
CONVERGED, MAX_ITERATIONS, LINE_SEARCH_FAILED, DIVERGED, OPTIMIZER_STOPPED = 0, 1, 2, 3, 4
MESSAGES = {CONVERGED: "converged",
            MAX_ITERATIONS: "no convergence in {max_iter} iterations",
            LINE_SEARCH_FAILED: "line search failed: no decrease of the energy along the "
                                "Newton or the gradient direction",
            DIVERGED: "the iterates diverged (energy or iterate not finite, or growing "
                      "without bound) after {nit} full Newton steps",
            OPTIMIZER_STOPPED: "the bound-constrained minimiser stopped short of the "
                               "tolerance ({detail})"}


@dataclass
class StepResult:
    """How a step solve ended (cf. scipy.optimize.OptimizeResult).

    ``status`` is one of :data:`CONVERGED`, :data:`MAX_ITERATIONS`,
    :data:`LINE_SEARCH_FAILED`, :data:`DIVERGED`, :data:`OPTIMIZER_STOPPED`;
    ``residual`` the relative residual reached (the pseudo-gradient for the
    exact methods, the gradient of the penalised energy for "penalty");
    ``inner_failures`` the Newton systems whose iterative solve (CG, for an
    applied Schur complement) stopped before its tolerance;
    ``wall_violation`` max (z_ν − g)_+ the method left (0 for the exact
    methods, which project onto the wall); ``indefinite`` whether the
    Newton matrix S + ∂²Φ of the last iteration was indefinite and its
    factorisation modified (the step energy not locally strictly convex at
    the solution), set by the caller from the operator's flag
    (:class:`~adhesive_contact.scheme.condensed.DenseSchur`);
    ``another_start`` whether a second start reached another solution
    (:class:`~adhesive_contact.scheme.state.ContactStep`)."""

    z: np.ndarray
    status: int
    message: str
    nit: int
    residual: float
    tolerance: float
    energy: float
    inner_failures: int = 0
    multiplier: np.ndarray = field(default=None, repr=False)  # wall reaction λ ≥ 0 per unknown
    on_wall: np.ndarray = field(default=None, repr=False)     # bool per unknown
    stuck: np.ndarray = field(default=None, repr=False)       # bool per node with a kink (ξ_a = 0)
    wall_violation: float = 0.0
    indefinite: bool = False
    another_start: bool = False

    @property
    def success(self):
        return self.status == CONVERGED


@dataclass(frozen=True)
class StepOptions:
    """What a step method is told (from the scene's ``[solver]`` table).

    ``tol`` the relative tolerance on the residual; ``max_iter`` the Newton
    iterations (the optimizer gets ``OPTIMIZER_ITERATIONS`` times as many:
    a quasi-Newton step is cheaper and slower); ``penalty`` ρ, the wall's
    penalty stiffness per contact unknown, and ``smoothing`` δ, the length
    below which the friction kink is rounded (both for "penalty" only, in
    absolute units, scaled by the caller)."""

    tol: float = 1e-10
    max_iter: int = 50
    penalty: float = None
    smoothing: float = None


#: L-BFGS-B iterations per ``max_iter``
OPTIMIZER_ITERATIONS = 100


@dataclass
class Kink:
    """The nodes whose friction has a kink: their tangential unknowns and κ_a.

    ξ_a = z[tangential[a]] + offset[a]: a tangential component the
    boundary holds (at a node of a 3D Γ_C whose other tangential component
    is free) has the index −1 and its held value in ``offset``; ``offset``
    is None when no component is held. Read and write the tangential
    unknowns with :meth:`take` and :meth:`put`, which skip the held ones."""

    tangential: np.ndarray   # (na, m) indices into z, −1 for a held component
    radius: np.ndarray       # (na,) κ_a ≥ 0
    offset: np.ndarray = None  # (na, m) held values (0 at the unknowns), or None

    def __post_init__(self):
        unknown = self.tangential >= 0
        self._unknown = None if unknown.all() else unknown
        self._index = np.where(unknown, self.tangential, 0)

    @property
    def held(self):
        """Whether some node has a held tangential component (index −1)."""
        return self._unknown is not None

    def take(self, v):
        """v at the tangential unknowns (na, m), 0 at the held components."""
        if self._unknown is None:
            return v[self.tangential]
        return np.where(self._unknown, v[self._index], 0)

    def xi(self, z):
        """ξ_a (na, m), held components included."""
        out = self.take(z)
        return out if self.offset is None else out + self.offset

    def put(self, v, rows, values):
        """v[tangential[rows]] = values[rows] (values (na, m) or a scalar)
        at the tangential unknowns of the nodes ``rows`` (a bool mask)."""
        values = np.broadcast_to(values, self.tangential.shape)
        if self._unknown is None:
            v[self.tangential[rows]] = values[rows]
            return
        keep = self._unknown[rows]
        v[self.tangential[rows][keep]] = values[rows][keep]


def no_kink():
    """The Kink of a problem without friction."""
    return Kink(np.zeros((0, 1), dtype=np.int64), np.zeros(0))


@dataclass
class Stationarity:
    """The first-order quantities of E at z (see :func:`stationarity`)."""

    g: np.ndarray          # ∇E where E is differentiable (the kink left out)
    Sz: np.ndarray         # S z (its quadratic part, kept for the energy's round-off)
    xi: np.ndarray         # (na, m) ξ_a at the nodes with a kink
    s: np.ndarray          # (na,) |ξ_a|
    at_zero: np.ndarray    # (na,) ξ_a = 0
    unit: np.ndarray       # (na, m) ξ_a/|ξ_a|, 0 at ξ_a = 0
    h: np.ndarray          # (na, m) the tangential gradient without the kink
    hn: np.ndarray         # (na,) |h_a|
    pg: np.ndarray         # the pseudo-gradient
    wall: np.ndarray       # bool: on the wall and pressed onto it
    scale: float           # the force scale of the step
    residual: float        # |pg|_∞ (absolute)

    @property
    def relative(self):
        return self.residual / self.scale


def kink_subgradient(h, kappa):
    """The element of least norm of h + B(0, κ_a) at nodes with ξ_a = 0,
    h_a (1 − κ_a/|h_a|)₊: zero where |h_a| ≤ κ_a (the node sticks), else
    the force that the kink cannot hold. ``h`` (na, m), ``kappa`` (na,)."""
    hn = np.linalg.norm(h, axis=1)
    slide = np.where(hn > kappa, 1.0 - kappa / np.where(hn > 0, hn, 1.0), 0.0)
    return h * slide[:, None]


def stationarity(S, c, energy, upper, z, kink):
    """The pseudo-gradient of E at z: the minimal-norm element of
    ∂E(z) + N_wall(z), with ∂E the Clarke subdifferential (kinks: the ball
    B(0, κ_a) at ξ_a = 0), and the force scale max(|c|, |Sz|, |∇Φ|, κ)."""
    tan, kappa = kink.tangential, kink.radius
    Sz = S @ z
    gphi = energy.gradient(z)
    g = Sz - c + gphi
    xi = kink.xi(z) if tan.size else np.zeros((0, 0))
    s = np.linalg.norm(xi, axis=1)
    at_zero = s == 0
    unit = np.where(at_zero[:, None], 0.0, xi / np.where(at_zero, 1.0, s)[:, None])
    h = (kink.take(g) if tan.size else np.zeros((0, 0))) - kappa[:, None] * unit
    hn = np.linalg.norm(h, axis=1)
    pg = g.copy()
    wall = np.isfinite(upper) & (z >= upper) & (g < 0)
    pg[wall] = 0.0
    if tan.size:
        kink.put(pg, at_zero, kink_subgradient(h, kappa))
    scale = max(np.abs(c).max(initial=0.0), np.abs(Sz).max(initial=0.0),
                np.abs(gphi).max(initial=0.0), kappa.max(initial=0.0), 1e-300)
    return Stationarity(g=g, Sz=Sz, xi=xi, s=s, at_zero=at_zero, unit=unit, h=h, hn=hn, pg=pg,
                        wall=wall, scale=scale, residual=np.abs(pg).max(initial=0.0))


def backtrack(directions, trial_of, total, bound, halvings=60):
    """Armijo backtracking along each direction in turn: α = 1, ½, ¼, …
    until ``total(trial) <= bound(direction, trial, α)``, with ``trial =
    trial_of(direction, α)``. Returns ``(trial, total(trial))``, or None
    when no direction gives a decrease; a ``bound`` of None skips a
    direction (not one of descent)."""
    for direction in directions:
        alpha = 1.0
        for _ in range(halvings):
            trial = trial_of(direction, alpha)
            limit = bound(direction, trial, alpha)
            if limit is None:
                break
            E_trial = total(trial)
            if E_trial <= limit:
                return trial, E_trial
            alpha *= 0.5
    return None
