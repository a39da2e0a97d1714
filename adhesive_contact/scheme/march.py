"""The time march of the fully discrete scheme (Problem 4.1), one for every
step controller.

Level 0 solves the problem at t = 0 with the elastic stiffness alone (no
memory yet). A level after it, from the state of level n − 1 and with the
step k = t_n − t_{n−1} its controller chose (:mod:`.controllers`):

1. the bonding step (4.2): β_n from level n − 1, by the scene's
   integrator (:mod:`.bonding`; explicit Euler, the paper's);
2. the load of level n: f(t_n) minus the memory history (:mod:`.memory`:
   the right rectangle rule, or the trapezoid of ``time.scheme =
   "second-order"``), the held values g_D(t_n);
3. the step solve (4.1): u_n minimises the step energy with the step
   matrix A + k R(0) (built once per step size, :class:`OperatorCache`),
   the contact terms with β_n and the wall u_ν ≤ g(t_n);
4. the checks of every level (:mod:`.level_checks`).

:class:`Stepper` takes these levels for a controller, which decides which
steps are taken and which levels are kept; :func:`march` runs a
controller from level 0 and returns the :class:`~.solution.Solution`
that says how the run ended.
"""

import time

import numpy as np

from ..threads import one_blas_thread
from .level_checks import check_level, check_load
from .memory import start_memory
from .operators import StepOperators
from .recorder import HistoryRecorder
from .solution import STEP_FAILED, STOPPED, SUCCESS, Solution, StepFailure
from .state import ContactStep, State, StepInput, bonding_step, history_load, initial_state, \
    step_solve


class OperatorCache:
    """The StepOperators of each step size k a run uses, built on first use
    and kept: a run factorises each step size once, not each step."""

    def __init__(self, problem):
        self.problem = problem
        self.built = {}

    def get(self, k, initial=False):
        """The operators of step k (with the t = 0 operator: ``initial``)."""
        if k not in self.built:
            self.built[k] = StepOperators.build(self.problem, k, initial=initial)
        return self.built[k]

    def seconds(self, name):
        return sum(getattr(op, name) for op in self.built.values())


class Stepper:
    """Takes the levels of a run (module docstring) for its controller and
    keeps the accepted ones: ``recorder`` gets each, ``indices`` their
    positions on the controller's grid, ``solves`` counts every step solve
    (an adaptive run's rejected and estimate trials too)."""

    def __init__(self, problem, cache, contact, recorder):
        self.problem, self.cache, self.contact, self.recorder = problem, cache, contact, recorder
        self.indices = []
        self.solves = 0

    def gap(self, t):
        return None if self.problem.gap is None else self.problem.gap.at(t)

    def level_zero(self, k):
        """Level 0 (t = 0, β_0, the elastic step matrix of the operators of
        the first step k): ((State, Level), None) or (None, the failure)."""
        problem = self.problem
        state = initial_state(problem, self.contact and self.contact.size)
        operators = self.cache.get(k, initial=True)
        b, known = history_load(problem, operators, True, 0.0, None)
        step = StepInput(index=0, t=0.0, k=0.0, b=b, known=known, beta=state.beta,
                         gap=self.gap(0.0), gap_before=None, z0=state.z)
        outcome, failure = self._solve(operators, step)
        if failure is not None:
            return None, failure
        memory = start_memory(problem.options.memory, problem.options.second_order, outcome.u)
        after = State(n=0, t=0.0, beta=state.beta, z=outcome.z, u=outcome.u,
                      frame_u=outcome.frame_u, memory=memory, gap=step.gap)
        return (after, outcome.level), None

    def step(self, state, index, t, k):
        """One level at ``t`` = t_n (``index`` on the controller's grid) from
        ``state`` over the step k: ((State, Level), None), or (None, the
        failure). A trial that is not kept leaves no trace: the memory is
        persistent and ``state`` unchanged."""
        problem = self.problem
        operators = self.cache.get(k)
        beta = bonding_step(problem, state, k)                                   # (4.2)
        h = state.memory.decayed(k)
        b, known = history_load(problem, operators, False, t, state.memory.fields(h))
        before = state.z_before if state.k_last == k else None   # equal steps: extrapolate
        step = StepInput(index=index, t=t, k=k, b=b, known=known, beta=beta, gap=self.gap(t),
                         gap_before=state.gap, z0=state.z, z_before=before)
        outcome, failure = self._solve(operators, step)                          # (4.1)
        if failure is not None:
            return None, failure
        after = State(n=index, t=t, beta=beta, z=outcome.z, u=outcome.u,
                      frame_u=outcome.frame_u, memory=state.memory.after(h, outcome.u, k),
                      z_before=state.z, frame_u_before=state.frame_u, k_last=k, gap=step.gap)
        return (after, outcome.level), None

    def _solve(self, operators, step):
        """The step solve of ``step`` with its checks: (StepOutcome, None) or
        (None, the failure)."""
        failure = check_load(step.index, step.t, step.b)
        if failure is not None:
            return None, failure
        outcome = step_solve(self.problem, operators, self.contact, step)
        self.solves += 1
        failure = (StepFailure(step.index, step.t, outcome.result,
                               self.problem.held_by_contact) if outcome.level is None
                   else check_level(self.problem, outcome.level))
        if failure is not None:
            if failure.result is None:
                failure.result = outcome.result   # an invalid state: the solve that gave it
            return None, failure
        return outcome, None

    def keep(self, level, index):
        """Record an accepted level as level n = the count so far."""
        level.n = len(self.indices)
        self.recorder.record(level)
        self.indices.append(index)

    def notes(self):
        """The contact step's notes (restored after a trial that is not kept)."""
        if self.contact is None:
            return None
        return set(self.contact.indefinite_steps), dict(self.contact.two_solution_steps)

    def restore(self, notes):
        if notes is not None:
            self.contact.indefinite_steps, self.contact.two_solution_steps = notes


def march(problem, controller, progress=None, raise_on_failure=False, recorder=None):
    """Run ``controller`` (:mod:`.controllers`) on ``problem`` from level 0.

    Parameters
    ----------
    problem : Problem (never changed by the run)
    controller : the step controller, e.g. :class:`.controllers.Uniform`
    progress : callable ``progress(done, total)``, called after each kept
        level (the controller's count of its grid); a return value of True
        stops the run (status STOPPED)
    raise_on_failure : raise the :class:`StepFailure` of a step that does
        not converge or gives an invalid state, instead of returning the
        history up to it
    recorder : what to keep per level (default :class:`HistoryRecorder`)

    Returns
    -------
    Solution : ``success``, ``status``, ``message`` say how the run ended.
    """
    t0 = time.perf_counter()
    cache = OperatorCache(problem)
    first = cache.get(controller.first_step, initial=True)
    contact = ContactStep(problem, first.within) if problem.boundary is not None else None
    recorder = recorder or HistoryRecorder(problem)
    stepper = Stepper(problem, cache, contact, recorder)
    t_loop = time.perf_counter()
    with one_blas_thread():   # a step's algebra is small or latency-bound
        status, failure = controller.run(stepper, progress)
    if failure is not None and raise_on_failure:
        raise failure
    t_end = time.perf_counter()
    timings = {"assembly": problem.assembly_seconds,
               "factorisation": cache.seconds("factor_seconds"),
               "schur": cache.seconds("schur_seconds"),
               "stepping": t_end - t_loop,
               "contact_solve": contact.seconds if contact is not None else 0.0,
               "total": problem.assembly_seconds + (t_end - t0)}
    history = recorder.history()
    t = np.asarray(history.pop("t"))
    message = {SUCCESS: "all steps converged", STEP_FAILED: str(failure),
               STOPPED: f"stopped after step {max(t.size - 1, 0)} "
                        f"(t = {t[-1] if t.size else 0.0:g})"}[status]
    level_of = {index: n for n, index in enumerate(stepper.indices)}
    notes = {} if contact is None else {
        "indefinite_steps": tuple(level_of[i] for i in sorted(contact.indefinite_steps)
                                  if i in level_of),
        "two_solution_steps": {level_of[i]: r for i, r in sorted(
            contact.two_solution_steps.items()) if i in level_of}}
    return Solution(problem=problem, status=status, message=message, failure=failure, t=t,
                    timings=timings, linear=first.linear,
                    adaptive=controller.facts(stepper), **notes, **history)
