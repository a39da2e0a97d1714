"""Hostile cases of the third reliability round (the defects found on the
newest surfaces), each kept as a test: bad input is one line naming the
key or value and what is allowed, exit 2, no traceback and nothing written.

The commands run in a child process where a defect used to hang or eat
the machine's memory, so that a hang fails the test instead of the suite.
"""

import os
import subprocess
import sys

import pytest

from adhesive_contact import load_scene

COMMANDS = (["solve"], ["check"], ["converge", "--param", "h", "--levels", "2"],
            ["sweep", "--set", "time.steps=1,2"])


def cli(*args, cwd, timeout=60):
    """``adhcontact ARGS`` in a child, with a time limit."""
    return subprocess.run([sys.executable, "-c", "from adhesive_contact_cli.main import main; "
                           "main()", *args], capture_output=True, text=True, timeout=timeout,
                          cwd=cwd)


def one_error_line(result, needle):
    assert result.returncode == 2, (result.returncode, result.stderr)
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: "), result.stderr
    assert needle in lines[0], lines[0]
    assert "Traceback" not in result.stderr + result.stdout


# ---------------------------------------------------------------- scene paths that are no scene

def _fifo(d):
    os.mkfifo(d / "scene.toml")
    return str(d / "scene.toml")


def _large(d):
    (d / "scene.toml").write_bytes(b"# " + b"x" * (2 << 20) + b"\n")
    return str(d / "scene.toml")


@pytest.mark.parametrize("make, needle", [
    (_fifo, "a named pipe (FIFO), not a regular file"),
    (lambda d: "/dev/zero", "'/dev/zero': a device, not a regular file"),
    (_large, "larger than 1 MiB, which no scene is"),
])
@pytest.mark.parametrize("command", COMMANDS, ids=lambda c: c[0])
def test_a_scene_path_that_is_no_scene_file_is_one_line_exit_2(tmp_path, make, needle, command):
    """A FIFO as the scene path hung every command; /dev/zero was read until
    memory ran out (exit 1 naming --force); both are refused before the file
    is opened, and a file past any scene's size before it is parsed."""
    path = make(tmp_path)
    result = cli(command[0], path, *command[1:], "--out", str(tmp_path / "out"), cwd=tmp_path) \
        if command[0] != "check" else cli("check", path, cwd=tmp_path)
    one_error_line(result, needle)
    assert not (tmp_path / "out").exists()


def test_the_library_refuses_a_scene_path_that_is_no_regular_file(tmp_path):
    os.mkfifo(tmp_path / "pipe.toml")
    with pytest.raises(OSError, match="a named pipe"):
        load_scene(tmp_path / "pipe.toml")
    with pytest.raises(OSError, match="a device"):
        load_scene("/dev/zero")


# ---------------------------------------------------------------- values past what the numbers hold

from conftest import assert_one_line_error, invoke, law, run, scene_dict, to_toml  # noqa: E402
import numpy as np  # noqa: E402

BASE = scene_dict({"contact.normal": law("compliance", c=1e4),
                   "loads": {"body": ["0", "-10*t"]}, "time.steps": 2})


@pytest.mark.parametrize("changes, needle", [
    ({"material.E": 5e-324}, "material.E: gives the elastic tensor mu = 0, bulk modulus 0, "
                             "below 1e-100, where the stiffness matrix underflows"),
    ({"material.E": 1e-310}, "material.E: gives the elastic tensor mu = 3.85e-311"),
    ({"material": {"lam": 1.0, "mu": 1e-200}}, "material.mu: gives the elastic tensor mu = 1e-200"),
    ({"material": None, "memory": {"kernel": "relaxation", "long_term": {"E": 1e-300, "nu": 0.3},
                                   "terms": [{"E": 100.0, "tau": 1.0}]}},
     "memory.long_term: gives the long-term tensor of the relaxation kernel mu = 3.85e-301"),
    ({"time.T": 5e-324}, "time.T: gives the time step k = T/steps = 0, below 1e-100"),
    ({"time.T": 1e-250, "time.steps": 3}, "time.T: gives the time step k = T/steps = 3.33e-251"),
])
@pytest.mark.parametrize("command", ["check", "solve"])
def test_moduli_and_steps_past_double_precision_are_refused(tmp_path, changes, needle, command):
    """E = 5e-324 or 1e-310 made a singular factorisation (a traceback; a
    sweep with it crashed whole; check exited 0); T = 5e-324 gave k = 0
    and every level at t = 0, exit 0."""
    data = scene_dict({k: v for k, v in changes.items() if v is not None}, BASE)
    for k, v in changes.items():
        if v is None:
            del data[k]
    (tmp_path / "s.toml").write_text(to_toml(data))
    args = [command, str(tmp_path / "s.toml")] + (["--out", str(tmp_path / "o")]
                                                  if command == "solve" else [])
    assert_one_line_error(invoke(*args), 2, needle)
    assert not (tmp_path / "o").exists()


def test_a_long_unknown_key_is_shown_cut_in_one_short_line(tmp_path):
    """A 10,000-character unknown key made a 10,059-character error line."""
    data = scene_dict({"contact.normal": {"law": "compliance", "c": 1e4, "x" * 10000: 1}}, BASE)
    (tmp_path / "s.toml").write_text(to_toml(data))
    result = invoke("check", str(tmp_path / "s.toml"))
    assert_one_line_error(result, 2, "unknown key; allowed here: c, law")
    assert len(result.stderr.strip()) < 200 and "…" in result.stderr


def test_adaptive_steps_from_one_uniform_step(tmp_path):
    """[time.adaptive] with time.steps = 1: the first pair took a doubled
    step of 2T (IndexError in solve, converge --param k and a sweep, which
    died instead of writing a row); now its pairs are of k_max/2 = T/2."""
    import json

    data = scene_dict({"time.steps": 1, "time.adaptive": {"tol": 0.01}}, BASE)
    (tmp_path / "s.toml").write_text(to_toml(data))
    result = invoke("solve", tmp_path / "s.toml", "--out", tmp_path / "o")
    assert result.exit_code == 0, result.stderr
    summary = json.loads((tmp_path / "o" / "summary.json").read_text())
    t = [s["t"] for s in summary["steps"]]
    assert t[0] == 0.0 and t[-1] == 1.0 and all(b > a for a, b in zip(t, t[1:]))
    assert summary["adaptive"]["accepted_steps"] == len(t) - 1 >= 2
    sweep = invoke("sweep", tmp_path / "s.toml", "--set", "contact.normal.c=1e3,1e4",
                   "--out", tmp_path / "sw")
    assert sweep.exit_code == 0, sweep.stderr
    rows = (tmp_path / "sw" / "runs.csv").read_text().splitlines()
    assert len(rows) == 3 and all(",ok," in row for row in rows[1:])


@pytest.mark.parametrize("strength, toughness, needle", [
    (1e200, 1.0, "initial stiffness about 1e401 = e^2 strength^2 / toughness, beyond 1e100"),
    (1e160, 1e-10, "initial stiffness about 1e331"),
])
def test_an_exponential_cohesive_law_whose_stiffness_overflows_is_refused(tmp_path, strength,
                                                                          toughness, needle):
    """The derived stiffness e² σ²/G was never range-checked: OverflowError."""
    data = scene_dict({
        "boundary": {"dirichlet": [], "contact": ["bottom"],
                     "displacement": {"top": ["0", "0.01*t"]}},
        "contact": {"normal": law("cohesive", shape="exponential", strength=strength,
                                  toughness=toughness),
                    "bonding": {"law": "cohesive"}}}, BASE)
    del data["loads"]
    (tmp_path / "s.toml").write_text(to_toml(data))
    assert_one_line_error(invoke("check", tmp_path / "s.toml"), 2,
                          "contact.normal.strength: gives the " + needle)


def test_converge_quantity_reads_every_number_of_a_sweep_row_and_refuses_one_with_no_value(
        tmp_path):
    """`--quantity normal_force_T` was refused though documented (any column
    of a sweep's runs.csv); `--quantity work_T` on a scene without an energy
    balance exited 0 with the quantity null on every level."""
    import json

    (tmp_path / "s.toml").write_text(to_toml(BASE))
    result = invoke("converge", tmp_path / "s.toml", "--param", "h", "--levels", "2",
                    "--reference", "fine", "--quantity", "normal_force_T", "--out",
                    tmp_path / "o")
    assert result.exit_code == 0, result.stderr
    rows = json.loads((tmp_path / "o" / "rates.json").read_text())
    assert rows["quantity"]["name"] == "normal_force_T"
    # the body's weight, 10 × its area 1, is carried by the clamped top and Γ_C
    # together: the same reference's top reaction and normal force add up to it
    reaction = invoke("converge", tmp_path / "s.toml", "--param", "h", "--levels", "2",
                      "--reference", "fine", "--quantity", "reaction_top_y_T", "--out",
                      tmp_path / "r")
    assert reaction.exit_code == 0, reaction.stderr
    top = json.loads((tmp_path / "r" / "rates.json").read_text())["quantity"]["reference"]
    assert 0.0 < rows["quantity"]["reference"] < 10.0
    assert rows["quantity"]["reference"] + top == pytest.approx(10.0, rel=1e-9)
    grown = scene_dict({"memory": {"kernel": "prony",
                                   "terms": [{"E": 100.0, "nu": 0.3, "tau": 1.0}]}}, BASE)
    (tmp_path / "g.toml").write_text(to_toml(grown))
    assert_one_line_error(invoke("converge", tmp_path / "g.toml", "--param", "h", "--levels",
                                 "2", "--quantity", "work_T", "--out", tmp_path / "g"), 2,
                          "--quantity: 'work_T' has no value in this scene: the run has no "
                          "energy balance")
    assert not (tmp_path / "g").exists()


@pytest.mark.parametrize("command", [["solve"], ["sweep", "--set", "time.steps=1,2"]],
                         ids=lambda c: c[0])
@pytest.mark.parametrize("kind", ["file", "link", "folder"])
def test_a_users_file_named_like_the_lock_is_never_touched(tmp_path, command, kind):
    """A user's own file named `.DIR.lock` beside --out was truncated and
    deleted by the run; a link of that name had its target truncated."""
    (tmp_path / "s.toml").write_text(to_toml(BASE))
    lock = tmp_path / ".out.lock"
    target = tmp_path / "notes.txt"
    target.write_text("my notes\n")
    if kind == "file":
        lock.write_text("my notes\n")
    elif kind == "link":
        lock.symlink_to(target)
    else:
        lock.mkdir()
        (lock / "inside.txt").write_text("mine\n")
    result = invoke(command[0], tmp_path / "s.toml", *command[1:], "--out", tmp_path / "out")
    assert_one_line_error(result, 2, "exists and is not a lock of adhcontact", alone=False)
    assert target.read_text() == "my notes\n"
    assert lock.is_symlink() if kind == "link" else lock.exists()
    if kind == "file":
        assert lock.read_text() == "my notes\n"
    if kind == "folder":
        assert (lock / "inside.txt").read_text() == "mine\n"
    assert not (tmp_path / "out").exists()


@pytest.mark.parametrize("foundation, needle", [
    ({"shape": "sphere", "point": [1.0, -1e17], "radius": 1e17},
     "contact.foundation.radius: is 1e+17, more than 1e+06 times the body's diameter"),
    ({"shape": "sphere", "point": [1.1, 0.3], "radius": 0.02},    # between the nodes
     "contact.foundation.point: (1.1, 0.3) lies inside the body"),
    ({"shape": "sphere", "point": [1.0, 0.6], "radius": 0.3},
     "contact.foundation: the mesh node (0.75, 0.5) lies inside the foundation"),
])
def test_a_foundation_in_the_body_or_too_flat_to_measure_is_refused(tmp_path, foundation,
                                                                     needle):
    """A sphere of radius 1e17 (its distance lost to round-off) and a disc
    inside the body were accepted; the body's contact nodes, which alone
    were checked, lie outside both."""
    data = scene_dict({"contact.foundation": foundation}, BASE)
    (tmp_path / "s.toml").write_text(to_toml(data))
    assert_one_line_error(invoke("check", tmp_path / "s.toml"), 2, needle)


COHESIVE = scene_dict({
    "boundary": {"dirichlet": [], "contact": ["bottom"],
                 "displacement": {"top": ["0", "0.001*t"]}},
    "contact": {"normal": law("cohesive", shape="bilinear", strength=1.0, toughness=0.01,
                              stiffness=1000.0),
                "bonding": {"law": "cohesive"}}}, BASE)
del COHESIVE["loads"]


def test_a_sweep_grid_with_one_invalid_combination_runs_it_as_a_failed_row(tmp_path):
    """strength 2 with stiffness 60 breaks 2 G K > σ² (4 > 1.2), each valid
    alone: the grid was refused whole, as the variant checked for strength
    = 2 was that combination; the docs promise a failed row. A value that
    is invalid alone on the scene is still refused before anything runs."""
    (tmp_path / "s.toml").write_text(to_toml(COHESIVE))
    result = invoke("sweep", tmp_path / "s.toml", "--set", "contact.normal.strength=1,2",
                    "--set", "contact.normal.stiffness=60,1000", "--out", tmp_path / "o")
    assert result.exit_code == 0, result.stderr
    rows = [row.split(",") for row in (tmp_path / "o" / "runs.csv").read_text().splitlines()]
    outcome = {(r[1], r[2]): r[3] for r in rows[1:]}
    assert outcome == {("1", "60"): "ok", ("1", "1000"): "ok", ("2", "60"): "failed",
                       ("2", "1000"): "ok"}
    alone = invoke("sweep", tmp_path / "s.toml", "--set", "contact.normal.strength=1,100",
                   "--out", tmp_path / "a")
    assert_one_line_error(alone, 2, "--set contact.normal.strength=100: is not valid in this "
                          "scene: contact.normal.toughness: must exceed", alone=False)
    assert not (tmp_path / "a").exists()


def test_adaptive_steps_that_cannot_keep_the_explicit_euler_bound_are_refused(tmp_path):
    """γ_ν = 1e12 puts the explicit Euler bound at 1e-8, below any k_min: the
    run went on at k_min until β left [0, 1] (the message named k = k_max
    and asked for [time.adaptive], which the scene had). With a reachable
    bound the message names the k_min that keeps it, and a run with it
    keeps β in [0, 1]."""
    import tomllib
    from pathlib import Path

    default = tomllib.loads((Path(__file__).resolve().parents[1] / "cli" /
                             "default_scene.toml").read_text())
    default["contact"]["bonding"]["gamma_nu"] = 1e12
    default["time"]["adaptive"] = {"tol": 0.1}
    (tmp_path / "s.toml").write_text(to_toml(default))
    assert_one_line_error(invoke("check", tmp_path / "s.toml"), 2,
                          "time.adaptive.k_min: the adaptive steps' smallest pair 2 k_min = "
                          "4.883e-05 is beyond the explicit Euler bound k <= 1e-08")
    default["contact"]["bonding"]["gamma_nu"] = 1e9   # bound 1e-5
    default["time"].update(T=0.002, steps=2)
    default["time"]["adaptive"]["k_min"] = 1e-5
    (tmp_path / "s.toml").write_text(to_toml(default))
    result = invoke("check", tmp_path / "s.toml")
    assert_one_line_error(result, 2, "give time.adaptive.k_min <= 5e-06")
    default["time"]["adaptive"]["k_min"] = 5e-6
    (tmp_path / "s.toml").write_text(to_toml(default))
    result = invoke("solve", tmp_path / "s.toml", "--out", tmp_path / "o", "-q")
    assert result.exit_code == 0, result.stderr


def test_an_adaptive_run_past_its_estimate_stops_when_its_pace_outgrows_the_disk(
        tmp_path, monkeypatch):
    """The estimate of an adaptive run counted the uniform grid only (tol
    1e-8: 9 levels estimated, 97,878 taken, 1.7 GB), so the guard could
    never fire. Now the estimate gives both ends, and the run projects its
    needs from its pace at every doubling past the estimate: here with 40 MB
    free (the uniform grid's 3 MB fits) it stops at the first checkpoint,
    writes the levels done and says what it would need."""
    import json
    import tomllib
    from pathlib import Path

    import adhesive_contact.resources as resources
    from adhesive_contact import parse_scene

    default = tomllib.loads((Path(__file__).resolve().parents[1] / "cli" /
                             "default_scene.toml").read_text())
    default["time"]["adaptive"] = {"tol": 0.001}
    text = to_toml(default)
    est = resources.estimate(parse_scene(text))
    assert est.levels == 41 and est.levels_at_most == 40 * 1024 + 1
    assert est.disk_bytes < 40e6 < est.disk_bytes_at_most
    assert "at most 4.1e+04 levels" in est.describe()
    (tmp_path / "s.toml").write_text(text)
    monkeypatch.setattr(resources, "free_disk", lambda folder: 40e6)
    result = invoke("solve", tmp_path / "s.toml", "--out", tmp_path / "o", "-q")
    assert_one_line_error(result, 1, "the adaptive steps need about", alone=False)
    assert "more than the 40 MB free" in result.stderr and "--force" in result.stderr
    run = json.loads((tmp_path / "o" / "summary.json").read_text())["run"]
    assert run["partial"] and 41 <= run["levels"] < 100


def test_coulomb_on_a_body_held_by_contact_alone_engages_from_zero_load():
    """A block on a compliant layer, held by nothing but Γ_C, pressed by 10 t
    and sheared by 1 t on its top (shear/normal 0.1 < μ = 0.5): it failed at
    step 1 ("a load they cannot balance"), the Coulomb bound being frozen at
    the zero pressure of t = 0 first. Now it holds, and at every level the
    nodal forces meet Coulomb's conditions by hand: |F_τ,a| ≤ μ p_a w_a,
    stuck nodes inside the cone, and the totals balance the loads."""
    from adhesive_contact.postprocess import total_contact_force

    data = scene_dict({
        "boundary": {"dirichlet": [], "contact": ["bottom"]},
        "loads": {"traction": {"top": ["1*t", "-10*t"]}},
        "contact": {"normal": law("compliance", c=1e4),
                    "friction": [law("coulomb", mu=0.5)]},
        "time.steps": 4}, BASE)
    problem, solution = run(data)
    assert solution.success, solution.message
    F = total_contact_force(solution)
    np.testing.assert_allclose(F, np.stack([-2.0 * solution.t, 20.0 * solution.t], axis=1),
                               rtol=1e-8, atol=1e-9)
    w = problem.boundary.node_weights
    p = 1e4 * np.maximum(solution.frame_displacement[:, :, 0], 0.0)   # c u_ν+
    bound = 0.5 * p * w
    tangential = np.abs(solution.contact_force[:, :, 1])
    assert np.all(tangential <= bound * (1 + 1e-8) + 1e-12)
    assert np.abs(F[-1, 0]) > 0     # friction carries the shear


def test_a_full_disk_ends_with_one_line_and_exit_1_not_a_crash(tmp_path):
    """The disk filling during the run (past the free-space check: here
    with --force) ended in SIGSEGV: the HDF5 library flushed and truncated
    through a Python file already closed when it cleaned up at exit. Now
    the run ends with exit 1, one line, and nothing left in the folder.
    A full disk needs a small file system of its own: a 3 MB tmpfs."""
    disk = tmp_path / "disk"
    disk.mkdir()
    mounted = subprocess.run(["mount", "-t", "tmpfs", "-o", "size=3m", "tmpfs", str(disk)],
                             capture_output=True, text=True)
    if mounted.returncode != 0:
        pytest.skip(f"no tmpfs can be mounted here (not root?): {mounted.stderr.strip()}")
    try:
        data = scene_dict({"mesh.cells": [40, 10], "time.steps": 100}, BASE)
        (tmp_path / "s.toml").write_text(to_toml(data))
        result = cli("solve", str(tmp_path / "s.toml"), "--out", str(disk / "o"), "--force",
                     "-q", cwd=tmp_path, timeout=120)
        assert result.returncode == 1, (result.returncode, result.stderr)
        assert result.stderr.strip().splitlines() == [
            f"error: --out: cannot write {str(disk / 'o')!r}: No space left on device"]
        assert list(disk.iterdir()) == []
    finally:
        subprocess.run(["umount", str(disk)], capture_output=True)
