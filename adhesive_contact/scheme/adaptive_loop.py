"""The time loop with adaptive steps (``[time.adaptive]``, docs/scheme.md,
"Adaptive time steps").

From the last accepted level t_n the loop takes, with the half step
h = k_max 2^{−j} of :mod:`.adaptive`,

1. one step of 2h (the estimate), then
2. two steps of h (the pair), each a level of the scene's scheme
   ((4.2), the step load with the nonuniform memory history of
   :mod:`.adaptive_memory`, (4.1), the level checks) with that step,

and accepts the pair (both levels recorded) when the controller does,
else retries from t_n with a smaller h. A rejected trial leaves no trace:
the memory is persistent and the state is rebuilt from t_n. The step
operators A + h R(0) are built once per quantised step the run uses and
kept (:class:`OperatorCache`). The problem is built on the grid
t_m = m k_min (:func:`~adhesive_contact.problem.build.time_grid`), on which
every level lies; the returned Solution's problem has the accepted times
and their gaps.
"""

import math
import time
from dataclasses import replace

import numpy as np

from .adaptive import Controller, PairNorm
from .adaptive_memory import instantaneous_only, start_memory
from .level_checks import check_level, check_load
from .operators import StepOperators
from .recorder import HistoryRecorder
from .solution import STEP_FAILED, STOPPED, SUCCESS, Solution, StepFailure
from .state import ContactStep, State, bonding_step, history_load, step_solve
from ..threads import one_blas_thread


class OperatorCache:
    """The StepOperators of each quantised step k_max 2^{−j} that a run
    uses, built on first use and kept: adaptivity factorises each step
    size once, not each step."""

    def __init__(self, problem, memory, sizes):
        self.problem, self.memory, self.sizes = problem, memory, sizes
        self.built = {}

    def get(self, j, initial=False):
        if j not in self.built:
            self.built[j] = StepOperators.build(self.problem, self.memory, self.sizes.size(j),
                                                initial=initial)
        return self.built[j]

    def seconds(self, name):
        return sum(getattr(op, name) for op in self.built.values())


def explicit_bound(problem):
    """The explicit Euler bound k_E of the bonding law when the explicit
    integrator advances β (∞ otherwise)."""
    bonding = problem.bonding
    if (bonding is None or getattr(bonding, "rate_independent", False)
            or problem.options.integrator != "explicit"):
        return math.inf
    return float(bonding.stable_step())


def solve_adaptive(problem, progress=None, raise_on_failure=False, recorder=None):
    """:func:`~adhesive_contact.scheme.loop.solve` for a scene with
    [time.adaptive]: the same arguments and Solution, its ``t`` the
    accepted (nonuniform) levels and its ``adaptive`` the controller's
    figures."""
    t0 = time.perf_counter()
    options = problem.options
    trapezoid = options.second_order
    bound = explicit_bound(problem)
    controller = Controller.of(options, bound)
    sizes = controller.sizes
    cache = OperatorCache(problem, instantaneous_only(options.memory, trapezoid), sizes)
    first = cache.get(sizes.first, initial=True)   # level 0 and the first pair: k_max
    contact = (ContactStep(problem, first.within) if problem.boundary is not None else None)
    recorder = recorder or HistoryRecorder(problem)
    measure = (problem.boundary.measure if problem.boundary is not None
               else np.zeros(0))
    norm = PairNorm(np.asarray(measure), options.material.mu)
    run = _Run(problem, cache, contact, recorder, controller, norm, progress)
    t_loop = time.perf_counter()
    with one_blas_thread():
        status, failure = run.march(first)
    if failure is not None and raise_on_failure:
        raise failure
    t_end = time.perf_counter()
    index = np.array(run.indices, dtype=np.int64)
    timings = {"assembly": problem.assembly_seconds,
               "factorisation": cache.seconds("factor_seconds"),
               "schur": cache.seconds("schur_seconds"),
               "stepping": t_end - t_loop,
               "contact_solve": contact.seconds if contact is not None else 0.0,
               "total": problem.assembly_seconds + (t_end - t0)}
    t = problem.times[index].copy()
    message = {SUCCESS: "all steps converged", STEP_FAILED: str(failure),
               STOPPED: f"stopped after step {max(index.size - 1, 0)} "
                        f"(t = {t[-1] if t.size else 0.0:g})"}[status]
    level_of = {m: n for n, m in enumerate(run.indices)}
    notes = {} if contact is None else {
        "indefinite_steps": tuple(level_of[m] for m in sorted(contact.indefinite_steps)
                                  if m in level_of),
        "two_solution_steps": {level_of[m]: r for m, r in sorted(
            contact.two_solution_steps.items()) if m in level_of}}
    ran = replace(problem, times=t, gap=None if problem.gap is None
                  else np.ascontiguousarray(problem.gap[index]))
    return Solution(problem=ran, status=status, message=message, failure=failure, t=t,
                    timings=timings, linear=first.linear, adaptive=run.facts(bound), **notes,
                    **recorder.history())


def history(state):
    """a_μ of the memory's history at the level of ``state`` (the rule's
    ∫_0^{t_n} R(t_n − s) ε(u(s)) ds: :meth:`decayed` over no step), or
    None without memory."""
    fields = state.memory.fields(state.memory.decayed(0.0))
    return None if fields is None else fields[1]


def difference(a, b):
    return None if a is None or b is None else a - b


class _Run:
    """One adaptive run's loop and what it counts."""

    def __init__(self, problem, cache, contact, recorder, controller, norm, progress):
        self.problem, self.cache, self.contact = problem, cache, contact
        self.recorder, self.controller, self.norm = recorder, controller, norm
        self.progress = progress
        self.indices = []   # the accepted levels' indices in problem.times
        self.solves = 0     # every step solve, of accepted, estimate and rejected trials

    def march(self, first):
        """Level 0, then accepted pairs to T: (status, failure or None)."""
        problem, sizes = self.problem, self.controller.sizes
        state = State(n=-1, t=0.0, beta=problem.beta0.copy(),
                      z=np.zeros(self.contact.size if self.contact is not None else 0),
                      u=np.zeros(problem.ndofs),
                      frame_u=np.zeros(0 if problem.boundary is None
                                       else problem.boundary.nodes.size * problem.dim),
                      memory=None)
        b, known = history_load(problem, first, 0, 0.0, None)
        failure = check_load(0, 0.0, b)
        if failure is not None:
            return STEP_FAILED, failure
        level, u, frame_u, z, result = step_solve(problem, first, self.contact, 0, 0.0, b,
                                                  state.beta, known, state.z)
        self.solves += 1
        failure = (StepFailure(0, 0.0, result, problem.held_by_contact) if level is None
                   else check_level(problem, level))
        if failure is not None:
            failure.result = failure.result if failure.result is not None else result
            return STEP_FAILED, failure
        memory = start_memory(problem.options.memory, problem.options.second_order, u)
        state = State(n=0, t=0.0, beta=state.beta, z=z, u=u, frame_u=frame_u, memory=memory)
        self.norm.scale(u)
        self.keep(level, 0)
        if self.stop():
            return (SUCCESS if sizes.units == 0 else STOPPED), None
        # the largest step whose pair fits in [0, T] (one uniform step,
        # time.steps = 1, leaves pairs of k_max/2); a rejection shrinks it
        at, j = 0, sizes.index(sizes.size(sizes.first), 0)
        while at < sizes.units:
            notes = self.notes()
            big, failure = self.trial(state, at, j - 1)
            self.restore(notes)   # the estimate's notes are not the run's
            if failure is not None and j < sizes.halvings:
                retry, j = self.controller.failed(j, at)
                continue
            one, failure = self.trial(state, at, j)
            two = None
            if one is not None:
                two, failure = self.trial(one[0], at + sizes.span(j), j)
            if two is None:
                retry, j_next = self.controller.failed(j, at)
                self.restore(notes)
                if not retry:
                    return STEP_FAILED, failure
                j = j_next
                continue
            self.norm.scale(one[0].u)
            self.norm.scale(two[0].u)
            order = self.controller.order
            err = (math.inf if big is None else
                   self.norm(two[0].u - big[0].u, two[0].beta - big[0].beta, order))
            memory = (0.0 if big is None else
                      self.norm.memory(difference(history(two[0]), history(big[0])), order))
            change = self.norm(two[0].u - state.u, two[0].beta - state.beta)
            accept, j_next = self.controller.judge(err, j, at, change, memory)
            if not accept:
                self.restore(notes)
                j = j_next
                continue
            for (_, level), index in ((one, at + sizes.span(j)), (two, at + 2 * sizes.span(j))):
                self.keep(level, index)
            state, at, j = two[0], at + 2 * sizes.span(j), j_next
            if self.stop():
                return (SUCCESS if at >= sizes.units else STOPPED), None
        return SUCCESS, None

    def trial(self, state, at, j):
        """One step of k_max 2^{−j} from ``state`` at unit ``at``:
        ((State, Level), None), or (None, the failure)."""
        problem, sizes = self.problem, self.controller.sizes
        k = sizes.size(j)
        operators = self.cache.get(j)
        index = at + sizes.span(j)
        t = float(problem.times[index])
        beta = bonding_step(problem, state, k)                                    # (4.2)
        h = state.memory.decayed(k)
        b, known = history_load(problem, operators, index, t, state.memory.fields(h))
        failure = check_load(index, t, b)
        if failure is not None:
            return None, failure
        before = state.z_before if state.k_last == k else None   # equal steps: extrapolate
        level, u, frame_u, z, result = step_solve(problem, operators, self.contact, index, t,
                                                  b, beta, known, state.z, before)   # (4.1)
        self.solves += 1
        failure = (StepFailure(index, t, result, problem.held_by_contact) if level is None
                   else check_level(problem, level))
        if failure is not None:
            failure.result = failure.result if failure.result is not None else result
            return None, failure
        after = State(n=index, t=t, beta=beta, z=z, u=u, frame_u=frame_u,
                      memory=state.memory.after(h, u, k), z_before=state.z,
                      frame_u_before=state.frame_u, k_last=k)
        return (after, level), None

    def keep(self, level, index):
        """Record an accepted level as level n = count, at ``index`` in problem.times."""
        level.n, level.index = len(self.indices), index
        self.recorder.record(level)
        self.indices.append(index)

    def stop(self):
        return (self.progress is not None
                and self.progress(self.indices[-1], self.controller.sizes.units) is True)

    def notes(self):
        if self.contact is None:
            return None
        return set(self.contact.indefinite_steps), dict(self.contact.two_solution_steps)

    def restore(self, notes):
        if notes is not None:
            self.contact.indefinite_steps, self.contact.two_solution_steps = notes

    def facts(self, bound):
        """The controller's figures for summary.json."""
        c, sizes = self.controller, self.controller.sizes
        steps = np.diff(np.asarray(self.indices)) * sizes.size(sizes.halvings)
        values, counts = np.unique(steps, return_counts=True)
        return {"tol": c.tol, "k_min": sizes.size(sizes.halvings),
                "k_max": sizes.size(sizes.first), "explicit_bound": bound
                if math.isfinite(bound) else None,
                "accepted_steps": int(steps.size), "accepted_pairs": c.accepted,
                "rejected_pairs": c.rejected, "forced_pairs": c.forced,
                "step_solves": self.solves,
                "step_sizes": {f"{v:.6g}": int(n) for v, n in zip(values, counts)},
                "factorised_steps": [sizes.size(j) for j in sorted(self.cache.built)]}
