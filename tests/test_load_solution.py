"""``load_solution``: an output folder of ``adhcontact solve`` read back as
the Solution that ``solve`` returns, equal to an in-process solve; a
missing or damaged folder named in one clear exception."""

import json
import shutil
import tomllib
import zipfile
from pathlib import Path

import numpy as np
import pytest
from adhesive_contact_cli.main import main
from conftest import glued_contact, runner, scene_dict, to_toml, wall_block

from adhesive_contact import (
    OutputFolderError,
    build_problem,
    load_solution,
    parse_scene,
    scene_from_dict,
    solve,
)
from adhesive_contact.scheme import STEP_FAILED, SUCCESS
from adhesive_contact.visuals import write_plots

ROOT = Path(__file__).resolve().parents[1]

#: a strip glued at the bottom, lifted at its top, with a probe
GLUED = scene_dict({
    "mesh.cells": [8, 2], "boundary.dirichlet": [],
    "boundary.displacement": {"top": ["0", "0.002*t"]},
    "contact": glued_contact(), "time.steps": 3, "output.probes": [[1.0, 0.25]]})

#: a small box on a compliant foundation (3D: no σ_zz)
BOX = scene_dict({
    "dim": 3, "mesh.domain": "box", "mesh.size": [1.0, 0.5, 0.5], "mesh.cells": [2, 2, 2],
    "boundary.dirichlet": ["top"], "boundary.contact": ["bottom"],
    "loads.body": ["0", "-100*t", "0"], "contact.normal": {"law": "compliance", "c": 1e3},
    "time.steps": 2})

#: with one Newton iteration allowed the wall block fails at step 1
FAILING = scene_dict({"solver.max_iter": 1}, wall_block())

ARRAYS = ("t", "u", "beta", "contact_force", "frame_displacement", "on_wall", "stuck",
          "probes", "iterations", "residual", "reaction")


def solve_into(folder, text, name="scene.toml"):
    """Run ``adhcontact solve`` on a scene text written to ``folder/name``."""
    folder.mkdir(parents=True, exist_ok=True)
    scene = folder / name
    scene.write_text(text)
    result = runner().invoke(main, ["solve", str(scene), "--out", str(folder / "out"), "-q"],
                             catch_exceptions=False)
    return result, folder / "out"


def assert_same_solution(loaded, direct):
    for name in ARRAYS:
        a, b = np.asarray(getattr(loaded, name)), np.asarray(getattr(direct, name))
        assert a.shape == b.shape and a.dtype.kind == b.dtype.kind, name
        np.testing.assert_allclose(a.astype(float), b.astype(float), rtol=0,
                                   atol=1e-12 * max(1.0, np.abs(b).max(initial=0.0)),
                                   err_msg=name)
    np.testing.assert_allclose(loaded.stress[-1], direct.stress[-1], rtol=0,
                               atol=1e-12 * np.abs(direct.stress[-1]).max())
    assert loaded.stress.shape[0] == 1
    if direct.stress_zz is None:
        assert loaded.stress_zz is None
    else:
        np.testing.assert_allclose(loaded.stress_zz[-1], direct.stress_zz[-1], rtol=0,
                                   atol=1e-12 * np.abs(direct.stress_zz[-1]).max())
    assert (loaded.status, loaded.success, loaded.message) == \
        (direct.status, direct.success, direct.message)
    assert loaded.steps == direct.steps
    assert loaded.linear == direct.linear and set(loaded.timings) == set(direct.timings)


@pytest.mark.parametrize("document", [GLUED, BOX], ids=["2d", "3d"])
def test_a_solved_folder_loads_as_the_solution_solve_returns(tmp_path, document):
    text = to_toml(document)
    result, out = solve_into(tmp_path, text)
    assert result.exit_code == 0, result.stderr
    direct = solve(build_problem(parse_scene(text)))
    loaded = load_solution(out)
    assert loaded.status == SUCCESS
    assert_same_solution(loaded, direct)
    # the problem rebuilt from summary.json: the same scene, the same mesh
    assert loaded.problem.scene.resolved == direct.problem.scene.resolved
    np.testing.assert_array_equal(loaded.problem.mesh.p, direct.problem.mesh.p)
    # the methods and the plots work on it as on the direct solution
    np.testing.assert_allclose(loaded.total_normal_force(), direct.total_normal_force(),
                               rtol=0, atol=1e-12 * np.abs(direct.total_normal_force()).max())
    drawn = tmp_path / "drawn"
    drawn.mkdir()
    failures = []
    assert set(write_plots(loaded, drawn, failures)) == {p.name for p in out.glob("*.png")}
    assert failures == []
    # the problem may be given: no rebuilding
    again = load_solution(out, problem=direct.problem)
    assert again.problem is direct.problem
    np.testing.assert_array_equal(again.u, loaded.u)


def test_a_failed_run_loads_with_its_levels_and_message(tmp_path):
    text = to_toml(FAILING)
    result, out = solve_into(tmp_path, text)
    assert result.exit_code == 1
    direct = solve(build_problem(parse_scene(text)))
    assert direct.status == STEP_FAILED and direct.t.size == 1
    loaded = load_solution(out)
    assert_same_solution(loaded, direct)
    assert loaded.failure is None and not loaded.success


def test_a_mesh_file_is_found_from_the_scene_folder_wherever_it_is_loaded(tmp_path,
                                                                         monkeypatch):
    # the curved foot, shortened: its mesh file is relative to the scene's folder
    document = tomllib.loads((ROOT / "studies" / "scenes" / "curved_foot.toml").read_text())
    document["mesh"] |= {"file": "meshes/half_disc.msh", "refine": 0}
    document["time"]["steps"] = 2
    (tmp_path / "scenes" / "meshes").mkdir(parents=True)
    shutil.copy(ROOT / "studies" / "meshes" / "half_disc.msh", tmp_path / "scenes" / "meshes")
    result, out = solve_into(tmp_path / "scenes", to_toml(document), "foot.toml")
    assert result.exit_code == 0, result.stderr
    monkeypatch.chdir(tmp_path)          # elsewhere than the scene
    loaded = load_solution(out)
    direct = solve(build_problem(scene_from_dict(document, tmp_path / "scenes")))
    assert_same_solution(loaded, direct)


@pytest.fixture(scope="module")
def folder(tmp_path_factory):
    """A solved output folder to damage in copies."""
    result, out = solve_into(tmp_path_factory.mktemp("solved"), to_toml(GLUED))
    assert result.exit_code == 0, result.stderr
    return out


def damaged(folder, tmp_path, change):
    copy = tmp_path / "copy"
    shutil.copytree(folder, copy)
    change(copy)
    return copy


def drop_key(path, key):
    with np.load(path) as data:
        arrays = {name: data[name] for name in data.files if name != key}
    np.savez_compressed(path, **arrays)


def edit_summary(path, change):
    document = json.loads(path.read_text())
    change(document)
    path.write_text(json.dumps(document))


def replace_key(path, key, value):
    with np.load(path) as data:
        arrays = {name: data[name] for name in data.files}
    arrays[key] = value(arrays[key])
    np.savez_compressed(path, **arrays)


def claim_entries(path, key, count):
    """Replace ``key`` by an array whose header claims ``count`` entries (the
    data holds 8 bytes): reading it would allocate 8·count bytes."""
    with np.load(path) as data:
        arrays = {name: data[name] for name in data.files if name != key}
    np.savez_compressed(path, **arrays)
    with zipfile.ZipFile(path, "a") as archive, archive.open(f"{key}.npy", "w") as f:
        np.lib.format.write_array_header_2_0(f, {"descr": "<f8", "fortran_order": False,
                                                 "shape": (count,)})
        f.write(b"\0" * 8)


@pytest.mark.parametrize("change, file, needle", [
    (lambda f: (f / "summary.json").unlink(), "summary.json", "no such file"),
    # tampered arrays: accepted, then a failure (or a traceback) in use;
    # a header of 1e11 entries tried to allocate 745 GiB
    (lambda f: replace_key(f / "solution.npz", "u", lambda u: u[:, :, :1]), "solution.npz",
     "holds 'u' of shape (4, 27, 1), not (4, 27, 2)"),
    (lambda f: replace_key(f / "solution.npz", "u", lambda u: u.astype(str)), "solution.npz",
     "holds 'u' of dtype <U"),
    (lambda f: replace_key(f / "solution.npz", "beta", lambda b: b[:, :-1]), "solution.npz",
     "holds 'beta' of shape (4, 7), not (4, 8)"),
    (lambda f: replace_key(f / "solution.npz", "contact_force", lambda c: c[:2]),
     "solution.npz", "holds 'contact_force' of shape (2, 9, 2), not (4, 9, 2)"),
    (lambda f: replace_key(f / "solution.npz", "on_wall", lambda w: w.astype(float)),
     "solution.npz", "holds 'on_wall' of dtype float64, not bool"),
    (lambda f: claim_entries(f / "solution.npz", "u", 10**11), "solution.npz",
     "holds 'u' of shape (100000000000,), not (4, 27, 2)"),
    (lambda f: (f / "summary.json").write_text("[" * 100000 + "]" * 100000),
     "summary.json", "is nested too deeply to be a summary.json"),
    (lambda f: edit_summary(f / "summary.json", lambda d: d["run"].update(levels="4")),
     "summary.json", "its run record is damaged (run.status, run.levels)"),
    (lambda f: (f / "summary.json").write_text("{\"schema\": 1, "), "summary.json",
     "not valid JSON"),
    (lambda f: edit_summary(f / "summary.json", lambda d: d.update(schema=1)),
     "summary.json", "has schema 1; this version reads schema 2: run the scene again"),
    (lambda f: edit_summary(f / "summary.json", lambda d: d.pop("source")), "summary.json",
     "keeps no scene text (written by an older version)"),
    (lambda f: edit_summary(f / "summary.json",
                            lambda d: d["source"].update(text="dim = 4")), "summary.json",
     "its scene cannot be built here: "),
    (lambda f: edit_summary(f / "summary.json",
                            lambda d: d["scene"]["time"].update(steps=7)), "summary.json",
     "records another scene than the problem's (they differ at time.steps)"),
    (lambda f: (f / "solution.npz").unlink(), "solution.npz", "no such file"),
    (lambda f: (f / "solution.npz").write_bytes((f / "solution.npz").read_bytes()[:200]),
     "solution.npz", "cannot be read"),
    (lambda f: drop_key(f / "solution.npz", "contact_force"), "solution.npz",
     "has no 'contact_force': it was written by an older version"),
])
def test_a_damaged_folder_names_the_file(folder, tmp_path, change, file, needle):
    copy = damaged(folder, tmp_path, change)
    with pytest.raises(OutputFolderError) as err:
        load_solution(copy)
    assert err.value.path == copy / file
    assert str(err.value).startswith(f"{copy / file}: ")
    assert needle in str(err.value) and "\n" not in str(err.value)


def test_a_missing_folder_and_another_problem_are_refused(folder, tmp_path):
    with pytest.raises(OutputFolderError, match="summary.json: no such file"):
        load_solution(tmp_path / "nowhere")
    other = build_problem(scene_from_dict(scene_dict({"title": "another"}, GLUED)))
    with pytest.raises(OutputFolderError, match=r"another scene .*\(they differ at title\)"):
        load_solution(folder, problem=other)
    assert zipfile.is_zipfile(folder / "solution.npz")     # the folder itself untouched
