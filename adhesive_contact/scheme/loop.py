"""The run of a problem: :func:`solve`, the march (:mod:`.march`) with the
step controller of its options (:mod:`.controllers`): the paper's uniform
steps k = T/N, or ``[time.adaptive]``'s step doubling.

With ``time.scheme = "second-order"`` the memory is the trapezoidal rule
(step matrix A + (k/2) R(0)) and β_n the exponential midpoint step with
the rate at t_{n−½} (:func:`.state.bonding_step`); the contact step is the
same, at t_n.
"""

from .controllers import controller_of
from .march import march


def solve(problem, progress=None, raise_on_failure=False, recorder=None, controller=None):
    """Run the scheme on a :class:`~adhesive_contact.problem.Problem`.

    Parameters
    ----------
    problem : Problem (never changed by the run)
    progress : callable ``progress(done, total)``, called after each kept
        level (for uniform steps ``progress(n, N)``); a return value of
        True stops the run (status STOPPED)
    raise_on_failure : raise :class:`StepFailure` when a step does not
        converge or gives an invalid state (:mod:`.level_checks`), instead
        of returning the history up to it
    recorder : what to keep per level (default :class:`HistoryRecorder`)
    controller : the step controller (:mod:`.controllers`; default that of
        the problem's options)

    Returns
    -------
    Solution : ``success``, ``status``, ``message`` say how the run ended.
    """
    controller = controller_of(problem) if controller is None else controller
    return march(problem, controller, progress, raise_on_failure, recorder)
