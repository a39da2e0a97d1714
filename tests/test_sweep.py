"""Tests for ``adhcontact sweep`` and :mod:`adhesive_contact.studies.sweep`:
settings parsed as TOML values, every variant validated before anything
runs, failed runs as rows, runs.csv against direct solves, resume."""

import csv
import time
import shutil

import numpy as np
import pytest
from adhesive_contact_cli.main import main
from adhesive_contact_cli.sweep import table
from conftest import assert_one_line_error, runner, scene_dict, to_toml, wall_block

import adhesive_contact.studies.sweep as sweep_module
from adhesive_contact import (
    StepFailure,
    build_problem,
    scene_from_dict,
    solve,
)
from adhesive_contact.postprocess import beta_mean, energies, reactions
from adhesive_contact.studies import StudyError, Sweep
from adhesive_contact.studies.sweep import variants, with_value
from adhesive_contact_cli.assignments import AssignmentError, parse_assignment, split_values

# an 8x4 block hanging from its top, pulled down onto a wall: with one
# Newton iteration allowed, the stiff layer (c = 5000) fails at step 1
SCENE_DICT = wall_block()
SCENE = to_toml(SCENE_DICT)

GRID = ("--set", "contact.normal.c=1e3,5000", "--set", "solver.max_iter=1,50")


def run(*args):
    return runner().invoke(main, ["sweep", *map(str, args)], catch_exceptions=False)



def read_rows(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def snapshot(folder):
    return {str(p.relative_to(folder)): p.read_bytes()
            for p in sorted(folder.rglob("*")) if p.is_file()}


@pytest.fixture(scope="module")
def scene_file(tmp_path_factory):
    path = tmp_path_factory.mktemp("scene") / "block.toml"
    path.write_text(SCENE)
    return path


@pytest.fixture(scope="module")
def grid_sweep(scene_file, tmp_path_factory):
    out = tmp_path_factory.mktemp("grid") / "out"
    result = run(scene_file, *GRID, "--out", out)
    assert result.exit_code == 0, (result.stdout, result.stderr)
    return out, result


@pytest.fixture
def counting(monkeypatch):
    calls = []
    real = sweep_module.run_variant

    def run_variant(document, values, base_dir=None):
        calls.append(dict(values))
        return real(document, values, base_dir)

    monkeypatch.setattr(sweep_module, "run_variant", run_variant)
    return calls


# ---------------------------------------------------------------- settings


def test_values_are_toml_scalars_split_outside_brackets():
    assert parse_assignment("contact.normal.c=1e2,1e3") == ("contact.normal.c", [100.0, 1000.0])
    assert parse_assignment("time.steps=10, 20") == ("time.steps", [10, 20])
    assert parse_assignment('mesh.cells=[8, 4],[16,8]') == ("mesh.cells", [[8, 4], [16, 8]])
    assert parse_assignment('contact.quadrature=nodal,"gauss"') == \
        ("contact.quadrature", ["nodal", "gauss"])
    assert parse_assignment("x.flag=true,false")[1] == [True, False]
    assert split_values('"a,b",[1,2]') == ['"a,b"', "[1,2]"]
    with pytest.raises(AssignmentError, match="expected KEY=V1,V2"):
        parse_assignment("contact.normal.c")
    with pytest.raises(AssignmentError, match="'1x' is not a TOML value") as err:
        parse_assignment("time.steps=10,1x")
    assert err.value.key == "set time.steps"


def test_grid_and_zip_variants():
    settings = [("a", [1, 2]), ("b", ["x", "y"])]
    assert variants(settings, "grid") == [{"a": 1, "b": "x"}, {"a": 1, "b": "y"},
                                          {"a": 2, "b": "x"}, {"a": 2, "b": "y"}]
    assert variants(settings, "zip") == [{"a": 1, "b": "x"}, {"a": 2, "b": "y"}]
    with pytest.raises(StudyError, match="set b: has 3 values, a has 2"):
        variants([("a", [1, 2]), ("b", [1, 2, 3])], "zip")
    with pytest.raises(StudyError, match="set twice"):
        variants([("a", [1]), ("a", [2])])


def test_with_value_sets_a_copy_and_indexes_arrays_of_tables():
    doc = {"contact": {"friction": [{"law": "tresca", "mu": 1.0}]}}
    new = with_value(doc, "contact.friction.0.mu", 0.2)
    assert new["contact"]["friction"][0]["mu"] == 0.2 and doc["contact"]["friction"][0]["mu"] == 1.0
    assert with_value(doc, "solver.max_iter", 3)["solver"] == {"max_iter": 3}
    with pytest.raises(ValueError, match="array of 1 tables; '1' is not an index"):
        with_value(doc, "contact.friction.1.mu", 0.2)
    with pytest.raises(ValueError, match="contact.friction.0.mu is a value, not a table"):
        with_value(doc, "contact.friction.0.mu.x", 0.2)


# ---------------------------------------------------------------- the command


def test_grid_sweep_rows_match_direct_solves_and_failures_are_rows(grid_sweep):
    out, result = grid_sweep
    assert {p.name for p in out.iterdir()} == {
        "study.json", "runs", "runs.csv", "by_contact.normal.c.png", "by_solver.max_iter.png"}
    for png in ("by_contact.normal.c.png", "by_solver.max_iter.png"):
        assert (out / png).read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    rows = read_rows(out / "runs.csv")
    assert [(r["contact.normal.c"], r["solver.max_iter"]) for r in rows] == [
        ("1000.0", "1"), ("1000.0", "50"), ("5000", "1"), ("5000", "50")]
    base = SCENE_DICT
    for row in rows:
        doc = with_value(with_value(base, "contact.normal.c", float(row["contact.normal.c"])),
                         "solver.max_iter", int(row["solver.max_iter"]))
        problem = build_problem(scene_from_dict(doc))
        try:
            solution = solve(problem, raise_on_failure=True)
        except StepFailure as err:
            assert row["outcome"] == "failed"
            assert int(row["failed_step"]) == err.n == 1
            assert float(row["failed_t"]) == pytest.approx(err.t, rel=1e-15)
            assert float(row["residual"]) == pytest.approx(err.result.residual, rel=1e-12)
            assert row["newton_total"] == "" and row["normal_force_T"] == ""
            continue
        assert row["outcome"] == "ok" and row["failed_step"] == ""
        assert int(row["newton_total"]) == solution.iterations.sum()
        assert int(row["newton_max"]) == solution.iterations.max()
        assert float(row["normal_force_T"]) == pytest.approx(
            -solution.contact_force[-1, :, 0].sum(), rel=1e-12)
        assert float(row["beta_mean_T"]) == pytest.approx(beta_mean(solution)[-1], rel=1e-14)
        assert int(row["on_wall_T"]) == solution.on_wall[-1].sum() > 0
        un = solution.frame_displacement[:, :, 0]
        assert int(row["separated_T"]) == (un[-1] < 0).sum()
        assert float(row["max_un_minus_g"]) == pytest.approx(
            (un - solution.gap).max(), abs=1e-15)
        # the held side's reaction: its peak (largest magnitude, signed) and at T
        held = reactions(solution)[:, 0, :]
        for c, axis in enumerate("xy"):
            biggest = held[np.abs(held[:, c]).argmax(), c]
            assert float(row[f"reaction_top_{axis}_peak"]) == pytest.approx(biggest, rel=1e-14)
            assert float(row[f"reaction_top_{axis}_T"]) == pytest.approx(held[-1, c], rel=1e-14)
        assert row["work_T"] == "" and row["debonded_area_T"] == "0.0"   # prony: no energy
        assert float(row["worker_peak_rss_mib"]) > 10
        assert float(row["seconds"]) > 0
    assert [r["outcome"] for r in rows] == ["ok", "ok", "failed", "ok"]
    assert "3 ok, 1 failed" in result.stdout and "FAILED at step 1" in result.stdout


def test_rerun_recomputes_nothing_and_a_lost_run_only_that(grid_sweep, scene_file, tmp_path,
                                                           counting):
    out = tmp_path / "out"
    shutil.copytree(grid_sweep[0], out)
    before = snapshot(out)
    result = run(scene_file, *GRID, "--out", out)
    assert result.exit_code == 0, result.stderr
    assert counting == [] and "0 computed now, 4 loaded" in result.stdout
    assert snapshot(out) == before
    (out / "runs" / "run_002.json").unlink()
    result = run(scene_file, *GRID, "--out", out)
    assert result.exit_code == 0, result.stderr
    assert counting == [{"contact.normal.c": 5000, "solver.max_iter": 1}]
    assert read_rows(out / "runs.csv")[2]["outcome"] == "failed"


def test_another_sweep_in_the_folder_exits_2(grid_sweep, scene_file, tmp_path, counting):
    out = tmp_path / "out"
    shutil.copytree(grid_sweep[0], out)
    before = snapshot(out)
    result = run(scene_file, "--set", "contact.normal.c=1e3,4000", "--set",
                 "solver.max_iter=1,50", "--out", out)
    assert_one_line_error(result, 2, "holds a different sweep", alone=False)
    assert "(set [[" in result.stderr and counting == []
    result = run(scene_file, *GRID, "--zip", "--out", out)
    assert_one_line_error(result, 2, "mode 'grid' there, 'zip' here", alone=False)
    assert snapshot(out) == before


def test_zip_sweep_in_two_processes(scene_file, tmp_path):
    out = tmp_path / "out"
    result = run(scene_file, "--set", "time.steps=2,4", "--set", "contact.normal.c=1e3,2e3",
                 "--zip", "--jobs", 2, "--out", out)
    assert result.exit_code == 0, result.stderr
    rows = read_rows(out / "runs.csv")
    assert [(r["time.steps"], r["contact.normal.c"]) for r in rows] == [
        ("2", "1000.0"), ("4", "2000.0")]
    assert [r["outcome"] for r in rows] == ["ok", "ok"]
    direct = solve(build_problem(scene_from_dict(scene_dict(
        {"time.steps": 4, "contact.normal.c": 2000.0}, SCENE_DICT))))
    assert float(rows[1]["normal_force_T"]) == pytest.approx(
        -direct.contact_force[-1, :, 0].sum(), rel=1e-12)
    assert int(rows[1]["newton_total"]) == direct.iterations.sum()


@pytest.mark.parametrize("sets, needle", [
    (("contact.normal.cc=1,2",), "--set contact.normal.cc=1: unknown key"),
    (("contact.normal.c=1e3,-5",), "--set contact.normal.c=-5: "),
    (("time.steps=2,1x",), "--set time.steps: '1x' is not a TOML value"),
    (("material.E.x=1",), "--set material.E.x: material.E is a value, not a table"),
    (("time.steps",), "--set: 'time.steps': expected KEY=V1,V2"),
    (("time.steps=2,4", "contact.normal.c=1,2,3"), "--set contact.normal.c: has 3 values"),
])
def test_bad_settings_exit_2_naming_them_before_anything_runs(scene_file, tmp_path, counting,
                                                              sets, needle):
    args = [item for s in sets for item in ("--set", s)]
    zip_ = ["--zip"] if len(sets) == 2 else []
    result = run(scene_file, *args, *zip_, "--out", tmp_path / "out")
    assert_one_line_error(result, 2, needle, alone=False)
    assert counting == [] and not (tmp_path / "out").exists()


def test_sweep_from_python_with_progress(tmp_path, capsys):
    events = []
    sweep = Sweep(SCENE, [("solver.max_iter", [1, 50])], folder=tmp_path / "out")
    result = sweep.run(progress=lambda *event: events.append(event))
    assert capsys.readouterr() == ("", "")
    assert events == [("runs", 0, 2), ("runs", 1, 2), ("runs", 2, 2)]
    assert [r["outcome"] for r in result.records] == ["failed", "ok"]
    assert result.records[0]["failure"]["step"] == 1
    assert "did not converge" in result.records[0]["failure"]["message"]
    assert result.computed == [0, 1]
    assert np.isfinite(result.rows[1]["normal_force_T"])


def test_sweep_reports_energies_and_debonded_area(tmp_path):
    """The built-in scene swept over its number of steps: the energies and
    the debonded area at T of each run are those of a direct solve."""
    from pathlib import Path

    text = (Path(__file__).resolve().parents[1] / "cli" / "default_scene.toml").read_text()
    result = Sweep(text, [("time.steps", [20, 40])], folder=tmp_path / "out").run()
    for row in result.rows:
        problem = build_problem(scene_from_dict(with_value(
            __import__("tomllib").loads(text), "time.steps", row["time.steps"])))
        solution = solve(problem)
        e = energies(solution)
        assert row["work_T"] == pytest.approx(e.external_work[-1], rel=1e-12)
        assert row["debonding_T"] == pytest.approx(e.dissipated["debonding"][-1], rel=1e-12)
        assert row["numerical_T"] == pytest.approx(e.dissipated["numerical"][-1], rel=1e-12)
        area = (solution.beta[-1] < 0.5) @ problem.boundary.measure
        assert row["debonded_area_T"] == pytest.approx(area) and area > 0
        assert row["glue_energy_per_area_T"] == pytest.approx(row["debonding_T"] / area)
        lift = reactions(solution)[:, 1, 1]        # the right side, lifted in y
        assert row["reaction_right_y_peak"] == pytest.approx(lift[np.abs(lift).argmax()])
    header = (tmp_path / "out" / "runs.csv").read_text().splitlines()[0].split(",")
    assert {"reaction_left_x_peak", "reaction_right_y_T", "work_T", "dissipated_T",
            "balance_T", "damage_T"} <= set(header)


# ---------------------------------------------------------------- a swept mesh file


def write_rectangle_msh(path, cells):
    """A 2 × 0.5 rectangle of ``cells`` triangles per side as gmsh 2.2, with
    the named sides top and foot (the bottom)."""
    import meshio
    from skfem import MeshTri

    mesh = MeshTri.init_tensor(np.linspace(0, 2, 2 * cells + 1),
                               np.linspace(0, 0.5, cells // 2 + 1))
    mesh = mesh.with_boundaries({"top": lambda x: np.isclose(x[1], 0.5),
                                 "foot": lambda x: np.isclose(x[1], 0.0)})
    blocks = [("line", mesh.facets[:, mesh.boundaries[s]].T) for s in ("top", "foot")]
    blocks.append(("triangle", mesh.t.T))
    tags = [np.full(len(b[1]), i + 1) for i, b in enumerate(blocks)]
    meshio.write(path, meshio.Mesh(
        np.column_stack([mesh.p.T, np.zeros(mesh.p.shape[1])]), blocks,
        cell_data={"gmsh:physical": tags, "gmsh:geometrical": tags},
        field_data={"top": np.array([1, 1]), "foot": np.array([2, 1]),
                    "body": np.array([3, 2])}), file_format="gmsh22", binary=False)


FILE_SCENE = scene_dict({
    "mesh": {"domain": "file", "file": "m1.msh"},
    "boundary": {"dirichlet": ["top"], "contact": ["foot"]},
    "loads": {"body": ["0", "-10*t"]},
    "contact": {"normal": {"law": "compliance", "c": 100.0}}, "time.steps": 2})


def test_a_swept_mesh_file_is_the_scene_folders_and_its_content_is_the_sweeps(
        tmp_path, monkeypatch):
    scenes = tmp_path / "scenes"
    scenes.mkdir()
    write_rectangle_msh(scenes / "m1.msh", 4)
    write_rectangle_msh(scenes / "m2.msh", 8)
    write_rectangle_msh(tmp_path / "m2.msh", 16)   # a decoy in the working directory
    scene = scenes / "scene.toml"
    scene.write_text(to_toml(FILE_SCENE))
    monkeypatch.chdir(tmp_path)
    args = [scene, "--set", 'mesh.file="m2.msh"', "--out", tmp_path / "out"]
    result = run(*args)
    assert result.exit_code == 0, result.output
    [row] = read_rows(tmp_path / "out" / "runs.csv")

    def force(folder):   # the scene's own m2.msh, read by the library from its file
        variant = folder / "variant.toml"
        variant.write_text(to_toml(scene_dict({"mesh.file": "m2.msh"}, FILE_SCENE)))
        from adhesive_contact import load_scene
        return solve(build_problem(load_scene(variant))).total_normal_force()[-1]

    assert float(row["normal_force_T"]) == pytest.approx(force(scenes), rel=1e-12)
    assert abs(float(row["normal_force_T"]) - force(tmp_path)) > 1e-6 * abs(force(tmp_path))
    # the mesh file changes: the folder holds another sweep, nothing is reused
    write_rectangle_msh(scenes / "m2.msh", 6)
    result = run(*args)
    assert_one_line_error(result, 2, "holds a different sweep (files")


# ---------------------------------------------------------------- many variants


@pytest.mark.parametrize("sets, count, sizes", [
    (("contact.normal.c=" + ",".join(str(100 + i) for i in range(100)),
      "solver.max_iter=" + ",".join(str(10 + i) for i in range(100))), "10,000", "100 x 100"),
    (("contact.normal.c=" + ",".join(str(100 + i) for i in range(1000)),
      "solver.max_iter=" + ",".join(str(10 + i) for i in range(1000))), "1,000,000",
     "1000 x 1000"),
])
def test_more_variants_than_the_maximum_are_refused_at_once(scene_file, tmp_path, counting,
                                                           sets, count, sizes):
    # every variant was built and validated first: no answer for 10^4 or 10^6
    started = time.perf_counter()
    result = run(scene_file, *[x for s in sets for x in ("--set", s)], "--out", tmp_path / "o")
    assert time.perf_counter() - started < 20
    assert_one_line_error(result, 2, f"--set: gives {count} variants ({sizes}); at most "
                          "1,000 unless forced (--force): each variant is a run")
    assert counting == [] and not (tmp_path / "o").exists()


def test_each_value_is_checked_once_and_a_bad_combination_is_a_failed_row(tmp_path,
                                                                         monkeypatch):
    built = []
    real = sweep_module.build_problem
    monkeypatch.setattr(sweep_module, "build_problem",
                        lambda scene: built.append(scene) or real(scene))
    settings = [("contact.normal.c", [1e3, 2e3, 3e3]), ("solver.max_iter", [20, 30, 40, 50])]
    sweep = Sweep(SCENE, settings, folder=tmp_path / "out")
    assert sweep.checked() == [0, 1, 2, 3, 4, 8]   # 3 + 4 - 1 builds, not 12
    assert len(built) == 6
    # values valid one by one, not together: 20 x 0.5 in 8 x 300 cells are
    # 2.5 x 0.00167, elongated 1500:1 (at most 1000:1)
    combo = [("mesh.size", [[2.0, 0.5], [20.0, 0.5]]), ("mesh.cells", [[8, 4], [8, 300]])]
    sweep = Sweep(SCENE, combo, folder=tmp_path / "combo")
    assert sweep.checked() == [0, 1, 2]
    result = sweep.run()
    assert [r["outcome"] for r in result.records] == ["ok", "ok", "ok", "failed"]
    failure = result.records[3]["failure"]
    assert failure["step"] is None and failure["message"].startswith(
        "not a valid scene: mesh.cells: cells of 2.5 x 0.00167 are elongated more than 1000:1")
    lines = table(result.rows, sweep.keys_set)
    assert lines[3].startswith("run   3: mesh.size=[20.0, 0.5], mesh.cells=[8, 300]: FAILED: "
                               "not a valid scene: mesh.cells: cells of 2.5 x 0.00167")


def test_a_value_nested_too_deeply_is_one_line():
    # --set title=[[[...]]] 3000 deep was a RecursionError (2,999 lines)
    with pytest.raises(AssignmentError, match=r"^set title: a value nested 3000 deep \(at most 16 "
                                         r"levels of brackets\)$"):
        parse_assignment("title=" + "[" * 3000 + "]" * 3000)
    assert parse_assignment('title="' + "[" * 40 + '"') == ("title", ["[" * 40])
    assert parse_assignment("mesh.cells=[[8, 4]]") == ("mesh.cells", [[[8, 4]]])


def test_runs_csv_rows_are_the_records_cells_in_column_order(tmp_path):
    """SweepRow puts each value of a run record under its column: the swept
    values, the measured columns, the failure's step and time, the scalar
    quantities (a quantity a run lacks, and whatever a failed or lost run
    has not, an empty cell); the message is the row's, not a column."""
    from adhesive_contact.studies.sweep import (MEASURED, SweepRow, lost_record,
                                                write_runs_csv)

    keys = ["contact.normal.c", "title"]
    measured = {column: None for column in MEASURED[3:]}
    ok = {"run": 0, "values": {"contact.normal.c": 1000.0, "title": "a"}, "outcome": "ok",
          "failure": None, **measured, "residual": 2.5e-13, "seconds": 0.125,
          "newton_total": 7, "newton_max": 3, "separated_T": 4,
          "quantities": {"work_T": 0.1, "reaction_top_y_T": -3.0}}
    failed = {"run": 1, "values": {"contact.normal.c": 5000.0, "title": "b"},
              "outcome": "failed", "residual": 0.25, "seconds": 0.5,
              "failure": {"step": 2, "t": 0.5, "residual": 0.25, "iterations": 1,
                          "message": "step 2 did not converge"}}
    lost = lost_record(2, {"contact.normal.c": 1e4, "title": "c"}, "its worker died")
    quantities = ["work_T", "reaction_top_y_T"]
    rows = [SweepRow.of(record, keys, quantities) for record in (ok, failed, lost)]
    assert (rows[1].outcome, rows[1].failed_step, rows[1].failed_t) == ("failed", 2, 0.5)
    assert rows[1]["message"] == "step 2 did not converge" and rows[0].message is None
    assert rows[2]["outcome"] == "lost" and rows[2].get("work_T") is None
    assert rows[0]["title"] == "a" and rows[0].get("no such column", "-") == "-"
    write_runs_csv(tmp_path / "runs.csv", rows, keys, quantities)
    with open(tmp_path / "runs.csv", newline="") as f:
        header, *cells = list(csv.reader(f))
    assert header == ["run", *keys, *MEASURED, *quantities]
    expected = [
        {"run": "0", "contact.normal.c": "1000.0", "title": "a", "outcome": "ok",
         "residual": "2.5e-13", "seconds": "0.125", "newton_total": "7", "newton_max": "3",
         "separated_T": "4", "work_T": "0.1", "reaction_top_y_T": "-3.0"},
        {"run": "1", "contact.normal.c": "5000.0", "title": "b", "outcome": "failed",
         "failed_step": "2", "failed_t": "0.5", "residual": "0.25", "seconds": "0.5"},
        {"run": "2", "contact.normal.c": "10000.0", "title": "c", "outcome": "lost"},
    ]
    assert cells == [[want.get(column, "") for column in header] for want in expected]
