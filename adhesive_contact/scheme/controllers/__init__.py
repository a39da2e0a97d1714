"""Step controllers: which steps a run takes and which levels it keeps
(:func:`~adhesive_contact.scheme.march.march` runs one).

A controller has ``first_step`` (the step k whose operators level 0 is
solved with), ``run(stepper, progress)`` (level 0, then its steps, each
kept level handed to ``stepper.keep``; returns (status, failure or
None)) and ``facts(stepper)`` (its figures for summary.json, or None).

- :class:`Uniform`: k = T/N, the paper's grid t_n = n k;
- :class:`StepDoubling`: ``[time.adaptive]``, steps k_max 2^{−j} judged by
  step doubling (docs/scheme.md, "Adaptive time steps").

:func:`controller_of` gives the one of a problem's options.
"""

from .step_doubling import StepDoubling
from .uniform import Uniform


def controller_of(problem):
    """The controller of ``problem``'s options: StepDoubling for
    ``[time.adaptive]``, else Uniform."""
    if problem.options.adaptive is not None:
        return StepDoubling.of(problem)
    return Uniform(problem.options.T, problem.options.steps)


__all__ = ["StepDoubling", "Uniform", "controller_of"]
