"""Tests for the ``adhcontact`` command line (docs/outputs.md)."""

import json
import tomllib
import zipfile
from importlib import resources

import meshio
import numpy as np
import pytest
from adhesive_contact_cli.main import main
from conftest import DELETE, assert_one_line_error, law, prony, runner, scene_dict, to_toml

from adhesive_contact import build_problem, parse_scene, solve

# an 8x4 block hanging from its top, pulled down onto a wall with a gap that
# is smallest in the middle: the wall becomes active at step 1 (7 nodes)
BLOCK = scene_dict({
    "title": "test block", "mesh.size": [2.0, 1.0], "mesh.cells": [8, 4],
    "memory": prony((200.0, 0.3, 0.5)), "loads.body": ["0", "-400*t"],
    "contact.gap": "0.002 + 0.01*(x - 1)**2", "contact.normal": law("compliance", c=5000.0),
    "time.steps": 3, "output.probes": [[1.0, 0.0], [0.0, 0.5]]})
SCENE = to_toml(BLOCK)

NPOINTS, NCELLS, NFACETS, NLEVELS = 45, 64, 8, 4
STEP_KEYS = {"t", "probes", "normal_force", "tangential_force", "beta_mean", "beta_min",
             "separated", "on_wall", "stick", "slip", "contact_measure", "max_penetration",
             "iterations", "residual", "reactions", "contact_force", "energy", "debonding",
             "peak_pressure", "peak_pressure_at", "stick_measure", "slip_measure"}
SUMMARY_KEYS = {"schema", "scene", "source", "mesh", "run", "smallness", "warnings", "timings",
                "linear", "bulk", "resources", "output", "iterations", "energy", "steps"}
SMALLNESS_KEYS = {"m_A", "m_nu", "m_tau", "trace_constant_squared", "rhs", "holds", "c_1tau",
                  "existence_rhs", "existence_holds", "convexity_rhs", "trace_refine",
                  "trace_lower_estimate",
                  "nonconvexity", "step_energy_convex"}
FILES = {"summary.json", "scalars.csv", "solution.npz", "solution.xdmf", "solution.h5", "contact.xdmf",
         "contact.h5", "deformed.png", "contact_traction.png", "beta.png"}


def edit(text, old, new):
    """``text`` with its one occurrence of ``old`` replaced by ``new``."""
    assert text.count(old) == 1, old
    return text.replace(old, new)


def run(*args):
    return runner().invoke(main, list(map(str, args)), catch_exceptions=False)


def strict_json(path):
    """Load JSON, failing on NaN or Infinity (not JSON)."""
    def refuse(name):
        raise ValueError(f"{name} in {path}")
    return json.loads(path.read_text(), parse_constant=refuse)


@pytest.fixture(scope="module")
def solved(tmp_path_factory):
    """The small scene solved once; returns (result, out folder, its parent)."""
    root = tmp_path_factory.mktemp("solve")
    scene = root / "scene.toml"
    scene.write_text(SCENE)
    out = root / "results" / "run"   # parents are created
    result = run("solve", scene, "--out", out)
    return result, out, root


def test_solve_writes_every_output(solved):
    result, out, root = solved
    assert result.exit_code == 0, result.stderr
    assert set(p.name for p in out.iterdir()) == FILES
    # no temporary folders left beside the output
    assert [p.name for p in out.parent.iterdir()] == ["run"]
    assert str(out) in result.stdout
    assert "45 nodes, 64 cells" in result.stdout


def test_npz_has_the_firm_keys_and_shapes(solved):
    _, out, _ = solved
    with np.load(out / "solution.npz") as data:
        # the firm keys, and the rest of the Solution (for load_solution)
        assert set(data.files) == {"points", "cells", "contact_facets", "t", "u", "beta",
                                   "reactions", "reaction_sides", "contact_nodes",
                                   "contact_points", "contact_pressure"} | {
            "contact_force", "frame_displacement", "on_wall", "stuck", "probes", "iterations",
            "residual", "held_reaction", "stress_last", "stress_zz_last", "u_levels",
            "scalar_names", "scalar_kinds", "scalar_values"}
        assert data["stress_last"].shape == (NCELLS, 2, 2)
        assert data["stress_zz_last"].shape == (NCELLS,)
        assert list(data["reaction_sides"]) == ["top"]
        assert data["reactions"].shape == (NLEVELS, 1, 2)
        assert data["points"].shape == (NPOINTS, 2)
        assert data["cells"].shape == (NCELLS, 3)
        assert data["contact_facets"].shape == (NFACETS, 2)
        assert data["t"].shape == (NLEVELS,)
        assert data["u"].shape == (NLEVELS, NPOINTS, 2)
        assert data["beta"].shape == (NLEVELS, NFACETS)
        assert np.issubdtype(data["cells"].dtype, np.integer)
        assert np.issubdtype(data["contact_facets"].dtype, np.integer)
        np.testing.assert_allclose(data["t"], [0, 1 / 3, 2 / 3, 1])
        # the contact facets are the bottom edges
        assert np.all(data["points"][data["contact_facets"], 1] == 0.0)
        top = data["points"][:, 1] == 1.0
        assert np.all(data["u"][:, top] == 0.0)
        assert np.abs(data["u"][-1]).max() > 0
        # the contact nodes: Γ_C's vertices in increasing index, their points,
        # and the pressure −F_ν / w_a with w_a half the lengths of the facets
        # around a, which sums to the summary's normal force
        nodes = data["contact_nodes"]
        np.testing.assert_array_equal(nodes, np.unique(data["contact_facets"]))
        np.testing.assert_array_equal(data["contact_points"], data["points"][nodes])
        facets = data["contact_facets"]
        length = np.linalg.norm(np.diff(data["points"][facets], axis=1)[:, 0], axis=1)
        w = np.zeros(len(data["points"]))
        np.add.at(w, facets.ravel(), np.repeat(length / 2, 2))
        pressure = data["contact_pressure"]
        np.testing.assert_allclose(pressure, -data["contact_force"][:, :, 0] / w[nodes],
                                   rtol=1e-12)
        summary = json.loads((out / "summary.json").read_text())
        np.testing.assert_allclose(pressure @ w[nodes],
                                   [s["normal_force"] for s in summary["steps"]], rtol=1e-12)


def test_the_history_is_stored_uncompressed_and_the_rest_compressed(solved):
    _, out, _ = solved
    with zipfile.ZipFile(out / "solution.npz") as archive:
        kinds = {entry.filename: entry.compress_type for entry in archive.infolist()}
    assert kinds.pop("u.npy") == zipfile.ZIP_STORED
    assert set(kinds.values()) == {zipfile.ZIP_DEFLATED} and "beta.npy" in kinds


def test_summary_has_one_record_per_level(solved):
    _, out, _ = solved
    summary = strict_json(out / "summary.json")
    assert set(summary) == SUMMARY_KEYS and summary["schema"] == 2
    assert summary["scene"]["title"] == "test block"
    assert set(summary["smallness"]) == SMALLNESS_KEYS
    assert isinstance(summary["warnings"], list)
    assert summary["scene"]["time"]["steps"] == 3
    assert summary["mesh"] == {"nodes": NPOINTS, "cells": NCELLS, "dofs": 2 * NPOINTS,
                               "free_dofs": 2 * NPOINTS - 18, "contact_facets": NFACETS,
                               "contact_nodes": 9}
    assert summary["bulk"]["path"] == "kernels"   # P1 triangles: the kernels apply
    assert "P1 kernels" in summary["bulk"]["reason"]
    timings = summary["timings"]
    assert set(timings) == {"assembly", "factorisation", "schur", "stepping", "contact_solve",
                            "total"}
    # the step method's share of the time loop: some, and never more than the loop
    assert 0.0 < timings["contact_solve"] < timings["stepping"] < timings["total"]
    assert len(summary["iterations"]) == NLEVELS
    steps = summary["steps"]
    assert len(steps) == NLEVELS
    for n, step in enumerate(steps):
        assert set(step) == STEP_KEYS
        assert list(step["reactions"]) == ["top"] and len(step["reactions"]["top"]) == 2
        assert len(step["contact_force"]) == 2
        assert step["t"] == pytest.approx(n / 3)
        assert np.shape(step["probes"]) == (2, 2)
        assert isinstance(step["tangential_force"], float)
        assert step["iterations"] == summary["iterations"][n]
        assert step["beta_mean"] == pytest.approx(1.0)   # no bonding law: β = β_0 = 1
        assert step["energy"] is None          # a prony kernel has no free energy
        assert step["debonding"]["area"] == 0.0 and step["debonding"]["front"] == []
        assert step["beta_min"] == pytest.approx(1.0)
        assert step["stick"] is None and step["slip"] is None    # no friction law
        assert isinstance(step["on_wall"], int)
        assert isinstance(step["separated"], int)
        assert step["separated"] + step["on_wall"] <= 9
        if step["separated"] == 0:     # the whole bottom, 2 long, is in contact
            assert step["contact_measure"] == pytest.approx(2.0, rel=1e-14)
    assert summary["energy"]["available"] is False
    assert "grows with time" in summary["energy"]["reason"]
    assert steps[0]["on_wall"] == 0
    assert steps[0]["normal_force"] == pytest.approx(0.0)
    assert steps[0]["max_penetration"] == pytest.approx(-0.002)   # min gap, at x = 1
    assert steps[-1]["on_wall"] > 0
    assert steps[-1]["normal_force"] > steps[1]["normal_force"] > 0
    assert abs(steps[-1]["max_penetration"]) < 1e-9                # on the wall, not through it
    with np.load(out / "solution.npz") as data:
        node = np.flatnonzero(np.all(data["points"] == [1.0, 0.0], axis=1))[0]
        np.testing.assert_allclose(steps[-1]["probes"][0], data["u"][-1, node], atol=1e-12)


def test_xdmf_reads_back_as_a_time_series(solved):
    _, out, _ = solved
    with np.load(out / "solution.npz") as data:
        u, points = data["u"], data["points"]
    reader = meshio.xdmf.TimeSeriesReader(out / "solution.xdmf")
    pts, cells = reader.read_points_cells()
    np.testing.assert_allclose(pts[:, :2], points)
    assert cells[0].type == "triangle" and cells[0].data.shape == (NCELLS, 3)
    assert reader.num_steps == NLEVELS
    t, point_data, cell_data = reader.read_data(NLEVELS - 1)
    assert t == pytest.approx(1.0)
    assert point_data["u"].shape == (NPOINTS, 3)
    np.testing.assert_allclose(point_data["u"][:, :2], u[-1])
    assert np.all(point_data["u"][:, 2] == 0.0)
    assert cell_data["stress"][0].shape == (NCELLS, 9)
    assert cell_data["von_mises"][0].shape == (NCELLS,)
    assert np.all(cell_data["von_mises"][0] >= 0) and cell_data["von_mises"][0].max() > 0
    # plane strain, ν = 0.3 in the material and the memory: σ_zz = ν (σ_xx + σ_yy)
    sig = cell_data["stress"][0].reshape(-1, 3, 3)
    np.testing.assert_allclose(sig[:, 2, 2], 0.3 * (sig[:, 0, 0] + sig[:, 1, 1]),
                               rtol=0, atol=1e-12 * np.abs(sig).max())
    dev = sig - np.trace(sig, axis1=1, axis2=2)[:, None, None] * np.eye(3) / 3
    np.testing.assert_allclose(cell_data["von_mises"][0],
                               np.sqrt(1.5 * np.sum(dev * dev, axis=(1, 2))), rtol=1e-12)

    contact = meshio.xdmf.TimeSeriesReader(out / "contact.xdmf")
    _, facet_cells = contact.read_points_cells()
    assert facet_cells[0].type == "line" and facet_cells[0].data.shape == (NFACETS, 2)
    assert contact.num_steps == NLEVELS
    assert contact.read_data(0)[2]["beta"][0].shape == (NFACETS,)


def test_hdf5_files_are_not_written_to_the_working_directory(tmp_path, monkeypatch):
    """meshio 5.3 puts the .h5 in the current directory; ours go beside the .xdmf."""
    work = tmp_path / "work"
    work.mkdir()
    monkeypatch.chdir(work)
    (tmp_path / "scene.toml").write_text(SCENE)
    result = run("solve", tmp_path / "scene.toml", "--out", tmp_path / "out")
    assert result.exit_code == 0, result.stderr
    assert list(work.iterdir()) == []
    assert (tmp_path / "out" / "solution.h5").stat().st_size > 0


def test_pngs_are_images(solved):
    _, out, _ = solved
    for name in ("deformed.png", "contact_traction.png", "beta.png"):
        data = (out / name).read_bytes()
        assert data[:8] == b"\x89PNG\r\n\x1a\n", name
        assert len(data) > 10_000, name


def test_default_out_is_named_after_the_scene(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "wall_case.toml").write_text(SCENE)
    result = run("solve", "wall_case.toml")
    assert result.exit_code == 0, result.stderr
    assert set(p.name for p in (tmp_path / "wall_case").iterdir()) == FILES


def test_existing_out_keeps_the_users_files(tmp_path):
    (tmp_path / "scene.toml").write_text(SCENE)
    out = tmp_path / "out"
    out.mkdir()
    (out / "summary.json").write_text("{}")   # a previous run's output
    (out / "notes.txt").write_text("mine")
    result = run("solve", tmp_path / "scene.toml", "--out", out)
    assert result.exit_code == 0, result.stderr
    assert set(p.name for p in out.iterdir()) == FILES | {"notes.txt"}
    assert (out / "notes.txt").read_text() == "mine"
    assert strict_json(out / "summary.json")["steps"]   # replaced by this run's
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out", "scene.toml"]


def test_out_dot_in_a_folder_of_scene_and_notes_loses_nothing(tmp_path, monkeypatch):
    # the data-loss defect: a folder holding a scene, notes and a summary.json
    # was replaced whole by ``--out .``, deleting the scene and the notes
    monkeypatch.chdir(tmp_path)
    (tmp_path / "scene.toml").write_text(SCENE)
    (tmp_path / "notes.txt").write_text("my notes")
    (tmp_path / "summary.json").write_text("{}")
    for _ in range(2):   # a second run into the same folder as well
        result = run("solve", "scene.toml", "--out", ".")
        assert result.exit_code == 0, result.stderr
        assert (tmp_path / "scene.toml").read_text() == SCENE
        assert (tmp_path / "notes.txt").read_text() == "my notes"
        assert set(p.name for p in tmp_path.iterdir()) == FILES | {"scene.toml", "notes.txt"}


def test_stale_outputs_of_a_previous_run_are_removed(tmp_path):
    # a run with contact, then one without, into the same folder: the
    # contact files of the first must not pass for the second's
    out = tmp_path / "out"
    (tmp_path / "scene.toml").write_text(SCENE)
    assert run("solve", tmp_path / "scene.toml", "--out", out).exit_code == 0
    no_contact = to_toml(scene_dict({"boundary.contact": [], "contact": DELETE}, BLOCK))
    (tmp_path / "free.toml").write_text(no_contact)
    result = run("solve", tmp_path / "free.toml", "--out", out)
    assert result.exit_code == 0, result.stderr
    assert set(p.name for p in out.iterdir()) == {"summary.json", "scalars.csv", "solution.npz",
                                                  "solution.xdmf", "solution.h5",
                                                  "deformed.png"}


def test_default_scene_runs_without_arguments(tmp_path):
    out = tmp_path / "default_out"
    result = run("solve", "--out", out)
    assert result.exit_code == 0, result.stderr
    text = resources.files("adhesive_contact_cli").joinpath("default_scene.toml").read_text()
    steps = tomllib.loads(text)["time"]["steps"]
    summary = strict_json(out / "summary.json")
    assert len(summary["steps"]) == steps + 1
    assert {"summary.json", "solution.npz", "solution.xdmf", "deformed.png"} <= set(
        p.name for p in out.iterdir())


def test_default_scene_default_out_is_default(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    result = run("solve")
    assert result.exit_code == 0, result.stderr
    assert (tmp_path / "default" / "summary.json").is_file()


def test_scene_without_contact_skips_contact_outputs(tmp_path):
    text = to_toml(scene_dict({"boundary.contact": DELETE, "contact": DELETE}, BLOCK))
    (tmp_path / "scene.toml").write_text(text)
    out = tmp_path / "out"
    result = run("solve", tmp_path / "scene.toml", "--out", out)
    assert result.exit_code == 0, result.stderr
    assert set(p.name for p in out.iterdir()) == FILES - {
        "contact.xdmf", "contact.h5", "contact_traction.png", "beta.png"}
    summary = strict_json(out / "summary.json")
    assert summary["mesh"]["contact_facets"] == 0
    # no contact: no smallness terms, and no warning but what the run shows
    # (this block, without its foundation, sags beyond small strains)
    assert summary["smallness"] is None
    assert all(w.startswith("at t = 1, ") and "small-strain" in w for w in summary["warnings"])
    assert result.stderr.count("warning:") == len(summary["warnings"])
    last = summary["steps"][-1]
    assert last["beta_mean"] is None and last["beta_min"] is None
    assert last["max_penetration"] is None and last["on_wall"] == 0
    assert (last["separated"], last["on_wall"], last["stick"], last["slip"]) == (0, 0, None,
                                                                                 None)
    with np.load(out / "solution.npz") as data:
        assert data["contact_facets"].shape == (0, 2)
        assert data["beta"].shape == (NLEVELS, 0)


def test_solve_in_3d(tmp_path):
    text = to_toml(scene_dict({
        "dim": 3, "mesh.domain": "box", "mesh.size": [2.0, 1.0, 1.0], "mesh.cells": [2, 2, 2],
        "loads.body": ["0", "-400*t", "0"], "output.probes": [[1.0, 0.0, 0.5]]}, BLOCK))
    (tmp_path / "scene.toml").write_text(text)
    out = tmp_path / "out"
    result = run("solve", tmp_path / "scene.toml", "--out", out)
    assert result.exit_code == 0, result.stderr
    with np.load(out / "solution.npz") as data:
        npoints, nf = data["points"].shape[0], data["contact_facets"].shape[0]
        assert data["points"].shape == (27, 3)
        assert data["cells"].shape[1] == 4
        assert data["contact_facets"].shape == (nf, 3) and nf > 0
        assert data["u"].shape == (NLEVELS, npoints, 3)
        assert data["beta"].shape == (NLEVELS, nf)
    step = strict_json(out / "summary.json")["steps"][-1]
    assert np.shape(step["probes"]) == (1, 3)
    assert isinstance(step["tangential_force"], list) and len(step["tangential_force"]) == 2
    assert (out / "deformed.png").stat().st_size > 0


BAD_SCENES = [
    # (id, changes to BLOCK, what the message must contain)
    ("unknown key", {"mesh.sise": [2.0, 1.0]}, "mesh.sise"),
    ("cells 0", {"mesh.cells": [0, 8]}, "mesh.cells"),
    ("missing E", {"material.E": DELETE}, "material.E"),
    ("steps not int", {"time.steps": "ten"}, "time.steps"),
    ("E zero", {"material.E": 0.0}, "material.E"),
    ("E negative", {"material.E": -5.0}, "material.E"),
    ("nu 0.5", {"material.nu": 0.5}, "material.nu"),
    ("T zero", {"time.T": 0.0}, "time.T"),
    ("T negative", {"time.T": -1.0}, "time.T"),
    ("steps zero", {"time.steps": 0}, "time.steps"),
    ("prony tau", {"memory": prony((200.0, 0.3, 0.0))}, "memory.terms[0].tau"),
    ("unknown side", {"boundary.dirichlet": ["middle"]}, "boundary.dirichlet"),
    ("held by a frictionless layer only", {"boundary.dirichlet": []},
     'boundary: the held sides (none) and the contact terms on Γ_C (a normal law, a wall) '
     'leave the body free to move rigidly (translation along x)'),
    ("held by nothing", {"boundary.dirichlet": [], "contact": DELETE},
     'boundary.dirichlet: must list at least one side: nothing holds the body; '
     'boundary.contact (bottom) carries no contact terms'),
    ("disallowed name", {"loads.body": ["0", "__import__('os')"]}, "loads.body[1]"),
    ("attribute access", {"loads.body": ["0", "t.real"]}, "loads.body[1]"),
    ("probe outside", {"output.probes": [[1.0, 0.0], [5.0, 0.5]]}, "output.probes[1]"),
    ("negative gap", {"contact.gap": "0.002 - 0.01*x"}, "contact.gap"),
]



@pytest.mark.parametrize("changes, key", [case[1:] for case in BAD_SCENES],
                         ids=[case[0] for case in BAD_SCENES])
def test_bad_scene_exits_2_with_one_line_naming_the_key(tmp_path, changes, key):
    scene = tmp_path / "scene.toml"
    scene.write_text(to_toml(scene_dict(changes, BLOCK)))
    result = run("solve", scene, "--out", tmp_path / "out")
    assert_one_line_error(result, 2, key)
    assert [p.name for p in tmp_path.iterdir()] == ["scene.toml"]   # nothing written


def test_invalid_toml_exits_2_with_one_line(tmp_path):
    scene = tmp_path / "scene.toml"
    scene.write_text(edit(SCENE, "dim = 2", "dim = = 2"))
    result = run("solve", scene, "--out", tmp_path / "out")
    assert_one_line_error(result, 2, "TOML")
    assert [p.name for p in tmp_path.iterdir()] == ["scene.toml"]   # nothing written


def test_missing_scene_file_exits_2(tmp_path):
    result = run("solve", tmp_path / "nowhere.toml", "--out", tmp_path / "out")
    assert_one_line_error(result, 2, "nowhere.toml")
    assert list(tmp_path.iterdir()) == []


def test_scene_that_is_a_folder_exits_2(tmp_path):
    result = run("solve", tmp_path, "--out", tmp_path / "out")
    assert_one_line_error(result, 2, "is a directory")
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("args, needle", [
    (["solve", "--outt", "x"], "--outt"),
    (["solve", "a.toml", "b.toml"], "b.toml"),
    (["solve", "--out"], "--out"),
    (["unknown-command"], "unknown-command"),
])
def test_bad_arguments_exit_2_with_one_line(tmp_path, monkeypatch, args, needle):
    monkeypatch.chdir(tmp_path)
    result = run(*args)
    assert_one_line_error(result, 2, needle)
    assert list(tmp_path.iterdir()) == []


def test_out_that_is_a_file_exits_2(tmp_path):
    (tmp_path / "scene.toml").write_text(SCENE)
    (tmp_path / "out").write_text("a file")
    result = run("solve", tmp_path / "scene.toml", "--out", tmp_path / "out")
    assert_one_line_error(result, 2, "--out")
    assert (tmp_path / "out").read_text() == "a file"


def test_solver_failure_exits_1_and_keeps_the_levels_before_it(tmp_path):
    scene = tmp_path / "scene.toml"
    scene.write_text(to_toml(scene_dict({"solver.max_iter": 1}, BLOCK)))
    out = tmp_path / "out"
    result = run("solve", scene, "--out", out)
    assert result.exit_code == 1, (result.stdout, result.stderr)
    errors = [line for line in result.stderr.splitlines() if line.startswith("error: ")]
    assert len(errors) == 1, result.stderr
    assert "did not converge" in errors[0] and "step 1" in errors[0]
    assert "The 1 levels before it were written" in errors[0]
    assert "Traceback" not in result.stderr
    summary = strict_json(out / "summary.json")
    assert summary["run"] == {
        "success": False, "status": "step failed", "partial": True, "levels": 1,
        "message": summary["run"]["message"], "failed_step": 1, "failed_t": 1 / 3}
    assert summary["run"]["message"].startswith("step 1 (t = 0.333333) did not converge")
    assert len(summary["steps"]) == 1
    with np.load(out / "solution.npz") as arrays:
        assert arrays["u"].shape == (1, NPOINTS, 2) and arrays["t"].tolist() == [0.0]


def test_the_failing_scene_converges_with_more_iterations(tmp_path):
    """The failure above is the iteration cap: with it lifted the wall is active."""
    scene = tmp_path / "scene.toml"
    scene.write_text(to_toml(scene_dict({"solver.max_iter": 50}, BLOCK)))
    result = run("solve", scene, "--out", tmp_path / "out")
    assert result.exit_code == 0, result.stderr
    steps = strict_json(tmp_path / "out" / "summary.json")["steps"]
    assert steps[1]["on_wall"] > 0 and steps[1]["iterations"] > 1


# --------------------------------------------------------------------------
# adhesion, friction and bonding: an 8x2 strip clamped on the left, glued to
# its foundation along the bottom and pulled up and along at its right end;
# the glue (adhesive_compliance + adhesive_spring) holds while Fremond's law
# debonds the right end; Tresca friction sticks the left part of Γ_C

FRICTION = [law("tresca", mu=1.0), law("adhesive_spring", gamma=2000.0, L=0.01)]

GLUED_SCENE = scene_dict({
    "title": "glued strip", "mesh.cells": [8, 2], "boundary.dirichlet": ["left"],
    "memory": prony((200.0, 0.3, 0.5)), "loads.traction.right": ["20*t", "40*t"],
    "contact": {
        "gap": 0.05,
        "normal": law("adhesive_compliance", c=10000.0, gamma=5000.0, L=0.01),
        "friction": FRICTION,
        "bonding": law("fremond", beta0=1.0, gamma_nu=15000.0, gamma_tau=7500.0, eps_a=0.0,
                       L=0.01)},
    "time.steps": 3})
GLUED = to_toml(GLUED_SCENE)

GLUED_NODES, GLUED_FACETS = 9, 8   # the bottom vertex on Γ_D is a (clamped) contact node


@pytest.fixture(scope="module")
def glued(tmp_path_factory):
    """GLUED solved once: (result, out folder, summary, npz arrays)."""
    root = tmp_path_factory.mktemp("glued")
    (root / "glued.toml").write_text(GLUED)
    out = root / "out"
    result = run("solve", root / "glued.toml", "--out", out)
    assert result.exit_code == 0, result.stderr
    with np.load(out / "solution.npz") as data:
        arrays = {key: data[key] for key in data.files}
    return result, out, strict_json(out / "summary.json"), arrays


def test_glued_summary_reports_the_smallness_terms(glued):
    _, _, summary, _ = glued
    assert set(summary) == SUMMARY_KEYS
    small = summary["smallness"]
    assert set(small) == SMALLNESS_KEYS
    flags = {"holds", "step_energy_convex", "existence_holds", "trace_lower_estimate"}
    assert all(isinstance(small[key], bool) for key in flags)
    for key in SMALLNESS_KEYS - flags:
        assert isinstance(small[key], float), key
    # what the library estimates, passed through unchanged (its formulas are
    # tested with the library); m_A = min(2 mu, d lam + 2 mu) checked here
    expected = build_problem(parse_scene(GLUED)).smallness
    assert small == pytest.approx(expected, rel=1e-12)
    E, nu = 1000.0, 0.3
    lam, mu = E * nu / ((1 + nu) * (1 - 2 * nu)), E / (2 * (1 + nu))
    assert small["m_A"] == pytest.approx(min(2 * mu, 2 * lam + 2 * mu))
    assert small["m_nu"] >= 10000.0 and small["m_tau"] > 0   # c; the glue's spring
    assert small["nonconvexity"] == 0.0 and small["step_energy_convex"] is True  # convex laws
    assert small["trace_constant_squared"] > 0
    assert small["rhs"] == pytest.approx(
        (small["m_tau"] + small["m_nu"]) * small["trace_constant_squared"])
    assert small["holds"] is (small["m_A"] > small["rhs"])
    # existence: max{√3 c_1τ, m_τ} + m_ν (c_1τ = 0: bounded friction here)
    assert small["c_1tau"] == 0.0 and small["existence_rhs"] == pytest.approx(small["rhs"])
    assert small["trace_lower_estimate"] is False   # the run's own mesh


def test_glued_warnings_are_listed_and_printed_before_stepping(glued):
    result, _, summary, _ = glued
    warnings = summary["warnings"]
    assert isinstance(warnings, list) and all(isinstance(w, str) for w in warnings)
    # the theory's conditions are recorded, not warned about: a sufficient
    # condition the scene misses says nothing about the run
    assert summary["smallness"]["holds"] is False
    assert not any("smallness" in w for w in warnings)
    lines = result.stderr.splitlines()
    printed = [line for line in lines if line.startswith("warning: ")]
    assert printed == [f"warning: {w}" for w in warnings]
    assert "error:" not in result.stderr and "Traceback" not in result.stderr
    # the scene's warnings before the progress bar's label, i.e. before the
    # time loop; what the run shows after it
    before = len(build_problem(parse_scene(GLUED)).warnings())
    label = next(i for i, line in enumerate(lines) if "glued: 3 steps" in line)
    assert all(lines.index(line) < label for line in printed[:before])
    assert all(lines.index(line) > label for line in printed[before:])


def test_glued_contact_states_are_counts_of_contact_nodes(glued):
    _, _, summary, _ = glued
    assert summary["mesh"]["contact_nodes"] == GLUED_NODES
    steps = summary["steps"]
    assert len(steps) == NLEVELS
    for step in steps:
        assert set(step) == STEP_KEYS
        counts = [step[key] for key in ("separated", "on_wall", "stick", "slip")]
        assert all(isinstance(c, int) and c >= 0 for c in counts), counts
        assert step["stick"] + step["slip"] + step["separated"] <= GLUED_NODES
        assert step["on_wall"] == 0      # the wall is 0.05 away
        assert isinstance(step["normal_force"], float)
        assert isinstance(step["tangential_force"], float)
    # the scene does something: the right end lifts off and slides
    assert steps[-1]["separated"] > 0 and steps[-1]["slip"] > 0
    # nothing moves at t = 0: friction holds all but the clamped node
    assert steps[0]["stick"] == GLUED_NODES - 1
    assert steps[-1]["normal_force"] < 0               # the glue pulls: tension


def test_glued_beta_is_a_nonincreasing_history_in_0_1(glued):
    _, _, _, data = glued
    beta = data["beta"]
    assert beta.shape == (NLEVELS, GLUED_FACETS)
    assert data["contact_facets"].shape == (GLUED_FACETS, 2)
    assert np.all((beta >= 0) & (beta <= 1))
    assert np.all(np.diff(beta, axis=0) <= 0)
    np.testing.assert_allclose(beta[0], 1.0, rtol=1e-12)   # beta0 = 1
    assert beta[-1].min() < 0.9                       # debonding happened


def test_glued_beta_mean_and_min_match_the_npz(glued):
    _, _, summary, data = glued
    ends = data["points"][data["contact_facets"]]     # (nf, 2 vertices, 2)
    length = np.linalg.norm(ends[:, 1] - ends[:, 0], axis=1)
    mean = data["beta"] @ length / length.sum()
    for n, step in enumerate(summary["steps"]):
        assert step["beta_mean"] == pytest.approx(mean[n], rel=1e-12)
        assert step["beta_min"] == pytest.approx(data["beta"][n].min(), rel=1e-12)


def test_glued_contact_xdmf_has_beta_per_time_step(glued):
    _, out, _, data = glued
    reader = meshio.xdmf.TimeSeriesReader(out / "contact.xdmf")
    reader.read_points_cells()
    assert reader.num_steps == NLEVELS
    for n in range(NLEVELS):
        t, _, cell_data = reader.read_data(n)
        assert t == pytest.approx(data["t"][n])
        np.testing.assert_allclose(cell_data["beta"][0], data["beta"][n])


def test_glued_plots_are_written(glued):
    result, out, _, _ = glued
    assert "Γ_C at t = 1: β mean" in result.stdout and "slip" in result.stdout
    # a prony kernel has no energy balance (no energy.png); the glue breaks
    assert set(p.name for p in out.iterdir()) == FILES | {"load_displacement.png",
                                                          "debonding.png"}
    for name in ("contact_traction.png", "beta.png", "load_displacement.png", "debonding.png"):
        assert (out / name).read_bytes()[:8] == b"\x89PNG\r\n\x1a\n", name


BAD_LAWS = [
    # (id, changes to GLUED_SCENE, what the message must contain)
    ("amontons", {"contact.friction": law("amontons", mu=1.0)}, "contact.friction.law"),
    ("coulomb without a normal compliance",
     {"contact.friction": law("coulomb", mu=1.0), "contact.normal": law("none")},
     "law 'coulomb' has the bound μ p_ν"),
    ("nonmonotone a <= b", {"contact.friction": law("nonmonotone", a=1.0, b=2.0, alpha=5.0)},
     "contact.friction.a"),
    ("nonmonotone a = b in a list",
     {"contact.friction": [law("nonmonotone", a=1.0, b=1.0, alpha=5.0), FRICTION[1]]},
     "contact.friction[0].a"),
    ("power q 1.5", {"contact.friction": [law("power", mu=1.0, q=1.5), FRICTION[1]]},
     "contact.friction[0].q"),
    ("friction entry missing L",
     {"contact.friction": [FRICTION[0], law("adhesive_spring", gamma=2000.0)]},
     "contact.friction[1].L"),
    ("bonding glue", {"contact.bonding.law": "glue"}, "contact.bonding.law"),
    ("bonding beta0 1.5", {"contact.bonding.beta0": 1.5}, "contact.bonding.beta0"),
    ("tresca with gauss", {"contact.quadrature": "gauss"}, "contact.quadrature"),
]


@pytest.mark.parametrize("changes, key", [case[1:] for case in BAD_LAWS],
                         ids=[case[0] for case in BAD_LAWS])
def test_bad_law_exits_2_with_one_line_naming_the_key(tmp_path, changes, key):
    scene = tmp_path / "scene.toml"
    scene.write_text(to_toml(scene_dict(changes, GLUED_SCENE)))
    result = run("solve", scene, "--out", tmp_path / "out")
    assert_one_line_error(result, 2, key)
    assert [p.name for p in tmp_path.iterdir()] == ["scene.toml"]   # nothing written


def test_glued_contact_xdmf_carries_the_contact_fields(glued):
    from adhesive_contact.postprocess import contact_state_codes, contact_traction

    _, out, _, arrays = glued
    problem = build_problem(parse_scene(GLUED))
    sol = solve(problem)
    reader = meshio.xdmf.TimeSeriesReader(out / "contact.xdmf")
    points, cells = reader.read_points_cells()
    # its points are the facets' vertices alone, in increasing mesh index
    vertices = np.unique(problem.boundary.facet_nodes)
    np.testing.assert_array_equal(points[:, :2], problem.mesh.p.T[vertices])
    np.testing.assert_array_equal(vertices[cells[0].data], problem.boundary.facet_nodes.T)
    nodes = np.searchsorted(vertices, problem.boundary.nodes)
    codes = contact_state_codes(sol)
    traction = contact_traction(sol, "global")
    for n in range(reader.num_steps):
        _, point_data, _ = reader.read_data(n)
        np.testing.assert_allclose(point_data["traction"][nodes, :2], traction[n],
                                   rtol=1e-9, atol=1e-9 * np.abs(traction).max())
        np.testing.assert_allclose(point_data["normal_traction"][nodes],
                                   -contact_traction(sol)[n, :, 0], rtol=1e-9, atol=1e-6)
        np.testing.assert_array_equal(point_data["state"][nodes], codes[n])
        np.testing.assert_allclose(point_data["u_normal"][nodes],
                                   sol.frame_displacement[n, :, 0], atol=1e-12)
        np.testing.assert_allclose(point_data["slip"][nodes],
                                   np.abs(sol.frame_displacement[n, :, 1]), atol=1e-12)
    # all stuck at t = 0; then the right end separates while the rest sticks
    # and finally slips; the clamped node (u = 0, held, not stuck by friction)
    # is in compliance
    clamped = problem.boundary.held.all(axis=1)
    assert clamped.sum() == 1 and np.all(codes[:, clamped] == 1)
    assert set(codes[0][~clamped].tolist()) == {3}
    assert set(codes[1][~clamped].tolist()) == {0, 3, 4}
    assert set(codes[-1][~clamped].tolist()) == {0, 4}
