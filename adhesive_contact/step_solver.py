"""Kept for imports written before the step methods became a subpackage:
the "newton" method, :mod:`adhesive_contact.step_methods.newton`."""

from .step_methods.newton import (  # noqa: F401
    CONVERGED,
    DIVERGED,
    LINE_SEARCH_FAILED,
    MAX_ITERATIONS,
    Kink,
    StepResult,
    minimise_step,
)
