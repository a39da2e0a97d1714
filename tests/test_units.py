"""``[output] units``: the axes of every figure name the units given, and
fall back to "units of length" / "units of E" without them; the figures'
other fixes (the von Mises label, the β mean, the step curves' ends, the
3D ticks). Labels are read from the matplotlib figures, not from PNGs."""

import json

import matplotlib.pyplot as plt
import matplotlib.text
import numpy as np
import pytest
from adhesive_contact_cli.main import main
from conftest import (
    assert_one_line_error,
    glued_contact,
    prony,
    runner,
    scene_dict,
    to_toml,
    wall_block,
)
from matplotlib.patches import StepPatch

from adhesive_contact import SceneError, build_problem, scene_from_dict, solve, visuals
from adhesive_contact.studies.study import scene_identity
from adhesive_contact.visuals import deformed as deformed_figure
from adhesive_contact.visuals import studies as study_figures

UNITS = {"length": "mm", "stress": "MPa", "time": "s", "force": "N"}

#: a strip glued at the bottom and lifted at its top: every 2D figure
GLUED = scene_dict({
    "mesh.cells": [8, 2], "boundary.dirichlet": [],
    "boundary.displacement": {"top": ["0", "0.002*t"]},
    "contact": glued_contact(), "time.steps": 2})

#: a small box pressed onto a compliant foundation: the 3D figures
BOX = scene_dict({
    "dim": 3, "mesh.domain": "box", "mesh.size": [1.0, 0.5, 0.5], "mesh.cells": [2, 2, 2],
    "boundary.dirichlet": ["top"], "boundary.contact": ["bottom"],
    "loads.body": ["0", "-100*t", "0"], "contact.normal": {"law": "compliance", "c": 1e3},
    "contact.bonding": {"law": "none", "beta0": 1.0}, "time.steps": 1})


@pytest.fixture(autouse=True)
def close_figures():
    """The figures a test keeps to read are closed after it."""
    yield
    plt.close("all")


def texts(fig):
    """Every text of a figure: titles, axis and colour-bar labels, ticks, legends."""
    return [t.get_text() for t in fig.findobj(matplotlib.text.Text) if t.get_text()]


def solved(document, units=None):
    scene = scene_from_dict(scene_dict({"output.units": units} if units else {}, document))
    return solve(build_problem(scene))


@pytest.fixture(scope="module")
def glued():
    return {"with": solved(GLUED, UNITS), "without": solved(GLUED)}


@pytest.fixture(scope="module")
def box():
    return {"with": solved(BOX, UNITS), "without": solved(BOX)}


def figures(solution):
    out = {"deformed": visuals.figure_deformed(solution)}
    boundary = solution.problem.boundary
    if boundary is not None and boundary.nodes.size:
        out["contact_traction"] = visuals.figure_contact_traction(solution)
        out["beta"] = visuals.figure_beta(solution)
    if solution.problem.dim == 3:
        out["contact_map"] = visuals.figure_contact_map(solution)
    if visuals.load_curves(solution):
        out["load_displacement"] = visuals.figure_load_displacement(solution)
    return out


def labels(fig):
    """{(axes index, "x"/"y"/"z"): label} of every axes that has one."""
    out = {}
    for i, ax in enumerate(fig.axes):
        for name in ("x", "y", "z"):
            getter = getattr(ax, f"get_{name}label", None)
            if getter is not None and getter():
                out[i, name] = getter()
    return out


def test_the_scene_reads_units_and_records_them():
    scene = scene_from_dict(scene_dict({"output.units": {"length": "mm", "time": "s"}}))
    assert scene.units == {"length": "mm", "time": "s"}
    assert scene.resolved["output"] == {"probes": [], "units": {"length": "mm", "time": "s"}}
    # no units: the record is that of a scene before units existed
    assert scene_from_dict(scene_dict()).resolved["output"] == {"probes": []}
    # the units name axes only: a study of the scene is the same study with or without them
    assert scene_identity(scene) == scene_identity(scene_from_dict(scene_dict()))


@pytest.mark.parametrize("units, message", [
    ({"lenght": "mm"}, "output.units.lenght: unknown key (did you mean 'length'?); allowed "
                       "here: force, length, stress, time"),
    ({"energy": "J"}, "output.units.energy: unknown key; allowed here: force, length, stress, "
                      "time"),
    ({"length": 1}, "output.units.length: must be a string, got 1"),
    ({"stress": ""}, "output.units.stress: must be a unit name of 1 to 16 printable"),
    ({"stress": "x" * 17}, "output.units.stress: must be a unit name of 1 to 16 printable"),
    ({"time": " s"}, "output.units.time: must be a unit name"),
    ("mm", "output.units: must be a table, got 'mm'"),
])
def test_bad_units_name_the_key(units, message):
    with pytest.raises(SceneError) as err:
        scene_from_dict(scene_dict({"output.units": units}))
    assert str(err.value).startswith(message)


def test_every_2d_axis_names_the_units_given(glued):
    figs = figures(glued["with"])
    assert set(figs) == {"deformed", "contact_traction", "beta", "load_displacement"}
    for name, fig in figs.items():
        assert not [t for t in texts(fig) if "units of" in t], name
    deformed = labels(figs["deformed"])
    assert deformed[0, "x"] == "x (mm)" and deformed[0, "y"] == "y (mm)"
    assert deformed[1, "x"] == ("von Mises stress (plane strain: σ_zz included; MPa)")
    traction = labels(figs["contact_traction"])
    assert traction[0, "y"].endswith("tension;\nMPa)")
    assert traction[2, "y"].endswith("foundation; mm)")
    assert traction[2, "x"] == "x along Γ_C (mm)"
    beta = labels(figs["beta"])
    assert beta[0, "x"] == "x along Γ_C (mm)" and beta[1, "y"] == "time t (s)"
    assert beta[3, "x"] == "time t (s)"
    load = labels(figs["load_displacement"])
    assert load[0, "x"] == "displacement (mm)"
    assert load[0, "y"] == "force on the body per unit thickness (N/mm)"


def test_without_units_the_axes_keep_the_scene_wording(glued):
    figs = figures(glued["without"])
    assert labels(figs["deformed"])[0, "x"] == "x (units of length)"
    assert labels(figs["deformed"])[1, "x"] == ("von Mises stress (plane strain: σ_zz "
                                                "included; units of E)")
    assert labels(figs["contact_traction"])[0, "y"].endswith("units of E)")
    assert labels(figs["beta"])[1, "y"] == "time t"
    load = labels(figs["load_displacement"])
    assert load[0, "x"] == "displacement"
    assert load[0, "y"] == "force on the body (per unit thickness in 2D)"


def test_beta_curves_have_no_end_lines_and_the_mean_is_defined(glued):
    fig = visuals.figure_beta(glued["with"])
    steps = [a for a in fig.axes[0].get_children() if isinstance(a, StepPatch)]
    drawn = np.union1d([0], visuals.levels.plot_levels(glued["with"]))   # level 0 and "auto"
    assert len(steps) == drawn.size
    assert all(step.get_data().baseline is None for step in steps)
    legend = [t.get_text() for t in fig.axes[3].get_legend().get_texts()]
    assert legend[0] == "mean over Γ_C (weighted by facet length)"


def test_the_3d_figures_name_the_units_and_keep_few_ticks(box):
    figs = figures(box["with"])
    assert set(figs) == {"deformed", "contact_traction", "beta", "contact_map"}
    for name, fig in figs.items():
        assert not [t for t in texts(fig) if "units of" in t], name
    deformed = figs["deformed"]
    ax = deformed.axes[0]
    assert deformed.get_suptitle().endswith("; x, y, z in mm")
    bar = [a for a in deformed.axes if a.name != "3d"]
    assert [a.get_xlabel() for a in bar] == ["von Mises stress (MPa)"]
    for axis, limits in ((ax.xaxis, ax.get_xlim()), (ax.yaxis, ax.get_ylim()),
                         (ax.zaxis, ax.get_zlim())):
        ticks = np.asarray(axis.get_majorticklocs())
        inside = ticks[(ticks >= min(limits) - 1e-12) & (ticks <= max(limits) + 1e-12)]
        assert 2 <= inside.size <= 5
    bars = [text for text in texts(figs["contact_map"]) if "normal traction" in text]
    assert bars == ["normal traction −σ_ν\n(> 0 compression; MPa)"]
    without = figures(box["without"])["deformed"]
    assert [a.get_xlabel() for a in without.axes if a.name != "3d"] == [
        "von Mises stress (units of E)"]


def run(*args):
    return runner().invoke(main, list(map(str, args)), catch_exceptions=False)


def capture(monkeypatch, module, name):
    """Keep the figures ``module.name`` makes while a command runs."""
    made = []
    original = getattr(module, name)

    def keep(*args, **kwargs):
        made.append(original(*args, **kwargs))
        return made[-1]

    monkeypatch.setattr(module, name, keep)
    return made


def test_solve_records_the_units_and_draws_with_them(tmp_path, monkeypatch):
    scene = tmp_path / "glued.toml"
    scene.write_text(to_toml(scene_dict({"output.units": UNITS}, GLUED)))
    made = capture(monkeypatch, deformed_figure, "figure_deformed")
    result = run("solve", scene, "--out", tmp_path / "out", "--quiet")
    assert result.exit_code == 0, result.stderr
    summary = json.loads((tmp_path / "out" / "summary.json").read_text())
    assert summary["scene"]["output"]["units"] == UNITS
    assert labels(made[0])[0, "x"] == "x (mm)"


def test_a_bad_unit_key_exits_2_on_one_line(tmp_path):
    scene = tmp_path / "glued.toml"
    scene.write_text(to_toml(scene_dict({"output.units": {"legnth": "mm"}}, GLUED)))
    result = run("solve", scene, "--out", tmp_path / "out")
    assert_one_line_error(result, 2, "output.units.legnth: unknown key (did you mean "
                                     "'length'?); allowed here: force, length, stress, time")
    assert not (tmp_path / "out").exists()


def test_converge_names_the_unit_of_h(tmp_path, monkeypatch):
    scene = tmp_path / "exact.toml"
    scene.write_text(to_toml(scene_dict({
        "mesh.size": [1.0, 0.5], "mesh.cells": [2, 1], "boundary": {"dirichlet": ["left"]},
        "memory": prony((200.0, 0.3, 0.5)), "time.steps": 2,
        "exact.u": ["0.01*x*x*(1+t)", "0.005*x*y"], "output.units": UNITS})))
    made = capture(monkeypatch, study_figures, "figure_error_vs_size")
    result = run("converge", scene, "--param", "h", "--levels", "2", "--out", tmp_path / "c")
    assert result.exit_code == 0, result.stderr
    assert made[0].axes[0].get_xlabel() == "mesh size h (mm)"
    document = json.loads((tmp_path / "c" / "rates.json").read_text())
    k_study = dict(document, param="k")
    assert visuals.figure_error_vs_size(k_study, "t", visuals.Units(UNITS)).axes[0] \
        .get_xlabel() == "time step k (s)"
    assert visuals.figure_error_vs_size(k_study, "t").axes[0].get_xlabel() == "time step k"
    header = (tmp_path / "c" / "errors.csv").read_text().splitlines()[0].split(",")
    assert header[:3] == ["level", "h [mm]", "k [s]"] and "E" in header


def test_a_quantity_study_names_its_unit(tmp_path, monkeypatch):
    """converge --quantity: errors.csv's Q and |Q − Q_ref| columns and the
    plot's axes carry the quantity's unit (a reaction in 2D: N/mm)."""
    scene = tmp_path / "block.toml"
    scene.write_text(to_toml(scene_dict({"output.units": UNITS, "mesh.cells": [4, 2],
                                         "time.steps": 2}, wall_block())))
    made = capture(monkeypatch, study_figures, "figure_quantity_vs_size")
    result = run("converge", scene, "--param", "h", "--levels", "2", "--ref-h", "1",
                 "--quantity", "normal_force_T", "--out", tmp_path / "q")
    assert result.exit_code == 0, result.stderr
    header = (tmp_path / "q" / "errors.csv").read_text().splitlines()[0].split(",")
    assert "quantity [N/mm]" in header and "err_q [N/mm]" in header and "rel_q" in header
    assert made[0].axes[0].get_ylabel() == "normal_force_T (N/mm)"
    assert made[0].axes[1].get_ylabel() == "|Q_h − Q_ref| of normal_force_T (N/mm)"


def test_sweep_names_the_unit_of_the_force(tmp_path, monkeypatch):
    scene = tmp_path / "block.toml"
    scene.write_text(to_toml(scene_dict({"output.units": UNITS, "mesh.cells": [4, 2]},
                                        wall_block())))
    made = capture(monkeypatch, study_figures, "figure_by_key")
    result = run("sweep", scene, "--set", "contact.normal.c=1e3,2e3", "--out", tmp_path / "s")
    assert result.exit_code == 0, result.stderr
    force = [ax.get_ylabel() for ax in made[0].axes if "normal contact force" in ax.get_ylabel()]
    assert force == ["total normal contact force at T\n(> 0 compression; N/mm)"]
    header = (tmp_path / "s" / "runs.csv").read_text().splitlines()[0].split(",")
    assert "normal_force_T [N/mm]" in header and "beta_mean_T" in header
    assert "contact.normal.c" in header and "outcome" in header
    rows = [{"outcome": "ok", "k": 1.0, "normal_force_T": 1.0, "seconds": 1.0,
             "newton_total": 1, "beta_mean_T": 1.0}]
    plain = visuals.figure_by_key(rows, ["k"], "k", "t")
    assert "total normal contact force at T\n(> 0 compression)" in [
        ax.get_ylabel() for ax in plain.axes]
    three = visuals.figure_by_key(rows, ["k"], "k", "t", visuals.Units(UNITS), dim=3)
    assert "total normal contact force at T\n(> 0 compression; N)" in [
        ax.get_ylabel() for ax in three.axes]
