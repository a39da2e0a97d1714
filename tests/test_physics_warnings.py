"""Warnings that fit the physics (problem/warnings.py, problem/plausibility.py):
strains and rotations beyond the small-strain model against closed forms
(a rigid rotation, a uniform stretch), P1 locking as ν → ½ with the
figures it quotes against Timoshenko's beam formula, moduli no solid has
in the named units, and the note of ``check`` on a Prony kernel."""

import math
import tomllib
from importlib import resources
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner
from conftest import scene_dict, to_toml

from adhesive_contact import build_problem, parse_scene, scene_from_dict, solve
from adhesive_contact.problem.plausibility import (
    LOCKING_FIGURES,
    NU_LOCKING,
    locking_warning,
    prony_note,
    unit_warnings,
)
from adhesive_contact.problem.warnings import (geometry_warning, solution_warnings,
                                               symmetric_extremes)
from adhesive_contact_cli.main import main

ROOT = Path(__file__).resolve().parents[1]
DEFAULT = resources.files("adhesive_contact_cli").joinpath("default_scene.toml").read_text()


def rotated(theta):
    """A 2 × 0.5 strip turned rigidly by theta·t: every side held at
    u = (R(θ) − I) x, so the solution is that field and ∇u = R − I in every
    cell: a linear strain (cos θ − 1) I and a Green–Lagrange strain 0."""
    c, s = f"(cos({theta}*t) - 1)", f"sin({theta}*t)"
    held = [f"{c}*x - {s}*y", f"{s}*x + {c}*y"]
    return scene_dict({"boundary.dirichlet": [], "boundary.contact": [],
                       "boundary.displacement": {side: held for side in
                                                 ("left", "right", "bottom", "top")},
                       "time.steps": 2})


def test_a_rigid_rotation_of_23_degrees_warns_with_its_closed_form():
    theta = 0.4
    sol = solve(build_problem(scene_from_dict(rotated(theta))))
    line = geometry_warning(sol)
    assert line.startswith("at t = 1, 100% of the body is beyond the small-strain model, with "
                           f"rotations up to {math.degrees(theta):.0f}°, where the linear "
                           "strain misses the Green–Lagrange strain by up to "
                           f"{1 - math.cos(theta):.3g} (more than 0.05)")
    assert "strains up to" not in line     # |cos θ − 1| = 0.079 < 0.1
    assert "cannot represent finite rotations" in line and "large strains" not in line
    # 15°: 1 − cos θ = 0.034, inside
    assert geometry_warning(solve(build_problem(scene_from_dict(rotated(0.26))))) is None


def test_a_uniform_stretch_of_20_percent_warns_of_large_strains():
    """Rollers on the left and bottom, the right side pulled by 0.4 on a
    length of 2: ε_xx = 0.2 exactly, ε_yy = −ν/(1 − ν) 0.2 (plane strain),
    ∇u symmetric (no rotation): ½ ε_xx² = 0.02 of Green–Lagrange gap."""
    stretch = scene_dict({"mesh.cells": [8, 2], "boundary.dirichlet": [],
                          "boundary.contact": [],
                          "boundary.displacement": {"left": ["0", "free"],
                                                    "bottom": ["free", "0"],
                                                    "right": ["0.4*t", "free"]},
                          "time.steps": 2})
    (line,) = solution_warnings(solve(build_problem(scene_from_dict(stretch))))
    assert "100% of the body is beyond the small-strain model, with strains up to 0.2 " \
           "(more than 0.1)" in line
    assert "rotations" not in line and line.count("large strains") == 1
    stretch["boundary"]["displacement"]["right"] = ["0.1*t", "free"]   # 5 %
    assert solution_warnings(solve(build_problem(scene_from_dict(stretch)))) == []


def test_the_built_in_scene_is_inside_and_a_larger_lift_is_not():
    assert geometry_warning(solve(build_problem(parse_scene(DEFAULT)))) is None
    lifted = solve(build_problem(parse_scene(DEFAULT.replace('"0.15*t"', '"0.4*t"'))))
    line = geometry_warning(lifted)
    assert line is not None and "cannot represent finite rotations" in line


def beam(nu, E=1000.0, P=0.1, L=10.0, h=1.0):
    """Timoshenko's tip deflection of a plane-strain cantilever."""
    return (P * L**3 / (3 * E / (1 - nu**2) * h**3 / 12)
            + P * L / (5 / 6 * E / (2 * (1 + nu)) * h))


@pytest.mark.parametrize("nu", [0.3, 0.49])
def test_the_locking_figures_quoted_are_those_of_the_cantilever(nu):
    """The warning quotes P1 tip deflections over the beam formula on 4
    cells through the thickness; the same cantilever computed here."""
    scene = scene_dict({"mesh.size": [10.0, 1.0], "mesh.cells": [40, 4],
                        "boundary.dirichlet": ["left"], "boundary.contact": [],
                        "material": {"E": 1000.0, "nu": nu},
                        "loads": {"traction": {"right": ["0", "-0.1"]}}})
    sol = solve(build_problem(scene_from_dict(scene)))
    tip = np.isclose(sol.problem.mesh.p[0], 10.0)
    ratio = -sol.u[-1][tip, 1].mean() / beam(nu)
    assert ratio == pytest.approx(LOCKING_FIGURES[nu], abs=0.006)


def test_nu_above_the_locking_bound_warns_with_the_figures():
    high = scene_from_dict(scene_dict({"material": {"E": 1.0, "nu": 0.4999}}))
    line = locking_warning(high)
    assert line.startswith("material.nu = 0.4999 (λ/μ = 5e+03) is above 0.45: P1 elements lock")
    assert "0.81 at ν = 0.3, 0.63 at ν = 0.45, 0.29 at ν = 0.49" in line
    assert line in build_problem(high).warnings()
    assert locking_warning(scene_from_dict(scene_dict({"material": {"E": 1.0,
                                                                    "nu": NU_LOCKING}}))) is None
    # a Lamé pair: ν = λ / (2(λ + μ)) = 0.49 for λ = 49 μ
    lame = scene_from_dict(scene_dict({"material": {"lam": 49.0, "mu": 1.0}}))
    assert locking_warning(lame).startswith("material.nu = 0.49 ")


def test_a_modulus_no_solid_has_in_the_named_units_warns_once():
    def warned(E, units):
        changes = {"material": {"E": E, "nu": 0.3}}
        if units:
            changes["output"] = {"units": units}
        return unit_warnings(scene_from_dict(scene_dict(changes)))

    (line,) = warned(1e9, {"stress": "MPa"})
    assert line.startswith("material.E = 1e+09 MPa is 1e+15 Pa: no solid or glue is that stiff")
    assert "output.units.stress = 'MPa'" in line
    assert warned(1e9, {"stress": "Pa"}) == []            # 1 GPa: a polymer
    assert warned(1e9, None) == []                        # no units: nothing to check
    assert warned(1e9, {"stress": "furlongs"}) == []      # a unit not known
    (soft,) = warned(1e-3, {"stress": "Pa"})
    assert "that soft" in soft
    # psi: 30e6 psi (steel) is fine, 30e12 psi is not
    assert warned(30e6, {"stress": "psi"}) == [] and len(warned(30e12, {"stress": "psi"})) == 1


def test_check_notes_that_a_prony_kernel_stiffens_the_body(tmp_path):
    """debonding.toml: E grows from E_0 to E_0 + Σ τ_m E_m (one ν throughout:
    the moduli add), computed here from the file."""
    path = ROOT / "studies/scenes/debonding.toml"
    document = tomllib.loads(path.read_text())
    E0 = document["material"]["E"]
    grown = E0 + sum(t["tau"] * t["E"] for t in document["memory"]["terms"])
    assert {t["nu"] for t in document["memory"]["terms"]} == {document["material"]["nu"]}
    out = CliRunner().invoke(main, ["check", str(path)]).stdout
    (line,) = [x for x in out.splitlines() if x.startswith("  note: ")]
    assert f"E grows from {E0:.4g} towards {grown:.4g}" in line
    assert 'is kernel = "relaxation"' in line
    relaxation = tmp_path / "r.toml"
    relaxation.write_text(DEFAULT)
    assert "note:" not in CliRunner().invoke(main, ["check", str(relaxation)]).stdout
    assert prony_note(parse_scene(DEFAULT)) is None


def test_the_built_in_scene_has_no_scene_warning():
    assert build_problem(parse_scene(DEFAULT)).warnings() == []


def test_check_shows_the_unit_warning(tmp_path):
    # a warning of the scene: check shows it, as solve does before a run
    path = tmp_path / "gpa.toml"
    path.write_text(to_toml(scene_dict({"material": {"E": 1e9, "nu": 0.3},
                                        "output": {"units": {"stress": "MPa"}}})))
    result = CliRunner().invoke(main, ["check", str(path)])
    assert "warning: material.E = 1e+09 MPa is 1e+15 Pa" in result.stdout


@pytest.mark.parametrize("d", [2, 3])
def test_closed_form_eigenvalues_are_lapacks(d):
    """The extreme eigenvalues of the small-strain check, in closed form,
    against numpy's eigvalsh: random symmetric matrices, multiples of I
    (p = 0), a double eigenvalue, and rank one (½ GᵀG of a single shear)."""
    rng = np.random.default_rng(7)
    A = rng.standard_normal((2000, d, d))
    A = A + A.transpose(0, 2, 1)
    A[0] = 3.0 * np.eye(d)
    A[1] = np.diag([2.0] * (d - 1) + [-1.0])
    g = np.zeros((d, d))
    g[0, 1] = 0.4
    A[2] = 0.5 * g.T @ g
    low, high = symmetric_extremes(A)
    w = np.linalg.eigvalsh(A)
    scale = np.abs(w).max(axis=1)
    # the cubic's trigonometric solution loses a few digits near a double root
    assert np.all(np.abs(low - w[:, 0]) <= 1e-12 * scale)
    assert np.all(np.abs(high - w[:, -1]) <= 1e-12 * scale)
