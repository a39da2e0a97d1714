"""docs/scenes.md against the key declarations (adhesive_contact/scene/keys.py):
the doc lists every declared key and no other (but the law parameters,
declared by the law registries), and where it states a key's default,
choices or range, they are the declared ones. The reader uses the same
declarations: a scene without its optional tables reads as their defaults.

The doc is read as it is written: each ``##``/``###`` section names its
table in its heading (``[mesh]``, ``[[memory.terms]]``; "Top level" is the
document); a table whose first column is ``key`` has a row per key (or
several: ``E``, ``nu``), its columns ``default`` and ``allowed``; a table
whose first column is a key (``law``) lists that key's choices.
"""

import re
import subprocess
import sys
import tomllib
from pathlib import Path

import pytest
from conftest import BLOCK

from adhesive_contact import scene_from_dict
from adhesive_contact.scene.keys import KEYS, REQUIRED, Interval

DOC = Path(__file__).resolve().parents[1] / "docs" / "scenes.md"
NUMBER = r"[-−]?\d+(?:\.\d+)?(?:e[-+]?\d+)?"


def _cells(line):
    return [c.strip() for c in line.strip().strip("|").split("|")]


def _ticked(text):
    return re.findall(r"`([^`]*)`", text)


def read_doc():
    """(rows, listed): ``rows`` maps a key to its row's cells by column name
    (the rows of a table of choices under ``"choices"``); ``listed`` is
    every key the doc names (by a row, a heading or a table of choices)."""
    rows, listed = {}, set()
    section = None
    lines = DOC.read_text(encoding="utf-8").splitlines()
    for i, line in enumerate(lines):
        if line.startswith("#"):
            tables = re.findall(r"`\[\[?([\w.]+)\]\]?`", line)
            section = "" if "Top level" in line else (tables[0] if tables else None)
            listed.update(tables)
            continue
        if section is None or not line.startswith("|") or i + 1 >= len(lines) \
                or not re.match(r"\|\s*-", lines[i + 1]) or lines[i - 1].startswith("|"):
            continue
        header = [c.strip("`").lower() for c in _cells(line)]
        body = []
        for row in lines[i + 2:]:
            if not row.startswith("|"):
                break
            body.append(dict(zip(header, _cells(row))))
        prefix = f"{section}." if section else ""
        if header[0] == "key":
            for row in body:
                for token in _ticked(row["key"]):
                    table = re.fullmatch(r"\[\[?([\w.]+)\]\]?", token)
                    if table or re.fullmatch(r"\w+", token):
                        name = table.group(1) if table else prefix + token
                        rows[name] = row
                        listed.add(name)
        elif _cells(line)[0].startswith("`"):   # the choices of one key
            name = prefix + header[0]
            rows[name] = {"choices": [_ticked(row[header[0]]) for row in body],
                          "rows": body}
            listed.add(name)
    return rows, listed


ROWS, LISTED = read_doc()


def law_parameters():
    """Every law parameter, by its dotted name (``contact.normal.c``)."""
    return {f"{key.table}.{p}" for key in KEYS.values() if key.laws
            for _, params in key.laws.values() for p in params}


def test_the_doc_is_read():
    # a change of the doc's layout that this reader misses must not pass quietly
    assert len(LISTED) > 60
    assert ROWS["solver.tol"]["default"] == "`1e-10`"
    assert ROWS["contact.normal.law"]["choices"][1] == ['"compliance"']


def test_the_doc_lists_every_declared_key():
    assert sorted(set(KEYS) - LISTED) == []


def test_the_doc_lists_only_declared_keys_and_law_parameters():
    assert sorted(LISTED - set(KEYS) - law_parameters()) == []


@pytest.mark.parametrize("name", sorted(KEYS))
def test_the_doc_states_the_declared_default(name):
    key = KEYS[name]
    row = ROWS.get(name)
    if row is None or "default" not in row:
        # named by a heading or a table of choices: a table, or a law key
        assert key.kind == "table" or key.laws, name
        assert key.default is None or key.required, name
        return
    stated = row["default"]
    if stated.startswith("required"):
        assert key.required, (name, stated)
    elif stated.startswith("`"):
        value = tomllib.loads(f"v = {_ticked(stated)[0]}")["v"]
        declared = list(key.default) if isinstance(key.default, tuple) else key.default
        assert key.default is not REQUIRED and value == declared, (name, stated)
    else:   # in words: an absent key sets nothing ("none", "no wall", "zero")
        assert key.default is None, (name, stated, key.default)


@pytest.mark.parametrize("name", sorted(n for n, k in KEYS.items() if k.choices))
def test_the_doc_offers_the_declared_choices(name):
    key = KEYS[name]
    row = ROWS[name]
    choices = key.choices
    everywhere = sorted({c for dim in (2, 3) for c in key.allowed(dim)} if isinstance(
        choices, dict) else choices, key=str)
    if "choices" in row:
        stated = [tomllib.loads(f"v = {ticked[0]}")["v"] for ticked in row["choices"]]
        assert sorted(stated) == sorted(everywhere), name
        return
    ticked = _ticked(row["allowed"])
    for value in everywhere:
        shown = f'"{value}"' if isinstance(value, str) else str(value)
        assert shown in ticked, (name, value, row["allowed"])


def test_the_doc_names_the_parameters_of_every_law():
    for key in (k for k in KEYS.values() if k.laws and "choices" in ROWS[k.name]):
        for row in ROWS[key.name]["rows"]:
            law = tomllib.loads(f"v = {_ticked(row['law'])[0]}")["v"]
            params = set(key.laws[law][1])
            stated = set(_ticked(row["parameters"])) - {"–"}
            assert stated == params, (key.name, law, stated)


def _intervals(text):
    """The intervals a cell states: (lo, hi, closed) of "[a, b]", "(a, b)", "a..b"."""
    text = text.replace("−", "-")
    found = [(float(a), float(b), left == "[") for left, a, b, right in re.findall(
        rf"([\[(])\s*({NUMBER})\s*,\s*({NUMBER})\s*([\])])", text)]
    found += [(float(a), float(b), True) for a, b in re.findall(
        rf"(?<![\w.])({NUMBER})\.\.({NUMBER})", text)]
    return found


BOUNDED = sorted(n for n, k in KEYS.items() if k.bounds is not None
                 and n in ROWS and len(_ticked(ROWS[n]["key"])) == 1)


@pytest.mark.parametrize("name", BOUNDED)
def test_the_doc_states_the_declared_bounds(name):
    key = KEYS[name]
    allowed = ROWS[name]["allowed"]
    if key.bounds == "positive":
        assert re.search(r">\s*0(?![.\d])", allowed), (name, allowed)
    elif key.bounds == "nonnegative":
        assert re.search(r"(≥|>=)\s*0(?![.\d])", allowed), (name, allowed)
    else:
        assert isinstance(key.bounds, Interval)
        bounds = (float(key.bounds.lo), float(key.bounds.hi), key.bounds.closed)
        assert bounds in _intervals(allowed), (name, allowed)


def test_a_scene_without_optional_tables_reads_as_the_declared_defaults():
    scene = scene_from_dict(BLOCK)
    assert scene.title == KEYS["title"].default
    assert (scene.mesh.pattern, scene.mesh.refine) == (KEYS["mesh.pattern"].default,
                                                       KEYS["mesh.refine"].default)
    assert scene.resolved["solver"] == {
        name: KEYS[f"solver.{name}"].default for name in ("method", "tol", "max_iter",
                                                          "linear")}
    contact = scene_from_dict({**BLOCK, "contact": {"gap": 0.0, "bonding": {"law": "none"}}})
    assert (contact.contact.quadrature, contact.contact.order, contact.contact.integrator) == (
        KEYS["contact.quadrature"].default, KEYS["contact.order"].default,
        KEYS["contact.bonding.integrator"].default)


@pytest.mark.parametrize("module", ["adhesive_contact.fem.meshes", "adhesive_contact.scene"])
def test_the_mesh_layer_and_the_scene_reader_import_alone(module):
    # the mesh layer raises SceneError and the reader uses the mesh layer's sides
    subprocess.run([sys.executable, "-c", f"import {module}"], check=True)
