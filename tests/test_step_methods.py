"""Step methods (solver.method): "newton", "newton-plain", "penalty" and
"optimizer" on the same discrete step problem of (4.1).

- where two exact methods converge they agree to 1e-6 relative, and each
  reports its iterations and residual per step;
- "penalty" leaves a wall violation ≈ λ/ρ, ∝ 1/solver.penalty, that the
  wall check of the exact methods does not trip on, and its distance to the
  exact solution falls with it;
- each method's failure mode, provoked on a small scene, is a failed step
  with its message and the history before it (exit 1 on the command line).
"""

import numpy as np
import pytest
from conftest import law, scene_dict, to_toml
from test_cli import run as run_cli
from test_cli import strict_json

from adhesive_contact import SceneError, build_problem, scene_from_dict, solve
from adhesive_contact.scheme import STEP_FAILED
from adhesive_contact.scheme.level_checks import WALL_SLACK, check_level
from adhesive_contact.step_methods import (
    MAX_ITERATIONS,
    METHODS,
    OPTIMIZER_STOPPED,
    StepOptions,
    minimise,
)
from adhesive_contact.step_methods.newton import minimise_step

TRESCA = law("tresca", mu=5.0)
WEAKENING = law("nonmonotone", a=8.0, b=4.0, alpha=50.0)
SHEAR, PRESS = ("150*x*t", "-80*t"), ("0", "-150*t")


def scene(method, friction=(), body=PRESS, gap=0.002, steps=2, **solver):
    changes = {"mesh.cells": [16, 4], "loads.body": list(body),
               "contact.normal": law("compliance", c=1e4), "contact.friction": list(friction),
               "time.steps": steps, "solver": {"method": method, **solver}}
    if gap is not None:
        changes["contact.gap"] = gap
    return scene_dict(changes)


def run(method, *args, **kwargs):
    problem = build_problem(scene_from_dict(scene(method, *args, **kwargs)))
    return problem, solve(problem)


def relative(a, b):
    return np.abs(a - b).max() / np.abs(b).max()


@pytest.mark.parametrize("method, friction, body, gap, tol", [
    ("newton-plain", (), PRESS, 0.002, 1e-10),      # the wall, frictionless
    ("newton-plain", (TRESCA,), SHEAR, None, 1e-10),  # Tresca, no wall
    ("optimizer", (), PRESS, 0.002, 1e-7),
    ("optimizer", (TRESCA,), SHEAR, 0.002, 1e-7),   # Tresca and the wall
])
def test_exact_methods_that_converge_agree(method, friction, body, gap, tol):
    _, ref = run("newton", friction, body, gap)
    problem, sol = run(method, friction, body, gap, tol=tol)
    assert ref.success and sol.success, sol.message
    # Tolerance: both stop at a relative pseudo-gradient ≤ tol ≤ 1e-7, the
    # step energy strictly convex here: measured ≤ 1.2e-8 apart
    assert relative(sol.u, ref.u) <= 1e-6
    # each method reports its iterations and residual per step
    assert np.all(sol.iterations[1:] >= 1) and np.all(sol.residual <= tol)
    if gap is not None:
        assert (ref.on_wall[-1] == sol.on_wall[-1]).all() and ref.on_wall[-1].any()


def test_l_bfgs_b_does_not_reach_the_newton_tolerance():
    """The optimizer stops about 1e-8 relative: tol = 1e-10 (the default)
    fails with L-BFGS-B's own reason, and the history before it kept."""
    _, sol = run("optimizer", (), PRESS)
    assert sol.status == STEP_FAILED and sol.failure.n == 1 and sol.t.size == 1
    assert sol.failure.result.status == OPTIMIZER_STOPPED
    assert "stopped short of the tolerance (L-BFGS-B: " in str(sol.failure)


def test_penalty_violation_falls_as_one_over_the_penalty():
    _, ref = run("newton", (TRESCA,), SHEAR)
    violation, distance = [], []
    for p in (1e3, 1e4, 1e5):
        problem, sol = run("penalty", (TRESCA,), SHEAR, penalty=p)
        assert sol.success
        violation.append(sol.gap_violation().max())
        distance.append(relative(sol.u, ref.u))
        # the wall check of the exact methods does not apply to it
        assert violation[-1] > 0
    violation, distance = np.array(violation), np.array(distance)
    # ρ (u_ν − g) ≈ λ, fixed by the solution: ×10 in ρ is ÷10 in the
    # violation (measured 9.94–9.99) and in the distance to the exact run
    np.testing.assert_allclose(violation[:-1] / violation[1:], 10.0, rtol=0.02)
    np.testing.assert_allclose(distance[:-1] / distance[1:], 10.0, rtol=0.02)
    # the exact method stays on the wall's side to round-off (scheme.level_checks.WALL_SLACK)
    assert ref.gap_violation().max() <= WALL_SLACK * (1.0 + np.abs(ref.normal_displacement).max())


def test_the_wall_check_still_applies_to_the_exact_methods():
    """The same penalty level handed to the check as if from "newton" trips it."""
    problem, sol = run("penalty", (TRESCA,), SHEAR, penalty=1e3)
    exact_problem = build_problem(scene_from_dict(scene("newton", (TRESCA,), SHEAR)))

    class Level:
        n, t = 2, sol.t[2]           # the wall is reached at t = 1
        u, beta, stress = sol.u[2], sol.beta[2], sol.stress[2]
        frame_displacement = sol.frame_displacement[2]
        gap, k = sol.gap[2], sol.t[1]

    assert check_level(problem, Level) is None
    failure = check_level(exact_problem, Level)
    assert failure is not None and "the rigid wall is crossed" in str(failure)


def test_too_large_a_penalty_fails_to_reach_the_tolerance():
    """ρ = 1e8 max S_ii: the gradient is round-off times ρ, above tol."""
    _, sol = run("penalty", (TRESCA,), SHEAR, penalty=1e8)
    assert sol.status == STEP_FAILED and sol.failure.result.status == MAX_ITERATIONS
    assert sol.t.size == sol.failure.n >= 1


def test_plain_newton_cycles_where_the_globalised_one_converges():
    """Tresca friction against the wall: the full Newton step alternates
    between active sets; the line search of "newton" settles them."""
    _, ref = run("newton", (TRESCA,), SHEAR)
    _, sol = run("newton-plain", (TRESCA,), SHEAR)
    # (the count depends on round-off: 7 with PARDISO's S, 12 with SuperLU's;
    # so does the step at which the full steps start to cycle: the first or
    # the second of the two, as the load is summed in one order or another)
    assert ref.success and ref.iterations.max() <= 15
    assert sol.status == STEP_FAILED and sol.failure.result.status == MAX_ITERATIONS
    assert sol.failure.result.residual > 1e-3 and sol.t.size == sol.failure.n


def test_plain_newton_failure_on_the_command_line(tmp_path):
    path = tmp_path / "scene.toml"
    path.write_text(to_toml(scene("newton-plain", (TRESCA,), SHEAR)))
    result = run_cli("solve", path, "--out", tmp_path / "out")
    assert result.exit_code == 1
    errors = [line for line in result.stderr.splitlines() if line.startswith("error: ")]
    assert len(errors) == 1 and "no convergence in 50 iterations" in errors[0]
    assert "Traceback" not in result.stderr
    summary = strict_json(tmp_path / "out" / "summary.json")
    # the levels before the failed step (which of the two: see the test above)
    assert summary["run"]["partial"] and len(summary["steps"]) == summary["run"]["failed_step"]
    assert summary["scene"]["solver"]["method"] == "newton-plain"


def test_penalty_run_reports_its_violation_in_summary(tmp_path):
    path = tmp_path / "scene.toml"
    path.write_text(to_toml(scene("penalty", (TRESCA,), SHEAR, penalty=1e3)))
    result = run_cli("solve", path, "--out", tmp_path / "out")
    assert result.exit_code == 0, result.stderr
    summary = strict_json(tmp_path / "out" / "summary.json")
    assert summary["scene"]["solver"] == {"method": "penalty", "tol": 1e-10, "max_iter": 50,
                                          "linear": "auto", "penalty": 1e3,
                                          "smoothing": 1e-6}
    # max_a (u_ν − g) > 0 in the steps (7.7e-7 at t = 1)
    assert summary["steps"][-1]["max_penetration"] > 5e-7


def test_slip_weakening_each_method_reports_how_it_ended():
    """Nonconvex friction (α(a − b) = 200) against the wall: "newton" and
    "penalty" converge, "newton-plain" cycles, L-BFGS-B stops at the kink."""
    outcome = {m: run(m, (WEAKENING,), SHEAR, tol=1e-7 if m == "optimizer" else 1e-10)[1]
               for m in METHODS}
    assert outcome["newton"].success and outcome["penalty"].success
    assert outcome["newton-plain"].failure.result.status == MAX_ITERATIONS
    # L-BFGS-B on this nonsmooth energy stops at the kink or gets through,
    # by round-off: with PARDISO's S it stops, with SuperLU's (equal to
    # 1e-16) it converges in 39 iterations. Either way it says so, and a
    # success agrees with Newton (measured 2.3e-8)
    optimizer = outcome["optimizer"]
    if optimizer.success:
        assert relative(optimizer.u, outcome["newton"].u) <= 1e-6
    else:
        assert optimizer.failure.result.status == OPTIMIZER_STOPPED
    # penalty solves a nearby problem: within 1e-5 (measured 6e-6)
    assert relative(outcome["penalty"].u, outcome["newton"].u) <= 1e-5


def test_the_interface_and_the_old_import_agree():
    problem, sol = run("newton", (TRESCA,), SHEAR, steps=1)
    from adhesive_contact.scheme.operators import StepOperators
    ops = StepOperators.build(problem, problem.options.k)
    step = ops.at(False)
    c = step.reduce(ops.to_frames(problem.loads(1.0)))
    from adhesive_contact.scheme.state import ContactStep
    contact = ContactStep(problem)
    contact.energy.set_bonding(problem.beta0)
    contact.kink.radius = contact.energy.node_kink(problem.boundary.point_node,
                                                   problem.boundary.nodes.size)
    z0, upper = np.zeros(c.size), problem.upper_bound(None)
    new = minimise("newton", step.S, c, contact.energy, upper, z0, StepOptions(), contact.kink)
    old = minimise_step(step.S, c, contact.energy, upper, z0, kink=contact.kink)
    assert new.success and np.array_equal(new.z, old.z) and new.nit == old.nit


def test_unknown_method_and_bad_penalty_are_refused():
    with pytest.raises(SceneError, match=r"^solver\.method: must be one of 'newton', "
                                         r"'newton-plain', 'penalty', 'optimizer', got 'cg'$"):
        scene_from_dict(scene("cg"))
    with pytest.raises(SceneError, match=r"^solver\.penalty: must be > 0, got -1$"):
        scene_from_dict(scene("penalty", penalty=-1.0))
    with pytest.raises(SceneError, match=r"^solver\.smoothing: must be > 0, got 0$"):
        scene_from_dict(scene("penalty", smoothing=0.0))


class TrescaNode:
    """Φ(ξ) = κ |ξ| on one node's tangential unknowns ξ ∈ R^m (z = ξ): the
    contact terms of a Tresca node, for closed-form step problems."""

    def __init__(self, kappa, m):
        self.kappa, self.unknowns = kappa, np.arange(m)

    def value(self, z):
        return self.kappa * np.linalg.norm(z)

    def gradient(self, z):
        s = np.linalg.norm(z)
        return self.kappa * z / s if s > 0 else np.zeros_like(z)

    def hessian(self, z, s_floor=0.0, kink_free=False):
        import scipy.sparse as sp
        m, s = z.size, max(np.linalg.norm(z), s_floor)
        if kink_free or m == 1 or s == 0:
            return sp.csr_matrix((m, m))
        e = z / s
        return sp.csr_matrix(self.kappa / s * (np.eye(m) - np.outer(e, e)))


def tresca_step(m, c, z0, **options):
    """min ½ s|ξ|² − cᵀξ + κ|ξ| (s = 4, κ = 1) from z0: its closed form
    ξ* = (|c| − κ)₊/s ĉ, and the "newton" result."""
    from adhesive_contact.scheme.condensed import DenseSchur
    from adhesive_contact.step_methods import Kink

    s, kappa, c = 4.0, 1.0, np.asarray(c, dtype=float)
    exact = max(np.linalg.norm(c) - kappa, 0.0) / s * c / np.linalg.norm(c)
    result = minimise_step(DenseSchur(s * np.eye(m)), c, TrescaNode(kappa, m), np.full(m, np.inf),
                           np.asarray(z0, dtype=float), tol=1e-12,
                           kink=Kink(np.arange(m)[None, :], np.array([kappa])), **options)
    return exact, result


def test_a_slip_direction_turns_within_one_newton_iteration():
    """2D: a node slipping forwards (ξ0 > 0) whose load now drives it
    backwards: the semismooth step reaches ξ* = (c + κ)/s < 0 in one
    iteration (the energy is quadratic on each side of the kink); holding
    the direction for the step first stops the node at 0."""
    exact, result = tresca_step(1, [-3.0], [0.3])
    assert result.success and result.nit == 1
    assert abs(result.z[0] - exact[0]) <= 1e-14
    _, held = tresca_step(1, [-3.0], [0.3], semismooth=False)
    assert held.success and held.nit >= 2
    assert abs(held.z[0] - exact[0]) <= 1e-14


@pytest.mark.parametrize("c, z0", [([3.0, 0.0], [0.0, 0.4]),     # slipping across: turns 90°
                                   ([-3.0, 1.0], [0.5, 0.1]),    # nearly reversed
                                   ([0.6, 0.5], [0.2, -0.3])])   # |c| < κ: it must stick
def test_a_3d_slip_direction_turns_to_the_closed_form(c, z0):
    """3D (two tangential unknowns): from a slip at an angle to the load,
    the step converges to the closed form of the Tresca node, and a node
    whose load is inside the friction bound ends stuck (ξ = 0 exactly)."""
    exact, result = tresca_step(2, c, z0)
    assert result.success and result.nit <= 6
    assert np.abs(result.z - exact).max() <= 1e-12
    assert bool(result.stuck[0]) == (np.linalg.norm(c) <= 1.0)


class NoContact:
    """Φ = 0 on all of z: the step problem is the quadratic ½ zᵀSz − cᵀz."""

    def __init__(self, m):
        self.unknowns = np.arange(m)

    def value(self, z):
        return 0.0

    def gradient(self, z):
        return np.zeros_like(z)

    def hessian(self, z, s_floor=0.0, kink_free=False):
        import scipy.sparse as sp
        return sp.csr_matrix((z.size, z.size))


def test_a_last_newton_step_is_not_lost_in_the_round_off_of_a_far_moved_body():
    """A body moved far along a soft mode (a cantilever lifted off its
    glue: |S| |z|² ≫ |E|) from a start a small force off equilibrium. The
    Newton step lands on z* to round-off, but ½ zᵀSz − cᵀz, a difference
    of terms of size |S||z|², moves by more than the round-off allowance of
    the line search (1e-13 |E|) while the true decrease is ~1e-18: judged
    by totals the step was refused for ever (residual 1.8e-7, 50
    iterations, on the strip of studies/convergence/adaptive held after it
    debonded). Judged by the change from the iterate, (Sz − c)·Δ + ½ΔᵀSΔ,
    it is taken at once."""
    from adhesive_contact.scheme.condensed import DenseSchur

    m = 80
    for seed in (0, 2):     # two draws whose totals refused the step (the others
        rng = np.random.default_rng(seed)   # passed by the luck of the round-off)
        Q, _ = np.linalg.qr(rng.standard_normal((m, m)))
        stiffness = np.full(m, 1e3)
        stiffness[0] = 1e-3                   # the soft mode
        S = (Q * stiffness) @ Q.T
        z_star = 100.0 * Q[:, 0] + 1e-2 * rng.standard_normal(m)
        c = S @ z_star
        z0 = z_star + 1e-9 * Q[:, 1]          # 1e-6 off in force, stiffness 1e3
        result = minimise_step(DenseSchur(S), c, NoContact(m), np.full(m, np.inf), z0,
                               tol=1e-10)
        assert result.success and result.nit == 1
        # z* to the conditioning (1e6) times the round-off of |z| = 100
        assert np.abs(result.z - z_star).max() <= 1e-8
