"""A second fuzzing suite (hypothesis, derandomised: the same examples every
run), one generator per surface added since the first: mesh files,
prescribed displacements, memory kernels, foundations, ``--set`` values,
schedulers (loopback listeners the test starts and stops), output folders
under faults (a SIGKILL at a drawn file move, a drawn file-size limit) and
tampered output folders.

Each property is what the command line promises: a bad input is a
:class:`~adhesive_contact.SceneError` (or AssignmentError, ClusterError,
OutputFolderError: one line naming the key, the file or the address),
never another exception, a hang or a quiet wrong result; what is accepted
is usable (finite where the scheme reads it). The number of examples per
surface is :data:`EXAMPLES`.
"""

import json
import math
import shutil
import signal
import subprocess
import sys
import textwrap
import time

import distributed  # noqa: F401  (imported here, so that no timing below includes it)
import meshio
import numpy as np
import pytest
from conftest import DELETE, KILL_AT_MOVE, Listener, law, runner, scene_dict, to_toml
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from adhesive_contact import OutputFolderError, SceneError, build_problem, load_solution
from adhesive_contact import scene_from_dict
from adhesive_contact.folders import MARKER, recover
from adhesive_contact.problem.build import time_grid
from adhesive_contact.studies import ClusterError, dask_executor
from adhesive_contact_cli.assignments import AssignmentError, parse_assignment
from adhesive_contact_cli.main import main

#: examples per surface (a few minutes in all)
EXAMPLES = {"mesh files": 150, "displacements": 300, "memory": 150, "foundations": 300,
            "set": 500, "schedulers": 20, "kill at a move": 40, "file-size limit": 25,
            "tampered folders": 120}


def fuzz(surface):
    return settings(derandomize=True, database=None, deadline=None,
                    max_examples=EXAMPLES[surface], suppress_health_check=list(HealthCheck))


def one_line(err):
    text = str(err)
    assert text and "\n" not in text and "Traceback" not in text, text
    return text


BLOCK = scene_dict({"title": "fuzz", "mesh.cells": [4, 2], "loads.body": ["0", "-10*t"],
                    "contact.normal": law("compliance", c=100.0), "time.steps": 3})

# ---------------------------------------------------------------- mesh files

DEFECTS = st.fixed_dictionaries({
    "scale": st.sampled_from([1.0, 1e-300, 1e300, 1e-50, 1e50]),
    "nan": st.none() | st.integers(0, 14), "inf": st.none() | st.integers(0, 14),
    "sliver": st.booleans(), "out_of_range": st.booleans(),
    "empty_group": st.sampled_from([None, "top", "foot"]),
    "cut": st.none() | st.integers(0, 2000)})


def write_strip(path, defects):
    """A 2 x 1 strip of 16 triangles (15 nodes) as gmsh 2.2, with ``defects``."""
    nx, ny = 5, 3
    x, y = np.meshgrid(np.linspace(0, 2, nx), np.linspace(0, 1, ny), indexing="ij")
    p = np.column_stack([x.ravel(), y.ravel(), np.zeros(x.size)]) * defects["scale"]
    idx = np.arange(nx * ny).reshape(nx, ny)
    tri = [[idx[i, j], idx[i + 1, j], idx[i + 1, j + 1]] for i in range(nx - 1)
           for j in range(ny - 1)] + [[idx[i, j], idx[i + 1, j + 1], idx[i, j + 1]]
                                      for i in range(nx - 1) for j in range(ny - 1)]
    if defects["sliver"]:
        tri.append([idx[0, 0], idx[0, 1], idx[0, 2]])
    if defects["out_of_range"]:
        tri.append([0, 1, 99])
    top = [[idx[i, ny - 1], idx[i + 1, ny - 1]] for i in range(nx - 1)]
    foot = [[idx[i, 0], idx[i + 1, 0]] for i in range(nx - 1)]
    for key, value in (("nan", np.nan), ("inf", np.inf)):
        if defects[key] is not None:
            p[defects[key], 0] = value
    blocks = [("line", np.array(top)), ("line", np.array(foot)), ("triangle", np.array(tri))]
    tags = [np.full(len(b[1]), i + 1) for i, b in enumerate(blocks)]
    field = {"top": np.array([1, 1]), "foot": np.array([2, 1]), "body": np.array([3, 2])}
    if defects["empty_group"]:
        field[defects["empty_group"]] = np.array([9, 1])
    meshio.write(path, meshio.Mesh(p, blocks, cell_data={
        "gmsh:physical": tags, "gmsh:geometrical": tags}, field_data=field),
        file_format="gmsh22", binary=False)
    if defects["cut"] is not None:
        path.write_bytes(path.read_bytes()[:defects["cut"]])


@fuzz("mesh files")
@given(defects=DEFECTS)
def test_fuzz_mesh_files(tmp_path_factory, defects):
    folder = tmp_path_factory.mktemp("mesh")
    write_strip(folder / "m.msh", defects)
    scene = {"dim": 2, "mesh": {"domain": "file", "file": str(folder / "m.msh")},
             "boundary": {"dirichlet": ["top"], "contact": ["foot"]},
             "material": {"E": 1000.0, "nu": 0.3}, "time": {"T": 1.0, "steps": 1},
             "contact": {"normal": law("compliance", c=100.0)}}
    try:
        problem = build_problem(scene_from_dict(scene))
    except SceneError as err:
        assert one_line(err).startswith(("mesh.file: ", "boundary"))
        return
    # accepted: a usable mesh, with contact on the foot
    assert np.isfinite(problem.mesh.p).all() and problem.boundary.facets.size == 4
    assert not any(defects[k] is not None for k in ("nan", "inf", "cut", "empty_group"))
    assert not defects["sliver"] and not defects["out_of_range"]


# ---------------------------------------------------------------- displacements

ATOMS = st.sampled_from(["t", "x", "y", "0", "1", "0.5", "1e308", "1e-308", "(t - 0.5)",
                         "(x - 2)"])
EXPRESSIONS = st.recursive(ATOMS, lambda inner: st.one_of(
    st.tuples(inner, st.sampled_from(["+", "-", "*", "/", "**"]), inner).map(
        lambda a: f"({a[0]} {a[1]} {a[2]})"),
    st.tuples(st.sampled_from(["sqrt", "log", "exp", "sin", "abs"]), inner).map(
        lambda a: f"{a[0]}({a[1]})"),
    st.tuples(inner, inner, inner).map(lambda a: f"where(t > 0.5, {a[0]}, {a[1]} + {a[2]})")),
    max_leaves=6)


@fuzz("displacements")
@given(expression=EXPRESSIONS | st.sampled_from([math.inf, -math.inf, math.nan, 1e308]))
def test_fuzz_prescribed_displacements(expression):
    scene = scene_dict({"boundary.dirichlet": ["left"], "boundary.contact": [],
                        "contact": DELETE, "loads": DELETE,
                        "boundary.displacement": {"right": [expression, "free"]}}, BLOCK)
    try:
        problem = build_problem(scene_from_dict(scene))
    except SceneError as err:
        assert one_line(err).startswith(("boundary.displacement.right[0]: ", "boundary."))
        return
    # accepted: finite on every level the run uses
    for t in time_grid(problem.scene):
        assert np.isfinite(problem.prescribed.values(t)).all(), (expression, t)


# ---------------------------------------------------------------- memory kernels

MODULI = st.sampled_from([1e-300, 1e-3, 1.0, 900.0, 1e99, 1e101, 1e308])
TAUS = st.sampled_from([1e-300, 1e-6, 0.05, 0.5, 1.0, 1e6, 1e300])


@fuzz("memory")
@given(kernel=st.sampled_from(["prony", "relaxation"]),
       terms=st.lists(st.tuples(MODULI, st.sampled_from([0.0, 0.3, 0.49]), TAUS),
                      min_size=1, max_size=4),
       steps=st.sampled_from([1, 2, 3, 50]))
def test_fuzz_memory_kernels(kernel, terms, steps):
    memory = {"kernel": kernel,
              "terms": [{"E": E, "nu": nu, "tau": tau} for E, nu, tau in terms]}
    changes = {"memory": memory, "time.steps": steps}
    if kernel == "relaxation":
        memory["long_term"] = {"E": 100.0, "nu": 0.3}
        changes["material"] = DELETE
    scene = scene_dict(changes, BLOCK)
    try:
        problem = build_problem(scene_from_dict(scene))
    except SceneError as err:
        assert one_line(err).startswith(("memory.", "time.steps: "))
        return
    assert problem.ndofs > 0


# ---------------------------------------------------------------- foundations

COMPONENTS = st.sampled_from([0.0, 1.0, -1.0, 5e-324, 1e-170, 1e-300, 1e150, 1e308, 0.3])


@fuzz("foundations")
@given(shape=st.sampled_from(["plane", "sphere"]),
       vector=st.tuples(COMPONENTS, COMPONENTS), point=st.tuples(COMPONENTS, COMPONENTS),
       radius=st.sampled_from([1e-300, 0.5, 1.0, 1e99, 1e101, 1e200]))
def test_fuzz_foundations(shape, vector, point, radius):
    foundation = {"shape": shape, "point": [point[0], -abs(point[1]) - 0.01]}
    if shape == "plane":
        foundation["normal"] = list(vector)
    else:
        foundation["radius"] = radius
    scene = scene_dict({"contact.foundation": foundation}, BLOCK)
    try:
        problem = build_problem(scene_from_dict(scene))
    except SceneError as err:
        assert one_line(err).startswith(("contact.foundation.", "contact"))
        return
    gap = problem.gap.at(0.0)
    assert not np.isnan(gap).any() and (gap >= 0).all()   # +inf: no wall at that node


# ---------------------------------------------------------------- --set values

SET_TEXT = st.text(alphabet="[]{}\"',=.:0123456789aex+- ", max_size=60) | st.builds(
    lambda n, s: "title=" + "[" * n + s + "]" * n, st.integers(0, 5000), st.text(max_size=5))


@fuzz("set")
@given(text=SET_TEXT)
def test_fuzz_set_values(text):
    started = time.perf_counter()
    try:
        key, values = parse_assignment(text)
    except AssignmentError as err:
        one_line(err)
    else:
        assert key and values
        json.dumps(values)   # plain TOML values only
    assert time.perf_counter() - started < 2


# ---------------------------------------------------------------- schedulers


@fuzz("schedulers")
@given(data=st.binary(max_size=64), close=st.booleans())
def test_fuzz_schedulers(data, close):
    listener = Listener(data, close)
    try:
        started = time.monotonic()
        with pytest.raises(ClusterError) as info:
            dask_executor(listener.address, timeout=0.5)
        assert time.monotonic() - started < 1.5
        one_line(info.value)
    finally:
        listener.close()


# ---------------------------------------------------------------- output folders under faults

NAMES = ["summary.json", "solution.h5", "solution.npz", "beta.png", "contact_map.png"]
KILLED = KILL_AT_MOVE + textwrap.dedent("""
    new, limit = json.loads(sys.argv[3]), int(sys.argv[4])
    if limit:
        import resource
        resource.setrlimit(resource.RLIMIT_FSIZE, (limit, limit))
    try:
        with folders.staged_folder(target, {names!r}) as staging:
            for name, size in new.items():
                with open(staging / name, "wb") as f:
                    f.write((b"new " + name.encode()).ljust(size, b"."))
    except OSError as err:
        print("full:", err)
        sys.exit(1)
""").format(names=NAMES)

RUNS = st.lists(st.sampled_from(NAMES[1:]), unique=True).map(lambda n: ["summary.json"] + n)


def whole(folder, old, new):
    """Which run ``folder`` holds (None: no summary.json); fails if mixed."""
    files = {p.name: p.read_bytes() for p in folder.iterdir() if p.is_file()
             and p.name != "notes.txt"}
    assert (folder / "notes.txt").read_text() == "mine"
    if "summary.json" not in files:
        return None
    run = "new" if files["summary.json"].startswith(b"new") else "old"
    expected = new if run == "new" else old
    assert set(files) == set(expected), (files.keys(), expected)
    assert all(data.startswith(run.encode()) for data in files.values())
    return run


def run_killed(tmp, old, new, kill_at, limit=0):
    target = tmp / "out"
    target.mkdir()
    for name in old:
        (target / name).write_bytes(b"old " + name.encode())
    (target / "notes.txt").write_text("mine")
    return subprocess.run([sys.executable, "-c", KILLED, str(target), str(kill_at),
                           json.dumps(new), str(limit)], capture_output=True, text=True,
                          timeout=60), target


@fuzz("kill at a move")
@given(old=RUNS, new=RUNS.map(lambda n: n), kill_at=st.integers(0, 14))
def test_fuzz_a_kill_at_a_drawn_move(tmp_path_factory, old, new, kill_at):
    tmp = tmp_path_factory.mktemp("kill")
    child, target = run_killed(tmp, old, {n: 16 for n in new}, kill_at)
    assert child.returncode in (0, -signal.SIGKILL), child.stderr
    at_kill = whole(target, old, new)
    recover(target)
    after = whole(target, old, new)
    assert after in ("old", "new") and (at_kill != "new" or after == "new")
    assert not [p for p in tmp.rglob(MARKER)]
    if child.returncode == 0:
        assert after == "new"


@fuzz("file-size limit")
@given(old=RUNS, new=RUNS, limit=st.integers(1, 4096), size=st.integers(1, 8192))
def test_fuzz_a_drawn_file_size_limit(tmp_path_factory, old, new, limit, size):
    tmp = tmp_path_factory.mktemp("full")
    child, target = run_killed(tmp, old, {n: size for n in new}, 10**6, limit)
    assert child.returncode in (0, 1), child.stderr
    after = whole(target, old, new)
    if child.returncode == 1:   # the disk was full: nothing of the earlier run changed
        assert child.stdout.startswith("full:") and after == "old"
        assert "Traceback" not in child.stderr
    else:
        assert size <= limit and after == "new"
    assert not [p for p in tmp.rglob(MARKER)]


# ---------------------------------------------------------------- tampered output folders


@pytest.fixture(scope="module")
def solved(tmp_path_factory):
    folder = tmp_path_factory.mktemp("solved")
    (folder / "scene.toml").write_text(to_toml(BLOCK))
    result = runner().invoke(main, ["solve", str(folder / "scene.toml"), "--out",
                                    str(folder / "out"), "-q"])
    assert result.exit_code == 0, result.output
    return folder / "out"


ARRAYS = ["t", "u", "beta", "contact_force", "frame_displacement", "on_wall", "stuck",
          "probes", "iterations", "residual", "held_reaction", "stress_last",
          "stress_zz_last", "points"]
MUTATIONS = st.one_of(
    st.tuples(st.just("array"), st.sampled_from(ARRAYS),
              st.sampled_from(["drop last", "add axis", "strings", "objects", "float",
                               "bool", "empty", "same"])),
    st.tuples(st.just("summary"), st.sampled_from(["run", "steps", "scene", "source",
                                                   "schema"]),
              st.sampled_from(["delete", "null", "string", "nested", "same"])))


def mutate_array(array, how):
    if how == "drop last":
        return array[..., :-1] if array.ndim and array.shape[-1] else array[:0]
    if how == "add axis":
        return array[..., None]
    if how == "strings":
        return array.astype(str)
    if how == "objects":
        return np.array([None] * 3, dtype=object)
    if how == "float":
        return array.astype(float)
    if how == "bool":
        return array.astype(bool)
    if how == "empty":
        return np.zeros((0,))
    return array


@fuzz("tampered folders")
@given(mutation=MUTATIONS)
def test_fuzz_tampered_folders(solved, tmp_path_factory, mutation):
    copy = tmp_path_factory.mktemp("tampered") / "out"
    shutil.copytree(solved, copy)
    kind, key, how = mutation
    if kind == "array":
        with np.load(copy / "solution.npz", allow_pickle=True) as data:
            arrays = {name: data[name] for name in data.files}
        arrays[key] = mutate_array(arrays[key], how)
        np.savez(copy / "solution.npz", **arrays)
    else:
        document = json.loads((copy / "summary.json").read_text())
        if how == "delete":
            document.pop(key, None)
        elif how != "same":
            document[key] = {"null": None, "string": "x", "nested": [[[[]]]]}[how]
        (copy / "summary.json").write_text(json.dumps(document))
    try:
        solution = load_solution(copy)
    except OutputFolderError as err:
        assert one_line(err).startswith(str(copy))
        return
    # accepted: the same solution as the untouched folder
    original = load_solution(solved)
    for name in ("t", "beta", "contact_force", "on_wall", "iterations"):
        np.testing.assert_array_equal(getattr(solution, name), getattr(original, name))
    np.testing.assert_array_equal(solution.u[-1], original.u[-1])
