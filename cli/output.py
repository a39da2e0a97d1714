"""The output folder of ``adhcontact solve`` (SPEC.md, "Command line").

:func:`write_outputs` writes every file into a temporary folder and then
moves it into place (:func:`_publish`), so a reader never sees a
half-written ``DIR`` and a user's own files in ``DIR`` are never touched:

- ``summary.json``: resolved scene, mesh counts, the smallness terms of
  MODEL.md §2 (null without contact), the warnings of the problem, timings,
  the estimated resources beside those used (``resources``), iterations
  and one record per time level (:func:`~.postprocess.step_records`);
- ``solution.npz``: points, cells, contact_facets, t, u, beta (firm keys);
- ``solution.xdmf`` + ``solution.h5``: time series for ParaView with point
  data u (3 components) and cell data stress (3×3 flattened) and von_mises
  (without h5py installed, the data is written inline in the XDMF file and
  there is no .h5);
- ``contact.xdmf`` + ``contact.h5``: the contact facets with cell data beta
  and point data u, one record per time level (only when the scene has
  contact facets);
- PNG plots (:mod:`.plots`).
"""

import glob
import os
import resource
import shutil
import tempfile
from pathlib import Path

import meshio
import numpy as np

from adhesive_contact.postprocess import stress_3x3, von_mises
from adhesive_contact.resources import estimate
from adhesive_contact.scheme import STEP_FAILED, STOPPED, SUCCESS
from adhesive_contact.storage import json_number, write_json

from . import plots
from .postprocess import smallness_record, step_records

CELL_TYPES = {2: "triangle", 3: "tetra"}
FACET_TYPES = {2: "line", 3: "triangle"}


class _XdmfSeriesWriter(meshio.xdmf.TimeSeriesWriter):
    """meshio's XDMF time-series writer with the HDF5 file beside the XDMF.

    meshio 5.3 opens ``Path(filename).stem + ".h5"`` relative to the current
    directory, not to the XDMF file; this writer opens it next to the XDMF
    file (the XDMF refers to it by base name, as the reader expects)."""

    def __enter__(self):
        if self.data_format != "HDF":
            return super().__enter__()
        import h5py

        self.h5_filename = str(self.filename.with_suffix(".h5"))
        self.h5_file = h5py.File(self.h5_filename, "w")
        return self


def pad_vectors(v):
    """Vectors (..., d) padded with zeros to (..., 3), as ParaView expects."""
    v = np.asarray(v, dtype=float)
    pad = [(0, 0)] * (v.ndim - 1) + [(0, 3 - v.shape[-1])]
    return np.pad(v, pad)


def _data_format():
    """"HDF" when h5py is installed (meshio needs it), else inline "XML"."""
    try:
        import h5py  # noqa: F401
    except ImportError:
        return "XML"
    return "HDF"


def summary(solution):
    """The ``summary.json`` document (a dict of plain JSON types)."""
    problem = solution.problem
    mesh, boundary = problem.mesh, problem.boundary
    return {
        "scene": problem.scene.resolved,
        "mesh": {
            "nodes": int(mesh.p.shape[1]),
            "cells": int(mesh.t.shape[1]),
            "dofs": int(problem.ndofs),
            "free_dofs": int(problem.free.size),
            "contact_facets": 0 if boundary is None else int(boundary.facets.size),
            "contact_nodes": 0 if boundary is None else int(boundary.nodes.size),
        },
        "run": run_record(solution),
        "smallness": smallness_record(problem),
        "warnings": [str(w) for w in problem.warnings()],
        "timings": {key: json_number(value) for key, value in solution.timings.items()},
        "linear": dict(solution.linear),
        "resources": resources_record(solution),
        "iterations": [int(i) for i in solution.iterations],
        "steps": step_records(solution),
    }


def resources_record(solution):
    """The estimate made from the scene before the run
    (:func:`adhesive_contact.resources.estimate`) beside what was used."""
    problem = solution.problem
    return {
        "estimate": estimate(problem.scene).record(),
        "used": {"dofs": int(problem.ndofs), "contact_unknowns": int(problem.columns.size),
                 "levels": int(solution.t.size), "backend": solution.linear.get("method"),
                 "seconds": json_number(solution.timings.get("total", float("nan"))),
                 "peak_memory_bytes": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
                 * 1024},
    }


def run_record(solution):
    """How the run ended: ``{"success", "status", "partial", "levels",
    "message", "failed_step", "failed_t"}``. ``status`` is "complete", "step
    failed" or "interrupted"; a partial run holds ``levels`` = M + 1 < N + 1
    time levels, those before the failure or the interruption."""
    failure = solution.failure
    return {
        "success": bool(solution.success),
        "status": {SUCCESS: "complete", STEP_FAILED: "step failed",
                   STOPPED: "interrupted"}[solution.status],
        "partial": bool(solution.t.size < solution.problem.times.size),
        "levels": int(solution.t.size),
        "message": " ".join(solution.message.split()),
        "failed_step": None if failure is None else int(failure.n),
        "failed_t": None if failure is None else json_number(failure.t),
    }


def write_summary(solution, path):
    """Write ``summary.json`` (strict JSON: no NaN or infinity)."""
    write_json(path, summary(solution))


def contact_facets(problem):
    """Node indices (nf, d) of the contact facets ((0, d) without Γ_C)."""
    d = problem.mesh.dim()
    if problem.boundary is None:
        return np.zeros((0, d), dtype=np.int64)
    return problem.boundary.facet_nodes.T.astype(np.int64)


def write_npz(solution, path):
    """Write ``solution.npz`` with exactly the firm keys of SPEC.md."""
    problem = solution.problem
    np.savez_compressed(
        path,
        points=problem.mesh.p.T,
        cells=problem.mesh.t.T.astype(np.int64),
        contact_facets=contact_facets(problem),
        t=solution.t,
        u=solution.u,
        beta=solution.beta,
    )


def write_xdmf(solution, folder):
    """Write the ParaView time series; return the names of the files written."""
    problem = solution.problem
    mesh = problem.mesh
    d = mesh.dim()
    points = mesh.p.T
    fmt = _data_format()
    h5 = fmt == "HDF"
    names = ["solution.xdmf"] + ["solution.h5"] * h5
    with _XdmfSeriesWriter(Path(folder) / names[0], fmt) as writer:
        writer.write_points_cells(points, [(CELL_TYPES[d], mesh.t.T)])
        for n, t in enumerate(solution.t):
            writer.write_data(
                float(t),
                point_data={"u": pad_vectors(solution.u[n])},
                cell_data={"stress": [stress_3x3(solution, n).reshape(-1, 9)],
                           "von_mises": [von_mises(stress_3x3(solution, n))]})
    if problem.boundary is not None and problem.boundary.facets.size:
        names += ["contact.xdmf"] + ["contact.h5"] * h5
        with _XdmfSeriesWriter(Path(folder) / "contact.xdmf", fmt) as writer:
            writer.write_points_cells(points, [(FACET_TYPES[d], contact_facets(problem))])
            for n, t in enumerate(solution.t):
                writer.write_data(float(t), point_data={"u": pad_vectors(solution.u[n])},
                                  cell_data={"beta": [solution.beta[n]]})
    return names


#: every file name ``adhcontact solve`` may write; in an existing folder a
#: run replaces these and touches nothing else
OUTPUT_NAMES = frozenset(
    ["summary.json", "solution.npz", "solution.xdmf", "solution.h5", "contact.xdmf",
     "contact.h5"] + [f"{name}.png" for name in plots.PLOT_NAMES])


def _publish(staging, target):
    """Move the files of folder ``staging`` into ``target``.

    A new ``target`` is ``staging`` renamed, in one step. Into an existing
    folder the files are moved one by one with :func:`os.replace` (each
    atomic), ``summary.json`` last and the previous ``summary.json`` removed
    first, so a folder with a ``summary.json`` always holds one whole run;
    outputs of a previous run that this run does not write are removed;
    any other file in ``target`` is left alone."""
    if not target.exists():
        os.chmod(staging, 0o755)  # mkdtemp makes it private
        os.rename(staging, target)
        return
    names = {p.name for p in staging.iterdir()}
    (target / "summary.json").unlink(missing_ok=True)
    for name in sorted(names - {"summary.json"}) + ["summary.json"]:
        os.replace(staging / name, target / name)
    for name in OUTPUT_NAMES - names:
        (target / name).unlink(missing_ok=True)
    staging.rmdir()


def _alive(pid):
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except OSError:       # another user's process: alive
        return True
    return True


def remove_stale(folder, prefix):
    """Remove the staging folders ``<prefix><pid>-XXXX`` in ``folder`` left by
    runs that were killed (their process ``pid`` no longer exists); return
    their names. A staging folder of a live run, or one named otherwise,
    stays."""
    removed = []
    for path in Path(folder).glob(f"{glob.escape(prefix)}*-*"):
        pid = path.name[len(prefix):].split("-", 1)[0]
        if path.is_dir() and pid.isdigit() and not _alive(int(pid)):
            shutil.rmtree(path, ignore_errors=True)
            removed.append(path.name)
    return removed


def write_outputs(solution, out, failures=None):
    """Write all outputs of a solve into folder ``out``, atomically.

    Parameters
    ----------
    solution : adhesive_contact.Solution
    out : path of the output folder; its parents are created. In an
        existing folder only the files of :data:`OUTPUT_NAMES` are replaced
        (see :func:`_publish`); a user's other files stay. The files are
        staged in a folder named after this process (``<out>.tmp-<pid>-*``
        beside a new ``out``, ``.adhcontact.tmp-<pid>-*`` inside an existing
        one); those of killed runs are removed first (:func:`remove_stale`).

    Returns
    -------
    list of str : the names of the files written, sorted.

    A plot that cannot be drawn is left out and named in ``failures`` (a
    list), if given; the data files are written all the same.
    """
    out = Path(out).absolute()
    if out.is_dir():   # staged inside, so that os.replace stays on one file system
        remove_stale(out, ".adhcontact.tmp-")
        tmp = Path(tempfile.mkdtemp(prefix=f".adhcontact.tmp-{os.getpid()}-", dir=out))
    else:
        out.parent.mkdir(parents=True, exist_ok=True)
        remove_stale(out.parent, f"{out.name}.tmp-")
        tmp = Path(tempfile.mkdtemp(prefix=f"{out.name}.tmp-{os.getpid()}-", dir=out.parent))
    try:
        write_summary(solution, tmp / "summary.json")
        write_npz(solution, tmp / "solution.npz")
        write_xdmf(solution, tmp)
        plots.write_plots(solution, tmp, failures)
        names = sorted(p.name for p in tmp.iterdir())
        _publish(tmp, out)
    except BaseException:
        shutil.rmtree(tmp, ignore_errors=True)
        raise
    return names
