"""Runs that fail or are interrupted: Ctrl-C stops ``adhcontact solve`` at
the end of a step, keeps the levels done (marked partial) and exits 130;
a failure at t = 0 writes nothing."""

import json
import signal
import subprocess
import sys
import threading
import time

import numpy as np
from adhesive_contact_cli.main import main
from click.testing import CliRunner
from conftest import law, scene_dict, to_toml

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


def test_ctrl_c_stops_at_the_end_of_a_step_and_keeps_the_levels_done(tmp_path):
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
    proc.send_signal(signal.SIGINT)
    assert proc.wait(60) == 130, "".join(lines)
    reader.join(5)
    errors = [line for line in lines if line.startswith("error: ")]
    assert len(errors) == 1 and "interrupted after step" in errors[0], "".join(lines)
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
