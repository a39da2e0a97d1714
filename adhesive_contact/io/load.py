"""A finished output folder of ``adhcontact solve`` read back as the
:class:`~adhesive_contact.Solution` that :func:`adhesive_contact.solve`
returns (docs/python.md, "Reading an output folder").

``summary.json`` gives how the run ended, its timings and linear backend,
and the scene's text, from which the problem is rebuilt (or the caller
gives the problem); ``solution.npz`` gives every array
(:mod:`.npz`). The stress is that of the last level only, as with the
:class:`~.streaming.StreamingRecorder` the command line solves with.
"""

import contextlib
import json
import zipfile
from pathlib import Path

import numpy as np

from ..scheme import Solution
from ..storage import plain
from .errors import OutputFolderError
from .npz import SOLUTION_KEYS
from .summary import STATUS_CODES, read_summary

#: the kinds of numpy dtype each kind of array may have ("f" floats, "b"
#: booleans, "i" integers; integers may stand for floats)
KINDS = {"f": "fiu", "b": "b", "i": "iu", "U": "U"}
KIND_NAMES = {"f": "float", "b": "bool", "i": "int", "U": "str"}


def array_headers(path, names):
    """{name: (shape, dtype)} of the arrays ``names`` in the npz file
    ``path``, read from their headers alone (nothing is allocated)."""
    headers = {}
    with zipfile.ZipFile(path) as archive:
        members = set(archive.namelist())
        for name in names:
            if f"{name}.npy" not in members:
                continue
            with archive.open(f"{name}.npy") as f:
                version = np.lib.format.read_magic(f)
                read = (np.lib.format.read_array_header_1_0 if version == (1, 0) else
                        np.lib.format.read_array_header_2_0)
                shape, _, dtype = read(f)
            headers[name] = (tuple(shape), dtype)
    return headers


def read_arrays(path, names, expected=None):
    """{name: array} of ``names`` from the npz file ``path``.

    ``expected``: {name: (shape, kind)} checked against each array's header
    before it is read (:data:`KINDS`); an array of another shape or kind
    is an :class:`OutputFolderError` naming it, and nothing is allocated."""
    with npz_errors(path):
        headers = array_headers(path, names)
        missing = [name for name in names if name not in headers]
        if missing:
            raise OutputFolderError(path, f"has no {missing[0]!r}: it was written by an "
                                    "older version; run the scene again to read it back")
        for name, (shape, kind) in (expected or {}).items():
            found, dtype = headers[name]
            if dtype.kind not in KINDS[kind] or dtype.hasobject:
                raise OutputFolderError(path, f"holds {name!r} of dtype {dtype}, not "
                                        f"{KIND_NAMES[kind]}: "
                                        "the file is damaged; run the scene again")
            if found != shape:
                raise OutputFolderError(path, f"holds {name!r} of shape {found}, not {shape} "
                                        "(of the problem and summary.json's run): the file "
                                        "is damaged; run the scene again")
        with np.load(path, allow_pickle=False) as data:
            return {name: data[name] for name in names}


@contextlib.contextmanager
def npz_errors(path):
    """A block reading the npz file ``path``: a missing or unreadable file
    is an :class:`OutputFolderError` naming it."""
    try:
        yield
    except FileNotFoundError:
        raise OutputFolderError(path, "no such file; an output folder of 'adhcontact solve' "
                                "has one (docs/outputs.md)") from None
    except (OSError, ValueError, EOFError, zipfile.BadZipFile) as err:
        raise OutputFolderError(path, f"cannot be read ({type(err).__name__}: {err}): the "
                                "file is damaged; run the scene again") from None


def rebuild_problem(path, document):
    """The problem of the scene text that summary.json (at ``path``) keeps."""
    from ..problem.build import build_problem
    from ..scene import SceneError, parse_scene

    source = document.get("source")
    if not isinstance(source, dict) or not isinstance(source.get("text"), str):
        raise OutputFolderError(path, "keeps no scene text (written by an older version); "
                                "pass problem=build_problem(load_scene(...)) of its scene")
    try:
        return build_problem(parse_scene(source["text"], source.get("folder")))
    except SceneError as err:
        raise OutputFolderError(path, f"its scene cannot be built here: {err}") from None


def _differing_key(a, b, prefix=""):
    """The first dotted key where two JSON documents differ (None if equal)."""
    if isinstance(a, dict) and isinstance(b, dict):
        for key in sorted(set(a) | set(b)):
            found = _differing_key(a.get(key), b.get(key), f"{prefix}{key}.")
            if found:
                return found
        return None
    return None if a == b else prefix.rstrip(".") or "scene"


def expected_arrays(problem, levels, with_fields=None):
    """{name: (shape, kind)} of the arrays of solution.npz for ``problem``
    and a run of ``levels`` time levels (:func:`read_arrays`), u at
    ``with_fields`` levels of them (default: every one)."""
    mesh, boundary, d = problem.mesh, problem.boundary, problem.dim
    npoints, ncells = mesh.p.shape[1], mesh.t.shape[1]
    nc = 0 if boundary is None else boundary.nodes.size
    nf = 0 if boundary is None else boundary.facets.size
    nprobes = 0 if problem.probe_map is None else problem.probe_map.shape[0]
    L = levels
    held = L if with_fields is None else with_fields
    shapes = {"points": ((npoints, d), "f"), "t": ((L,), "f"), "u": ((held, npoints, d), "f"),
              "beta": ((L, nf), "f"), "contact_force": ((L, nc, d), "f"),
              "frame_displacement": ((L, nc, d), "f"), "on_wall": ((L, nc), "b"),
              "stuck": ((L, nc), "b"), "probes": ((L, nprobes, d), "f"),
              "iterations": ((L,), "i"), "residual": ((L,), "f"),
              "held_reaction": ((L, problem.prescribed.fixed.size), "f"),
              "stress_last": ((ncells, d, d), "f")}
    if d == 2:
        shapes["stress_zz_last"] = ((ncells,), "f")
    return shapes


def load_solution(folder, problem=None):
    """The :class:`~adhesive_contact.Solution` of an output folder of
    ``adhcontact solve``.

    Parameters
    ----------
    folder : path of the folder (``summary.json`` and ``solution.npz``)
    problem : Problem, optional
        The problem that was solved; by default it is rebuilt from the scene
        text kept in ``summary.json`` (a relative ``mesh.file`` is taken in
        the scene file's folder, as when it was run). It must be of the
        scene ``summary.json`` records.

    Returns
    -------
    Solution
        As :func:`adhesive_contact.solve` returned it: t, u, beta,
        contact_force, frame_displacement, on_wall, stuck, probes,
        iterations, residual, reaction per level; status, message, timings,
        linear. ``stress`` (and ``stress_zz`` in 2D) holds the last level
        only, shape (1, ...); ``failure`` is None (the failed step and its
        time are ``message`` and summary.json's ``run``).

    Raises
    ------
    OutputFolderError
        A file is missing, damaged, of another layout or of another scene
        than ``problem``; the message names the file.
    """
    folder = Path(folder)
    summary_path, npz_path = folder / "summary.json", folder / "solution.npz"
    document = read_summary(summary_path)
    if problem is None:
        problem = rebuild_problem(summary_path, document)
    recorded = json.loads(json.dumps(plain(problem.scene.resolved)))
    key = _differing_key(recorded, document["scene"])
    if key:
        raise OutputFolderError(summary_path, f"records another scene than the problem's "
                                f"(they differ at {key})")
    names = ("points", "t", "u", "beta", "held_reaction", "stress_last") + SOLUTION_KEYS
    names += ("stress_zz_last",) if problem.dim == 2 else ()
    run = document["run"]
    levels = run.get("levels") if isinstance(run, dict) else None
    if not isinstance(run, dict) or run.get("status") not in STATUS_CODES or \
            not isinstance(levels, int) or isinstance(levels, bool) or levels < 0:
        raise OutputFolderError(summary_path, "its run record is damaged (run.status, "
                                "run.levels); run the scene again")
    field_levels, scalars = _fields_and_scalars(npz_path, levels)
    arrays = read_arrays(npz_path, names, expected_arrays(
        problem, levels, None if field_levels is None else field_levels.size))
    if not np.array_equal(arrays["points"], problem.mesh.p.T):
        raise OutputFolderError(npz_path, "holds another mesh than the problem's")
    zz = arrays.get("stress_zz_last")
    gap = None if problem.gap is None else problem.gap.levels(arrays["t"])
    return Solution(
        problem=problem, status=STATUS_CODES[run["status"]], message=run["message"], failure=None,
        t=arrays["t"], u=arrays["u"], beta=arrays["beta"],
        stress=arrays["stress_last"][None], stress_zz=None if zz is None else zz[None],
        contact_force=arrays["contact_force"],
        frame_displacement=arrays["frame_displacement"], on_wall=arrays["on_wall"],
        stuck=arrays["stuck"], probes=arrays["probes"], iterations=arrays["iterations"],
        residual=arrays["residual"], reaction=arrays["held_reaction"], gap=gap,
        timings={k: (float("nan") if v is None else v)
                 for k, v in document.get("timings", {}).items()},
        linear=dict(document.get("linear", {})), adaptive=document.get("adaptive"),
        field_levels=field_levels, scalars=scalars)


#: the optional arrays of solution.npz: the levels with fields and the
#: scalars of every level (written since [output] every)
OPTIONAL = ("u_levels", "scalar_names", "scalar_kinds", "scalar_values")


def _fields_and_scalars(path, levels):
    """(field levels, scalars) of solution.npz at ``path`` for a run of
    ``levels`` levels: the levels whose u it holds (None: every level) and
    {name: (kind, values)} of its scalars (None when not recorded)."""
    with npz_errors(path):
        headers = array_headers(path, OPTIONAL)
    if "u_levels" not in headers:
        return None, None
    count = headers["u_levels"][0]
    names = headers.get("scalar_names", ((0,), None))[0]
    expected = {"u_levels": (count, "i")}
    if "scalar_values" in headers:
        expected.update(scalar_names=(names, "U"), scalar_kinds=(names, "U"),
                        scalar_values=((levels, *names), "f"))
    arrays = read_arrays(path, tuple(expected), expected)
    field_levels = np.asarray(arrays["u_levels"], dtype=np.int64)
    if field_levels.size and (np.any(np.diff(field_levels) <= 0) or field_levels[0] < 0
                              or field_levels[-1] >= levels):
        raise OutputFolderError(path, f"holds 'u_levels' that are not increasing levels "
                                f"of the run's {levels}: the file is damaged; run the scene "
                                "again")
    if field_levels.size == levels:
        field_levels = None   # every level
    scalars = None
    if "scalar_values" in arrays:
        values = arrays["scalar_values"]
        scalars = {str(name): (str(kind), values[:, i]) for i, (name, kind) in
                   enumerate(zip(arrays["scalar_names"], arrays["scalar_kinds"]))}
    return field_levels, scalars
