"""The warnings a run gives from what it shows (problem/warnings.py): the
step energy not locally strictly convex at a solution, a step with two
solutions, and none for the built-in scene (whose smallness condition
fails by orders of magnitude: the theory's sufficient conditions are
recorded, not warned about)."""

from types import SimpleNamespace

import numpy as np
import scipy.sparse as sp
from click.testing import CliRunner
from conftest import law, scene_dict

from adhesive_contact import build_problem, scene_from_dict, solve
from adhesive_contact.problem.warnings import (
    nonconvex_step_warning,
    solution_warnings,
    step_list,
)
from adhesive_contact.scheme.condensed import DenseSchur, dense_solver
from adhesive_contact.scheme.full_system import truncated_cg
from adhesive_contact_cli.main import main


def weakening(T, steps):
    """A soft strip sheared over slip-weakening friction (a = 10 falling to
    b = 5 over 1/300 of slip): nonconvex steps, one with two solutions."""
    return scene_from_dict(scene_dict({
        "material": {"E": 100.0, "nu": 0.3}, "loads.body": ["40*x*t", "-40*t"],
        "contact.normal": law("compliance", c=1e4),
        "contact.friction": [law("nonmonotone", a=10.0, b=5.0, alpha=300.0)],
        "time.T": T, "time.steps": steps}))


def test_a_step_with_two_solutions_is_named_and_another_run_finds_the_other():
    """The run flags step 17 (t = 0.85): from Γ_C at rest the same step
    reaches another solution. A separate one-step run to t = 0.85 (no
    memory, so its step is the same minimisation, started at rest) ends
    at a contact displacement that differs from the run's by what the
    warning says. Step 12 (t = 0.6), where the slip front snaps on (17
    Newton iterations), has two solutions as well: the run started with the
    stick front moved on (ContactStep.front_moved_on) reaches one whose
    frame displacement is 2 % off the one the start without it reached,
    meets an indefinite Newton matrix on the way, and its second start from
    rest ends 5 % off in the contact unknowns; from step 13 on the runs
    with and without the front moved on agree to round-off."""
    sol = solve(build_problem(weakening(1.0, 20)))
    assert sol.success and sorted(sol.two_solution_steps) == [12, 17]
    (line,) = [w for w in solution_warnings(sol) if "more than one solution" in w]
    assert line.startswith("steps 12, 17 (t = 0.6, 0.85) have more than one solution")
    one = solve(build_problem(weakening(0.85, 1)))
    assert one.success
    a, b = sol.frame_displacement[17], one.frame_displacement[-1]
    difference = np.abs(a - b).max() / max(np.abs(a).max(), np.abs(b).max())
    assert difference > 1e-3
    assert abs(difference - sol.two_solution_steps[17]) <= 0.01 * difference
    # the steps before it, on one branch: the separate run agrees there
    early = solve(build_problem(weakening(0.5, 1)))
    assert np.allclose(early.frame_displacement[-1], sol.frame_displacement[10],
                       rtol=1e-6, atol=1e-9 * np.abs(sol.frame_displacement[10]).max())


def test_the_built_in_scene_prints_no_warning(tmp_path):
    result = CliRunner().invoke(main, ["solve", "--out", str(tmp_path / "out")])
    assert result.exit_code == 0, result.stderr
    assert "warning:" not in result.stderr


def test_steps_are_listed_as_ranges_with_their_times():
    t = np.linspace(0.0, 1.0, 11)
    assert step_list([3, 4, 5, 9], t) == "steps 3–5, 9 (t = 0.3–0.5, 0.9)"
    assert step_list([2], t) == "step 2 (t = 0.2)"
    assert step_list(list(range(0, 20, 2)), np.arange(20.0), most=2) == \
        "steps 0, 2 and 8 more ranges (t = 0, 2)"
    line = nonconvex_step_warning(SimpleNamespace(indefinite_steps=(3, 4), t=t))
    assert line.startswith("the step energy is not locally strictly convex at the solution "
                           "of steps 3–4 (t = 0.3–0.4)")
    assert nonconvex_step_warning(SimpleNamespace(indefinite_steps=(), t=t)) is None


def test_an_indefinite_newton_matrix_is_flagged_and_a_definite_one_is_not():
    """dense_solver flags a matrix with a negative eigenvalue; not an SPD
    one, nor a PSD one whose Cholesky fails on round-off only; the dense
    Schur operator passes the flag of its last Newton system on."""
    rng = np.random.default_rng(0)
    Q, _ = np.linalg.qr(rng.standard_normal((30, 30)))
    spd = Q @ np.diag(np.linspace(1.0, 10.0, 30)) @ Q.T
    indefinite = Q @ np.diag(np.r_[np.linspace(1.0, 10.0, 29), -0.5]) @ Q.T
    singular = Q @ np.diag(np.r_[np.linspace(1.0, 10.0, 29), 0.0]) @ Q.T
    assert dense_solver(spd).indefinite is False
    assert dense_solver(indefinite).indefinite is True
    assert dense_solver(singular).indefinite is False
    S = DenseSchur(spd)
    free = np.ones(30, dtype=bool)
    S.newton_solve(sp.csr_matrix((30, 30)), np.ones(30), free)
    assert S.indefinite is False and S.indefinite_solves == 0
    S.newton_solve(sp.csr_matrix(indefinite - spd), np.ones(30), free)
    assert S.indefinite is True and S.indefinite_solves == 1
    met = []
    truncated_cg(lambda v: indefinite @ v, lambda r: r, np.ones(30), 1e-12, 0.0, 200,
                 on_negative_curvature=lambda: met.append(1))
    truncated_cg(lambda v: spd @ v, lambda r: r, np.ones(30), 1e-12, 0.0, 200,
                 on_negative_curvature=lambda: met.append(2))
    assert met == [1]
