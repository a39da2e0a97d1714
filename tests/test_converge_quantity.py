"""Tests for ``adhcontact converge --quantity NAME`` (docs/outputs.md): the
quantity's error against the fine reference and its fitted rate against a
direct computation (each level solved here, its top reaction read from the
solution, the slope by numpy's polyfit), resuming, and bad names.
A tiny scene (4x2 cells, 2 steps, 3 levels in h)."""

import json
import shutil
from types import SimpleNamespace

import numpy as np
import pytest
from adhesive_contact_cli.main import main
from conftest import assert_one_line_error, law, prony, runner, scene_dict, to_toml

from adhesive_contact import parse_scene
from adhesive_contact.fem.meshes import mesh_size
from adhesive_contact.postprocess import reaction_sides, reactions
from adhesive_contact.problem.build import build_problem
from adhesive_contact.scheme import solve
from adhesive_contact.studies.levels import level_scene, reference_scene

# a block hanging from its top, pressed by its weight onto a compliant wall
# whose gap varies along x: the top's vertical reaction changes with the mesh
CONTACT = scene_dict({
    "title": "small block on a compliant wall", "mesh.size": [1.0, 0.5],
    "mesh.cells": [4, 2], "memory": prony((200.0, 0.3, 0.5)),
    "loads.body": ["0", "-400*t"], "contact.gap": "0.001 + 0.01*(x - 0.5)**2",
    "contact.normal": law("compliance", c=300.0), "time.steps": 2})
TEXT = to_toml(CONTACT)
NAME = "reaction_top_y_peak"
ARGS = ("--param", "h", "--levels", 3, "--quantity", NAME)


def run(*args):
    return runner().invoke(main, ["converge", *map(str, args)], catch_exceptions=False)


@pytest.fixture(scope="module")
def scene_file(tmp_path_factory):
    path = tmp_path_factory.mktemp("scene") / "contact.toml"
    path.write_text(TEXT)
    return path


@pytest.fixture(scope="module")
def study(scene_file, tmp_path_factory):
    out = tmp_path_factory.mktemp("quantity") / "out"
    result = run(scene_file, *ARGS, "--out", out)
    assert result.exit_code == 0, (result.stdout, result.stderr)
    return SimpleNamespace(out=out, result=result)


def top_y_peak(scene):
    """Solve ``scene`` and read the signed peak of the top side's y reaction."""
    problem = build_problem(scene)
    solution = solve(problem, raise_on_failure=True)
    side = reaction_sides(problem).index("top")
    values = reactions(solution)[:, side, 1]
    return float(values[np.argmax(np.abs(values))]), mesh_size(problem.mesh)


def test_error_and_rate_equal_a_direct_computation(study):
    scene = parse_scene(TEXT)
    q_ref, _ = top_y_peak(reference_scene(scene, "h", 3))
    direct = [top_y_peak(level_scene(scene, "h", level)) for level in range(3)]
    errors = np.array([abs(q - q_ref) for q, _ in direct])
    sizes = np.array([h for _, h in direct])
    document = json.loads((study.out / "rates.json").read_text())
    assert document["quantity"]["name"] == NAME
    assert document["quantity"]["reference"] == pytest.approx(q_ref, rel=1e-12)
    for row, (q, h), err in zip(document["levels"], direct, errors):
        assert row["quantity"] == pytest.approx(q, rel=1e-12)
        assert row["err_q"] == pytest.approx(err, rel=1e-9, abs=1e-12 * abs(q_ref))
        assert row["rel_q"] == pytest.approx(err / abs(q_ref), rel=1e-9, abs=1e-12)
    slope = np.polyfit(np.log(sizes), np.log(errors), 1)[0]
    assert document["rates"]["Q"] == pytest.approx(slope, rel=1e-9)
    pair = np.log(errors[1] / errors[2]) / np.log(sizes[1] / sizes[2])
    assert document["levels"][2]["rate_q"] == pytest.approx(pair, rel=1e-9)
    header = (study.out / "errors.csv").read_text().splitlines()[0].split(",")
    assert header[-4:] == ["quantity", "err_q", "rel_q", "rate_q"]
    assert (study.out / "quantity_vs_h.png").stat().st_size > 0
    assert f"quantity {NAME}: Q_ref = {q_ref:.6g}" in study.result.stdout


def test_rerun_computes_nothing_and_a_record_without_the_quantity_is_recomputed(
        study, scene_file, tmp_path, counting):
    out = tmp_path / "out"
    shutil.copytree(study.out, out)
    rates = (out / "rates.json").read_text()
    result = run(scene_file, *ARGS, "--out", out)
    assert result.exit_code == 0, result.stderr
    assert counting.levels == [] and counting.reference == 0
    assert (out / "rates.json").read_text() == rates
    path = out / "levels" / "level_01.json"          # as a version without quantities wrote it
    record = json.loads(path.read_text())
    path.write_text(json.dumps({k: v for k, v in record.items() if k != "quantities"}))
    result = run(scene_file, *ARGS, "--out", out)
    assert result.exit_code == 0, result.stderr
    assert counting.levels == [1] and counting.reference == 0
    again, before = json.loads((out / "rates.json").read_text()), json.loads(rates)
    assert [row["err_q"] for row in again["levels"]] == [row["err_q"] for row in before["levels"]]
    assert again["rates"] == before["rates"]


def test_a_reference_without_quantities_is_recomputed(study, scene_file, tmp_path, counting):
    out = tmp_path / "out"
    shutil.copytree(study.out, out)
    with np.load(out / "reference.npz") as data:
        arrays = {key: data[key] for key in data.files if key != "quantities"}
    np.savez_compressed(out / "reference.npz", **arrays)
    result = run(scene_file, *ARGS, "--out", out)
    assert result.exit_code == 0, result.stderr
    assert counting.reference == 1 and counting.levels == []
    with np.load(out / "reference.npz") as data:
        assert NAME in json.loads(str(data["quantities"]))


def test_another_quantity_is_another_study(study, scene_file, tmp_path):
    out = tmp_path / "out"
    shutil.copytree(study.out, out)
    result = run(scene_file, "--param", "h", "--levels", 3, "--quantity", "normal_force_T",
                 "--out", out)
    assert_one_line_error(result, 2, "quantity 'reaction_top_y_peak' there, 'normal_force_T' "
                          "here", alone=False)


def test_bad_name_exits_2_listing_the_allowed_names(scene_file, tmp_path):
    out = tmp_path / "out"
    result = run(scene_file, "--param", "h", "--levels", 3, "--quantity", "peak_force",
                 "--out", out)
    assert_one_line_error(result, 2, "--quantity: no quantity 'peak_force' in this scene; "
                          "allowed: beta_min_T, beta_mean_T, max_un_minus_g", alone=False)
    for name in ("normal_force_T", "reaction_top_x_peak, reaction_top_x_T, reaction_top_y_peak",
                 "debonding_T"):
        assert name in result.stderr
    assert not out.exists()


def test_exact_reference_with_a_quantity_exits_2(tmp_path):
    exact = scene_dict({
        "title": "manufactured, no contact", "mesh.size": [1.0, 0.5], "mesh.cells": [4, 2],
        "boundary": {"dirichlet": ["left"]}, "time.steps": 2,
        "exact.u": ["0.01*x*x*(1+t)", "0.005*x*y"]})
    path = tmp_path / "exact.toml"
    path.write_text(to_toml(exact))
    result = run(path, "--param", "h", "--levels", 2, "--reference", "exact",
                 "--quantity", "reaction_left_x_peak", "--out", tmp_path / "out")
    assert_one_line_error(result, 2, "--quantity: 'reaction_left_x_peak' is not computable "
                          "from the scene's [exact] solution", alone=False)
    assert not (tmp_path / "out").exists()
