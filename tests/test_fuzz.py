"""Generated scenes (hypothesis): malformed ones are refused with exit 2, one
line, no traceback and no output folder; small valid ones finish (exit 0)
or fail with a diagnosis (exit 1), never with a traceback.

Each malformed scene is a valid base with one defect of a kind (a wrong
type, a missing required key, an unknown key or a typo of a known one, a
number out of range or not finite, an empty or duplicate list, an unknown
or conflicting side, broken TOML, a hostile expression, an enormous size),
so every one of them must be refused. The examples are derandomized: the
same scenes every run.
"""

import math
import tomllib

from adhesive_contact_cli.main import main
from click.testing import CliRunner
from conftest import DELETE, law, scene_dict, to_toml
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

BASE = scene_dict({
    "title": "fuzz", "mesh.cells": [4, 2], "loads.body": ["0", "-10*t"],
    "contact.gap": "0.01", "contact.normal": law("compliance", c=100.0), "time.steps": 1})

FUZZ = settings(derandomize=True, database=None, deadline=None,
                suppress_health_check=list(HealthCheck))

# ---------------------------------------------------------------- defects

#: a key and values of the wrong type there
WRONG_TYPES = [("title", [1, True, [], {}]), ("dim", ["2", 2.0, True]),
               ("mesh.size", ["1", 2.0, {"a": 1}]), ("mesh.cells", [[4.0, 2], ["4", 2], 3]),
               ("mesh.refine", [1.5, "1"]), ("material.E", ["1000", [1000], True]),
               ("time.steps", [1.0, "3"]), ("time.T", ["1", [1]]),
               ("boundary.dirichlet", ["top", [1]]), ("loads.body", ["0", [0], [[], 0]]),
               ("contact.normal", ["compliance", 5]), ("contact.normal.c", ["5", True]),
               ("solver.max_iter", [2.5, "50"]), ("output.probes", [[1, 2], [["a", 0]]])]
REQUIRED = ["dim", "mesh", "mesh.domain", "mesh.size", "mesh.cells", "boundary",
            "boundary.dirichlet", "material", "material.E", "material.nu", "time", "time.T",
            "time.steps", "contact.normal.law", "contact.normal.c"]
TABLES = ["", "mesh.", "boundary.", "material.", "time.", "loads.", "contact.",
          "contact.normal.", "solver.", "output."]
KNOWN = {"": ["title", "dim"], "mesh.": ["size", "cells", "refine", "pattern"],
         "material.": ["E", "nu"], "time.": ["T", "steps"], "contact.": ["gap", "order"],
         "contact.normal.": ["c"], "solver.": ["tol", "max_iter"], "loads.": ["body"]}
#: keys and values outside their range
OUT_OF_RANGE = [("dim", [1, 4, 0, -2]), ("mesh.cells", [[0, 2], [4, -1], [2**62, 1]]),
                ("mesh.size", [[0.0, 1.0], [-1.0, 1.0], [1e-300, 1e-300], [1e300, 1.0]]),
                ("mesh.refine", [-1, 13, 10**6]), ("material.E", [0.0, -1.0]),
                ("material.nu", [0.5, -1.0, 7.0]), ("time.T", [0.0, -1.0]),
                ("time.steps", [0, -5, 10**12, 2**63 - 1]), ("contact.normal.c", [-1.0, 0.0]),
                ("contact.order", [0, 11]), ("solver.tol", [0.0, -1e-8, 1.0, 1e300]),
                ("solver.max_iter", [0, 10**9]), ("contact.gap", [-0.1]),
                ("output.probes", [[[5.0, 5.0]], [[-1.0, 0.2]]]),
                ("mesh.domain", ["box", "circle"]), ("mesh.pattern", ["zigzag"])]
NON_FINITE = ["mesh.size.0", "material.E", "material.nu", "time.T", "contact.normal.c",
              "solver.tol", "contact.gap", "output.probes.0.0"]
#: expressions that must be refused wherever a load or gap is expected
HOSTILE = ["x.real", "__import__('os')", "().__class__", "open('f')", "eval('1')",
           "lambda: 1", "[i for i in (1, 2)]", "{1: 2}", "'a'", "f'{x}'", "x if x else 1",
           "x and 1", "x[0]", "q + 1", "sin", "sin(x, x)", "sin(x=1)", "(x := 1)",
           "9**9**9", "10**10**10", "1e308*10", "sqrt(-1 - x)", "0/0", "1/0*x", "log(x - 5)",
           "exp(1000*x + 1000)", "x**1e308 + 2**1e308", "(" * 150 + "x" + ")" * 150,
           "-" * 150 + "x", "x" * 3000, "+".join(["x"] * 1500), "", "   ", "1 +", "x @ x",
           "x // 2", "x % 2", "~x", "not x", "x is x", "x in x", "True", "None", "b'x'",
           "1j", "sin(*x)"]
HUGE = [{"mesh.cells": [200000, 200000]}, {"mesh.cells": [4000, 4000], "mesh.refine": 4},
        {"time.steps": 10**8}, {"time.steps": 10**12}, {"mesh.refine": 12},
        {"mesh.cells": [2**62, 1]}]


def _set(changes):
    return scene_dict(changes, BASE)


def _delete(dotted):
    return scene_dict({dotted: DELETE}, BASE)


def _nested_set(data, dotted, value):
    """Set ``a.b.0.c`` (integers index lists) in place."""
    *head, last = dotted.split(".")
    inner = data
    for key in head:
        inner = inner[int(key)] if key.isdigit() else inner.setdefault(key, {})
    inner[int(last) if last.isdigit() else last] = value
    return data


def _typo(name, draw):
    """A near miss of a key: one character dropped, doubled or changed case."""
    i = draw(st.integers(0, len(name) - 1))
    kind = draw(st.sampled_from(["drop", "double", "case", "append"]))
    if kind == "drop" and len(name) > 1:
        return name[:i] + name[i + 1:]
    if kind == "double":
        return name[:i] + name[i] * 2 + name[i + 1:]
    if kind == "case" and name[i].swapcase() != name[i]:
        return name[:i] + name[i].swapcase() + name[i + 1:]
    return name + "_"


@st.composite
def malformed(draw):
    """(TOML text, what kind of defect) of a scene that must be refused."""
    kind = draw(st.sampled_from(["type", "missing", "unknown", "typo", "range", "nonfinite",
                                 "lists", "sides", "toml", "expression", "huge"]))
    if kind == "type":
        key, values = draw(st.sampled_from(WRONG_TYPES))
        data = _set({key: draw(st.sampled_from(values))})
    elif kind == "missing":
        data = _delete(draw(st.sampled_from(REQUIRED)))
    elif kind == "unknown":
        table = draw(st.sampled_from(TABLES))
        name = draw(st.text("abcdefghijklmnopqrstuvwxyz_", min_size=1, max_size=12))
        data = _set({table + "zz" + name: draw(st.sampled_from([1, "a", [1], 2.5]))})
    elif kind == "typo":
        table = draw(st.sampled_from(sorted(KNOWN)))
        name = draw(st.sampled_from(KNOWN[table]))
        wrong = _typo(name, draw)
        data = scene_dict(BASE)
        holder = data
        for part in table.rstrip(".").split(".") if table else []:
            holder = holder.setdefault(part, {})
        holder[wrong] = holder.pop(name) if name in holder else 1
    elif kind == "range":
        key, values = draw(st.sampled_from(OUT_OF_RANGE))
        data = _set({key: draw(st.sampled_from(values))})
    elif kind == "nonfinite":
        data = _nested_set(scene_dict({"output.probes": [[1.0, 0.2]]}, BASE),
                           draw(st.sampled_from(NON_FINITE)),
                           draw(st.sampled_from([math.inf, -math.inf, math.nan])))
    elif kind == "lists":
        data = _set(draw(st.sampled_from([
            {"boundary.dirichlet": []}, {"boundary.dirichlet": ["top", "top"]},
            {"boundary.contact": ["bottom", "bottom"]}, {"mesh.cells": []},
            {"mesh.size": []}, {"mesh.cells": [4, 2, 2]}, {"loads.body": []},
            {"loads.body": ["0", "0", "0"]}, {"output.probes": [[]]},
            {"contact.friction": [{"law": "tresca"}]},
            {"memory": {"kernel": "prony", "terms": []}}])))
    elif kind == "sides":
        data = _set(draw(st.sampled_from([
            {"boundary.dirichlet": ["up"]}, {"boundary.contact": ["Bottom"]},
            {"boundary.contact": ["top"]}, {"boundary.contact": ["front"]},
            {"loads.traction": {"top": ["0", "0"]}}, {"loads.traction": {"bottom": [0, 1]}},
            {"loads.traction": {"middle": [0, 1]}},
            {"boundary.contact": [], "contact.gap": "0.1"}])))
    elif kind == "toml":
        text = to_toml(BASE)
        cut = draw(st.integers(0, len(text) - 1))
        junk = draw(st.sampled_from(["[", "]", "=", '"', "[[", "\n[mesh]\n", "= =",
                                     "\nmesh = 1\n", "\x00", "[" * 5000, "a = [" * 3000]))
        text = text[:cut] + junk + text[cut:]
        try:
            tomllib.loads(text)
        except (tomllib.TOMLDecodeError, RecursionError):
            return text, kind
        data = _set({"title": 1})   # the junk happened to be valid TOML
    elif kind == "expression":
        source = draw(st.sampled_from(HOSTILE))
        where = draw(st.sampled_from(["loads.body", "contact.gap", "traction"]))
        data = _set({"loads.body": [source, "0"]} if where == "loads.body" else
                    {"contact.gap": source} if where == "contact.gap" else
                    {"boundary.contact": ["bottom"],
                     "loads.traction": {"left": ["0", source]}})
    else:
        data = _set(draw(st.sampled_from(HUGE)))
    return to_toml(data), kind


def _invoke(tmp_path, text):
    scene = tmp_path / "scene.toml"
    scene.write_text(text)
    out = tmp_path / "out"
    result = CliRunner().invoke(main, ["solve", str(scene), "--out", str(out)])
    return result, out


@settings(FUZZ, max_examples=240)
@given(case=malformed())
def test_malformed_scenes_exit_2_with_one_line(tmp_path_factory, case):
    text, kind = case
    tmp_path = tmp_path_factory.mktemp("fuzz")
    result, out = _invoke(tmp_path, text)
    lines = result.stderr.strip().splitlines()
    assert result.exit_code == 2, (kind, text, result.stderr, result.exception)
    assert len(lines) == 1 and lines[0].startswith("error: "), (kind, result.stderr)
    assert "Traceback" not in result.stderr + result.stdout
    assert not out.exists()



@st.composite
def small_valid(draw):
    """A small valid 2D scene: a few cells, a polynomial load, maybe a wall,
    a compliance law, friction and bonding."""
    coefficient = st.sampled_from([-50.0, -5.0, 0.0, 2.0, 20.0])
    changes = {
        "mesh.cells": [draw(st.integers(1, 4)), draw(st.integers(1, 3))],
        "material.E": draw(st.sampled_from([10.0, 1000.0])),
        "material.nu": draw(st.sampled_from([0.0, 0.3, 0.45])),
        "loads.body": [f"{draw(coefficient)}*t*x", f"{draw(coefficient)}*t + {draw(coefficient)}*y"],
        "time.steps": draw(st.integers(1, 3)),
        "contact.normal.c": draw(st.sampled_from([10.0, 1e3, 1e5])),
    }
    if draw(st.booleans()):
        changes["contact.gap"] = draw(st.sampled_from(["0", "0.001", "0.01*x"]))
    else:
        changes["contact.gap"] = DELETE
    if draw(st.booleans()):
        changes["contact.friction"] = draw(st.sampled_from([
            law("tresca", mu=0.3), law("nonmonotone", a=0.2, b=0.1, alpha=5.0)]))
    if draw(st.booleans()):
        changes["contact.bonding"] = law("fremond", gamma_nu=1.0, gamma_tau=1.0,
                                         eps_a=0.01, L=1.0)
    return to_toml(scene_dict(changes, BASE))


@settings(FUZZ, max_examples=6)
@given(text=small_valid())
def test_small_valid_scenes_finish_or_fail_with_a_diagnosis(tmp_path_factory, text):
    tmp_path = tmp_path_factory.mktemp("valid")
    result, out = _invoke(tmp_path, text)
    assert result.exit_code in (0, 1), (text, result.stderr, result.exception)
    assert "Traceback" not in result.stderr + result.stdout
    if result.exit_code == 1:
        errors = [line for line in result.stderr.splitlines() if line.startswith("error: ")]
        assert len(errors) == 1 and ("did not converge" in errors[0]
                                     or "invalid state" in errors[0]), result.stderr
    else:
        assert (out / "summary.json").is_file()
