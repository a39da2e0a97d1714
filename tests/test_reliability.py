"""Untrusted scenes and long runs: every defect found in review ends as exit 2
(one line naming the key), exit 1 (a diagnosis), or a correct result; the
resource guard; stale staging folders; plots that cannot cost the data;
determinism; a sweep killed mid-run loses and recomputes nothing."""

import json
import os
import signal
import subprocess
import sys
import time

import numpy as np
import pytest
from adhesive_contact_cli import output as output_module
from adhesive_contact_cli import plots
from adhesive_contact_cli.main import main
from click.testing import CliRunner
from conftest import DELETE, law, prony, scene_dict, to_toml

from adhesive_contact import (
    SceneError,
    build_problem,
    compile_expression,
    resources,
    scene_from_dict,
    solve,
)
from adhesive_contact.verification import manufactured

BLOCK = scene_dict({"title": "block", "mesh.cells": [4, 2], "loads.body": ["0", "-10*t"],
                    "contact.normal": law("compliance", c=100.0), "time.steps": 2})
#: a manufactured scene (its loads come from [exact])
EXACT = {"dim": 2, "mesh": {"domain": "rectangle", "size": [1.0, 1.0], "cells": [2, 2]},
         "boundary": {"dirichlet": ["left"]}, "material": {"E": 100.0, "nu": 0.3},
         "time": {"T": 1.0, "steps": 1}, "exact": {"u": ["x*t", "0"]}}


def run(*args):
    return CliRunner().invoke(main, [str(a) for a in args])


def solve_scene(tmp_path, data, *extra):
    scene = tmp_path / "scene.toml"
    scene.write_text(data if isinstance(data, str) else to_toml(data))
    out = tmp_path / "out"
    return run("solve", scene, "--out", out, *extra), out


def assert_refused(result, out, needle):
    lines = result.stderr.strip().splitlines()
    assert result.exit_code == 2, (result.stderr, result.exception)
    assert len(lines) == 1 and lines[0].startswith("error: ") and needle in lines[0], lines
    assert not out.exists()


# ---------------------------------------------------------------- the defects, exit 2


@pytest.mark.parametrize("changes, base, needle", [
    # loads that are not finite were accepted and failed at step 0 (exit 1)
    ({"loads.body": ["9**9**9", "0"]}, BLOCK, "loads.body[0]: is not finite: inf at ("),
    ({"loads.body": ["0", "1e308*10"]}, BLOCK, "loads.body[1]: is not finite: inf"),
    ({"loads.body": ["sqrt(-1 - x)", "0"]}, BLOCK, "loads.body[0]: is not finite: nan"),
    ({"boundary.contact": DELETE, "contact": DELETE, "loads.body": ["0/0", "0"]}, BLOCK,
     "loads.body[0]: is not finite: nan"),   # a quiet NaN with exit 0 before
    ({"boundary.contact": ["bottom", "left"], "loads.traction": {"right": ["0", "1/(t - 1)"]}},
     BLOCK, "loads.traction.right[1]: is not finite: inf at ("),   # at t = T
    # MemoryError / ValueError tracebacks
    ({"mesh.cells": [200000, 200000]}, BLOCK, "mesh.cells: gives 4e+10 nodes"),
    ({"time.steps": 1000000000000}, BLOCK, "time.steps: must be an integer in 1..1e+08"),
    ({"time.steps": 2**63 - 1}, BLOCK, "time.steps: must be an integer in 1..1e+08"),
    ({"mesh.cells": [2**62, 1]}, BLOCK, "mesh.cells: gives 9.22e+18 nodes"),
    # [exact]: hangs in sympy, OverflowError, KeyError
    ({"exact.u": ["9**9**9*x", "0"]}, EXACT, "exact.u[0]: a constant part is not finite"),
    ({"exact.u": ["10**10**10", "0"]}, EXACT, "exact.u[0]: a constant part is not finite"),
    ({"exact.u": ["x**1e308", "0"]}, EXACT, "exact.u[0]: the exponent 1e+308 is too large"),
    ({"exact.u": ["1/0*x", "0"]}, EXACT, "exact.u[0]: a constant part is not finite"),
    ({"exact.u": ["x", "log(x - 2)"]}, EXACT, "exact.u[1]: is not finite: nan at ("),
    # a 100,000-character title took 30 s in the plots
    ({"title": "a" * 100000}, BLOCK, "title: must have at most 500 characters, got 100000"),
    # tolerances that accept the start as the solution (0 iterations, exit 0)
    ({"solver.tol": 1e300}, BLOCK, "solver.tol: must lie in [1e-14, 0.001]"),
    ({"solver.tol": 1.0, "solver.max_iter": 1}, BLOCK, "solver.tol: must lie in"),
    ({"solver.max_iter": 10**9}, BLOCK, "solver.max_iter: must be an integer in 1..10000"),
    # "Factor is exactly singular"
    ({"mesh.size": [float("inf"), 1.0]}, BLOCK, "mesh.size[0]: must be a finite length"),
    ({"mesh.size": [1e-300, 1e-300]}, BLOCK, "mesh.size[0]: must be a finite length"),
    ({"mesh.size": [1.0, 1e-5], "mesh.cells": [1, 1]}, BLOCK, "elongated more than 1000:1"),
    ({"memory": {"kernel": "function", "r": "exp(-t)/0", "E": 100.0, "nu": 0.3}}, BLOCK,
     "memory.r: is not finite: r(0) = inf"),
    ({"memory": {"kernel": "function", "r": "1/(t - 0.5)", "E": 100.0, "nu": 0.3}}, BLOCK,
     "memory.r: is not finite: r(0.5) = inf"),
])
def test_defect_is_refused_with_one_line_naming_the_key(tmp_path, changes, base, needle):
    result, out = solve_scene(tmp_path, scene_dict(changes, base))
    assert_refused(result, out, needle)


def test_deeply_nested_toml_is_one_line(tmp_path):
    result, out = solve_scene(tmp_path, "a = " + "[" * 5000 + "]" * 5000 + "\n")
    assert_refused(result, out, "nested too deeply")


def test_exact_scene_refused_before_sympy_sees_it(tmp_path, monkeypatch):
    """The refusal of a huge exponent comes from the scene's own check: the
    derivation (which would hang on 9**9**9) is never started."""
    def never(*args, **kwargs):
        raise AssertionError("sympy was given the expression")
    monkeypatch.setattr(manufactured.ManufacturedSolution, "__init__", never)
    for source in ("9**9**9*x", "x**1e308", "x**(2**7)", "2**x**70"):
        with pytest.raises(SceneError, match=r"exact.u\[0\]: "):
            build_problem(scene_from_dict(scene_dict({"exact.u": [source, "0"]}, EXACT)))


def test_exact_scene_within_the_bounds_still_derives_its_loads():
    problem = build_problem(scene_from_dict(scene_dict({"exact.u": ["x**3*t", "0"]}, EXACT)))
    assert solve(problem).success


# ---------------------------------------------------------------- the evaluator


@pytest.mark.parametrize("source, message", [
    ("x.real", "attribute access is not allowed"),
    ("().__class__.__bases__", "attribute access is not allowed"),
    ("__import__('os').system('true')", "attribute access is not allowed"),
    ("__import__('os')", "function '__import__' is not allowed"),
    ("open('/etc/passwd')", "function 'open' is not allowed"),
    ("(lambda: 1)()", "only calls to named functions"),
    ("lambda: 1", "lambda is not allowed"),
    ("[i for i in (1, 2)]", "comprehensions are not allowed"),
    ("sum(i for i in (1, 2))", "function 'sum' is not allowed"),
    ("'abc'", "string literals are not allowed"),
    ("sin('x')", "string literals are not allowed"),
    ("os", "name 'os' is not allowed"),
    ("x" * 2001, "too long"),
    ("(" * 101 + "x" + ")" * 101, "nested too deeply"),
    ("-" * 200 + "x", "nested too deeply"),
    ("1" * 400, "number literal is too large"),
])
def test_evaluator_refuses_with_exit_2(tmp_path, source, message):
    with pytest.raises(Exception, match=message):
        compile_expression(source)
    result, out = solve_scene(tmp_path, scene_dict({"loads.body": [source, "0"]}, BLOCK))
    assert_refused(result, out, message)
    assert result.stderr.startswith("error: loads.body[0]: ")


@pytest.mark.parametrize("source", ["9**9**9", "10**10**10", "x**1e308 + 2", "exp(1e5*x)",
                                    "1e308*10*x", "2**2**2**2**2**2"])
def test_huge_results_are_refused_where_used(tmp_path, source):
    result, out = solve_scene(tmp_path, scene_dict({"loads.body": ["0", source]}, BLOCK))
    assert_refused(result, out, "loads.body[1]: is not finite: inf at (")


def test_a_function_of_a_comparison_is_computed_in_float64():
    value = compile_expression("exp(x > 1)")(np.array([2.0, 0.0]))
    assert value.dtype == np.float64
    assert value.tolist() == [np.exp(1.0), 1.0]   # was 2.71875 (float16)


def test_a_flat_sum_is_not_nested_and_evaluates_in_order():
    terms = [f"{i}*x" for i in range(1, 300)]    # 299 terms, 1700 characters
    x = np.array([0.5, 3.0])
    expected = np.zeros(2)
    for i in range(1, 300):
        expected = expected + i * x
    assert compile_expression("+".join(terms))(x).tolist() == expected.tolist()
    assert compile_expression("-".join(["x"] * 900))(x).tolist() == (-898 * x).tolist()


# ---------------------------------------------------------------- resource guard


def test_the_estimate_counts_what_the_build_makes():
    for changes in ({}, {"mesh.pattern": "cross", "mesh.refine": 2},
                    {"boundary.contact": ["bottom", "left"], "mesh.refine": 1}):
        scene = scene_from_dict(scene_dict(changes, BLOCK))
        est, problem = resources.estimate(scene), build_problem(scene)
        assert est.dofs == problem.ndofs and est.cells == problem.mesh.t.shape[1]
        # an upper bound: a corner shared by two contact sides is counted
        # twice (one shared with a Dirichlet side is a contact node)
        extra = 0 if len(scene.contact_sides) == 1 else 1
        assert est.contact_nodes == problem.boundary.nodes.size + extra
        assert est.levels == scene.steps + 1


def test_a_scene_larger_than_the_machine_is_refused_unless_forced(tmp_path, monkeypatch):
    est = resources.estimate(scene_from_dict(BLOCK))
    monkeypatch.setattr(resources, "available_memory", lambda: est.memory_bytes / 2)
    result, out = solve_scene(tmp_path, BLOCK)
    assert_refused(result, out, "is too large for this machine: it would need about")
    assert "--force" in result.stderr and "mesh.cells" in result.stderr
    result, out = solve_scene(tmp_path, BLOCK, "--force")
    assert result.exit_code == 0, result.stderr
    record = json.loads((out / "summary.json").read_text())["resources"]
    assert record["estimate"]["dofs"] == record["used"]["dofs"] == 30
    assert record["estimate"]["levels"] == record["used"]["levels"] == 3
    assert record["used"]["peak_memory_bytes"] > 0 and record["used"]["seconds"] > 0


def test_a_run_longer_than_a_day_is_refused(tmp_path):
    result, out = solve_scene(tmp_path, scene_dict({"time.steps": 10**8 - 1,
                                                    "mesh.cells": [1, 1]}, BLOCK))
    assert_refused(result, out, "is too large for this machine")


def test_converge_and_sweep_check_their_largest_run_and_their_out(tmp_path):
    scene = tmp_path / "scene.toml"
    scene.write_text(to_toml(BLOCK))
    result = run("converge", scene, "--param", "k", "--levels", 20, "--steps", 1000,
                 "--out", tmp_path / "c")
    assert_refused(result, tmp_path / "c", "the largest run of the study is too large")
    result = run("converge", scene, "--param", "k", "--levels", 40, "--out", tmp_path / "c")
    assert_refused(result, tmp_path / "c", "--levels")
    result = run("sweep", scene, "--set", "time.steps=2,99999999", "--out", tmp_path / "s")
    assert_refused(result, tmp_path / "s", "the variant time.steps=99999999 is too large")
    locked = tmp_path / "locked"
    locked.mkdir(mode=0o500)
    if os.access(locked, os.W_OK):   # root writes anywhere: a file in the way instead
        locked = tmp_path / "file"
        locked.write_text("a file")
    for args in (("converge", scene, "--param", "k"), ("sweep", scene, "--set",
                                                       "time.steps=1,2")):
        result = run(*args, "--out", locked / "out")
        assert_refused(result, locked / "out", "cannot be written")


# ---------------------------------------------------------------- outputs


def test_a_dollar_in_the_title_is_drawn(tmp_path):
    result, out = solve_scene(tmp_path, scene_dict({"title": "$x^$ and $"}, BLOCK))
    assert result.exit_code == 0, result.stderr
    assert {"deformed.png", "beta.png", "contact_traction.png"} <= set(os.listdir(out))
    assert plots.plot_title("$x^$") == r"\$x^\$"
    assert len(plots.plot_title("a" * 500)) == plots.TITLE_CHARS


def test_a_plot_that_fails_is_a_warning_and_the_data_is_kept(tmp_path, monkeypatch):
    def broken(solution, path):
        raise RuntimeError("no font")
    monkeypatch.setattr(plots, "plot_beta", broken)
    result, out = solve_scene(tmp_path, BLOCK)
    assert result.exit_code == 0, result.stderr
    assert "warning: beta.png was not drawn: RuntimeError: no font" in result.stderr
    assert {"summary.json", "solution.npz", "deformed.png"} <= set(os.listdir(out))
    assert "beta.png" not in os.listdir(out)


def dead_pid():
    """The pid of a process that has ended."""
    child = subprocess.Popen([sys.executable, "-c", "pass"])
    child.wait()
    return child.pid


def test_staging_folders_of_killed_runs_are_removed(tmp_path):
    stale = tmp_path / f"out.tmp-{dead_pid()}-abcd"
    live = tmp_path / f"out.tmp-{os.getpid()}-efgh"
    other = tmp_path / "out.tmp-notes"
    for folder in (stale, live, other):
        folder.mkdir()
        (folder / "summary.json").write_text("{")
    result, out = solve_scene(tmp_path, BLOCK)
    assert result.exit_code == 0, result.stderr
    assert not stale.exists() and live.exists() and other.exists()
    inside = out / f".adhcontact.tmp-{dead_pid()}-ijkl"
    inside.mkdir()
    assert output_module.remove_stale(out, ".adhcontact.tmp-") == [inside.name]


# ---------------------------------------------------------------- determinism


def test_the_same_scene_gives_bit_identical_arrays():
    scene = scene_from_dict(scene_dict({"memory": prony((50.0, 0.3, 0.5)),
                                        "contact.friction": law("tresca", mu=0.3),
                                        "loads.body": ["5*t", "-40*t"]}, BLOCK))
    first, second = (solve(build_problem(scene)) for _ in range(2))
    for name in ("u", "beta", "t", "iterations"):
        assert np.array_equal(getattr(first, name), getattr(second, name)), name


SWEEP = scene_dict({"mesh.cells": [8, 4], "time.steps": 60,
                    "memory": prony((50.0, 0.3, 0.5))}, BLOCK)


def records(folder):
    """{name: record without the wall time and memory} of a sweep folder."""
    out = {}
    for path in sorted((folder / "runs").glob("*.json")):
        record = json.loads(path.read_text())
        out[path.name] = {k: v for k, v in record.items()
                          if "seconds" not in k and "rss" not in k and k != "timings"}
    return out


def test_a_sweep_gives_the_same_records_with_one_or_two_jobs(tmp_path):
    scene = tmp_path / "scene.toml"
    scene.write_text(to_toml(scene_dict({"time.steps": 3}, SWEEP)))
    for jobs in (1, 2):
        result = run("sweep", scene, "--set", "contact.normal.c=50,100,200", "--jobs", jobs,
                     "--out", tmp_path / f"jobs{jobs}")
        assert result.exit_code == 0, result.stderr
    one, two = records(tmp_path / "jobs1"), records(tmp_path / "jobs2")
    assert len(one) == 3 and one == two


# ---------------------------------------------------------------- SIGKILL


def test_a_sweep_killed_mid_run_loses_and_recomputes_nothing(tmp_path):
    scene = tmp_path / "scene.toml"
    scene.write_text(to_toml(scene_dict({"time.steps": 400}, SWEEP)))
    out = tmp_path / "out"
    args = ["sweep", str(scene), "--set", "contact.normal.c=50,60,70,80,90,100", "--out",
            str(out)]
    child = subprocess.Popen([sys.executable, "-c", "from adhesive_contact_cli.main import "
                              "main; main()", *args], stdout=subprocess.DEVNULL,
                             stderr=subprocess.DEVNULL)
    runs = out / "runs"
    while child.poll() is None and not list(runs.glob("run_*.json")):
        time.sleep(0.02)
    child.send_signal(signal.SIGKILL)
    child.wait()
    saved = {p.name: p.read_bytes() for p in runs.glob("run_*.json")}
    assert 1 <= len(saved) < 6
    # no file that looks whole but is not: records parse, the rest is named tmp
    for path in runs.iterdir():
        if path.name in saved:
            assert json.loads(saved[path.name])["values"]
        else:
            assert path.name.startswith(".") and ".tmp-" in path.name
    result = run(*args)
    assert result.exit_code == 0, result.stderr
    assert f"{6 - len(saved)} computed now, {len(saved)} loaded" in result.stdout
    assert all((runs / name).read_bytes() == data for name, data in saved.items())
