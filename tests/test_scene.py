"""The scene reader: resolved values, and one clear error per bad input."""

import tomllib
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
from conftest import DELETE, law, scene_dict, to_toml

from adhesive_contact import SceneError, build_problem, parse_scene, scene_from_dict

ROOT = Path(__file__).resolve().parents[1]


def base():
    """A 2 × 1 block of 4 × 2 cells pressed by a traction onto a compliant wall."""
    return scene_dict({
        "mesh.size": [2.0, 1.0], "mesh.cells": [4, 2], "boundary.dirichlet": ["left"],
        "material.nu": 0.25, "loads.traction.top": ["0", "-t"], "contact.gap": 0.01,
        "contact.normal": law("compliance", c=100.0), "time.steps": 4})


def test_defaults_and_lame_pair():
    scene = scene_from_dict(base())
    # plane strain Lamé pair from (E, ν) = (1000, 0.25): λ = Eν/((1+ν)(1−2ν)) = 400, μ = 400
    assert scene.material.lam == pytest.approx(400.0, rel=1e-14)
    assert scene.material.mu == pytest.approx(400.0, rel=1e-14)
    assert scene.mesh.pattern == "diagonal" and scene.mesh.refine == 0
    assert scene.contact.quadrature == "nodal"
    assert scene.k == 0.25
    assert scene.memory is None
    assert scene.resolved["time"] == {"T": 1.0, "steps": 4, "k": 0.25}


def test_resolved_record_lists_every_table_with_its_defaults():
    assert scene_from_dict(base()).resolved == {
        "title": "untitled", "dim": 2,
        "mesh": {"domain": "rectangle", "size": [2.0, 1.0], "cells": [4, 2],
                 "pattern": "diagonal", "refine": 0},
        "boundary": {"dirichlet": ["left"], "contact": ["bottom"]},
        "material": {"E": 1000.0, "nu": 0.25, "lam": 400.0,
                     "mu": 400.0},
        "memory": None,
        "loads": {"body": ["0", "0"], "traction": {"top": ["0", "-t"]}},
        "contact": {"gap": 0.01, "quadrature": "nodal", "order": 4,
                    "normal": {"law": "compliance", "c": 100.0}, "friction": [],
                    "bonding": {"law": "none"}},
        "time": {"T": 1.0, "steps": 4, "k": 0.25},
        "solver": {"method": "newton", "tol": 1e-10, "max_iter": 50, "linear": "auto"},
        "output": {"probes": []},
        "exact": None,
    }


def test_resolved_record_keeps_what_the_scene_gave():
    # numbers stay numbers (gap, beta0) or their text (loads); the material
    # pair given is kept; a bonding table records the integrator
    data = base()
    data["material"] = {"lam": 3.0, "mu": 2.0}
    data["memory"] = {"kernel": "function", "r": 2, "E": 1.0, "nu": 0.2}
    data["loads"] = {"body": [0, -1.5]}
    data["contact"]["gap"] = "0.01 + x"
    data["contact"]["bonding"] = {"law": "none", "beta0": 1}
    resolved = scene_from_dict(data).resolved
    assert resolved["material"] == {"lam": 3.0, "mu": 2.0}
    assert resolved["memory"] == {"kernel": "function", "r": "2", "E": 1.0, "nu": 0.2}
    assert resolved["loads"] == {"body": ["0", "-1.5"], "traction": {}}
    contact = resolved["contact"]
    assert contact["gap"] == "0.01 + x"
    assert contact["beta0"] == 1 and type(contact["beta0"]) is int
    assert contact["integrator"] == "explicit" and contact["bonding"] == {"law": "none"}


def test_resolved_record_follows_a_replaced_discretisation():
    # the record is derived from the dataclasses: nothing to patch
    scene = scene_from_dict(base())
    finer = replace(scene, mesh=replace(scene.mesh, refine=2), steps=16)
    assert finer.resolved["mesh"]["refine"] == 2
    assert finer.resolved["time"] == {"T": 1.0, "steps": 16, "k": 0.0625}
    assert scene.resolved["mesh"]["refine"] == 0
    other = {**finer.resolved, "mesh": scene.resolved["mesh"], "time": scene.resolved["time"]}
    assert other == scene.resolved


def test_lame_input_is_taken_as_is():
    data = base()
    data["material"] = {"lam": 3.0, "mu": 2.0}
    scene = scene_from_dict(data)
    assert (scene.material.lam, scene.material.mu) == (3.0, 2.0)


def test_shipped_default_scene_is_the_studies_copy():
    assert (ROOT / "cli" / "default_scene.toml").read_text() == \
        (ROOT / "studies" / "scenes" / "default.toml").read_text()


@pytest.mark.parametrize("path, value, message", [
    (("mesh", "sise"), [1, 1], "mesh.sise: unknown key"),
    (("material", "E"), DELETE, "material.E: missing; a number is required"),
    (("material", "lam"), 1.0, "material.E: give exactly one pair"),
    (("time", "steps"), "ten", "time.steps: must be an integer"),
    (("time", "steps"), 0, "time.steps: must be an integer in 1..1e+08, got 0"),
    (("time", "T"), -1.0, "time.T: must be > 0"),
    (("material", "E"), 0.0, "material.E: must be > 0"),
    (("material", "nu"), 0.5, "material.nu: must lie in (-1, 0.5)"),
    (("mesh", "cells"), [0, 2], "mesh.cells: must be a list of 2 integers >= 1"),
    (("mesh", "pattern"), "zigzag", "mesh.pattern: must be one of 'diagonal', 'cross'"),
    (("boundary", "dirichlet"), ["lfet"], "boundary.dirichlet[0]: unknown side"),
    (("boundary", "contact"), ["left"], "boundary.contact: side 'left' is also Dirichlet"),
    (("loads", "traction", "left"), ["0", "1"], "loads.traction.left: a traction acts on a Neumann side only"),
    (("loads", "traction", "top"), ["0", "os.system('x')"], "loads.traction.top[1]"),
    (("loads", "traction", "top"), ["0", "q*t"], "name 'q' is not allowed"),
    (("contact", "gap"), -0.1, "contact.gap: must be >= 0"),
    (("contact", "normal", "law"), "glue", "contact.normal.law: must be one of"),
    (("contact", "normal", "c"), -1.0, "contact.normal.c: must be > 0"),
    (("contact", "quadrature"), "simpson", "contact.quadrature: must be one of"),
    (("memory",), {"kernel": "prony", "terms": [{"E": 1.0, "nu": 0.2, "tau": 0.0}]},
     "memory.terms[0].tau: must be > 0"),
    (("memory",), {"kernel": "maxwell"}, "memory.kernel: must be one of 'prony', 'function'"),
    (("memory",), {"kernel": "function", "r": "exp(-x)", "E": 1.0, "nu": 0.2},
     "memory.r: expression uses 'x'"),
    (("dim",), 4, "dim: must be 2 (plane strain) or 3"),
])
def test_bad_input_names_the_key(path, value, message):
    data = scene_dict({".".join(path): value}, base())
    with pytest.raises(SceneError) as err:
        scene_from_dict(data)
    text = str(err.value)
    assert message in text
    assert "\n" not in text


def test_gauss_quadrature_takes_only_the_laws_without_a_kink():
    data = base()
    data["contact"]["quadrature"] = "gauss"
    data["contact"]["friction"] = [{"law": "power", "mu": 1.0, "q": 0.5},
                                   {"law": "tresca", "mu": 1.0}]
    with pytest.raises(SceneError) as err:
        scene_from_dict(data)
    assert str(err.value) == ("contact.quadrature: 'gauss' takes smooth friction laws only "
                              "(power, adhesive_spring); 'tresca' needs 'nodal'")
    data["contact"]["friction"] = [{"law": "power", "mu": 1.0, "q": 0.5},
                                   {"law": "adhesive_spring", "gamma": 1.0, "L": 0.1}]
    assert scene_from_dict(data).contact.quadrature == "gauss"


def test_a_scene_document_written_as_toml_reads_back():
    # the tests' TOML writer: what the command-line tests give adhcontact
    data = scene_dict({"memory": {"kernel": "prony", "terms": [{"E": 1.0, "nu": 0.2, "tau": 2}]},
                       "contact.friction": [law("tresca", mu=1.0), law("power", mu=1.0, q=1)],
                       "output.probes": [[1.0, 0.5]], "title": 'a "quoted" title'}, base())
    text = to_toml(data)
    assert tomllib.loads(text) == data
    assert parse_scene(text).resolved == scene_from_dict(data).resolved


def test_invalid_toml_is_a_scene_error():
    with pytest.raises(SceneError, match="not valid TOML"):
        parse_scene("dim = = 2")


def test_geometry_checks_happen_at_build():
    data = base()
    data["contact"]["gap"] = "0.01 - 0.02*t"  # negative once t > 0.5
    with pytest.raises(SceneError, match=r"contact.gap: must be finite and >= 0 on Γ_C, got -0.005 at \(0, 0\), t = 0.75"):
        build_problem(scene_from_dict(data))
    data = base()
    data["output"] = {"probes": [[1.0, 0.5], [3.0, 0.5]]}
    with pytest.raises(SceneError, match=r"output.probes\[1\]: point \(3, 0.5\) is outside"):
        build_problem(scene_from_dict(data))


def test_initial_bonding_is_the_facet_mean():
    data = base()
    data["contact"]["bonding"] = {"law": "none", "beta0": "x/2"}
    problem = build_problem(scene_from_dict(data))
    nodes = problem.boundary.facet_nodes
    x = problem.mesh.p[0, nodes]
    # P_B of a linear function is its value at the facet midpoint
    assert np.allclose(problem.beta0, x.mean(axis=0) / 2, rtol=0, atol=1e-14)


@pytest.mark.parametrize("changes, message", [
    ({"contact": {"bonding": {"law": "none", "beta_0": 0.5}}},
     "contact.bonding.beta_0: unknown key (did you mean 'beta0'?); allowed here: L, beta0, "
     "eps_a, gamma_nu, gamma_tau, integrator, law"),
    ({"loads": {"bdy": ["0", "0"]}},
     "loads.bdy: unknown key (did you mean 'body'?); allowed here: body, traction"),
    ({"contact": {"gapp": 0.1}},
     "contact.gapp: unknown key (did you mean 'gap'?); allowed here: bonding, foundation, "
     "friction, gap, normal, order, quadrature"),
])
def test_unknown_key_lists_every_allowed_key_and_the_closest(changes, message):
    with pytest.raises(SceneError) as info:
        scene_from_dict(scene_dict(changes))
    assert str(info.value) == message
