"""Runs that fail or are interrupted: Ctrl-C stops ``adhcontact solve`` at
the end of a step, keeps the levels done (marked partial) and exits 130;
it stops a sweep, whose finished runs are kept and resumed from, with
exit 130 and one line; a failure at t = 0 writes nothing."""

import json
import os
import signal
import subprocess
import sys
import threading
import time

import numpy as np
import pytest
from adhesive_contact_cli.main import main
from click.testing import CliRunner
from conftest import COMPLIANT_BLOCK, invoke, law, prony, scene_dict, to_toml


# a small block pushed onto a compliant foundation: a few ms per step, so
# 4000 steps run for many seconds unless interrupted
SCENE_DICT = scene_dict({
    "title": "long run",
    "mesh": {"domain": "rectangle", "size": [1.0, 0.5], "cells": [4, 2]},
    "material.E": 100.0,
    "loads": {"body": ["0", "-10*t"]},
    "contact": {"normal": law("compliance", c=1000.0)},
    "time.steps": 4000,
})
SCENE = to_toml(SCENE_DICT)


@pytest.mark.parametrize("sig, exit_code, said", [(signal.SIGINT, 130, "interrupted after step"),
                                             (signal.SIGTERM, 143,
                                              "interrupted by SIGTERM after step")])
def test_ctrl_c_stops_at_the_end_of_a_step_and_keeps_the_levels_done(tmp_path, sig, exit_code, said):
    """Ctrl-C, and SIGTERM (what a batch system sends before its kill: it
    used to end the run at once and leave nothing), stop at the end of a
    step and write the levels done."""
    (tmp_path / "scene.toml").write_text(SCENE)
    out = tmp_path / "out"
    code = "from adhesive_contact_cli.main import main; main()"
    proc = subprocess.Popen([sys.executable, "-c", code, "solve", "scene.toml", "--out", "out"],
                            cwd=tmp_path, stderr=subprocess.PIPE, text=True)
    lines = []
    started = threading.Event()

    def read():
        for line in proc.stderr:
            lines.append(line)
            if "long run" in line or "scene: 4000 steps" in line:
                started.set()

    reader = threading.Thread(target=read, daemon=True)
    reader.start()
    assert started.wait(60), "".join(lines)   # the progress bar is shown: the loop runs
    time.sleep(0.5)
    proc.send_signal(sig)
    returned = proc.wait(60)
    assert returned == exit_code, (returned, "".join(lines))
    reader.join(5)
    errors = [line for line in lines if line.startswith("error: ")]
    assert len(errors) == 1 and said in errors[0], "".join(lines)
    assert "Traceback" not in "".join(lines)
    run = json.loads((out / "summary.json").read_text())["run"]
    assert run["status"] == "interrupted" and run["partial"] and not run["success"]
    assert 1 <= run["levels"] < 4001
    with np.load(out / "solution.npz") as arrays:
        assert arrays["u"].shape[0] == arrays["t"].size == run["levels"]


def test_failure_at_the_first_level_writes_nothing(tmp_path):
    (tmp_path / "scene.toml").write_text(
        to_toml(scene_dict({"loads.body": ["0", "-10 - 10*t"], "solver.max_iter": 1,
                            "time.steps": 3}, SCENE_DICT)))
    result = CliRunner().invoke(main, ["solve", str(tmp_path / "scene.toml"),
                                       "--out", str(tmp_path / "out")])
    assert result.exit_code == 1
    assert "step 0 (t = 0) did not converge: no convergence in 1 iterations" in result.stderr
    assert "Nothing was written." in result.stderr
    assert [p.name for p in tmp_path.iterdir()] == ["scene.toml"]


def default_sigint():
    """In the child before it runs: SIGINT's default disposition."""
    signal.signal(signal.SIGINT, signal.SIG_DFL)


def interrupt_when(args, cwd, ready, timeout=120):
    """Run ``adhcontact args`` in its own process group, send the group
    SIGINT (what Ctrl-C in a terminal does) once ``ready()`` holds, and
    return (exit code, stderr, whether a process of the group outlived it
    by 5 s)."""
    code = "from adhesive_contact_cli.main import main; main()"
    # SIGINT as a terminal leaves it: a shell without job control starts
    # background commands with SIGINT ignored, and Python then keeps it so
    proc = subprocess.Popen([sys.executable, "-c", code, *args], cwd=cwd,
                            stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True,
                            start_new_session=True, preexec_fn=default_sigint)
    deadline = time.monotonic() + timeout
    while not ready():
        assert proc.poll() is None and time.monotonic() < deadline, proc.stderr.read()
        time.sleep(0.05)
    os.killpg(proc.pid, signal.SIGINT)
    code = proc.wait(60)
    stderr = proc.stderr.read()
    for _ in range(50):
        try:
            os.killpg(proc.pid, 0)   # raises once no process of the group is left
        except ProcessLookupError:
            return code, stderr, False
        time.sleep(0.1)
    return code, stderr, True


@pytest.mark.parametrize("jobs", [1, 2])
def test_ctrl_c_stops_a_sweep_which_resumes_from_the_runs_done(tmp_path, jobs):
    # each run some 2000 steps of a few ms: seconds, so the first finishes
    # well before the last and the interrupt lands among them
    (tmp_path / "scene.toml").write_text(to_toml(scene_dict({"time.steps": 1500}, SCENE_DICT)))
    runs = tmp_path / "out" / "runs"
    values = "contact.normal.c=1000,2000,3000,4000,5000,6000"
    args = ["sweep", "scene.toml", "--set", values, "--out", "out", "--jobs", str(jobs)]
    code, stderr, left = interrupt_when(args, tmp_path,
                                        lambda: runs.is_dir() and any(runs.glob("run_*.json")))
    assert code == 130, stderr
    assert not left   # no worker left computing
    errors = [line for line in stderr.splitlines() if line.startswith("error: ")]
    assert errors == ["error: interrupted; the finished runs are saved in out/ and the same "
                      "command resumes from them"], stderr
    assert "Traceback" not in stderr
    done = len(list(runs.glob("run_*.json")))
    assert 1 <= done < 6
    result = subprocess.run([sys.executable, "-c",
                             "from adhesive_contact_cli.main import main; main()", *args],
                            cwd=tmp_path, capture_output=True, text=True, timeout=300)
    assert result.returncode == 0, result.stderr
    assert f"{6 - done} computed now, {done} loaded" in result.stdout




# ----------------------------------------------------------------
# A sweep killed mid-run loses and recomputes nothing.


SWEEP = scene_dict({"mesh.cells": [8, 4], "time.steps": 60,
                    "memory": prony((50.0, 0.3, 0.5))}, COMPLIANT_BLOCK)


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
    result = invoke(*args)
    assert result.exit_code == 0, result.stderr
    assert f"{6 - len(saved)} computed now, {len(saved)} loaded" in result.stdout
    assert all((runs / name).read_bytes() == data for name, data in saved.items())
