"""u_0 solves the t = 0 problem with the elastic stiffness alone (docs/scheme.md).

With memory, when k R(0) is small beside the elastic tensor, the t = 0
problem is solved by the proximal iteration on the factorisation of
A + k R(0) (scheme.operators); when it is not, A is factorised and its Schur
complement applied, not formed, with the Newton systems solved by CG
preconditioned with the Schur complement of A + k R(0)
(scheme.condensed.ImplicitSchur). Without memory the same problem goes
through the formed, dense Schur complement: the paths must agree.
"""

import numpy as np
import pytest
from conftest import law, prony, scene_dict

from adhesive_contact import build_problem, scene_from_dict, solve
from adhesive_contact.scheme.memory import step_tensor
from adhesive_contact.scheme.operators import StepOperators, contraction

# the strip of conftest.BLOCK pressed onto a wall, sheared, for 3 steps
CHANGES = {"loads.body": ["30*(1 + x)", "-400 - 100*x*(1 + t)"],
         "contact.gap": "0.01 + 0.05*(x - 1)**2",
         "contact.normal": law("compliance", c=5000.0), "time.steps": 3}
MEMORY = prony((300.0, 0.3, 0.2))
# k R(0) beyond the elastic tensor: the proximal iteration would not contract
STRONG = prony((30000.0, 0.3, 0.2))


@pytest.mark.parametrize("memory, proximal", [(MEMORY, True), (STRONG, False)])
@pytest.mark.parametrize("friction", [None, law("tresca", mu=20.0)])
def test_initial_state_with_memory_equals_the_elastic_problem(friction, memory, proximal):
    changes = {**CHANGES, "contact.friction": friction} if friction else CHANGES
    problem = build_problem(scene_from_dict(scene_dict({**changes, "memory": memory})))
    operators = StepOperators.build(problem, problem.options.k)
    assert (operators.shift is not None) == proximal
    assert (operators.initial is operators.step) == proximal
    with_memory = solve(problem)
    without = solve(build_problem(scene_from_dict(scene_dict(changes))))
    u0, ref = with_memory.u[0], without.u[0]
    # the case exercises the wall and (with friction) both stick and slip
    assert with_memory.on_wall[0].any() and not with_memory.on_wall[0].all()
    if friction:
        assert with_memory.stuck[0].any() and not with_memory.stuck[0].all()
    assert np.abs(u0 - ref).max() <= 1e-10 * np.abs(ref).max()
    # and the memory does act afterwards
    assert np.abs(with_memory.u[-1] - without.u[-1]).max() > 1e-3 * np.abs(ref).max()


@pytest.mark.parametrize("dim", [2, 3])
def test_contraction_bounds_the_spectral_radius(dim):
    """ρ((A + D)⁻¹ D) on the free dofs, from a dense generalised eigenproblem,
    lies below the bound of scheme.operators.contraction, which a P1 space
    nearly attains (pure shear and pure dilatation fields exist locally)."""
    import scipy.linalg as la

    changes = {"memory": prony((300.0, 0.45, 0.2)), "time.steps": 2}
    if dim == 3:
        changes.update({"dim": 3, "mesh.domain": "box", "mesh.size": [2.0, 1.0, 1.0],
                        "mesh.cells": [4, 2, 2], "loads.body": ["0", "-400", "0"]})
    problem = build_problem(scene_from_dict(scene_dict(changes)))
    material, k = problem.scene.material, problem.scene.k
    elastic = (material.lam, material.mu)
    shift = step_tensor(problem.options.memory, problem.options.second_order, k)
    free = problem.free
    A = problem.assembly.stiffness(*elastic)[free][:, free].toarray()
    D = problem.assembly.stiffness(*shift)[free][:, free].toarray()
    rho = np.abs(la.eigh(D, A + D, eigvals_only=True)).max()
    bound = contraction(elastic, shift, dim)
    assert 0.0 < bound < 1.0
    assert rho <= bound * (1 + 1e-10)
    assert rho >= 0.9 * bound


def test_a_proximal_iteration_that_does_not_settle_is_a_failed_step():
    """Told a contraction far below the true one, the t = 0 iteration runs
    out of its 14 solves (ρ ≈ 0.27 needs about 25) and the step fails with
    what it reached and what to try, not with an unconverged u."""
    from adhesive_contact.scheme.state import ContactStep, proximal_solve
    from adhesive_contact.step_methods import MAX_ITERATIONS
    from conftest import level_zero_input

    problem = build_problem(scene_from_dict(scene_dict({**CHANGES,
                                                        "memory": prony((1200.0, 0.3, 0.2))})))
    operators = StepOperators.build(problem, problem.options.k)
    assert operators.shift is not None and 0.2 < operators.contraction <= 0.3
    step = level_zero_input(problem, operators)
    contact = ContactStep(problem)
    args = (operators.step, operators.shift, contact, step)
    u, *_, result = proximal_solve(*args, contraction=operators.contraction)
    assert u is not None and result.success
    u, *_, result = proximal_solve(*args, contraction=1e-3)
    assert u is None and result.status == MAX_ITERATIONS
    assert "did not settle in 14 step solves" in result.message
    assert "try a smaller time step" in result.message
