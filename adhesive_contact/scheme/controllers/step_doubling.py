"""Adaptive steps by step doubling (``[time.adaptive]``, docs/scheme.md,
"Adaptive time steps").

From the last accepted level t_n the controller takes, with the half step
h = k_max 2^{−j} of :mod:`..adaptive`,

1. one step of 2h (the estimate), then
2. two steps of h (the pair), each a level of the scene's scheme
   (:class:`~adhesive_contact.scheme.march.Stepper`) with that step,

and accepts the pair (both levels kept) when the rule of
:class:`~adhesive_contact.scheme.adaptive.Controller` does, else retries
from t_n with a smaller h. A rejected trial leaves no trace: the memory
is persistent and the state is rebuilt from t_n. Positions are counted in
units of k_min on the grid t_m = m k_min, on which every level lies; the
step operators A + h R(0) are built once per quantised step the run uses.
"""

import math

import numpy as np

from ..adaptive import Controller, PairNorm
from ..solution import STEP_FAILED, STOPPED, SUCCESS


def explicit_bound(problem):
    """The explicit Euler bound k_E of the bonding law when the explicit
    integrator advances β (∞ otherwise)."""
    bonding = problem.bonding
    if (bonding is None or getattr(bonding, "rate_independent", False)
            or problem.options.integrator != "explicit"):
        return math.inf
    return float(bonding.stable_step())


def history(state):
    """a_μ of the memory's history at the level of ``state`` (the rule's
    ∫_0^{t_n} R(t_n − s) ε(u(s)) ds: :meth:`decayed` over no step), or
    None without memory."""
    fields = state.memory.fields(state.memory.decayed(0.0))
    return None if fields is None else fields[1]


def difference(a, b):
    return None if a is None or b is None else a - b


class StepDoubling:
    """The adaptive controller of a problem (module docstring)."""

    def __init__(self, rule, norm, bound, k_min):
        self.rule, self.norm, self.bound, self.k_min = rule, norm, bound, k_min
        self.sizes = rule.sizes
        self.first_step = self.sizes.size(self.sizes.first)   # level 0 and the first pair

    @classmethod
    def of(cls, problem):
        """The controller of ``problem``'s ``[time.adaptive]``."""
        options = problem.options
        bound = explicit_bound(problem)
        measure = (problem.boundary.measure if problem.boundary is not None
                   else np.zeros(0))
        return cls(Controller.of(options, bound),
                   PairNorm(np.asarray(measure), options.material.mu), bound,
                   options.adaptive.k_min)

    def time(self, index):
        """t of grid unit ``index`` (units of k_min: no drift of t)."""
        return self.k_min * index

    def run(self, stepper, progress=None):
        """Level 0, then accepted pairs to T: (status, failure or None)."""
        sizes, rule = self.sizes, self.rule
        taken, failure = stepper.level_zero(self.first_step)
        if failure is not None:
            return STEP_FAILED, failure
        state, level = taken
        self.norm.scale(state.u)
        stepper.keep(level, 0)
        if self._stop(stepper, progress):
            return (SUCCESS if sizes.units == 0 else STOPPED), None
        # the largest step whose pair fits in [0, T] (one uniform step,
        # time.steps = 1, leaves pairs of k_max/2); a rejection shrinks it
        at, j = 0, sizes.index(sizes.size(sizes.first), 0)
        while at < sizes.units:
            notes = stepper.notes()
            big, failure = self._trial(stepper, state, at, j - 1)
            stepper.restore(notes)   # the estimate's notes are not the run's
            if failure is not None and j < sizes.halvings:
                retry, j = rule.failed(j, at)
                continue
            one, failure = self._trial(stepper, state, at, j)
            two = None
            if one is not None:
                two, failure = self._trial(stepper, one[0], at + sizes.span(j), j)
            if two is None:
                retry, j_next = rule.failed(j, at)
                stepper.restore(notes)
                if not retry:
                    return STEP_FAILED, failure
                j = j_next
                continue
            accept, j_next = self._judge(state, big, one, two, j, at)
            if not accept:
                stepper.restore(notes)
                j = j_next
                continue
            for (_, level), index in ((one, at + sizes.span(j)), (two, at + 2 * sizes.span(j))):
                stepper.keep(level, index)
            state, at, j = two[0], at + 2 * sizes.span(j), j_next
            if self._stop(stepper, progress):
                return (SUCCESS if at >= sizes.units else STOPPED), None
        return SUCCESS, None

    def _trial(self, stepper, state, at, j):
        """One step of k_max 2^{−j} from ``state`` at unit ``at``."""
        index = at + self.sizes.span(j)
        return stepper.step(state, index, float(self.time(index)), self.sizes.size(j))

    def _judge(self, state, big, one, two, j, at):
        """(accept, next j) of the pair (one, two) against the estimate ``big``."""
        norm, order = self.norm, self.rule.order
        norm.scale(one[0].u)
        norm.scale(two[0].u)
        err = (math.inf if big is None else
               norm(two[0].u - big[0].u, two[0].beta - big[0].beta, order))
        memory = (0.0 if big is None else
                  norm.memory(difference(history(two[0]), history(big[0])), order))
        change = norm(two[0].u - state.u, two[0].beta - state.beta)
        return self.rule.judge(err, j, at, change, memory)

    def _stop(self, stepper, progress):
        return progress is not None and progress(stepper.indices[-1], self.sizes.units) is True

    def facts(self, stepper):
        """The controller's figures for summary.json."""
        c, sizes = self.rule, self.sizes
        steps = np.diff(np.asarray(stepper.indices)) * sizes.size(sizes.halvings)
        values, counts = np.unique(steps, return_counts=True)
        return {"tol": c.tol, "k_min": sizes.size(sizes.halvings),
                "k_max": sizes.size(sizes.first), "explicit_bound": self.bound
                if math.isfinite(self.bound) else None,
                "accepted_steps": int(steps.size), "accepted_pairs": c.accepted,
                "rejected_pairs": c.rejected, "forced_pairs": c.forced,
                "step_solves": stepper.solves,
                "step_sizes": {f"{v:.6g}": int(n) for v, n in zip(values, counts)},
                "factorised_steps": sorted(stepper.cache.built, reverse=True)}
