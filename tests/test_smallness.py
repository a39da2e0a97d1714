"""The smallness conditions of the theory (adhesive_contact.problem.smallness):
the trace constant of the mesh actually run, and the existence, estimate
and convexity conditions side by side."""

import dataclasses

import numpy as np
import pytest
from conftest import law, scene_dict

from adhesive_contact import scene_from_dict
from adhesive_contact.problem import smallness as module
from adhesive_contact.laws import make_friction, make_normal_law

SCENE = scene_dict({"mesh.cells": [4, 1], "mesh.size": [2.0, 0.5],
                    "contact.normal": law("compliance", c=50.0),
                    "contact.friction": [law("power", mu=3.0, q=0.5),
                                         law("nonmonotone", a=2.0, b=1.0, alpha=4.0)]})


def terms(scene):
    return module.smallness(scene, make_normal_law(scene.contact.normal),
                            make_friction(scene.contact.friction))


def test_the_trace_constant_is_that_of_the_mesh_run_and_grows_under_refinement():
    scene = scene_from_dict(SCENE)
    values = []
    for refine in (0, 1, 2):
        s = terms(dataclasses.replace(scene, mesh=dataclasses.replace(scene.mesh,
                                                                      refine=refine)))
        assert s["trace_refine"] == refine and s["trace_lower_estimate"] is False
        values.append(s["trace_constant_squared"])
    # a maximum over nested subspaces: nondecreasing; and it does move
    # (measured +11 %, +9 % on this coarse strip)
    assert values[0] < values[1] < values[2] and values[2] > 1.1 * values[0]


def test_above_the_size_limit_the_coarse_mesh_is_used_and_said(monkeypatch):
    scene = scene_from_dict(SCENE)
    fine = dataclasses.replace(scene, mesh=dataclasses.replace(scene.mesh, refine=2))
    monkeypatch.setattr(module, "MAX_TRACE_DOFS", 10)
    s = terms(fine)
    assert s["trace_refine"] == 0 and s["trace_lower_estimate"] is True
    assert s["trace_constant_squared"] == pytest.approx(terms(scene)["trace_constant_squared"],
                                                        rel=1e-12)


def test_the_three_conditions():
    s = terms(scene_from_dict(SCENE))
    ce2 = s["trace_constant_squared"]
    # c_1τ = μ of the power law (|∂j| = μ s^q ≤ μ (1 + s)); m_τ = α (a − b) = 4
    assert s["c_1tau"] == 3.0 and s["m_tau"] == 4.0 and s["nonconvexity"] == 4.0
    assert s["existence_rhs"] == pytest.approx((max(np.sqrt(3) * 3.0, 4.0) + 50.0) * ce2)
    assert s["rhs"] == pytest.approx((4.0 + 50.0) * ce2)
    assert s["convexity_rhs"] == pytest.approx(4.0 * ce2)
    # existence asks the most here: √3 c_1τ = 5.2 > m_τ
    assert s["existence_rhs"] > s["rhs"] > s["convexity_rhs"]
    for flag, rhs in (("existence_holds", "existence_rhs"), ("holds", "rhs"),
                      ("step_energy_convex", "convexity_rhs")):
        assert s[flag] is bool(s["m_A"] > s[rhs])
