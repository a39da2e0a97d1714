"""No quiet wrong answers: what every converged level must satisfy.

Before each step solve the loop checks that the load of the step is
finite (a load expression can overflow or divide by zero where it is used),
and after each level that

- u_n, σ_n and β_n are finite;
- 0 ≤ β_n ≤ 1 up to round-off (``BETA_SLACK``): the exact β stays in
  [0, 1], but explicit Euler (4.2) leaves it once k (γ_ν + γ_τ) L² > 1,
  and β² then revives the glue. Not for a manufactured solution: its
  source s_β breaks the invariance of [0, 1] (F ≥ 0 for β ≤ 0, F ≤ 0 for
  β ≥ 1), so a coarse k may leave it by the discretisation error alone;
- u_ν ≤ g at the contact nodes whose u_ν is not held, up to round-off (``WALL_SLACK`` relative to
  the size of g and u_ν): the exact step methods project onto the wall.
  Not for ``solver.method = "penalty"``, which solves a nearby problem
  and leaves a violation by design; it is recorded
  (:meth:`~.solution.Solution.gap_violation`) instead.

A violation stops the run with :class:`InvalidState`, one paragraph that
says what failed, where, the figures and what to try.
"""

import numpy as np

from ..laws.bonding import BEYOND_TIME_SCALE
from ..scene import where
from ..step_methods import EXACT
from .solution import StepFailure

BETA_SLACK = 1e-12
WALL_SLACK = 1e-10


class InvalidState(StepFailure):
    """A level that converged to values the model does not allow."""

    def __init__(self, n, t, reason, result=None):
        # result: the step solve's StepResult (it converged), None for a
        # failure found before the solve
        self.n, self.t, self.result, self.reason = n, t, result, reason
        RuntimeError.__init__(self, f"step {n} (t = {t:g}) gave an invalid state: {reason}")

    def __reduce__(self):
        return (type(self), (self.n, self.t, self.reason, self.result))


def _facet_midpoint(problem, facet):
    return where(problem.mesh.p[:, problem.boundary.facet_nodes[:, facet]].mean(axis=1),
                 digits=4)


def check_load(n, t, b):
    """None if the step load b is finite, else the :class:`InvalidState`."""
    if np.all(np.isfinite(b)):
        return None
    return InvalidState(n, t, "the load (body force, tractions and memory history) is not "
                        "finite (NaN or infinity). Check the load expressions of [loads] "
                        "for values that overflow or divide by zero at this time")


def check_level(problem, level):
    """None if level n is admissible, else the :class:`InvalidState`."""
    n, t = level.n, level.t
    for name in ("u", "beta", "stress"):
        if not np.all(np.isfinite(getattr(level, name))):
            return InvalidState(n, t, f"{name} is not finite (NaN or infinity). Check the "
                                "loads, the gap and the laws for values that overflow")
    beta = level.beta
    if beta.size and problem.beta_source is None and (beta.min() < -BETA_SLACK or beta.max() > 1 + BETA_SLACK):
        facet = int(np.argmin(beta) if beta.min() < -BETA_SLACK else np.argmax(beta))
        reason = (f"beta = {beta[facet]:.4g} leaves [0, 1] on the contact facet at "
                  f"{_facet_midpoint(problem, facet)}")
        bonding = problem.bonding
        if bonding is not None and problem.options.integrator == "explicit":
            k, bound = (level.k or problem.options.k), bonding.stable_step()
            reason += (f". The explicit Euler step of the bonding law keeps beta in [0, 1] "
                       f"only for k (gamma_nu + gamma_tau) L^2 <= 1, i.e. k <= {bound:.4g}; "
                       f"this run has k = {k:.4g}")
            if k > bound and problem.options.adaptive is None:
                need = int(np.ceil(problem.options.T / bound))
                reason += (f". Use at least time.steps = {need} or [time.adaptive] tol; "
                           f"{BEYOND_TIME_SCALE} "
                           f"(docs/scheme.md#accuracy-guides-of-the-time-step)")
        return InvalidState(n, t, reason)
    gap = level.gap
    exact = problem.options.solver.method in EXACT
    if exact and gap is not None and level.frame_displacement.shape[0]:
        u_nu = level.frame_displacement[:, 0]
        # the wall acts where u_ν is free: a held u_ν is the scene's to set
        excess = np.where(problem.boundary.held[:, 0], -np.inf, u_nu - gap)
        worst = int(np.argmax(excess))
        finite = np.isfinite(gap)   # +inf: no wall at the node
        scale = 1.0 + max(np.abs(gap[finite]).max(initial=0.0), np.abs(u_nu).max())
        if excess[worst] > WALL_SLACK * scale:
            x = problem.mesh.p[:, problem.boundary.nodes[worst]]
            return InvalidState(n, t, (
                f"u_nu - g = {excess[worst]:.3g} > 0 at the contact node "
                f"{where(x, digits=4)}: the rigid wall is crossed"))
    return None
