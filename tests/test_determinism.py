"""Determinism: the same scene gives bit-identical arrays, and a sweep the
same records with one or two jobs."""

import json

import numpy as np
from conftest import COMPLIANT_BLOCK, invoke, law, prony, scene_dict, to_toml

from adhesive_contact import build_problem, scene_from_dict, solve

def test_the_same_scene_gives_bit_identical_arrays():
    scene = scene_from_dict(scene_dict({"memory": prony((50.0, 0.3, 0.5)),
                                        "contact.friction": law("tresca", mu=0.3),
                                        "loads.body": ["5*t", "-40*t"]}, COMPLIANT_BLOCK))
    first, second = (solve(build_problem(scene)) for _ in range(2))
    for name in ("u", "beta", "t", "iterations"):
        assert np.array_equal(getattr(first, name), getattr(second, name)), name


SWEEP = scene_dict({"mesh.cells": [8, 4], "time.steps": 60,
                    "memory": prony((50.0, 0.3, 0.5))}, COMPLIANT_BLOCK)


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
        result = invoke("sweep", scene, "--set", "contact.normal.c=50,100,200", "--jobs", jobs,
                     "--out", tmp_path / f"jobs{jobs}")
        assert result.exit_code == 0, result.stderr
    one, two = records(tmp_path / "jobs1"), records(tmp_path / "jobs2")
    assert len(one) == 3 and one == two
