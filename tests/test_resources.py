"""The resource guard (adhesive_contact.resources): the estimate of memory,
time and output counts what the build makes, and a run larger than the
machine or longer than a day is refused unless forced; converge and sweep
check their largest run."""

import json
import os

from conftest import COMPLIANT_BLOCK, assert_refused, invoke, scene_dict, solve_scene, to_toml

from adhesive_contact import build_problem, resources, scene_from_dict

def test_the_estimate_counts_what_the_build_makes():
    for changes in ({}, {"mesh.pattern": "cross", "mesh.refine": 2},
                    {"boundary.contact": ["bottom", "left"], "mesh.refine": 1}):
        scene = scene_from_dict(scene_dict(changes, COMPLIANT_BLOCK))
        est, problem = resources.estimate(scene), build_problem(scene)
        assert est.dofs == problem.ndofs and est.cells == problem.mesh.t.shape[1]
        # an upper bound: a corner shared by two contact sides is counted
        # twice (one shared with a Dirichlet side is a contact node)
        extra = 0 if len(scene.contact_sides) == 1 else 1
        assert est.contact_nodes == problem.boundary.nodes.size + extra
        assert est.levels == scene.steps + 1


def test_a_scene_larger_than_the_machine_is_refused_unless_forced(tmp_path, monkeypatch):
    est = resources.estimate(scene_from_dict(COMPLIANT_BLOCK))
    monkeypatch.setattr(resources, "available_memory", lambda: est.memory_bytes / 2)
    result, out = solve_scene(tmp_path, COMPLIANT_BLOCK)
    assert_refused(result, out, "is too large for this machine: it would need about")
    assert "--force" in result.stderr and "mesh.cells" in result.stderr
    result, out = solve_scene(tmp_path, COMPLIANT_BLOCK, "--force")
    assert result.exit_code == 0, result.stderr
    record = json.loads((out / "summary.json").read_text())["resources"]
    assert record["estimate"]["dofs"] == record["used"]["dofs"] == 30
    assert record["estimate"]["levels"] == record["used"]["levels"] == 3
    assert record["used"]["peak_memory_bytes"] > 0 and record["used"]["seconds"] > 0


def test_a_run_longer_than_a_day_is_refused(tmp_path):
    result, out = solve_scene(tmp_path, scene_dict({"time.steps": 10**8 - 1,
                                                    "mesh.cells": [1, 1]}, COMPLIANT_BLOCK))
    assert_refused(result, out, "is too large for this machine")


def test_converge_and_sweep_check_their_largest_run_and_their_out(tmp_path):
    scene = tmp_path / "scene.toml"
    scene.write_text(to_toml(COMPLIANT_BLOCK))
    result = invoke("converge", scene, "--param", "k", "--levels", 20, "--steps", 1000,
                 "--out", tmp_path / "c")
    assert_refused(result, tmp_path / "c", "the largest run of the study is too large")
    result = invoke("converge", scene, "--param", "k", "--levels", 40, "--out", tmp_path / "c")
    assert_refused(result, tmp_path / "c", "--levels")
    result = invoke("sweep", scene, "--set", "time.steps=2,99999999", "--out", tmp_path / "s")
    assert_refused(result, tmp_path / "s", "the variant time.steps=99999999 is too large")
    locked = tmp_path / "locked"
    locked.mkdir(mode=0o500)
    if os.access(locked, os.W_OK):   # root writes anywhere: a file in the way instead
        locked = tmp_path / "file"
        locked.write_text("a file")
    for args in (("converge", scene, "--param", "k"), ("sweep", scene, "--set",
                                                       "time.steps=1,2")):
        result = invoke(*args, "--out", locked / "out")
        assert_refused(result, locked / "out", "cannot be written")
