"""Tests for ``adhcontact converge`` (docs/outputs.md; docs/verification.md):
the firm outputs, the fine reference, resuming, refusing another study and
running levels in parallel. Tiny scenes (4x2 cells, a few steps, 3 levels)."""

import csv
import json
import shutil
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest
from adhesive_contact_cli.main import main
from conftest import DELETE, assert_one_line_error, law, prony, reference_mesh, runner, scene_dict, to_toml
from skfem import Basis, ElementTriP1, ElementVector, Functional
from skfem.helpers import ddot, sym_grad

import adhesive_contact.studies.convergence as converge_module
from adhesive_contact import StepFailure, build_problem, parse_scene, solve
from adhesive_contact.studies.convergence import trust
from adhesive_contact.studies.levels import default_reference_refinement, run_reference


# no contact: u* is smooth and the library derives body force and tractions;
# 8 steps keep the time error below the space error of the 3 levels
EXACT = scene_dict({
    "title": "manufactured, no contact", "mesh.size": [1.0, 0.5], "mesh.cells": [4, 2],
    "boundary": {"dirichlet": ["left"]}, "memory": prony((200.0, 0.3, 0.5)),
    "time.steps": 8, "exact.u": ["0.01*x*x*(1+t)", "0.005*x*y"]})

# a block hanging from its top, pressed by its weight onto a compliant wall
CONTACT = scene_dict({
    "title": "small block on a compliant wall", "mesh.size": [1.0, 0.5],
    "mesh.cells": [4, 2], "memory": prony((200.0, 0.3, 0.5)),
    "loads.body": ["0", "-400*t"], "contact.gap": "0.001 + 0.01*(x - 0.5)**2",
    "contact.normal": law("compliance", c=300.0), "time.steps": 2})

EXACT_SCENE, CONTACT_SCENE = to_toml(EXACT), to_toml(CONTACT)

REF_K = default_reference_refinement("k")[1]
FIRM_LEVEL_KEYS = {"h", "k", "dofs", "err_u", "err_beta", "E", "seconds"}
CSV_COLUMNS = ["level", "h", "k", "dofs", "steps", "err_u", "err_beta", "E", "rate_E",
               "seconds", "rel_u", "rel_beta", "rel_E"]


def run(*args):
    return runner().invoke(main, ["converge", *map(str, args)], catch_exceptions=False)


def strict_json(path):
    """Load JSON, failing on NaN or Infinity (not JSON)."""
    def refuse(name):
        raise ValueError(f"{name} in {path}")
    return json.loads(path.read_text(), parse_constant=refuse)



def snapshot(folder):
    """{relative path: bytes} of every file under ``folder``."""
    return {str(p.relative_to(folder)): p.read_bytes()
            for p in sorted(folder.rglob("*")) if p.is_file()}


def read_csv(path):
    lines = path.read_text().splitlines()
    return lines[0].split(","), [line.split(",") for line in lines[1:]]


@pytest.fixture(scope="module")
def scenes(tmp_path_factory):
    folder = tmp_path_factory.mktemp("scenes")
    (folder / "exact.toml").write_text(EXACT_SCENE)
    (folder / "contact.toml").write_text(CONTACT_SCENE)
    return SimpleNamespace(exact=folder / "exact.toml", contact=folder / "contact.toml")


@pytest.fixture(scope="module")
def exact_study(scenes, tmp_path_factory):
    """An h-study of the exact scene, 3 levels (reference exact by default)."""
    out = tmp_path_factory.mktemp("exact") / "out"
    result = run(scenes.exact, "--param", "h", "--levels", 3, "--out", out)
    assert result.exit_code == 0, (result.stdout, result.stderr)
    return SimpleNamespace(out=out, result=result)


@pytest.fixture(scope="module")
def fine_study(scenes, tmp_path_factory):
    """A k-study of the contact scene against a fine reference, 3 levels."""
    out = tmp_path_factory.mktemp("fine") / "out"
    result = run(scenes.contact, "--param", "k", "--levels", 3, "--out", out)
    assert result.exit_code == 0, (result.stdout, result.stderr)
    return SimpleNamespace(out=out, result=result)


# ---------------------------------------------------------------- (1) exact


def test_exact_study_writes_the_firm_outputs(exact_study):
    out = exact_study.out
    assert {p.name for p in out.iterdir()} == {
        "study.json", "levels", "errors.csv", "rates.json", "error_vs_h.png",
        "work_precision.png"}
    assert sorted(p.name for p in (out / "levels").iterdir()) == [
        "level_00.json", "level_01.json", "level_02.json"]
    for png in ("error_vs_h.png", "work_precision.png"):
        data = (out / png).read_bytes()
        assert data[:8] == b"\x89PNG\r\n\x1a\n" and len(data) > 10_000

    doc = strict_json(out / "rates.json")
    assert doc["param"] == "h"
    assert set(doc["rates"]) == {"u", "beta", "E"}
    assert doc["reference"]["kind"] == "exact"
    levels = doc["levels"]
    assert len(levels) == 3
    for n, level in enumerate(levels):
        assert FIRM_LEVEL_KEYS <= set(level)
        assert level["level"] == n and level["steps"] == 8 and level["k"] == 0.125
        assert level["err_beta"] == 0.0          # no contact boundary
        assert level["E"] == pytest.approx(level["err_u"] + level["err_beta"], rel=1e-14)
        assert level["seconds"] > 0
    hs = np.array([level["h"] for level in levels])
    np.testing.assert_allclose(hs[1:] / hs[:-1], 0.5, rtol=1e-12)    # nested refinement
    assert [level["dofs"] for level in levels] == [30, 90, 306]
    E = np.array([level["E"] for level in levels])
    assert np.all(np.diff(E) < 0)
    # the least-squares slope of log E against log h, first order
    assert doc["rates"]["E"] > 0.8
    assert doc["rates"]["E"] == pytest.approx(np.polyfit(np.log(hs), np.log(E), 1)[0],
                                              rel=1e-9)
    assert doc["rates"]["u"] == doc["rates"]["E"]
    assert doc["rates"]["beta"] is None          # no β error to fit: NaN -> null
    assert levels[0]["rate_E"] is None
    assert levels[1]["rate_E"] == pytest.approx(np.log(E[0] / E[1]) / np.log(2), rel=1e-9)

    header, rows = read_csv(out / "errors.csv")
    assert header == CSV_COLUMNS
    assert len(rows) == 3
    for row, level in zip(rows, levels):
        record = dict(zip(header, row))
        assert float(record["E"]) == level["E"] and int(record["dofs"]) == level["dofs"]
        # the relative errors of rates.json, null there (no β error) empty here
        assert (float(record["rel_u"]), float(record["rel_E"])) == (level["rel_u"],
                                                                    level["rel_E"])
        assert level["rel_beta"] is None and record["rel_beta"] == ""
    assert rows[0][header.index("rate_E")] == ""

    study = strict_json(out / "study.json")
    assert (study["param"], study["levels"], study["reference"]) == ("h", 3, "exact")
    assert study["ref_h"] is None and study["ref_k"] is None
    assert study["scene"]["exact"]["u"] == ["0.01*x*x*(1+t)", "0.005*x*y"]
    assert len(study["sha256"]) == 64

    # relative errors: over max_t ‖ε(u*)‖, by hand for u* = (0.01 x²(1+t), 0.005 x y)
    # on [0, 1] × [0, 0.5] at t = T = 1: ε = [[0.04 x, 0.0025 y], [0.0025 y, 0.005 x]]
    norm = np.sqrt(0.04**2 / 3 * 0.5 + 0.005**2 / 3 * 0.5 + 2 * 0.0025**2 * 0.5**3 / 3)
    for level in levels:
        assert level["rel_u"] * norm == pytest.approx(level["err_u"], rel=1e-10)
        assert level["rel_E"] == level["rel_u"] and level["rel_beta"] is None   # no Γ_C
    assert 0.01 < levels[-1]["rel_u"] < levels[0]["rel_u"] < 0.5

    stdout = exact_study.result.stdout
    assert "‖ε(u−u_h)‖" in stdout and "least-squares rates" in stdout
    # the table says which norms, which times, against what, which h; rel beside each error
    assert ("‖ε(u−u_h)‖ = ‖ε(u(t_n)) − ε(u_h^n)‖ in L²(Ω);  ‖β−β_h‖ = ‖β(t_n) − β_h^n‖ in "
            "L²(Γ_C);  E = max of their sum") in stdout
    assert "each the max over the time levels t_n" in stdout
    assert "u, β: the scene's exact solution" in stdout
    assert "h = the largest edge length (cell diameter) of the mesh" in stdout
    row = next(line for line in stdout.splitlines() if line.split()[:1] == ["0"])
    assert row.split()[4:6] == [f"{levels[0]['err_u']:.3e}", f"{levels[0]['rel_u']:.1e}"]
    assert "needed" in exact_study.result.stderr or ">= 4" in exact_study.result.stderr


def test_default_out_is_named_after_the_scene_and_param(scenes, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    result = run(scenes.exact, "--param", "k", "--levels", 2)
    assert result.exit_code == 0, result.stderr
    assert [p.name for p in tmp_path.iterdir()] == ["exact-converge-k"]
    assert (tmp_path / "exact-converge-k" / "error_vs_k.png").is_file()
    doc = strict_json(tmp_path / "exact-converge-k" / "rates.json")
    assert [level["k"] for level in doc["levels"]] == [0.125, 0.0625]


# ---------------------------------------------------------------- (2) fine


def test_fine_reference_k_study(fine_study, scenes):
    out = fine_study.out
    assert {p.name for p in out.iterdir()} == {
        "study.json", "levels", "reference.npz", "errors.csv", "rates.json",
        "error_vs_k.png", "work_precision.png"}
    doc = strict_json(out / "rates.json")
    assert doc["param"] == "k"
    levels = doc["levels"]
    assert [level["steps"] for level in levels] == [2, 4, 8]
    assert len({level["h"] for level in levels}) == 1
    assert len({level["dofs"] for level in levels}) == 1
    E = np.array([level["E"] for level in levels])
    assert np.all(E > 0) and np.all(np.diff(E) < 0)
    assert doc["rates"]["E"] > 0.8
    # the reference: the library's default refinement for a k-study beyond the
    # finest level (8 steps)
    ref_h, ref_k = default_reference_refinement("k")
    steps = 8 * 2 ** ref_k
    info = doc["reference"]
    assert (info["kind"], info["ref_h"], info["ref_k"], info["steps"], info["refine"]) == \
        ("fine", ref_h, ref_k, steps, ref_h)
    assert ref_k >= 1 and info["k"] == 1.0 / steps
    with np.load(out / "reference.npz") as saved:
        assert {"t", "u", "beta", "facets", "refine", "steps", "seconds"} <= set(saved.files)
        assert int(saved["steps"]) == steps and int(saved["refine"]) == ref_h
        # only the levels the errors read: those of the finest level's grid
        np.testing.assert_array_equal(saved["kept"], np.arange(0, steps + 1, 2 ** ref_k))
        assert saved["u"].shape[0] == 8 + 1 and saved["u"].shape[2] == 2
        assert float(saved["seconds"]) == info["seconds"]
        fresh = run_reference(parse_scene(CONTACT_SCENE), "k", 3)
        whole = solve(build_problem(fresh.scene))       # every level, solved here
        np.testing.assert_allclose(saved["t"], whole.t, rtol=0, atol=1e-15)
        np.testing.assert_allclose(saved["u"], whole.u[saved["kept"]], rtol=0, atol=1e-15)
        np.testing.assert_array_equal(saved["facets"], fresh.facets)
    assert np.abs(fresh.level_u(steps)).max() > 1e-4   # the block moves: the errors mean something
    # relative errors over the reference's own norms on the level's time grid,
    # ‖ε(u_ref)‖ by scikit-fem here; β_ref = 1 on Γ_C (no bonding law): ‖β_ref‖ = √|Γ_C| = 1
    basis = Basis(reference_mesh([1.0, 0.5], [4, 2]), ElementVector(ElementTriP1()))
    strain_norm = Functional(lambda w: ddot(sym_grad(w["u"]), sym_grad(w["u"])))
    for level in levels:
        ratio = steps // level["steps"]
        norms = np.sqrt([strain_norm.assemble(basis,
                                              u=basis.interpolate(fresh.level_u(n).ravel()))
                         for n in range(0, steps + 1, ratio)])
        assert level["rel_u"] == pytest.approx(level["err_u"] / norms.max(), rel=1e-10)
        assert level["rel_beta"] == 0.0 and level["err_beta"] == 0.0
        assert level["rel_E"] == pytest.approx(level["E"] / (norms + 1.0).max(), rel=1e-10)
    assert "u, β: the fine reference run" in fine_study.result.stdout


def test_the_progress_names_each_level_and_its_run(exact_study, fine_study):
    """Levels run here: a line naming the study, then a bar per level over
    its steps, labelled with the level, its refinement and its steps (on
    stderr; a bar that is not on a terminal shows its label)."""
    err = exact_study.result.stderr.splitlines()
    assert "exact: h-study, 3 levels" in err
    labels = [line for line in err if line.startswith("level ")]
    assert labels == ["level 0 (1 of 3): refine 0, 8 steps",
                      "level 1 (2 of 3): refine 1, 8 steps",
                      "level 2 (3 of 3): refine 2, 8 steps"]
    err = fine_study.result.stderr.splitlines()
    assert err.index("reference run") < err.index("contact: k-study, 3 levels") < err.index(
        "level 0 (1 of 3): refine 0, 2 steps") < err.index("level 2 (3 of 3): refine 0, 8 steps")


# ---------------------------------------------------------------- (3) resume


def test_rerun_recomputes_nothing(fine_study, tmp_path, scenes, counting):
    out = tmp_path / "out"
    shutil.copytree(fine_study.out, out)
    before = snapshot(out)
    result = run(scenes.contact, "--param", "k", "--levels", 3, "--out", out)
    assert result.exit_code == 0, result.stderr
    assert counting.levels == [] and counting.reference == 0
    assert snapshot(out) == before           # rates.json, errors.csv, ... identical
    assert "0 of 3 levels computed now" in result.stdout


def test_a_study_saved_before_relative_errors_resumes_without_them(exact_study, tmp_path,
                                                                   scenes, counting):
    out = tmp_path / "out"
    shutil.copytree(exact_study.out, out)
    for path in (out / "levels").iterdir():       # level records as an older version wrote
        record = json.loads(path.read_text())
        path.write_text(json.dumps({k: v for k, v in record.items()
                                    if not k.startswith("rel_")}))
    result = run(scenes.exact, "--param", "h", "--levels", 3, "--out", out)
    assert result.exit_code == 0, result.stderr
    assert counting.levels == [] and "0 of 3 levels computed now" in result.stdout
    levels = strict_json(out / "rates.json")["levels"]
    assert all(level[key] is None for level in levels for key in ("rel_u", "rel_beta", "rel_E"))
    row = next(line for line in result.stdout.splitlines() if line.split()[:1] == ["0"])
    assert row.split()[4:6] == [f"{levels[0]['err_u']:.3e}", "—"]


def test_interrupted_study_computes_only_the_missing_levels(fine_study, tmp_path, scenes,
                                                            counting, monkeypatch):
    out = tmp_path / "out"
    counted = converge_module.run_level

    def fail_on_level_2(scene, param, level, reference=None, **kwargs):
        if level == 2:
            raise StepFailure(3, 0.375, SimpleNamespace(message="simulated failure",
                                                        residual=1.0, tolerance=1e-10, nit=50))
        return counted(scene, param, level, reference, **kwargs)

    monkeypatch.setattr(converge_module, "run_level", fail_on_level_2)
    result = run(scenes.contact, "--param", "k", "--levels", 3, "--out", out)
    assert_one_line_error(result, 1, "simulated failure", alone=False)
    assert "level 2" in result.stderr
    assert counting.levels == [0, 1] and counting.reference == 1
    assert sorted(p.name for p in out.iterdir()) == ["levels", "reference.npz", "study.json"]
    assert sorted(p.name for p in (out / "levels").iterdir()) == [
        "level_00.json", "level_01.json"]

    monkeypatch.setattr(converge_module, "run_level", counted)
    result = run(scenes.contact, "--param", "k", "--levels", 3, "--out", out)
    assert result.exit_code == 0, result.stderr
    assert counting.levels == [0, 1, 2] and counting.reference == 1   # only level 2 now
    err = result.stderr.splitlines()
    assert "contact: k-study, 3 levels, 2 loaded from the folder" in err
    assert [line for line in err if line.startswith("level ")] == [
        "level 2 (3 of 3): refine 0, 8 steps"]
    resumed = strict_json(out / "rates.json")
    whole = strict_json(fine_study.out / "rates.json")
    for key in ("err_u", "err_beta", "E", "h", "k", "dofs"):
        np.testing.assert_allclose([level[key] for level in resumed["levels"]],
                                   [level[key] for level in whole["levels"]],
                                   rtol=1e-12, atol=0)


# ---------------------------------------------------------------- (4) another study


@pytest.mark.parametrize("change, needle", [
    (("--levels", "4"), "levels 3 there, 4 here"),
    (("--ref-k", str(REF_K + 1)), f"ref_k {REF_K} there, {REF_K + 1} here"),
    (("--param", "hk"), "param 'k' there, 'hk' here"),
    ("scene", "another scene"),
])
def test_another_study_in_the_same_out_exits_2(fine_study, tmp_path, scenes, change, needle,
                                               counting):
    out = tmp_path / "out"
    shutil.copytree(fine_study.out, out)
    before = snapshot(out)
    args = {"--param": "k", "--levels": "3"}
    scene = scenes.contact
    if change == "scene":
        scene = tmp_path / "contact.toml"
        scene.write_text(to_toml(scene_dict({"contact.normal.c": 400.0}, CONTACT)))
    else:
        args[change[0]] = change[1]
    flat = [item for pair in args.items() for item in pair]
    result = run(scene, *flat, "--out", out)
    assert_one_line_error(result, 2, "holds a different study", alone=False)
    assert needle in result.stderr
    assert "use another --out or remove it" in result.stderr
    assert snapshot(out) == before
    assert counting.levels == [] and counting.reference == 0


def test_non_empty_folder_without_a_study_is_left_alone(tmp_path, scenes):
    out = tmp_path / "mine"
    out.mkdir()
    (out / "notes.txt").write_text("keep me")
    result = run(scenes.exact, "--param", "h", "--levels", 2, "--out", out)
    assert_one_line_error(result, 2, "--out", alone=False)
    assert snapshot(out) == {"notes.txt": b"keep me"}


# ---------------------------------------------------------------- (5) bad arguments


@pytest.mark.parametrize("args, needle", [
    (("--param", "h", "--reference", "exact"), "--reference"),
    (("--param", "x"), "--param"),
    (("--param", "h", "--levels", "1"), "--levels"),
    (("--param", "h", "--jobs", "0"), "--jobs"),
    (("--levels", "3",), "--param"),
])
def test_bad_arguments_exit_2_and_write_nothing(tmp_path, scenes, monkeypatch, args, needle):
    monkeypatch.chdir(tmp_path)
    result = run(scenes.contact, *args, "--out", tmp_path / "out")
    assert_one_line_error(result, 2, needle, alone=False)
    assert list(tmp_path.iterdir()) == []


def test_exact_reference_without_exact_table_names_what_is_allowed(tmp_path, scenes):
    result = run(scenes.contact, "--param", "h", "--reference", "exact", "--out",
                 tmp_path / "out")
    assert_one_line_error(result, 2, "--reference", alone=False)
    assert "fine" in result.stderr and "[exact]" in result.stderr
    assert not (tmp_path / "out").exists()


def test_ref_refinement_with_exact_reference_exits_2(tmp_path, scenes):
    result = run(scenes.exact, "--param", "h", "--ref-h", "1", "--out", tmp_path / "out")
    assert_one_line_error(result, 2, "--ref-h", alone=False)
    assert not (tmp_path / "out").exists()


def test_bad_scene_exits_2_and_writes_nothing(tmp_path):
    scene = tmp_path / "bad.toml"
    scene.write_text(to_toml(scene_dict({"material.nu": 0.7}, CONTACT)))
    result = run(scene, "--param", "h", "--out", tmp_path / "out")
    assert_one_line_error(result, 2, "nu", alone=False)
    assert [p.name for p in tmp_path.iterdir()] == ["bad.toml"]


# ---------------------------------------------------------------- (6) --jobs


def test_parallel_levels_give_the_same_errors(fine_study, tmp_path, scenes):
    out = tmp_path / "out"
    result = run(scenes.contact, "--param", "k", "--levels", 3, "--jobs", 2, "--out", out)
    assert result.exit_code == 0, result.stderr
    parallel = strict_json(out / "rates.json")["levels"]
    serial = strict_json(fine_study.out / "rates.json")["levels"]
    for key in ("err_u", "err_beta", "E"):
        np.testing.assert_allclose([level[key] for level in parallel],
                                   [level[key] for level in serial], rtol=0, atol=1e-12)
    assert [level["steps"] for level in parallel] == [2, 4, 8]
    # in workers the runs cannot report their steps here: one bar of the levels
    assert "contact: k-study, 3 levels" in result.stderr.splitlines()
    assert not [line for line in result.stderr.splitlines() if line.startswith("level ")]


def test_step_failure_exits_1_in_the_reference_and_in_a_worker(fine_study, tmp_path, counting):
    """A stiff wall and one Newton iteration: every run fails at step 1. The
    reference failure leaves study.json only; with a reference in place the
    levels fail in the worker processes, and the message reaches the user."""
    scene = tmp_path / "fail.toml"
    scene.write_text(to_toml(scene_dict({"contact.normal.c": 5000.0, "solver.max_iter": 1},
                                        CONTACT)))
    out = tmp_path / "out"
    args = (scene, "--param", "k", "--levels", 3, "--jobs", 2, "--out", out)
    result = run(*args)
    assert_one_line_error(result, 1, "reference run: step 1", alone=False)
    assert "did not converge" in result.stderr
    assert sorted(p.name for p in out.iterdir()) == ["levels", "study.json"]
    assert counting.reference == 1

    shutil.copy(fine_study.out / "reference.npz", out / "reference.npz")
    result = run(*args)
    assert_one_line_error(result, 1, "did not converge", alone=False)
    error = result.stderr.strip().splitlines()[-1]
    assert error.startswith("error: level ") and "step 1" in error
    failed = int(error.split()[2].rstrip(":"))
    assert counting.reference == 1 and counting.levels == []   # levels ran in workers
    saved = {p.name for p in (out / "levels").iterdir()}
    assert f"level_{failed:02d}.json" not in saved and len(saved) < 3
    assert not (out / "rates.json").exists()


def test_level0_refine_and_steps_override_the_scene(scenes, tmp_path):
    """--refine/--steps set level 0: an h-study keeps --steps at every level,
    a k-study starts from --refine; both enter the study (another study in
    the same folder is refused)."""
    out = tmp_path / "h"
    result = run(scenes.exact, "--param", "h", "--levels", 2, "--steps", 16, "--out", out)
    assert result.exit_code == 0, result.output
    levels = strict_json(out / "rates.json")["levels"]
    assert [lv["steps"] for lv in levels] == [16, 16]
    assert [lv["refine"] for lv in levels] == [0, 1]
    again = run(scenes.exact, "--param", "h", "--levels", 2, "--steps", 8, "--out", out)
    assert again.exit_code == 2
    out = tmp_path / "k"
    result = run(scenes.exact, "--param", "k", "--levels", 2, "--refine", 1, "--out", out)
    assert result.exit_code == 0, result.output
    levels = strict_json(out / "rates.json")["levels"]
    assert [lv["refine"] for lv in levels] == [1, 1]
    assert [lv["steps"] for lv in levels] == [8, 16]


def test_finished_study_rerun_with_jobs_computes_nothing(fine_study, tmp_path, scenes,
                                                         counting):
    """A finished study rerun with --jobs 2 loads every level (no pool of zero workers)."""
    out = tmp_path / "study"
    shutil.copytree(fine_study.out, out)
    result = run(scenes.contact, "--param", "k", "--levels", 3, "--jobs", 2, "--out", out)
    assert result.exit_code == 0, (result.stdout, result.stderr)
    assert counting.levels == [] and counting.reference == 0


def test_fine_reference_in_3d_with_contact(tmp_path):
    """3D fine references carry β between nested meshes (a fine facet finds
    the coarse facet it refines): the study runs and the error falls."""
    text = to_toml(scene_dict({"dim": 3, "mesh.domain": "box", "mesh.size": [1.0, 0.5, 0.5],
                               "mesh.cells": [2, 1, 1], "loads.body": ["0", "-400*t", "0"]},
                              CONTACT))
    path = tmp_path / "box.toml"
    path.write_text(text)
    result = run(path, "--param", "h", "--levels", 2, "--ref-h", 1, "--out", tmp_path / "out")
    assert result.exit_code == 0, (result.stdout, result.stderr)
    rows = list(csv.DictReader((tmp_path / "out" / "errors.csv").open()))
    assert len(rows) == 2 and 0 < float(rows[1]["E"]) < float(rows[0]["E"])


def test_a_study_too_large_for_the_machine_is_refused(tmp_path):
    """The block scene (1122 dofs) in h over 5 levels has a fine reference
    of 1122 · 4⁶ ≈ 4.6e6 dofs: refused before anything runs or is written."""
    scene = tmp_path / "default.toml"
    scene.write_text((Path(__file__).resolve().parents[1] / "studies" / "scenes"
                      / "block.toml").read_text())
    result = run(scene, "--param", "h", "--out", tmp_path / "out")
    assert_one_line_error(result, 2, "--levels: the fine reference would have about 4.6e+06 dofs", alone=False)
    assert not (tmp_path / "out").exists()
    ok = run(scene, "--param", "k", "--levels", 2, "--out", tmp_path / "k")
    assert ok.exit_code == 0


# ----------------------------------------------------------------
# A convergence study says when its rates are not to be trusted:
# errors that do not decrease, pairwise rates that scatter, a fine
# reference too close to the finest level.


def document(errors, rates, param="h", reference=None):
    levels = [{"level": i, "E": e, "rate_E": r} for i, (e, r) in enumerate(zip(errors, rates))]
    return {"param": param, "levels": levels, "reference": reference or {"kind": "exact"}}


def test_a_clean_first_order_study_has_no_warning():
    assert trust(document([8e-3, 4e-3, 2e-3, 1e-3], [None, 1.0, 1.0, 1.0])) == []


def test_errors_that_grow_and_rates_that_scatter_are_named():
    # the case met in a trial: a fitted 0.50 from pairwise rates including -0.51
    warnings = trust(document([8e-3, 2e-3, 2.85e-3, 1e-3], [None, 2.0, -0.51, 1.51]))
    assert warnings[0] == "E does not decrease from level 1 to 2 (0.002 to 0.00285)"
    assert warnings[1].startswith("the pairwise rates of E scatter from -0.51 to 2.00")
    assert len(warnings) == 2


def test_a_fine_reference_too_close_is_named():
    near = {"kind": "fine", "ref_h": 1, "ref_k": 0}
    warnings = trust(document([8e-3, 4e-3, 2e-3], [None, 1.0, 1.0], "h", near))
    assert warnings == ["the fine reference is refined only 1 more times than the finest "
                        "level: its own error biases the finest errors (use --ref-h 2 or more)"]
    assert trust(document([8e-3, 4e-3, 2e-3], [None, 1.0, 1.0], "h",
                          {"kind": "fine", "ref_h": 2, "ref_k": 0})) == []


def test_steps_that_the_relaxation_check_refuses_are_refused_before_the_study(tmp_path):
    # --steps 1 skipped the check of time.steps = 1 (k = 1 against tau = 0.05):
    # the study ran and ended with exit 1 after writing its folder
    scene = tmp_path / "relax.toml"
    scene.write_text(to_toml(scene_dict({
        "mesh.cells": [4, 2], "boundary.dirichlet": ["left"], "boundary.contact": [],
        "loads.body": ["0", "-t"],
        "memory": {"kernel": "relaxation", "long_term": {"E": 100.0, "nu": 0.3},
                   "terms": [{"E": 900.0, "tau": 0.05}]},
        "material": DELETE, "time.steps": 40})))
    out = tmp_path / "out"
    result = run(scene, "--param", "h", "--levels", 2, "--steps", 1,
                 "--out", out)
    assert_one_line_error(result, 2, "--steps: the time step k = 1 is too large for the "
                          "relaxation time tau = 0.05")
    assert not out.exists()


def test_errors_csv_and_rates_json_rows_are_the_level_records(tmp_path):
    """LevelRow puts each entry of a level record under its column: errors.csv
    holds the level's size, errors, time and relative errors, the pairwise
    rate of E (log(E_a/E_b)/log(h_a/h_b), the first level none), and in a
    study of a quantity Q_h, |Q_h − Q_ref|, that over |Q_ref| and its rate;
    a relative error saved as NaN or not at all is an empty cell; rates.json
    keeps its level entries in their documented order."""
    import math

    records = [
        {"level": 0, "refine": 0, "steps": 4, "h": 0.5, "k": 0.25, "dofs": 30,
         "err_u": 0.04, "err_beta": 0.0, "E": 0.04, "seconds": 0.5, "rel_u": 0.2,
         "rel_beta": math.nan, "rel_E": 0.2, "newton_iterations": 9,
         "quantities": {"q": 2.5}},
        {"level": 1, "refine": 1, "steps": 4, "h": 0.25, "k": 0.25, "dofs": 90,
         "err_u": 0.01, "err_beta": 0.0, "E": 0.01, "seconds": 1.5,
         "newton_iterations": 11, "quantities": {"q": 2.125}},
    ]
    document = converge_module.results(records, "h", {"kind": "fine", "quantity": 2.0}, "q")
    assert list(document["levels"][0]) == [
        "h", "k", "dofs", "err_u", "err_beta", "E", "seconds", "rel_u", "rel_beta", "rel_E",
        "level", "steps", "refine", "rate_E", "newton_iterations",
        "quantity", "err_q", "rel_q", "rate_q"]
    converge_module.write_errors_csv(tmp_path / "errors.csv", document)
    with open(tmp_path / "errors.csv", newline="") as f:
        header, *cells = list(csv.reader(f))
    assert header == CSV_COLUMNS + ["quantity", "err_q", "rel_q", "rate_q"]
    rate_e = math.log(0.04 / 0.01) / math.log(0.5 / 0.25)
    rate_q = math.log(0.5 / 0.125) / math.log(0.5 / 0.25)
    assert cells[0] == ["0", "0.5", "0.25", "30", "4", "0.04", "0.0", "0.04", "", "0.5",
                        "0.2", "", "0.2", "2.5", "0.5", "0.25", ""]
    assert cells[1][:13] == ["1", "0.25", "0.25", "90", "4", "0.01", "0.0", "0.01",
                             repr(rate_e), "1.5", "", "", ""]
    assert cells[1][13:16] == ["2.125", "0.125", "0.0625"]
    assert float(cells[1][16]) == pytest.approx(rate_q, rel=1e-15)
    plain = converge_module.results(records, "h", {"kind": "fine"})
    assert "quantity" not in plain["levels"][1]
    converge_module.write_errors_csv(tmp_path / "plain.csv", plain)
    with open(tmp_path / "plain.csv", newline="") as f:
        assert [row[:9] for row in csv.reader(f)][1:] == [c[:9] for c in cells]
