"""Prescribed displacements ([boundary.displacement]), the reactions of the
held sides, and the relaxation kernel ([memory] kernel = "relaxation")."""

import numpy as np
import pytest
from conftest import DELETE, prony, scene_dict

from adhesive_contact import SceneError, build_problem, scene_from_dict, solve
from adhesive_contact.postprocess import prescribed_history, reaction_sides, reactions

L, H = 2.0, 0.5
E, NU = 1000.0, 0.3
STRAIN = 0.01          # u_x = STRAIN t x / L on the right end

#: a strip on rollers (left: u_x = 0, bottom: u_y = 0) stretched at its right end
STRETCH = scene_dict({
    "mesh.cells": [8, 2], "boundary.dirichlet": [], "boundary.contact": [],
    "boundary.displacement": {"left": ["0", "free"], "bottom": ["free", "0"],
                              "right": [f"{STRAIN * L}*t", "free"]},
    "time.steps": 2,
})


def plane_strain_modulus(E, nu):
    """σ_xx / ε_xx in plane strain with σ_yy = 0: E / (1 − ν²)."""
    return E / (1.0 - nu ** 2)


def test_a_stretched_strip_is_uniform_and_its_reactions_balance():
    problem = build_problem(scene_from_dict(STRETCH))
    sol = solve(problem)
    assert sol.success
    x, y = problem.mesh.p
    for n, t in enumerate(sol.t):
        eps = STRAIN * t
        np.testing.assert_allclose(sol.u[n][:, 0], eps * x, rtol=0, atol=1e-12)
        np.testing.assert_allclose(sol.u[n][:, 1], -NU / (1 - NU) * eps * y, rtol=0,
                                   atol=1e-12)
    assert reaction_sides(problem) == ("left", "bottom", "right")
    R = reactions(sol)
    assert R.shape == (3, 3, 2)
    force = plane_strain_modulus(E, NU) * STRAIN * sol.t * H       # σ_xx · H
    np.testing.assert_allclose(R[:, 2, 0], force, rtol=1e-10, atol=1e-10)
    np.testing.assert_allclose(R[:, 0, 0], -force, rtol=1e-10, atol=1e-10)
    # free components carry no reaction, and the bottom holds nothing (σ_yy = 0)
    assert np.all(R[:, 0, 1] == 0) and np.all(R[:, 2, 1] == 0) and np.all(R[:, 1, 0] == 0)
    np.testing.assert_allclose(R[:, 1, 1], 0.0, atol=1e-10)
    history = prescribed_history(sol, "right")
    np.testing.assert_allclose(history[:, 0], STRAIN * L * sol.t, rtol=1e-14)
    assert np.isnan(history[:, 1]).all()


def test_a_corner_held_by_two_sides_is_shared():
    # clamped left and a right end pulled sideways: the sides add up to zero
    data = scene_dict({"boundary.dirichlet": ["left"],
                       "boundary.displacement": {"right": ["free", "0.01*t"]},
                       "boundary.contact": [], "mesh.cells": [8, 2]})
    problem = build_problem(scene_from_dict(data))
    sol = solve(problem)
    R = reactions(sol)
    np.testing.assert_allclose(R.sum(axis=1), 0.0, atol=1e-10 * np.abs(R).max())
    assert R[-1, 1, 1] > 0                 # the right end is pulled up


@pytest.mark.parametrize("displacement, missing", [
    ({"left": ["0", "free"]}, "translation along y"),
    ({"bottom": ["free", "0"]}, "translation along x"),
    ({"left": ["free", "0"], "right": ["free", "0"]}, "translation along x"),
])
def test_rigid_motions_left_free_are_refused(displacement, missing):
    data = scene_dict({"boundary.dirichlet": [], "boundary.contact": [],
                       "boundary.displacement": displacement})
    with pytest.raises(SceneError) as err:
        build_problem(scene_from_dict(data))
    assert str(err.value).startswith("boundary: the held sides")
    assert missing in str(err.value)


def test_components_held_on_two_sides_hold_the_body():
    # x on the left stops the x translation and the rotation, y on the top the rest
    data = scene_dict({"boundary.dirichlet": [], "boundary.contact": [],
                       "boundary.displacement": {"left": ["0", "free"],
                                                 "top": ["free", "0"]}})
    build_problem(scene_from_dict(data))      # no error


def test_sides_that_disagree_at_a_corner_are_refused():
    data = scene_dict({"boundary.dirichlet": ["left"], "boundary.contact": [],
                       "boundary.displacement": {"bottom": ["0.1", "free"]}})
    with pytest.raises(SceneError, match=r"boundary.displacement.bottom\[0\]: holds the "
                       r"node \(0, 0\) at another value than boundary.dirichlet\[0\]"):
        build_problem(scene_from_dict(data))


@pytest.mark.parametrize("changes, message", [
    ({"boundary.displacement": {"right": ["free", "free"]}},
     "boundary.displacement.right: prescribes no component"),
    ({"boundary.displacement": {"right": ["0"]}},
     "boundary.displacement.right: must be a list of 2 entries"),
    ({"boundary.displacement": {"top": ["0", "0"]}},
     "boundary.displacement.top: is also a Dirichlet side"),
    ({"boundary.displacement": {"right": ["0", "z"]}},
     "boundary.displacement.right[1]: expression uses 'z'"),
    ({"boundary.displacement": {"middle": ["0", "0"]}},
     "boundary.displacement.middle: unknown side"),
    ({"boundary.displacement": {"right": [True, "0"]}},
     "boundary.displacement.right[0]: must be a number, an expression or \"free\""),
    ({"boundary.dirichlet": []}, "boundary.dirichlet: must list at least one side"),
])
def test_bad_displacement_tables_name_the_key(changes, message):
    with pytest.raises(SceneError) as err:
        scene_from_dict(scene_dict(changes))
    assert message in str(err.value)


@pytest.mark.parametrize("dim", [2, 3])
def test_a_body_held_by_nothing_is_told_what_to_hold_and_the_advice_works(dim):
    # Γ_C listed, but [contact] sets no contact term: nothing holds the body
    base = scene_dict({"boundary.dirichlet": []})
    if dim == 3:
        base = scene_dict({"dim": 3, "mesh.domain": "box", "mesh.size": [2.0, 0.5, 0.5],
                           "mesh.cells": [4, 2, 2]}, base)
    with pytest.raises(SceneError) as err:
        scene_from_dict(base)
    message = str(err.value)
    assert "\n" not in message
    assert message.startswith("boundary.dirichlet: must list at least one side: nothing "
                              "holds the body; boundary.contact (bottom) carries no contact "
                              "terms")
    held = ", ".join(['"0"'] * (dim - 1) + ['"0.01*t"'])
    assert 'boundary.dirichlet = ["left"]' in message
    assert f"[boundary.displacement], e.g. left = [{held}]" in message
    # either fix the message names is a valid scene that holds every rigid motion
    build_problem(scene_from_dict(scene_dict({"boundary.dirichlet": ["left"]}, base)))
    moved = scene_dict({"boundary.displacement": {"left": ["0"] * (dim - 1) + ["0.01*t"]}},
                       base)
    problem = build_problem(scene_from_dict(moved))
    assert problem.prescribed.fixed.size == dim * np.isclose(problem.mesh.p[0], 0).sum()


@pytest.mark.parametrize("dim", [2, 3])
def test_glue_without_friction_leaves_the_tangential_translations_free(dim):
    # a normal law restrains the normal translation and the rotations that
    # tilt Γ_C, not a slide along it (nor, in 3D, the turn about its normal)
    base = scene_dict({"boundary.dirichlet": [], "contact.normal": {
        "law": "adhesive_compliance", "c": 1e4, "gamma": 5e3, "L": 0.01}})
    if dim == 3:
        base = scene_dict({"dim": 3, "mesh.domain": "box", "mesh.size": [2.0, 0.5, 0.5],
                           "mesh.cells": [4, 2, 2]}, base)
    with pytest.raises(SceneError) as err:
        build_problem(scene_from_dict(base))
    free = ("translation along x" if dim == 2 else
            "translation along x, translation along z, rotation about the axis along y "
            "through (1, 0.25, 0.25)")
    assert str(err.value).startswith(
        "boundary: the held sides (none) and the contact terms on Γ_C (a normal law) leave "
        f"the body free to move rigidly ({free}): ")


def test_a_contact_node_with_a_held_component_stays_on_contact():
    # the roller corner holds u_x = u_τ; its u_ν is a contact unknown
    data = scene_dict({"boundary.dirichlet": ["top"],
                       "boundary.displacement": {"left": ["0", "free"]},
                       "contact.normal": {"law": "compliance", "c": 10.0}})
    problem = build_problem(scene_from_dict(data))
    corner = np.flatnonzero((problem.mesh.p[0] == 0) & (problem.mesh.p[1] == 0))
    assert corner.size == 1 and corner[0] in problem.boundary.nodes
    assert problem.boundary.nodes.size == 17      # every bottom node
    a = int(np.flatnonzero(problem.boundary.nodes == corner[0])[0])
    assert problem.boundary.held[a].tolist() == [False, True]
    # frictionless: the normal components are the unknowns, the corner's too
    assert problem.columns.tolist() == list(range(0, 2 * 17, 2))


def test_a_manufactured_solution_with_a_held_side_is_reproduced():
    # u* linear in x, y: P1 reproduces it; the right end is held at u*
    u = ["0.01*t*x + 0.002*y", "-0.003*t*y"]
    data = scene_dict({"boundary.dirichlet": [], "boundary.contact": [],
                       "boundary.displacement": {"left": u, "right": [u[0], "free"]},
                       "exact": {"u": u}, "time.steps": 2, "mesh.cells": [4, 2]})
    problem = build_problem(scene_from_dict(data))
    sol = solve(problem)
    x, y = problem.mesh.p
    for n, t in enumerate(sol.t):
        np.testing.assert_allclose(sol.u[n][:, 0], 0.01 * t * x + 0.002 * y, atol=1e-12)
        np.testing.assert_allclose(sol.u[n][:, 1], -0.003 * t * y, atol=1e-12)
    wrong = scene_dict({"boundary.displacement.right": ["0.02*t*x", "free"]}, data)
    with pytest.raises(SceneError, match=r"boundary.displacement.right\[0\]: must equal "
                       r"exact.u\[0\]"):
        build_problem(scene_from_dict(wrong))


def test_memory_sees_the_held_part():
    # with a Prony term the stretched strip's right reaction follows
    # E/(1−ν²) + k Σ_j e^{−(t_n − t_j)/τ} E_1/(1−ν²) ε_j (rectangle rule, exact
    # recursion): the history is of the whole u, the held part included
    E1, tau, steps = 500.0, 0.5, 4
    data = scene_dict({"memory": prony((E1, NU, tau)), "time.steps": steps}, STRETCH)
    sol = solve(build_problem(scene_from_dict(data)))
    k = 1.0 / steps
    eps = STRAIN * sol.t
    stress = plane_strain_modulus(E, NU) * eps + np.array([
        k * sum(np.exp(-(t - sol.t[j]) / tau) * plane_strain_modulus(E1, NU) * eps[j]
                for j in range(1, n + 1)) if n else 0.0
        for n, t in enumerate(sol.t)])
    np.testing.assert_allclose(reactions(sol)[:, 2, 0], stress * H, rtol=1e-10)


# ---------------------------------------------------------------- relaxation


def relaxation_scene(steps, E_inf=100.0, terms=((900.0, 0.5),), T=1.0):
    return scene_dict({
        "material": DELETE,
        "memory": {"kernel": "relaxation", "long_term": {"E": E_inf, "nu": NU},
                   "terms": [{"E": Ei, "tau": tau} for Ei, tau in terms]},
        "boundary.displacement.right": [f"{STRAIN * L}", "free"],   # stretched, held
        "time.T": T, "time.steps": steps,
    }, STRETCH)


def test_relaxation_scene_reads_the_instantaneous_tensor():
    scene = scene_from_dict(relaxation_scene(4))
    assert scene.material.E == pytest.approx(1000.0) and scene.material.nu == NU
    (term,) = scene.memory.prony_terms
    assert term.tensor.mu == pytest.approx(-900.0 / (2 * (1 + NU)) / 0.5, rel=1e-14)
    assert scene.resolved["memory"] == {"kernel": "relaxation",
                                        "long_term": {"E": 100.0, "nu": NU},
                                        "terms": [{"E": 900.0, "nu": NU, "tau": 0.5}]}
    both = scene_dict({"material": {"E": 1.0, "nu": 0.3}}, relaxation_scene(4))
    with pytest.raises(SceneError, match="^material: a relaxation kernel"):
        scene_from_dict(both)
    with pytest.raises(SceneError, match="^time.steps: the time step k = 1 is too large"):
        scene_from_dict(relaxation_scene(1))


def test_relaxation_test_follows_the_modulus():
    """A strip stretched at t = 0 and held: σ_xx(t) = E(t)/(1 − ν²) ε_0 with
    E(t) = E_∞ + E_1 e^{−t/τ}. The scheme gives the right rectangle rule of
    ∫_0^t G'(s) ds, E(0) + Σ_{m<n} k G'(t_m), exactly (to round-off); it
    overestimates the integral of the decreasing G' by at most k |G'(0)| =
    k E_1/τ in all, and its error is O(k), halving with k."""
    E_inf, E1, tau = 100.0, 900.0, 0.5
    errors = []
    for steps in (20, 40):
        sol = solve(build_problem(scene_from_dict(relaxation_scene(steps))))
        assert sol.success
        k = 1.0 / steps
        modulus = (reactions(sol)[:, 2, 0] / H / STRAIN) * (1 - NU ** 2)
        m = np.arange(sol.t.size)
        rectangle = E_inf + E1 - (k / tau) * E1 * (1 - np.exp(-m * k / tau)) / (
            1 - np.exp(-k / tau))
        np.testing.assert_allclose(modulus, rectangle, rtol=1e-9)
        closed = E_inf + E1 * np.exp(-sol.t / tau)
        errors.append(np.abs(modulus - closed).max())
        assert errors[-1] <= k * E1 / tau            # the rectangle rule's bound
    assert errors[1] / errors[0] == pytest.approx(0.5, abs=0.05)


def test_reactions_contact_and_loads_balance():
    # Σ_sides R + Σ_a F_a + ∫ f_N = 0 with memory, contact and a traction
    from adhesive_contact.postprocess import total_contact_force
    from adhesive_contact.postprocess import applied_traction

    data = scene_dict({"boundary.dirichlet": ["left"], "mesh.cells": [8, 2],
                       "boundary.displacement": {"top": ["free", "-0.001*t*x"]},
                       "memory": prony((200.0, 0.3, 0.5)), "time.steps": 3,
                       "loads.traction.right": ["20*t", "40*t"],
                       "contact.normal": {"law": "adhesive_compliance", "c": 1e4,
                                          "gamma": 50.0, "L": 0.01}})
    problem = build_problem(scene_from_dict(data))
    sol = solve(problem)
    assert sol.success and reaction_sides(problem) == ("left", "top")
    total = (reactions(sol).sum(axis=1) + total_contact_force(sol)
             + applied_traction(problem, "right", sol.t))
    np.testing.assert_allclose(total, 0.0, atol=1e-9 * np.abs(reactions(sol)).max())


def test_cli_refuses_a_body_free_to_move_with_exit_2(tmp_path):
    from conftest import to_toml
    from test_cli import run

    path = tmp_path / "loose.toml"
    path.write_text(to_toml(scene_dict({"boundary.dirichlet": [], "boundary.contact": [],
                                        "boundary.displacement": {"left": ["0", "free"]}})))
    result = run("solve", path, "--out", tmp_path / "out")
    assert result.exit_code == 2
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: boundary: the held sides (left)")
    assert "(translation along y)" in lines[0] and "Traceback" not in result.stderr


def test_large_displacements_and_far_stiffness_are_warned():
    from adhesive_contact.problem.warnings import solution_warnings, stiffness_warning

    # the right end moved by 0.4 on a length of 2: a strain of 0.2 everywhere
    data = scene_dict({"boundary.displacement.right": ["0.4*t", "free"]}, STRETCH)
    sol = solve(build_problem(scene_from_dict(data)))
    (line,) = solution_warnings(sol)
    assert line.startswith("at t = 1, 100% of the body is beyond the small-strain model, "
                           "with strains up to 0.2 (more than 0.1)")
    assert solution_warnings(solve(build_problem(scene_from_dict(STRETCH)))) == []
    # the stiffness needs no solution: it is a warning of the problem, before a run
    stiff = scene_dict({"contact.normal": {"law": "compliance", "c": 1e12}})
    problem = build_problem(scene_from_dict(stiff))
    line = stiffness_warning(problem)
    assert line in problem.warnings()
    assert line.startswith("contact.normal.c = 1e+12 times the body's size is 2.1e+09 times")
