"""The paper's uniform steps: k = T/N, levels t_n = n k, n = 0..N."""

import numpy as np

from ..solution import STEP_FAILED, STOPPED, SUCCESS


class Uniform:
    """k = T/N, every level kept (:mod:`..controllers`)."""

    def __init__(self, T, steps):
        self.steps = int(steps)
        self.first_step = T / self.steps
        self.times = self.first_step * np.arange(self.steps + 1)

    def run(self, stepper, progress=None):
        """Level 0, then the steps n = 1..N: (status, failure or None)."""
        N = self.steps
        taken, failure = stepper.level_zero(self.first_step)
        if failure is not None:
            return STEP_FAILED, failure
        state, level = taken
        stepper.keep(level, 0)
        if progress is not None and progress(0, N) is True:
            return (STOPPED if N > 0 else SUCCESS), None
        for n in range(1, N + 1):
            taken, failure = stepper.step(state, n, float(self.times[n]), self.first_step)
            if failure is not None:
                return STEP_FAILED, failure
            state, level = taken
            stepper.keep(level, n)
            if progress is not None and progress(n, N) is True:
                return (STOPPED if n < N else SUCCESS), None
        return SUCCESS, None

    def facts(self, stepper):
        """None: a uniform run has no controller figures."""
        return None
