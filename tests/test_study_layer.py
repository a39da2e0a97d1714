"""Tests for the study layer (:mod:`adhesive_contact.studies`): a toy study
of cheap runs (no scheme) for identity, storage, resume, failures and a
pluggable executor; then the convergence study from Python."""

import json
from concurrent.futures import ThreadPoolExecutor, as_completed
from types import SimpleNamespace

import pytest
from conftest import to_toml

import adhesive_contact.studies.convergence as convergence_study
from adhesive_contact import StepFailure
from adhesive_contact.storage import plain
from adhesive_contact.studies import (
    ConvergenceStudy,
    RunFailed,
    Study,
    StudyError,
    StudyFolderError,
    StudyMismatch,
)

CALLS = SimpleNamespace(setup=0, runs=[])


def _setup(factor):
    CALLS.setup += 1
    return {"factor": factor}


def _square(state, key):
    CALLS.runs.append(key)
    if key == state.get("fail"):
        raise StepFailure(2, 0.5, SimpleNamespace(message="simulated", residual=1.0,
                                                  tolerance=1e-10, nit=3))
    return {"key": key, "value": state["factor"] * key * key}


class Squares(Study):
    """Run k computes factor · k² for k = 0..n−1."""

    kind = "toy study"
    compute = _square

    def __init__(self, folder, n, factor, fail=None):
        super().__init__(folder)
        self.n, self.factor, self.fail = n, factor, fail

    def identity(self):
        return {"n": self.n, "factor": self.factor}

    def keys(self):
        return list(range(self.n))

    def context(self):
        return _setup_failing, (self.factor, self.fail)


def _setup_failing(factor, fail):
    return {**_setup(factor), "fail": fail}


@pytest.fixture(autouse=True)
def calls():
    CALLS.setup, CALLS.runs = 0, []
    return CALLS


def run_all(study, **kwargs):
    study.create()
    done = study.load()
    computed = study.run_missing(done, **kwargs)
    return done, computed


def test_runs_are_saved_one_file_each_and_a_rerun_computes_nothing(tmp_path, calls):
    study = Squares(tmp_path / "s", 4, 3.0)
    done, computed = run_all(study)
    assert computed == [0, 1, 2, 3] and calls.runs == [0, 1, 2, 3]
    assert calls.setup == 1                     # the state is built once
    assert {k: r["value"] for k, r in done.items()} == {0: 0, 1: 3.0, 2: 12.0, 3: 27.0}
    assert sorted(p.name for p in (tmp_path / "s" / "runs").iterdir()) == [
        f"run_{k}.json" for k in range(4)]
    stored = json.loads((tmp_path / "s" / "study.json").read_text())
    assert stored["n"] == 4 and stored["factor"] == 3.0 and len(stored["sha256"]) == 64

    calls.runs = []
    again = Squares(tmp_path / "s", 4, 3.0)
    assert again.open() is True
    done, computed = run_all(again)
    assert computed == [] and calls.runs == []
    assert done[3]["value"] == 27.0

    # a lost record is the only run computed again
    (tmp_path / "s" / "runs" / "run_2.json").unlink()
    (tmp_path / "s" / "runs" / "run_1.json").write_text("{ half")
    done, computed = run_all(Squares(tmp_path / "s", 4, 3.0))
    assert computed == [1, 2] and calls.runs == [1, 2]


def test_another_study_is_refused_naming_the_difference(tmp_path):
    run_all(Squares(tmp_path / "s", 2, 3.0))
    with pytest.raises(StudyMismatch, match="factor 3.0 there, 4.0 here") as err:
        Squares(tmp_path / "s", 2, 4.0).open()
    assert err.value.difference == "factor 3.0 there, 4.0 here"
    with pytest.raises(StudyMismatch, match="n 2 there, 3 here"):
        Squares(tmp_path / "s", 3, 3.0).create()
    mine = tmp_path / "mine"
    mine.mkdir()
    (mine / "notes.txt").write_text("keep")
    with pytest.raises(StudyFolderError, match="not a toy study"):
        Squares(mine, 2, 3.0).create()
    assert [p.name for p in mine.iterdir()] == ["notes.txt"]
    (tmp_path / "file").write_text("")
    with pytest.raises(StudyFolderError, match="not a folder"):
        Squares(tmp_path / "file", 2, 3.0).open()


def test_a_failed_run_stops_the_study_and_keeps_the_finished_ones(tmp_path, calls):
    study = Squares(tmp_path / "s", 4, 1.0, fail=2)
    with pytest.raises(RunFailed, match="run 2: step 2 .* did not converge: simulated") as err:
        run_all(study, label=lambda key: f"run {key}")
    assert err.value.label == "run 2"
    assert calls.runs == [0, 1, 2]              # run 3 never started
    assert sorted(p.name for p in (tmp_path / "s" / "runs").iterdir()) == [
        "run_0.json", "run_1.json"]


def test_any_executor_with_submit_and_as_completed(tmp_path, calls):
    """A thread pool stands for a cluster: each task carries the context,
    the state is built once in the (one) worker process, the driver saves."""
    yielded = []

    def counting_as_completed(futures):
        for future in as_completed(futures):
            yielded.append(future)
            yield future

    saved = []
    study = Squares(tmp_path / "s", 5, 2.0)
    with ThreadPoolExecutor(max_workers=2) as executor:
        done, computed = run_all(study, executor=executor, as_completed=counting_as_completed,
                                 on_record=lambda key, record: saved.append(key))
    assert sorted(computed) == [0, 1, 2, 3, 4] and len(yielded) == 5
    assert sorted(saved) == [0, 1, 2, 3, 4] and sorted(calls.runs) == [0, 1, 2, 3, 4]
    assert calls.setup == 1
    assert {k: r["value"] for k, r in done.items()} == {k: 2.0 * k * k for k in range(5)}


# ---------------------------------------------------------------- convergence from Python

EXACT_SCENE = to_toml({
    "title": "manufactured, no contact", "dim": 2,
    "mesh": {"domain": "rectangle", "size": [1.0, 0.5], "cells": [4, 2]},
    "boundary": {"dirichlet": ["left"]},
    "material": {"E": 1000.0, "nu": 0.3},
    "time": {"T": 1.0, "steps": 4},
    "exact": {"u": ["0.01*x*x*(1+t)", "0.005*x*y"]},
})


def test_convergence_study_from_python(tmp_path, monkeypatch, capsys):
    events = []
    calls = []
    real = convergence_study.run_level

    def counted(scene, param, level, reference=None, **kwargs):
        calls.append(level)
        return real(scene, param, level, reference, **kwargs)

    monkeypatch.setattr(convergence_study, "run_level", counted)
    scene = tmp_path / "exact.toml"
    scene.write_text(EXACT_SCENE)
    study = ConvergenceStudy(scene, param="h", levels=3, reference="exact",
                             folder=tmp_path / "out")
    result = study.run(progress=lambda *event: events.append(event))
    assert capsys.readouterr() == ("", "")           # the library prints nothing
    assert calls == [0, 1, 2] and result.computed == [0, 1, 2]
    assert result.reference_loaded is None
    # in this process each level reports its time levels done, 0 to steps + 1,
    # between the finished-levels counts
    assert [e for e in events if e[0] == "levels"] == [
        ("levels", 0, 3), ("levels", 1, 3), ("levels", 2, 3), ("levels", 3, 3)]
    stages = [e[0] for e in events]
    steps = study.scene.steps
    for level in range(3):
        mine = [e for e in events if e[0] == f"level {level}"]
        assert mine == [(f"level {level}", n, steps + 1) for n in range(steps + 2)]
        first = stages.index(f"level {level}")
        assert events[first - 1] == ("levels", level, 3)
        assert events[first + len(mine)] == ("levels", level + 1, 3)
    doc = result.document
    assert set(doc) >= {"param", "levels", "rates"} and doc["param"] == "h"
    assert [level["dofs"] for level in doc["levels"]] == [30, 90, 306]
    assert doc["rates"]["E"] > 0.8
    assert json.loads((tmp_path / "out" / "rates.json").read_text())["rates"]["E"] == \
        pytest.approx(doc["rates"]["E"], rel=1e-15)
    assert sorted(result.files) == ["errors.csv", "rates.json"]
    assert json.loads((tmp_path / "out" / "study.json").read_text())["scene_file"] == str(scene)

    again = ConvergenceStudy(EXACT_SCENE, param="h", levels=3, folder=tmp_path / "out").run()
    assert calls == [0, 1, 2] and again.computed == []
    assert plain(again.document) == json.loads((tmp_path / "out" / "rates.json").read_text())


@pytest.mark.parametrize("kwargs, key, needle", [
    ({"param": "x"}, "param", "h, k, hk"),
    ({"param": "h", "levels": 1}, "levels", ">= 2"),
    ({"param": "h", "reference": "fine", "ref_h": 20}, "levels", "dofs"),
    ({"param": "h", "ref_k": 1}, "ref_h/ref_k", "only with reference fine"),
])
def test_convergence_study_arguments_are_checked_before_anything_is_written(
        tmp_path, kwargs, key, needle):
    with pytest.raises(StudyError, match=needle) as err:
        ConvergenceStudy(EXACT_SCENE, folder=tmp_path / "out", **kwargs)
    assert err.value.key == key
    assert not (tmp_path / "out").exists()
