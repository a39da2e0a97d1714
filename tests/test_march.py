"""The one time march (scheme/march.py) with any step controller
(scheme/controllers): the uniform controller given explicitly is the
default run, and a controller of one's own with unequal steps gives, on a
path-independent problem (an elastic block pressed onto a compliant
layer and a wall, no memory, friction or bonding: each level is the
minimiser of a convex energy at its t), the levels of the uniform run at
the same times."""

import numpy as np
import pytest
from conftest import law, scene_dict

from adhesive_contact import build_problem, scene_from_dict, solve
from adhesive_contact.scheme.controllers import Uniform, controller_of
from adhesive_contact.scheme.solution import STEP_FAILED, SUCCESS

BLOCK = scene_dict({
    "mesh.size": [2.0, 1.0], "mesh.cells": [8, 4], "loads.body": ["0", "-400*t"],
    "contact.gap": "0.002 + 0.01*(x - 1)**2", "contact.normal": law("compliance", c=5000.0),
    "time.steps": 4})


class Listed:
    """A controller of one's own: the steps of a list, every level kept."""

    def __init__(self, steps):
        self.steps = list(steps)
        self.first_step = self.steps[0]

    def run(self, stepper, progress=None):
        taken, failure = stepper.level_zero(self.first_step)
        if failure is not None:
            return STEP_FAILED, failure
        state, level = taken
        stepper.keep(level, 0)
        t = 0.0
        for index, k in enumerate(self.steps, start=1):
            t += k
            taken, failure = stepper.step(state, index, t, k)
            if failure is not None:
                return STEP_FAILED, failure
            state, level = taken
            stepper.keep(level, index)
        return SUCCESS, None

    def facts(self, stepper):
        return None


def test_the_uniform_controller_is_the_default_run():
    problem = build_problem(scene_from_dict(BLOCK))
    assert isinstance(controller_of(problem), Uniform)
    default = solve(problem)
    given = solve(problem, controller=Uniform(problem.options.T, problem.options.steps))
    for name in ("t", "u", "beta", "contact_force", "reaction", "gap"):
        np.testing.assert_array_equal(getattr(given, name), getattr(default, name))


def test_a_controller_of_ones_own_meets_the_uniform_levels_at_its_times():
    problem = build_problem(scene_from_dict(BLOCK))
    uniform = solve(problem)
    unequal = solve(problem, controller=Listed([0.25, 0.25, 0.5]))
    assert uniform.success and unequal.success
    np.testing.assert_allclose(unequal.t, [0.0, 0.25, 0.5, 1.0], rtol=0, atol=1e-15)
    assert uniform.on_wall[-1].any()                  # the wall acts at T
    scale = np.abs(uniform.u).max()
    for n, m in ((0, 0), (1, 1), (2, 2), (3, 4)):
        # each level minimises a strictly convex energy at its own t, whatever
        # the steps before it: the step solves' tolerance (1e-10) is the floor
        assert np.abs(unequal.u[n] - uniform.u[m]).max() <= 1e-8 * scale
        np.testing.assert_array_equal(unequal.gap[n], uniform.gap[m])
    # the level numbers are the kept levels', the steps the controller's
    assert unequal.t.size == 4 and np.allclose(np.diff(unequal.t), [0.25, 0.25, 0.5])


def test_a_failed_step_of_a_controller_keeps_the_levels_before_it():
    data = dict(BLOCK)
    data["solver"] = {"max_iter": 1}
    problem = build_problem(scene_from_dict(data))
    solution = solve(problem, controller=Listed([0.25, 0.25, 0.5]))
    assert solution.status == STEP_FAILED and not solution.success
    assert solution.t.size == solution.failure.n >= 1
    assert "did not converge" in solution.message
