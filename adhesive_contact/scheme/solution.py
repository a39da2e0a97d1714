"""What a run returns: the history it kept and how it ended."""

from dataclasses import dataclass, field

import numpy as np

#: Solution.status
SUCCESS, STEP_FAILED, STOPPED = 0, 1, 2


class StepFailure(RuntimeError):
    """A step solve that did not converge; carries the step and its result.
    ``held_by_contact``: the rigid motions only the contact terms hold (in
    words), whose load may exceed what they can hold."""

    def __init__(self, n, t, result, held_by_contact=()):
        self.n, self.t, self.result = n, t, result
        self.held_by_contact = tuple(held_by_contact)
        advice = ("Try more time steps (smaller k), a larger solver.max_iter, or check the "
                  "smallness condition of the contact laws")
        if self.held_by_contact:
            advice = (f"Only the contact terms hold the body against "
                      f"{', '.join(self.held_by_contact)}: a load they cannot balance (one "
                      "that pulls Γ_C off a layer without glue, or shears it past the friction "
                      "bound times |Γ_C|) has no equilibrium; check the load, or hold more "
                      "components. Else t" + advice[1:])
        super().__init__(
            f"step {n} (t = {t:g}) did not converge: {result.message}; projected "
            f"residual reached {result.residual:.2e} (tolerance {result.tolerance:.1e}) "
            f"after {result.nit} iterations. {advice}")

    def __reduce__(self):   # survive pickling back from a worker process
        return (type(self), (self.n, self.t, self.result, self.held_by_contact))


@dataclass
class Solution:
    """The discrete history, and how the run ended (cf. scipy's OptimizeResult).

    Arrays are indexed by the time level n = 0..M, M = N for a run that
    succeeded; a run that stopped early (a step that did not converge, or
    a progress callback that asked to stop) holds the levels that converged
    before it, and says so in ``success``, ``status``, ``message``. What
    each array holds is the recorder's choice: the default
    (:class:`~adhesive_contact.scheme.recorder.HistoryRecorder`) keeps every
    level in memory; :class:`~adhesive_contact.io.StreamingRecorder` reads
    u from disk and keeps σ of the last level only."""

    problem: object
    status: int                   # SUCCESS, STEP_FAILED or STOPPED
    message: str
    failure: object               # the StepFailure of a failed step, else None
    t: np.ndarray                 # (M+1,)
    u: np.ndarray                 # (M+1, npoints, d)
    beta: np.ndarray              # (M+1, nf) β per contact facet
    stress: np.ndarray            # (M+1, ncells, d, d) σ_n per cell
    stress_zz: np.ndarray         # (M+1, ncells) plane strain σ_zz (2D), or None
    contact_force: np.ndarray     # (M+1, nc, d) force of Γ_C on the body, nodal frames
    frame_displacement: np.ndarray  # (M+1, nc, d) [u_ν, u_τ] at the contact nodes
    on_wall: np.ndarray           # (M+1, nc) bool
    stuck: np.ndarray             # (M+1, nc) bool: held at ξ = 0 by a friction kink
    probes: np.ndarray            # (M+1, nprobes, d)
    iterations: np.ndarray        # (M+1,) Newton iterations per step
    residual: np.ndarray          # (M+1,) final relative projected residual
    gap: np.ndarray = None        # (M+1, nc) g(x_a, t_n) of the wall, None without one
    reaction: np.ndarray = None   # (M+1, nD) force of the support per held dof
                                  # (problem.prescribed.fixed); see adhesive_contact.postprocess.reactions
    timings: dict = field(default_factory=dict)
    linear: dict = field(default_factory=dict)   # the linear backend and why: {"method", "reason"}
    # the steps n whose Newton matrix at the solution was indefinite (the step
    # energy not locally strictly convex there), and those of them where a
    # second start from z = 0 reached another solution: n -> |Δz|_∞/|z|_∞
    indefinite_steps: tuple = ()
    two_solution_steps: dict = field(default_factory=dict)
    # [time.adaptive]: the controller's figures (tol, accepted and rejected
    # pairs, step solves, step sizes used, ...), else None
    adaptive: dict = None
    # the levels whose u (and σ) ``u`` holds, increasing, when not every
    # level's: a folder written with [output] every > 1 read back
    # (adhesive_contact.io.load_solution); None: u[n] is level n
    field_levels: np.ndarray = None
    # the scalars of every level recorded with those fields ({name: (kind,
    # values)}, adhesive_contact.postprocess.level_scalars), or None
    scalars: dict = None

    @property
    def success(self):
        """True when every level n = 0..N converged."""
        return self.status == SUCCESS

    @property
    def steps(self):
        """The number of steps computed, M (levels 1..M)."""
        return self.t.size - 1

    def levels_with_fields(self):
        """The levels whose u this solution holds (every level by default)."""
        if self.field_levels is None:
            return np.arange(self.t.size)
        return np.asarray(self.field_levels)

    def nearest_field_level(self, n):
        """The level with fields nearest to level ``n`` (``n`` itself when held)."""
        levels = self.levels_with_fields()
        return int(levels[np.argmin(np.abs(levels - int(n) % self.t.size))])

    def displacement(self, n):
        """u at level ``n`` (npoints, d); ValueError for a level without
        fields (:meth:`levels_with_fields`)."""
        if self.field_levels is None:
            return np.asarray(self.u[n])
        n = int(n) % self.t.size
        position = np.searchsorted(self.field_levels, n)
        if position == len(self.field_levels) or self.field_levels[position] != n:
            raise ValueError(f"level {n} has no fields here: the run wrote them at "
                             f"{len(self.field_levels)} of {self.t.size} levels "
                             "([output] every, fields); its scalars are in scalars.csv")
        return np.asarray(self.u[position])

    @property
    def normal_displacement(self):
        """u_ν at the contact nodes (M+1, nc)."""
        return self.frame_displacement[:, :, 0]

    def total_normal_force(self):
        """Σ_a of the normal force Γ_C exerts, positive in compression (M+1,)."""
        return -self.contact_force[:, :, 0].sum(axis=1)

    def total_tangential_force(self):
        """Σ_a of the tangential forces in the nodal tangent frames (M+1, d−1)."""
        return self.contact_force[:, :, 1:].sum(axis=1)

    def gap_violation(self):
        """max_a (u_ν − g) per level over the contact nodes whose u_ν is not
        held (−inf without a wall or such nodes)."""
        gap = self.gap
        if gap is None or gap.shape[1] == 0:
            return np.full(self.t.size, -np.inf)
        excess = self.normal_displacement - gap
        return np.where(self.problem.boundary.held[:, 0], -np.inf, excess).max(axis=1)
