"""What a run writes (docs/outputs.md): the field levels of ``[output]
every``, the fields of ``[output] fields``, ``scalars.csv`` and the contact
and debonding metrics of every level.

The built-in default scene (a glued strip lifted at its right end, 40
steps) is run with every = 1 and with every = 7: the thinned run must
hold the same numbers at the levels it keeps (the fields are a
subsample, the scheme is the same), its field levels must be those an
independent reading of its forces gives (every 7th, the first, the last,
the first level of each force's largest magnitude), and it must read back
with the energies of the full run."""

import csv
from importlib import resources

import meshio
import numpy as np
import pytest
from adhesive_contact_cli.main import main
from conftest import runner

from adhesive_contact import build_problem, load_solution, parse_scene, solve
from adhesive_contact.io.field_levels import FieldLevels, field_levels, reported_forces
from adhesive_contact.postprocess import energies
from adhesive_contact.postprocess.fracture import new_debonding
from adhesive_contact.postprocess.level_scalars import level_scalars
from adhesive_contact.postprocess.units import unit_of, with_unit

DEFAULT = resources.files("adhesive_contact_cli").joinpath("default_scene.toml").read_text()
EVERY = 7


def run(*args):
    return runner().invoke(main, list(map(str, args)), catch_exceptions=False)


def with_output(text, lines):
    return text + "\n[output]\n" + "\n".join(lines) + "\n"


def read_csv(path):
    with open(path, newline="") as f:
        rows = list(csv.reader(f))
    return rows[0], np.array([[float(v) if v else np.nan for v in row] for row in rows[1:]])


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    """The default scene written whole and with every = 7: {name: folder}."""
    root = tmp_path_factory.mktemp("levels")
    out = {}
    for name, lines in (("whole", []), ("thinned", [f"every = {EVERY}"]),
                        ("scalars_only", ["fields = []"]),
                        ("stress_only", ["fields = [\"stress\"]", "every = 20"])):
        scene = root / f"{name}.toml"
        scene.write_text(with_output(DEFAULT, lines) if lines else DEFAULT)
        result = run("solve", scene, "--out", root / name, "--quiet")
        assert result.exit_code == 0, result.stderr
        out[name] = root / name
    return out


# ---------------------------------------------------------------- choosing the levels


def brute_force_levels(forces, every):
    """Every N-th level, the first and the last, and per force component
    the first level of its largest magnitude: read off the whole history."""
    count = forces.shape[0]
    levels = set(range(0, count, every)) | {count - 1}
    levels |= set(np.argmax(np.abs(forces), axis=0).tolist())
    return sorted(levels)


@pytest.mark.parametrize("every", [1, 2, 5, 13, 1000])
def test_the_chooser_as_it_goes_keeps_what_the_whole_history_gives(every):
    rng = np.random.default_rng(every)
    for _ in range(20):
        count = int(rng.integers(1, 60))
        forces = rng.normal(size=(count, 5)) * rng.uniform(0.1, 10.0, size=5)
        forces[rng.random(forces.shape) < 0.2] = 0.0     # ties at zero
        chooser, kept = FieldLevels(every), set()
        for n in range(count):
            write, keep, drop = chooser.offer(n, forces[n])
            assert not (write and keep)
            kept = (kept | {n} if keep else kept) - set(drop)
            # a kept candidate is always a current peak
            assert kept <= set(chooser.peak_level.tolist())
        pending = chooser.end()
        assert set(pending) >= kept
        assert chooser.levels() == brute_force_levels(forces, every)


def test_the_field_levels_of_a_run_are_its_grid_and_its_peaks(runs):
    thinned = load_solution(runs["thinned"])
    whole = load_solution(runs["whole"])
    problem = whole.problem
    forces = reported_forces(problem, whole.reaction, whole.contact_force)
    expected = brute_force_levels(forces, EVERY)
    assert list(thinned.field_levels) == expected
    assert list(field_levels(problem, whole.reaction, whole.contact_force, EVERY)) == expected
    # the peaks off the grid are there: the lift's largest pull is one of them
    grip = whole.problem.prescribed.side_reactions(whole.reaction)[:, 1, 1]   # right, y
    assert int(np.argmax(np.abs(grip))) in thinned.field_levels


# ---------------------------------------------------------------- the files


def test_a_thinned_run_holds_the_whole_run_at_its_field_levels(runs):
    whole = load_solution(runs["whole"])
    thinned = load_solution(runs["thinned"])
    levels = thinned.field_levels
    assert thinned.u.shape == (levels.size, *whole.u.shape[1:])
    np.testing.assert_array_equal(thinned.u, whole.u[levels])
    for name in ("t", "beta", "contact_force", "reaction", "iterations"):
        np.testing.assert_array_equal(getattr(thinned, name), getattr(whole, name))
    # read back, its energies are those of the whole run (recorded in the npz)
    a, b = energies(whole), energies(thinned)
    np.testing.assert_allclose(b.external_work, a.external_work, rtol=0, atol=1e-14)
    np.testing.assert_allclose(b.dissipated_total, a.dissipated_total, rtol=0, atol=1e-14)
    assert thinned.displacement(levels[-1]).shape == whole.u.shape[1:]
    missing = next(n for n in range(whole.t.size) if n not in set(levels))
    with pytest.raises(ValueError, match=f"level {missing} has no fields here"):
        thinned.displacement(missing)


def test_the_xdmf_series_holds_the_field_levels_in_order(runs):
    thinned = load_solution(runs["thinned"])
    with meshio.xdmf.TimeSeriesReader(runs["thinned"] / "solution.xdmf") as reader:
        reader.read_points_cells()
        times, us = [], []
        for k in range(reader.num_steps):
            t, point_data, cell_data = reader.read_data(k)
            times.append(t)
            us.append(point_data["u"][:, :2])
        assert set(cell_data) == {"stress", "von_mises"}
    np.testing.assert_array_equal(times, thinned.t[thinned.field_levels])
    np.testing.assert_array_equal(np.array(us), thinned.u)


def test_fields_choose_the_files(runs):
    files = {p.name for p in runs["scalars_only"].iterdir()}
    assert {"summary.json", "scalars.csv", "solution.npz"} <= files
    assert not {"solution.xdmf", "solution.h5", "contact.xdmf", "contact.h5"} & files
    with np.load(runs["scalars_only"] / "solution.npz") as data:
        assert data["u"].shape[0] == 0 and data["u_levels"].size == 0
    files = {p.name for p in runs["stress_only"].iterdir()}
    assert {"solution.xdmf", "solution.h5"} <= files
    assert not {"contact.xdmf", "contact.h5"} & files
    with meshio.xdmf.TimeSeriesReader(runs["stress_only"] / "solution.xdmf") as reader:
        reader.read_points_cells()
        _, point_data, cell_data = reader.read_data(0)
    assert not point_data and set(cell_data) == {"stress"}


def test_the_scalars_do_not_depend_on_what_is_written(runs):
    header, whole = read_csv(runs["whole"] / "scalars.csv")
    for name in ("thinned", "scalars_only", "stress_only"):
        other_header, other = read_csv(runs[name] / "scalars.csv")
        assert other_header == header
        np.testing.assert_array_equal(other, whole)


# ---------------------------------------------------------------- scalars.csv


def test_scalars_csv_rows_balance_the_forces(runs):
    header, rows = read_csv(runs["whole"] / "scalars.csv")
    col = {name: i for i, name in enumerate(header)}
    assert rows.shape[0] == 41 and header[0] == "t"
    solution = load_solution(runs["whole"])
    np.testing.assert_array_equal(rows[:, col["t"]], solution.t)
    # no loads: Σ reactions + Σ contact forces = 0 in each direction, every level
    # (a side's reaction along a component it leaves free is 0)
    for c in "xy":
        total = rows[:, col[f"contact_force_{c}"]].copy()
        total += sum(rows[:, i] for name, i in col.items() if name.startswith("reaction_")
                     and name.endswith(f"_{c}"))
        scale = np.abs(rows[:, col["contact_force_y"]]).max()
        assert np.abs(total).max() < 1e-9 * scale
    # the grip's displacement is the prescribed lift 0.15 t, exactly
    np.testing.assert_allclose(rows[:, col["displacement_right_y"]], 0.15 * solution.t,
                               rtol=1e-12, atol=1e-15)
    # the energy balance closes to the solver's tolerance
    work = np.abs(rows[:, col["external_work"]]).max()
    assert np.abs(rows[:, col["balance"]]).max() < 1e-6 * work


def test_units_go_into_the_column_names(tmp_path):
    scene = tmp_path / "units.toml"
    scene.write_text(with_output(DEFAULT.replace("steps = 40", "steps = 16"),
                                 ['units = { length = "mm", force = "N", time = "s", '
                                  'stress = "MPa" }']))
    result = run("solve", scene, "--out", tmp_path / "out", "--quiet")
    assert result.exit_code == 0, result.stderr
    header, _ = read_csv(tmp_path / "out" / "scalars.csv")
    assert header[0] == "t [s]"
    assert "reaction_right_y [N/mm]" in header          # 2D: per unit thickness
    assert "peak_pressure [MPa]" in header and "contact_width [mm]" in header
    assert "external_work [N]" in header                # an energy per unit thickness
    assert "beta_mean" in header and "iterations" in header


def test_units_of_each_kind():
    units = {"length": "mm", "force": "N", "stress": "MPa", "time": "s"}
    assert [unit_of(k, units, 3) for k in ("force", "energy", "measure", "toughness")] == \
        ["N", "N·mm", "mm²", "N/mm"]
    assert [unit_of(k, units, 2) for k in ("force", "energy", "measure", "toughness")] == \
        ["N/mm", "N", "mm", "N/mm"]
    assert unit_of("force", {"stress": "MPa", "length": "mm"}, 3) == "MPa·mm²"
    assert unit_of("force", {"force": "N"}, 2) is None      # per length: needs the length
    assert with_unit("beta_mean", "1", units, 2) == "beta_mean"
    with pytest.raises(ValueError, match="unknown kind"):
        unit_of("speed", units, 2)


# ---------------------------------------------------------------- debonding metrics


PRECRACK = DEFAULT.replace("beta0 = 1.0", 'beta0 = "where(x > 3, 0, 1)"').replace(
    "steps = 40", "steps = 16")


def test_the_debonded_length_leaves_out_the_precrack():
    problem = build_problem(parse_scene(PRECRACK))
    solution = solve(problem)
    assert solution.success
    boundary = problem.boundary
    precrack = boundary.measure[problem.beta0 < 0.5].sum()
    assert precrack == pytest.approx(1.0, rel=1e-12)            # x in [3, 4] of the strip
    new, damage = new_debonding(solution)
    assert new[0] == 0.0 and damage[0] == 0.0
    # every facet below ½ is the pre-crack or new: the measures add up
    total = (solution.beta < 0.5) @ boundary.measure
    np.testing.assert_allclose(new + precrack, total, rtol=1e-12)
    np.testing.assert_allclose(damage, (problem.beta0 - solution.beta) @ boundary.measure,
                               rtol=1e-12)
    assert new[-1] > 0.04                                  # the front ran a facet at least
    columns = {c.name: c.values for c in level_scalars(solution)}
    np.testing.assert_array_equal(columns["debonded_length"], new)


def test_the_glue_energy_per_area_is_per_new_area(tmp_path):
    scene = tmp_path / "precrack.toml"
    scene.write_text(PRECRACK)
    result = run("solve", scene, "--out", tmp_path / "out", "--quiet")
    assert result.exit_code == 0, result.stderr
    import json
    steps = json.loads((tmp_path / "out" / "summary.json").read_text())["steps"]
    last = steps[-1]
    glue = last["energy"]["dissipated"]["debonding"]
    assert last["debonding"]["area"] == pytest.approx(last["debonding"]["new_area"] + 1.0)
    assert last["debonding"]["energy_per_area"] == pytest.approx(
        glue / last["debonding"]["new_area"], rel=1e-12)
