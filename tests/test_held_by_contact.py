"""A body held by its contact terms (docs/model.md, 'A body held by
contact'): which rigid motions the held sides and the contact terms leave
free (the refusal lists exactly those), and scenes loaded by force whose
rigid motions only the contact terms hold, against closed forms and
balances of force."""

import numpy as np
import pytest
from conftest import scene_dict, to_toml
from test_cli import run, strict_json

from adhesive_contact import SceneError, build_problem, scene_from_dict, solve
from adhesive_contact.fem.dirichlet import rigid_modes
from adhesive_contact.postprocess import applied_traction, total_contact_force
from adhesive_contact.scheme.operators import StepOperators

E, NU = 1000.0, 0.3          # the material of conftest.BLOCK (2 × 0.5, 16 × 4 cells)
Q, C = 50.0, 1e4             # the pressure on top and the layer's stiffness

#: a block on a compliant layer pressed by a pressure on its top, on
#: rollers at x = 0: only the layer holds its vertical translation
PRESSED = {"boundary.dirichlet": [], "boundary.displacement": {"left": ["0", "free"]},
           "contact.normal": {"law": "compliance", "c": C},
           "loads.traction": {"top": ["0", f"-{Q}*t"]}, "time.steps": 2}

#: a strip held only by its glue (normal and tangential), pulled at its right end
LAP_SHEAR = {"boundary.dirichlet": [],
             "contact.normal": {"law": "adhesive_compliance", "c": 1e4, "gamma": 5e3,
                                "L": 0.01},
             "contact.friction": {"law": "adhesive_spring", "gamma": 5e3, "L": 0.01},
             "loads.traction": {"right": ["20*t", "0"]}, "time.steps": 2}


def refusal(changes):
    with pytest.raises(SceneError) as err:
        build_problem(scene_from_dict(scene_dict(changes)))
    return str(err.value)


@pytest.mark.parametrize("displacement, free", [
    ({"left": ["0", "free"]}, "translation along y"),
    ({"bottom": ["free", "0"]}, "translation along x"),
    # u_x = 0 along the top y = 0.5 holds one combination of the x
    # translation and the rotation: what is left turns about a point of the top
    ({"top": ["0", "free"]}, "translation along y, rotation about (1, 0.5)"),
    ({"left": ["free", "0"]}, "translation along x, rotation about (0, 0.25)"),
])
def test_the_refusal_lists_exactly_the_motions_the_held_sides_leave(displacement, free):
    message = refusal({"boundary.dirichlet": [], "boundary.contact": [],
                       "boundary.displacement": displacement})
    assert message.startswith(f"boundary: the held sides ({', '.join(displacement)}) leave "
                              f"the body free to move rigidly ({free}): hold more")


@pytest.mark.parametrize("contact, free", [
    # a frictionless wall or layer: the slide along Γ_C
    ({"contact.gap": 0.0}, "translation along x"),
    ({"contact.normal": {"law": "compliance", "c": C}}, "translation along x"),
    # friction alone (no wall, no normal law): the lift off Γ_C, and the
    # turn about a point of Γ_C (which moves it along its normal only)
    ({"contact.friction": {"law": "tresca", "mu": 1.0}},
     "translation along y, rotation about (1, 0)"),
])
def test_a_contact_term_restrains_only_its_own_motions(contact, free):
    message = refusal({"boundary.dirichlet": [], "boundary.displacement": {},
                       **contact, "loads.traction": {"top": ["0", "-1"]}})
    assert f"leave the body free to move rigidly ({free}):" in message
    assert "or add a contact term that restrains it" in message


def test_held_sides_and_contact_terms_together_hold_the_body():
    # rollers on the left hold the slide, the layer the lift and the tilt
    problem = build_problem(scene_from_dict(scene_dict(PRESSED)))
    assert problem.held_by_contact == ("translation along y",)
    assert problem.smallness["held_by_contact"] == ["translation along y"]
    assert problem.smallness["holds"] is False and problem.smallness["rhs"] is None
    assert any(w.startswith("only the contact terms hold the body against translation "
                            "along y") for w in problem.warnings())
    # held on the top as well: nothing is left to the contact terms
    held = build_problem(scene_from_dict(scene_dict({"boundary.dirichlet": ["top"]})))
    assert held.held_by_contact == ()


@pytest.mark.parametrize("linear", ["superlu", "pardiso", "amg"])
def test_a_block_pressed_onto_a_layer_by_a_load_is_the_closed_form(linear):
    """Uniform pressure q on top, rollers at x = 0, a layer of stiffness c
    below: σ_yy = −q, σ_xx = 0, so u_y = −q/c − q(1 − ν²) y/E and
    u_x = qν(1 + ν) x/E (plane strain), linear: P1 is exact, and the
    layer alone sets the amplitude q/c of the vertical translation."""
    problem = build_problem(scene_from_dict(scene_dict({**PRESSED, "solver.linear": linear})))
    sol = solve(problem)
    assert sol.success
    x, y = problem.mesh.p
    for n, t in enumerate(sol.t):
        q = Q * t
        np.testing.assert_allclose(sol.u[n][:, 1], -q / C - q * (1 - NU ** 2) * y / E,
                                   rtol=0, atol=1e-9)
        np.testing.assert_allclose(sol.u[n][:, 0], q * NU * (1 + NU) * x / E, rtol=0,
                                   atol=1e-9)


def test_the_interior_is_regular_and_the_free_motion_is_the_kernel_of_S():
    """A_II (the free dofs off the contact unknowns) is nonsingular: its
    solves are exact; S = A_CC − A_CI A_II⁻¹ A_IC has the vertical
    translation (u_ν = −1 at every contact node) in its kernel, and no other
    direction of S is that small."""
    problem = build_problem(scene_from_dict(scene_dict(PRESSED)))
    operators = StepOperators.build(problem, problem.options.k)
    step = operators.step
    A = problem.assembly.stiffness(problem.scene.material.lam, problem.scene.material.mu)
    R = operators.rotation                    # the nodal frames of Γ_C
    free = problem.free
    A_II = (R.T @ A @ R).tocsr()[free][:, free][step.interior][:, step.interior]
    b = np.random.default_rng(0).standard_normal(step.interior.size)
    x = step.solver.solve(b)
    assert np.linalg.norm(A_II @ x - b) <= 1e-10 * np.linalg.norm(b)
    S = step.S.matrix
    lift = np.zeros(S.shape[0])
    lift[:] = -1.0                       # the contact unknowns are the normals u_ν
    assert problem.columns.size == problem.boundary.nodes.size
    assert np.linalg.norm(S @ lift) <= 1e-10 * np.abs(S).max() * np.linalg.norm(lift)
    eigenvalues = np.linalg.eigvalsh(S)
    assert eigenvalues[1] > 1e-6 * eigenvalues[-1]     # one null direction only


def test_a_lap_shear_strip_held_only_by_its_glue_balances_its_load():
    problem = build_problem(scene_from_dict(scene_dict(LAP_SHEAR)))
    assert problem.held_by_contact == ("translation along x", "translation along y",
                                       "rotation")
    sol = solve(problem)
    assert sol.success
    pulled = applied_traction(problem, "right", sol.t)
    np.testing.assert_allclose(pulled[-1], [20.0 * 0.5, 0.0], rtol=1e-12, atol=1e-12)
    # the glue's force balances the pull: no support takes any of it
    np.testing.assert_allclose(total_contact_force(sol) + pulled, 0.0, atol=1e-8)
    # the glue's moment about the origin balances the pull's, 20 H · H/2
    # (small strain: the discrete forces are orthogonal to the rotation mode)
    forces = np.einsum("aic,ac->ai", problem.boundary.frame, sol.contact_force[-1])
    xc = problem.mesh.p[:, problem.boundary.nodes]
    moment = np.sum(xc[0] * forces[:, 1] - xc[1] * forces[:, 0])
    assert moment == pytest.approx(20.0 * 0.5 * 0.25, rel=1e-8)


def test_the_rigid_modes_of_the_check_are_the_kernel_of_the_stiffness():
    # rigid_modes spans the kernel of the stiffness: K m = 0 for each column
    problem = build_problem(scene_from_dict(scene_dict(PRESSED)))
    modes = rigid_modes(problem.mesh.p)
    K = problem.assembly.stiffness(problem.scene.material.lam, problem.scene.material.mu)
    assert np.abs(K @ modes).max() <= 1e-10 * abs(K).max()


def test_a_load_past_what_the_contact_terms_hold_exits_1_and_says_so(tmp_path):
    # Tresca's bound 1 on |Γ_C| = 2 holds a shear of at most 2; the rollers
    # on top leave the slide to the friction, and the pull is 2.5
    data = scene_dict({"boundary.dirichlet": [], "boundary.displacement": {"top": ["free", "0"]},
                       "contact.friction": {"law": "tresca", "mu": 1.0},
                       "loads.traction": {"right": ["5", "0"]}})
    path = tmp_path / "overload.toml"
    path.write_text(to_toml(data))
    result = run("solve", path, "--out", tmp_path / "out")
    assert result.exit_code == 1
    assert "did not converge" in result.stderr
    assert ("Only the contact terms hold the body against translation along x: a load they "
            "cannot balance") in result.stderr
    assert "Traceback" not in result.stderr


def test_a_scene_nothing_restrains_exits_2_with_the_free_motions(tmp_path):
    data = scene_dict({"boundary.dirichlet": [], "contact.gap": 0.0,
                       "loads.traction": {"top": ["0", "-1"]}})
    path = tmp_path / "sliding.toml"
    path.write_text(to_toml(data))
    result = run("solve", path, "--out", tmp_path / "out")
    assert result.exit_code == 2
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1 and "Traceback" not in result.stderr
    assert lines[0].startswith("error: boundary: the held sides (none) and the contact terms "
                               "on Γ_C (a wall) leave the body free to move rigidly "
                               "(translation along x): ")


def test_the_summary_and_check_of_a_body_held_by_contact(tmp_path):
    path = tmp_path / "pressed.toml"
    path.write_text(to_toml(scene_dict(PRESSED)))
    result = run("solve", path, "--out", tmp_path / "out")
    assert result.exit_code == 0, result.stderr
    small = strict_json(tmp_path / "out" / "summary.json")["smallness"]
    assert small["held_by_contact"] == ["translation along y"]
    assert small["holds"] is False and small["trace_constant_squared"] is None
    checked = run("check", path)
    assert checked.exit_code == 0
    assert ("the conditions do not apply: only the contact terms hold the body against "
            "translation along y") in checked.output


#: a 1 × 0.5 × 1 box on a compliant layer at its bottom (y = 0), pressed on top
BOX = {"dim": 3, "mesh": {"domain": "box", "size": [1.0, 0.5, 1.0], "cells": [4, 2, 4]},
       "boundary": {"dirichlet": [], "contact": ["bottom"]},
       "material": {"E": 1000.0, "nu": 0.3},
       "loads": {"traction": {"top": ["0", "-10*t", "0"]}},
       "contact": {"normal": {"law": "compliance", "c": 1e4}},
       "time": {"T": 1.0, "steps": 1}}


@pytest.mark.parametrize("displacement, held", [
    # u_x = u_z = 0 on the left: only the vertical translation is left, which
    # the layer holds; its SVD basis vector has a rotation part of round-off
    # size, which was named a rotation about an axis through a point 1e15 away
    ({"left": ["0", "free", "0"]}, ("translation along y",)),
    ({"front": ["0", "free", "0"]}, ("translation along y",)),
    # u_x = u_z = 0 on the top y = 0.5: the turns about x and z through a
    # point of the top, the one of each axis nearest the centroid
    ({"top": ["0", "free", "0"]}, ("translation along y",
                                   "rotation about the axis along x through (0.5, 0.5, 0.5)",
                                   "rotation about the axis along z through (0.5, 0.5, 0.5)")),
])
def test_3d_a_translation_held_by_contact_is_named_a_translation(displacement, held):
    problem = build_problem(scene_from_dict(scene_dict(
        {"boundary.displacement": displacement}, base=BOX)))
    assert problem.held_by_contact == held
    line = next(w for w in problem.warnings() if w.startswith("only the contact terms"))
    assert line.startswith(f"only the contact terms hold the body against {', '.join(held)}:")
    assert "e+" not in line


def test_3d_the_refusal_names_the_free_translation_alone():
    """u_x held on the left, the layer holding the lift and the tilts: the
    slide along z is free, and named so (not a rotation with a shift)."""
    with pytest.raises(SceneError) as err:
        build_problem(scene_from_dict(scene_dict(
            {"boundary.displacement": {"left": ["0", "free", "free"]}}, base=BOX)))
    message = str(err.value)
    assert "leave the body free to move rigidly (translation along z):" in message
