"""Shared helpers for the tests: scene documents built from small changes
to a base (``scene_dict``) and written as TOML for the command line
(``to_toml``); run a scene through the library, and build the independent
reference quantities (meshes, stiffness, loads) straight from scikit-fem.

Nothing here calls the library's assembly, load map or contact boundary:
the references must not share code with what they check.
"""

import copy
import json
import re

import matplotlib
import numpy as np
import pytest
from skfem import (
    Basis,
    ElementTriP1,
    ElementVector,
    FacetBasis,
    LinearForm,
    MeshQuad,
    MeshTri,
    asm,
)
from skfem.models.elasticity import lame_parameters, linear_elasticity

from adhesive_contact import build_problem, parse_scene, scene_from_dict, solve

# the tests draw figures into files and read them: no display, whatever the
# machine has (the library chooses no backend, tests/test_visuals.py)
matplotlib.use("Agg")

# ---------------------------------------------------------------- scene documents

#: a 2 × 0.5 strip of 16 × 4 cells clamped on top, Γ_C at the bottom, one step
BLOCK = {
    "dim": 2,
    "mesh": {"domain": "rectangle", "size": [2.0, 0.5], "cells": [16, 4]},
    "boundary": {"dirichlet": ["top"], "contact": ["bottom"]},
    "material": {"E": 1000.0, "nu": 0.3},
    "time": {"T": 1.0, "steps": 1},
}

#: the value of a change that removes the key
DELETE = object()


def scene_dict(changes=None, base=BLOCK):
    """A scene document: a copy of ``base`` with ``changes`` applied.

    ``changes`` maps dotted keys to values, in order: ``{"mesh.cells": [8, 4],
    "contact.normal": law("compliance", c=5.0), "loads": DELETE}`` sets
    ``mesh.cells``, sets the whole [contact.normal] table (creating
    [contact]) and removes [loads].
    """
    data = copy.deepcopy(base)
    for dotted, value in (changes or {}).items():
        *head, last = dotted.split(".")
        table = data
        for key in head:
            table = table.setdefault(key, {})
        if value is DELETE:
            del table[last]
        else:
            table[last] = copy.deepcopy(value)
    return data


def law(name, **params):
    """A law table {"law": name, **params}."""
    return {"law": name, **params}


def prony(*terms):
    """A [memory] table of Prony terms given as (E, nu, tau)."""
    return {"kernel": "prony",
            "terms": [{"E": E, "nu": nu, "tau": tau} for E, nu, tau in terms]}


def wall_block(steps=3):
    """The 8 × 4 block of the study tests, hanging from its top, pulled down
    onto a compliant layer (c = 5000) and a wall with a gap smallest in the
    middle; with one Newton iteration allowed it fails at step 1."""
    return scene_dict({
        "title": "test block",
        "mesh": {"domain": "rectangle", "size": [2.0, 1.0], "cells": [8, 4]},
        "memory": prony((200.0, 0.3, 0.5)),
        "loads": {"body": ["0", "-400*t"]},
        "contact": {"gap": "0.002 + 0.01*(x - 1)**2", "normal": law("compliance", c=5000.0)},
        "time.steps": steps,
    })


def assert_one_line_error(result, code, needle, alone=True):
    """A command that ended with exit ``code`` and one ``error: ...`` line
    containing ``needle``, no traceback; ``alone``: nothing else on stderr
    (else warnings may come before the error)."""
    assert result.exit_code == code, (result.stdout, result.stderr)
    lines = result.stderr.strip().splitlines()
    errors = [line for line in lines if line.startswith("error: ")]
    assert len(errors) == 1 and (len(lines) == 1 or not alone), result.stderr
    assert needle in errors[0], errors[0]
    assert "Traceback" not in result.stderr + result.stdout


def glued_contact(gap=0.05):
    """The [contact] table of the glued strip: adhesive compliance, slip
    weakening and an adhesive spring, Frémond bonding, a wall at ``gap``."""
    return {"gap": gap,
            "normal": law("adhesive_compliance", c=1e4, gamma=5e3, L=0.01),
            "friction": [law("nonmonotone", a=2.0, b=1.0, alpha=50.0),
                         law("adhesive_spring", gamma=2e3, L=0.01)],
            "bonding": {"law": "fremond", "beta0": 1.0, "gamma_nu": 1e5,
                        "gamma_tau": 5e4, "eps_a": 0.0, "L": 0.01}}


def to_toml(data):
    """The TOML text of a scene document (tomllib reads, but cannot write).

    Tables become ``[a.b]`` sections, lists of tables ``[[a.b]]`` ones; the
    values are strings, numbers, booleans and lists of them.
    """
    lines = []
    _write_table(lines, data, ())
    return "\n".join(lines).strip() + "\n"


def _is_tables(value):
    return isinstance(value, list) and value and all(isinstance(v, dict) for v in value)


def _write_table(lines, table, path, header=None):
    if header:
        lines += ["", header]
    for key, value in table.items():
        if not isinstance(value, dict) and not _is_tables(value):
            lines.append(f"{_toml_key(key)} = {_toml_value(value)}")
    for key, value in table.items():
        name = ".".join(_toml_key(k) for k in path + (key,))
        if isinstance(value, dict):
            _write_table(lines, value, path + (key,), f"[{name}]")
        elif _is_tables(value):
            for item in value:
                _write_table(lines, item, path + (key,), f"[[{name}]]")


def _toml_key(key):
    return key if re.fullmatch(r"[A-Za-z0-9_-]+", key) else json.dumps(key)


def _toml_value(value):
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, (int, float)):
        return repr(value)
    if isinstance(value, str):
        return json.dumps(value)      # a TOML basic string
    if isinstance(value, list):
        return "[" + ", ".join(_toml_value(v) for v in value) + "]"
    raise TypeError(f"no TOML value for {value!r}")


def run(scene):
    """(problem, solution) of a scene document, or of its TOML text."""
    scene = parse_scene(scene) if isinstance(scene, str) else scene_from_dict(scene)
    problem = build_problem(scene)
    return problem, solve(problem)


def reference_mesh(size, cells, pattern="diagonal"):
    """The structured rectangle mesh, built here with named sides."""
    xs = np.linspace(0.0, size[0], cells[0] + 1)
    ys = np.linspace(0.0, size[1], cells[1] + 1)
    if pattern == "cross":
        mesh = MeshQuad.init_tensor(xs, ys).to_meshtri(style="x")
    else:
        mesh = MeshTri.init_tensor(xs, ys)
    L, H = size
    return mesh.with_boundaries({
        "left": lambda x: np.isclose(x[0], 0.0),
        "right": lambda x: np.isclose(x[0], L),
        "bottom": lambda x: np.isclose(x[1], 0.0),
        "top": lambda x: np.isclose(x[1], H),
    })


def same_mesh(problem, mesh):
    """Assert the library's mesh is ours (same vertices, same order), so that
    nodal vectors can be compared entry by entry."""
    assert problem.mesh.p.shape == mesh.p.shape
    np.testing.assert_allclose(problem.mesh.p, mesh.p, rtol=0, atol=1e-14)


def vector_basis(mesh, intorder=6):
    return Basis(mesh, ElementVector(ElementTriP1()), intorder=intorder)


def stiffness(mesh, E=None, nu=None, lam=None, mu=None):
    """Plane-strain P1 stiffness from scikit-fem's own elasticity model."""
    if lam is None:
        lam, mu = lame_parameters(E, nu)
    return asm(linear_elasticity(lam, mu), vector_basis(mesh, intorder=2)).tocsr()


def load_vector(mesh, body=None, traction=None, intorder=6):
    """⟨f, v⟩ = (f_0, v)_Ω + Σ_sides (f_N, v)_side with f_0 = body(x, y) and
    traction = {side: f(x, y)}, each a callable returning a pair of arrays.
    The rule of order ``intorder`` is exact for the polynomial loads used in
    the tests (degree ≤ 3 times P1)."""
    basis = vector_basis(mesh, intorder)
    f = np.zeros(basis.N)
    if body is not None:
        @LinearForm
        def lf(v, w):
            fx, fy = body(w.x[0], w.x[1])
            return fx * v[0] + fy * v[1]
        f += asm(lf, basis)
    for side, func in (traction or {}).items():
        fb = FacetBasis(mesh, basis.elem, facets=mesh.boundaries[side], intorder=intorder)

        @LinearForm
        def lt(v, w, func=func):
            fx, fy = func(w.x[0], w.x[1])
            return fx * v[0] + fy * v[1]
        f += asm(lt, fb)
    return f


def clamped_dofs(mesh, sides):
    basis = vector_basis(mesh, 2)
    return np.unique(np.concatenate([basis.get_dofs(mesh.boundaries[s]).all() for s in sides]))


def relative_max(a, b):
    """max|a − b| / max|b|."""
    return np.abs(np.asarray(a) - np.asarray(b)).max() / np.abs(np.asarray(b)).max()


@pytest.fixture
def rng():
    return np.random.default_rng(20240611)


def runner():
    """A click CliRunner keeping stderr apart (click >= 8.2 always does)."""
    import inspect

    from click.testing import CliRunner

    if "mix_stderr" in inspect.signature(CliRunner).parameters:
        return CliRunner(mix_stderr=False)
    return CliRunner()


#: a block on a compliant foundation, loaded down in time (two steps)
COMPLIANT_BLOCK = scene_dict({"title": "block", "mesh.cells": [4, 2],
                              "loads.body": ["0", "-10*t"],
                              "contact.normal": law("compliance", c=100.0), "time.steps": 2})


def invoke(*args):
    """``adhcontact ARGS`` in this process (click's runner)."""
    from adhesive_contact_cli.main import main
    from click.testing import CliRunner

    return CliRunner().invoke(main, [str(a) for a in args])


def solve_scene(tmp_path, data, *extra):
    """``adhcontact solve`` of a scene (TOML text or a dict) into tmp_path/out."""
    scene = tmp_path / "scene.toml"
    scene.write_text(data if isinstance(data, str) else to_toml(data))
    out = tmp_path / "out"
    return invoke("solve", scene, "--out", out, *extra), out


def assert_refused(result, out, needle):
    """Exit 2, one line "error: ..." holding ``needle``, and nothing written."""
    lines = result.stderr.strip().splitlines()
    assert result.exit_code == 2, (result.stderr, result.exception)
    assert len(lines) == 1 and lines[0].startswith("error: ") and needle in lines[0], lines
    assert not out.exists()


@pytest.fixture
def counting(monkeypatch):
    """Count the calls of run_level (by level) and run_reference that a
    convergence study makes (adhesive_contact.studies.convergence)."""
    from types import SimpleNamespace

    import adhesive_contact.studies.convergence as converge_module

    calls = SimpleNamespace(levels=[], reference=0)
    real_level, real_reference = converge_module.run_level, converge_module.run_reference

    def run_level(scene, param, level, reference=None, **kwargs):
        calls.levels.append(level)
        return real_level(scene, param, level, reference, **kwargs)

    def run_reference(*args, **kwargs):
        calls.reference += 1
        return real_reference(*args, **kwargs)

    monkeypatch.setattr(converge_module, "run_level", run_level)
    monkeypatch.setattr(converge_module, "run_reference", run_reference)
    return calls


#: the standard linear solid of the held-strain tests: E_∞ + E_1 e^{−t/τ}, τ = 1, ν = 0
SLS_E_INF, SLS_E_1, SLS_STRAIN = 500.0, 500.0, 1e-3


def held_strain_run(steps, T, scheme, adaptive=None):
    """A 4 × 1 bar of the standard linear solid SLS_* stretched by SLS_STRAIN
    at t = 0 and held to T in ``steps`` steps of ``time.scheme`` (with
    ``adaptive`` as [time.adaptive], k_max = T/steps): the solution (σ_xx
    is uniform in every cell)."""
    time = {"T": T, "steps": steps, "scheme": scheme}
    if adaptive is not None:
        time["adaptive"] = adaptive
    _, solution = run(scene_dict({
        "mesh.size": [4.0, 1.0], "mesh.cells": [4, 1],
        "boundary": {"dirichlet": [], "displacement": {
            "left": ["0", "free"], "right": [repr(4.0 * SLS_STRAIN), "free"],
            "bottom": ["free", "0"]}},
        "material": DELETE,
        "memory": {"kernel": "relaxation", "long_term": {"E": SLS_E_INF, "nu": 0.0},
                   "terms": [{"E": SLS_E_1, "tau": 1.0}]},
        "time": time}))
    return solution


#: the start of a script run in a subprocess that SIGKILLs itself at move
#: number ``sys.argv[2]`` (os.replace and os.rename counted from 0) and
#: imports ``adhesive_contact.folders`` alone (it needs storage.py only: the
#: package's slow __init__ is skipped); ``target`` is ``sys.argv[1]``, and
#: ``calls[0]`` counts the moves made
KILL_AT_MOVE = """
import importlib.util, json, os, signal, sys, types
package = types.ModuleType("adhesive_contact")
package.__path__ = importlib.util.find_spec("adhesive_contact").submodule_search_locations
sys.modules["adhesive_contact"] = package
from adhesive_contact import folders
target, kill_at = sys.argv[1], int(sys.argv[2])
calls = [0]
def counted(real):
    def move(*args, **kwargs):
        if calls[0] == kill_at:
            os.kill(os.getpid(), signal.SIGKILL)
        calls[0] += 1
        return real(*args, **kwargs)
    return move
os.replace, os.rename = counted(os.replace), counted(os.rename)
"""


class Listener:
    """A loopback TCP listener that is no dask scheduler, started here and
    stopped by ``close()``: it accepts, sends ``data`` (nothing: silent, as
    an HTTP server waiting for a request is) and, with ``close``, closes the
    connection at once."""

    def __init__(self, data=b"", close=False):
        import socket
        import threading

        self.data, self.close_after, self.sockets = data, close, []
        self.server = socket.socket()
        self.server.bind(("127.0.0.1", 0))
        self.server.listen(8)
        self.address = f"tcp://127.0.0.1:{self.server.getsockname()[1]}"
        threading.Thread(target=self.serve, daemon=True).start()

    def serve(self):
        while True:
            try:
                conn, _ = self.server.accept()
            except OSError:
                return
            self.sockets.append(conn)
            try:
                if self.data:
                    conn.sendall(self.data)
                if self.close_after:
                    conn.close()
            except OSError:
                pass

    def close(self):
        self.server.close()
        for conn in self.sockets:
            conn.close()


def level_zero_input(problem, operators):
    """The StepInput of level 0 of ``problem`` (t = 0, β_0, no history, z = 0)
    on ``operators``, as the march builds it."""
    from adhesive_contact.scheme.state import StepInput, history_load, initial_state

    state = initial_state(problem)
    b, known = history_load(problem, operators, True, 0.0, None)
    gap = None if problem.gap is None else problem.gap.at(0.0)
    return StepInput(index=0, t=0.0, k=0.0, b=b, known=known, beta=state.beta, gap=gap,
                     gap_before=None, z0=state.z)
