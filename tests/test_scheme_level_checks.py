"""No quiet wrong answers: a level with non-finite values, β outside
[0, 1] or u_ν beyond the wall stops the run with InvalidState, the history
before it kept."""

import dataclasses
from pathlib import Path

import numpy as np
import pytest
from conftest import level_zero_input, scene_dict

from adhesive_contact import SceneError, build_problem, parse_scene, scene_from_dict, solve
from adhesive_contact.studies.levels import with_discretisation
from adhesive_contact.scheme import STEP_FAILED, InvalidState
from adhesive_contact.scheme.level_checks import check_level
from adhesive_contact.scheme.operators import StepOperators
from adhesive_contact.scheme.state import ContactStep, step_solve

ROOT = Path(__file__).resolve().parents[1]


def debonding(steps):
    text = (ROOT / "studies/scenes/debonding.toml").read_text()
    return build_problem(with_discretisation(parse_scene(text), steps=steps))


def first_level(problem):
    """Level 0 of a run, computed step by step with the scheme's functions."""
    operators = StepOperators.build(problem, problem.options.k)
    step = level_zero_input(problem, operators)
    return step_solve(problem, operators, ContactStep(problem), step).level


def test_explicit_euler_beyond_its_bound_stops_with_the_figures():
    # the bound k <= 1/((gamma_nu + gamma_tau) L^2) = 1/15 with T = 1: 6 steps break it
    problem = debonding(6)
    bound = problem.bonding.stable_step()
    assert problem.scene.k > bound
    sol = solve(problem)
    assert sol.status == STEP_FAILED and isinstance(sol.failure, InvalidState)
    n = sol.failure.n
    assert sol.t.size == n                     # levels 0..n-1 kept
    assert np.all((sol.beta >= 0) & (sol.beta <= 1))
    text = str(sol.failure)
    assert f"step {n} (t = " in text and "leaves [0, 1]" in text
    assert f"k <= {bound:.4g}" in text and f"k = {problem.scene.k:.4g}" in text
    assert f"time.steps = {int(np.ceil(1 / bound))}" in text
    with pytest.raises(InvalidState):
        solve(problem, raise_on_failure=True)


def test_within_the_bound_the_same_scene_runs():
    assert solve(debonding(50)).success


def test_non_finite_load_between_the_checked_times_stops_at_its_step(monkeypatch):
    # no contact boundary: before, a load 0/0 gave exit 0 and an all-NaN u.
    # Validation checks the loads on every level of the run: a load infinite
    # at t_1 = 0.025 only is refused there; without that check (a load no
    # check could see) the scheme stops at the level
    scene = scene_dict({"boundary": {"dirichlet": ["left"], "contact": []},
                        "loads.body": ["1/(t - 0.025)", "0"], "time.steps": 40})
    with pytest.raises(SceneError, match=r"^loads\.body\[0\]: is not finite: inf at "
                                         r"\(0, 0\), t = 0\.025$"):
        build_problem(scene_from_dict(scene))
    import adhesive_contact.problem.build as build
    monkeypatch.setattr(build, "check_loads", lambda *args: None)
    sol = solve(build_problem(scene_from_dict(scene)))
    assert isinstance(sol.failure, InvalidState) and sol.failure.n == 1
    assert "the load (body force" in str(sol.failure) and sol.t.size == 1


def test_a_level_beyond_the_wall_is_named():
    """The exact step solve projects onto the wall, so the check is fed a
    converged level moved beyond it: the node and the excess are named."""
    problem = build_problem(parse_scene((ROOT / "studies/scenes/wall.toml").read_text()))
    level = first_level(problem)
    assert check_level(problem, level) is None
    moved = level.frame_displacement.copy()
    a = 3
    moved[a, 0] = problem.gap.at(0.0)[a] + 1e-3
    failure = check_level(problem, dataclasses.replace(level, frame_displacement=moved))
    x = problem.mesh.p[:, problem.boundary.nodes[a]]
    assert isinstance(failure, InvalidState)
    assert "u_nu - g = 0.001 > 0" in str(failure)
    assert f"({x[0]:.4g}, {x[1]:.4g})" in str(failure)


def test_a_level_with_non_finite_values_is_named():
    problem = build_problem(parse_scene((ROOT / "studies/scenes/wall.toml").read_text()))
    level = first_level(problem)
    for name in ("u", "beta", "stress"):
        broken = getattr(level, name).copy()
        broken.flat[0] = np.inf
        failure = check_level(problem, dataclasses.replace(level, **{name: broken}))
        assert f"{name} is not finite" in str(failure)
