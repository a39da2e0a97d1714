"""``adhcontact check``: validates without running, prints the sizes, the
estimate (its counts those of the mesh line), the bonding bound and the
smallness figures, the resolved scene with --resolved only, and writes
nothing; a bad scene is exit 2, one line."""

import json
import logging
from pathlib import Path

from adhesive_contact_cli.main import main
from click.testing import CliRunner
from conftest import scene_dict, to_toml

from adhesive_contact import load_scene

ROOT = Path(__file__).resolve().parents[1]


def test_check_prints_what_a_run_would_be_and_writes_nothing(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    path = ROOT / "studies/scenes/debonding.toml"
    result = CliRunner().invoke(main, ["check", str(path)])
    assert result.exit_code == 0, result.output
    out = result.stdout
    assert "debonding: valid scene" in out
    assert "80 contact facets, 81 contact nodes, 160 contact unknowns" in out
    assert "explicit Euler bound of the bonding law: k <= 0.06667 (k = 0.02: within" in out
    assert "smallness: m_A = 769.2" in out and "estimate: " in out
    assert "{" not in out and "resolved scene" not in out
    # the estimate counts the mesh built: 160 contact unknowns as its mesh line
    assert "891 nodes" in out and f"estimate: {2 * 891:.3g} dofs, 160 contact unknowns," in out
    full = CliRunner().invoke(main, ["check", str(path), "--resolved"]).stdout
    assert full.startswith(out)
    resolved = json.loads(full[full.index("{"):])
    assert resolved == json.loads(json.dumps(load_scene(path).resolved))
    assert list(tmp_path.iterdir()) == []


def test_the_estimate_of_check_counts_the_contact_unknowns_of_its_mesh_line(tmp_path):
    """On the built-in scene the contact unknowns of the estimate (before the
    mesh exists: 81 bottom nodes x 2) would differ from the mesh's (each end
    node has one component held: 79 x 2 + 2); check reports the mesh's in
    both lines."""
    out = CliRunner().invoke(main, ["check"]).stdout
    assert "81 contact nodes, 160 contact unknowns" in out
    assert "972 dofs, 160 contact unknowns, 41 time levels" in out


def test_a_mesh_file_run_prints_nothing_of_scikit_fem(tmp_path, caplog):
    """A 3D mesh file of more than 1000 vertices and cells, refined once:
    scikit-fem would say it copies the arrays to C order and that the named
    boundaries were dropped by the refinement; the library hands it
    C-ordered arrays and refines the mesh without names."""
    import numpy as np
    from skfem import MeshTet
    from test_geometry import write_msh

    from adhesive_contact import build_problem, scene_from_dict
    mesh = MeshTet.init_tensor(np.linspace(0, 2, 13), np.linspace(0, 1, 9),
                               np.linspace(0, 0.5, 6)).with_boundaries(
        {"bottom": lambda x: np.isclose(x[2], 0), "top": lambda x: np.isclose(x[2], 0.5)})
    assert mesh.p.shape[1] < 1000 < mesh.t.shape[1]
    write_msh(tmp_path / "block.msh", mesh, ["bottom", "top"])
    scene = scene_dict({"dim": 3, "mesh": {"domain": "file", "file": str(tmp_path / "block.msh"),
                                           "refine": 1},
                        "boundary": {"dirichlet": ["top"], "contact": ["bottom"]},
                        "contact.normal": {"law": "compliance", "c": 1e3}})
    with caplog.at_level(logging.DEBUG, logger="skfem"):   # what it would print
        problem = build_problem(scene_from_dict(scene))
        assert problem.mesh.p.shape[1] > 1000 and problem.smallness is not None
    said = [r.getMessage() for r in caplog.records if r.name.startswith("skfem")
            and r.levelno >= logging.WARNING]
    assert said == []


def test_check_refuses_a_bad_scene_with_one_line(tmp_path):
    path = tmp_path / "bad.toml"
    path.write_text(to_toml(scene_dict({"time.steps": 0})))
    result = CliRunner().invoke(main, ["check", str(path)])
    assert result.exit_code == 2
    assert result.stderr.strip().splitlines() == [
        "error: time.steps: must be an integer in 1..1e+08, got 0"]


def test_quiet_solve_prints_no_warning_but_keeps_them(tmp_path):
    # a contact stiffness 1e12 times the body's warns
    path = tmp_path / "stiff.toml"
    path.write_text(to_toml(scene_dict({"contact.normal": {"law": "compliance", "c": 1e12},
                                        "time.steps": 2})))
    out = tmp_path / "out"
    loud = CliRunner().invoke(main, ["solve", str(path), "--out", str(tmp_path / "loud")])
    quiet = CliRunner().invoke(main, ["solve", str(path), "--out", str(out), "--quiet"])
    assert loud.exit_code == quiet.exit_code == 0
    assert "warning: " in loud.stderr and "steps" in loud.stderr
    assert quiet.stderr == ""
    warnings = json.loads((out / "summary.json").read_text())["warnings"]
    assert warnings and all(w.split()[0] in loud.stderr for w in warnings)


def test_progress_shows_t_and_the_newton_iterations():
    from types import SimpleNamespace

    from adhesive_contact_cli.main import level_status
    assert level_status(None) is None
    assert level_status(SimpleNamespace(t=0.25, iterations=4)) == "t = 0.25, 4 Newton iterations"


def test_check_and_sweep_show_the_stiffness_warning(tmp_path):
    """A contact stiffness far from the body's needs no solution: ``check``
    and ``sweep`` show it (the sweep once, naming the runs it holds for),
    as ``solve`` does before a run."""
    stiff = scene_dict({"contact.normal": {"law": "compliance", "c": 1e12}, "time.steps": 1})
    path = tmp_path / "stiff.toml"
    path.write_text(to_toml(stiff))
    needle = "warning: contact.normal.c = 1e+12 times the body's size"
    checked = CliRunner().invoke(main, ["check", str(path)])
    assert checked.exit_code == 0 and needle in checked.stdout
    swept = CliRunner().invoke(main, ["sweep", str(path), "--set", "time.steps=1,2",
                                      "--out", str(tmp_path / "sweep")])
    assert swept.exit_code == 0, swept.stderr
    (line,) = [w for w in swept.stderr.splitlines() if "contact.normal.c = 1e+12" in w]
    assert line.startswith("warning: run 0, 1: contact.normal.c = 1e+12")


def test_check_of_a_scene_too_large_to_build_prints_the_estimate_without_building(tmp_path):
    # an 8.1e7-node mesh: check built it and ran out of memory
    import subprocess
    import sys

    scene = tmp_path / "huge.toml"
    scene.write_text(to_toml(scene_dict({"mesh.cells": [18000, 4500], "time.steps": 20})))
    code = ("import resource, sys; from adhesive_contact_cli.main import main; "
            "main(['check', sys.argv[1]])")
    result = subprocess.run([sys.executable, "-c", code, str(scene)], capture_output=True,
                            text=True, timeout=120)
    assert result.returncode == 0, result.stderr
    lines = result.stdout.splitlines()
    assert lines[0].startswith("huge: valid scene (untitled), too large to build here: it "
                               "would need about")
    assert lines[1].startswith("  estimate: 1.62e+08 dofs")   # 2 x 18001 x 4501
    assert lines[3].startswith("  not built: ")
    peak = subprocess.run([sys.executable, "-c", code.replace(
        "main(['check', sys.argv[1]])", "\ntry:\n    main(['check', sys.argv[1]])\n"
        "except SystemExit:\n    pass\nprint(resource.getrusage(resource.RUSAGE_SELF)"
        ".ru_maxrss)"), str(scene)], capture_output=True, text=True, timeout=120)
    assert int(peak.stdout.splitlines()[-1]) < 500 * 1024   # KiB: nothing was built
