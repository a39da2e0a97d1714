"""The time loop of the fully discrete scheme (Problem 4.1).

u_0 solves the problem at t = 0 with the elastic stiffness alone (no memory
yet). For n = 1..N, with k = T/N and t_n = n k: the bonding step (4.2),
by the scene's integrator (:mod:`.bonding`: explicit Euler as in the paper,
implicit or exponential), gives β_n from level n − 1; u_n minimises the step energy with the
step matrix A + k R(0), the load f(t_n) minus the memory history (right
rectangle rule), the contact terms with β_n and the wall u_ν ≤ g(t_n).

With ``time.scheme = "second-order"`` the memory is the trapezoidal rule
(step matrix A + (k/2) R(0)) and β_n the exponential midpoint step with
the rate at t_{n−½} (:func:`.state.bonding_step`); the contact step is the
same, at t_n.
"""

import time

from .adaptive_loop import solve_adaptive
from .level_checks import check_level, check_load
from .memory import start_memory
from .operators import StepOperators
from .recorder import HistoryRecorder
from .solution import STEP_FAILED, STOPPED, SUCCESS, Solution, StepFailure
from .state import (
    ContactStep,
    State,
    bonding_step,
    initial_state,
    step_load,
    step_solve,
)
from ..threads import one_blas_thread


def solve(problem, progress=None, raise_on_failure=False, recorder=None):
    """Run the scheme on a :class:`~adhesive_contact.problem.Problem`.

    Parameters
    ----------
    problem : Problem (never changed by the run)
    progress : callable ``progress(n, N)``, called after each level; a
        return value of True stops the run (status STOPPED)
    raise_on_failure : raise :class:`StepFailure` when a step does not
        converge or gives an invalid state (:mod:`.checks`), instead of
        returning the history up to it
    recorder : what to keep per level (default :class:`HistoryRecorder`)

    Returns
    -------
    Solution : ``success``, ``status``, ``message`` say how the run ended.
    """
    if problem.options.adaptive is not None:   # [time.adaptive]: scheme/adaptive_loop.py
        return solve_adaptive(problem, progress, raise_on_failure, recorder)
    t0 = time.perf_counter()
    memory = start_memory(problem)
    operators = StepOperators.build(problem, memory)
    contact = (ContactStep(problem, operators.within) if problem.boundary is not None
               else None)
    recorder = recorder or HistoryRecorder(problem)
    t_loop = time.perf_counter()
    with one_blas_thread():   # a step's algebra is small or latency-bound
        status, failure, state = march(problem, operators, contact, recorder,
                                       initial_state(problem, memory, contact and contact.size),
                                       progress)
    if failure is not None and raise_on_failure:
        raise failure
    t_end = time.perf_counter()
    timings = {"assembly": problem.assembly_seconds,
               "factorisation": operators.factor_seconds,
               "schur": operators.schur_seconds,
               "stepping": t_end - t_loop,
               "contact_solve": contact.seconds if contact is not None else 0.0,
               "total": problem.assembly_seconds + (t_end - t0)}
    message = {SUCCESS: "all steps converged", STEP_FAILED: str(failure),
               STOPPED: f"stopped after step {state.n} (t = {state.t:g})"}[status]
    done = recorder.count
    notes = {} if contact is None else {
        "indefinite_steps": tuple(n for n in sorted(contact.indefinite_steps) if n < done),
        "two_solution_steps": {n: r for n, r in sorted(contact.two_solution_steps.items())
                               if n < done}}
    return Solution(problem=problem, status=status, message=message, failure=failure,
                    t=problem.times[:done].copy(), timings=timings,
                    linear=operators.linear, **notes, **recorder.history())


def march(problem, operators, contact, recorder, state, progress=None):
    """Levels n = 0..N from ``state``, each handed to ``recorder``: the
    scheme itself. Returns (status, failure or None, the last state)."""
    for n, t in enumerate(problem.times):
        beta = bonding_step(problem, state)                                  # (4.2)
        b, history = step_load(problem, operators, state, n, t)
        failure = check_load(n, t, b)
        if failure is None:
            level, u, frame_u, z, result = step_solve(problem, operators, contact, n, t, b,
                                                      beta, history, state.z,
                                                      state.z_before)           # (4.1)
            failure = (StepFailure(n, t, result, problem.held_by_contact) if level is None
                       else check_level(problem, level))
            if failure is not None and failure.result is None:
                failure.result = result   # an invalid state: the solve that gave it
        if failure is not None:
            return STEP_FAILED, failure, state
        recorder.record(level)
        state.memory.advance(n, u)   # u_0 only for the trapezoidal rule
        state = State(n=n, t=t, beta=beta, z=z, u=u, frame_u=frame_u, memory=state.memory,
                      z_before=state.z if n >= 1 else None,
                      frame_u_before=state.frame_u if n >= 1 else None)
        if progress is not None and progress(n, problem.options.steps) is True:
            return (STOPPED if n < problem.options.steps else SUCCESS), None, state
    return SUCCESS, None, state
