"""The output folder of ``adhcontact solve`` (docs/outputs.md).

:func:`staged_output` gives a staging folder that the run writes into
and then publishes into place (:mod:`adhesive_contact.folders`), so a
folder that held a whole run holds it or the new whole run whatever
happens, and a user's own files in ``DIR`` are never touched.
The run streams its levels there as they are computed
(:class:`adhesive_contact.io.StreamingRecorder`); :func:`write_results`
adds the rest:

- ``summary.json``: resolved scene, mesh counts, how the run ended, the
  smallness terms (null without contact), the warnings of the problem,
  timings, the linear backend, the estimated resources beside those used
  (``resources``), iterations and one record per time level
  (:func:`~.summary.step_records`);
- ``solution.npz``: points, cells, contact_facets, t, u, beta (firm keys);
- ``solution.xdmf`` + ``solution.h5`` and ``contact.xdmf`` + ``contact.h5``
  (:mod:`adhesive_contact.io.xdmf`), written by the recorder;
- PNG plots (:func:`adhesive_contact.visuals.write_plots`).
"""

import contextlib
import resource
from pathlib import Path

from adhesive_contact.folders import staged_folder
from adhesive_contact.io import write_npz, write_xdmf
from adhesive_contact.postprocess import energies
from adhesive_contact.problem.warnings import solution_warnings
from adhesive_contact.resources import estimate
from adhesive_contact.scheme import STEP_FAILED, STOPPED, SUCCESS
from adhesive_contact.storage import json_number, read_json, write_json
from adhesive_contact.visuals import PLOT_NAMES, write_plots

from .summary import energy_record, smallness_record, step_records

#: the version of summary.json's layout (docs/outputs.md): raised when a key
#: changes meaning or goes; new keys do not change it
SCHEMA = 2


def summary(solution, source=None, history=None, lines=None):
    """The ``summary.json`` document (a dict of plain JSON types).

    ``source``: ``{"text", "folder"}``, the scene's TOML text and the
    absolute folder its relative paths are taken in (None: the working
    directory), from which :func:`adhesive_contact.io.load_solution`
    rebuilds the problem. ``lines``: the run's
    :func:`~adhesive_contact.problem.warnings.solution_warnings`, when the
    caller has them already (they read every level's gradients)."""
    problem = solution.problem
    if lines is None:
        lines = solution_warnings(solution)
    mesh, boundary = problem.mesh, problem.boundary
    return {
        "schema": SCHEMA,
        "scene": problem.scene.resolved,
        **({"source": source} if source is not None else {}),
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
        "warnings": [str(w) for w in problem.warnings()] + list(lines),
        "timings": {key: json_number(value) for key, value in solution.timings.items()},
        "linear": dict(solution.linear),
        "bulk": dict(problem.assembly.record),
        **({"adaptive": {key: json_number(v) if isinstance(v, float) else v
                         for key, v in solution.adaptive.items()}}
           if solution.adaptive is not None else {}),
        "resources": resources_record(solution),
        "iterations": [int(i) for i in solution.iterations],
        "energy": energy_record(solution),
        "steps": step_records(solution, history),
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
        "partial": bool(solution.t.size < solution.problem.times.size
                        if solution.adaptive is None else not solution.success),
        "levels": int(solution.t.size),
        "message": " ".join(solution.message.split()),
        "failed_step": None if failure is None else int(failure.n),
        "failed_t": None if failure is None else json_number(failure.t),
    }


def write_summary(solution, path, source=None, history=None, lines=None):
    """Write ``summary.json`` (strict JSON: no NaN or infinity)."""
    write_json(path, summary(solution, source, history, lines))


#: every file name ``adhcontact solve`` may write; in an existing folder a
#: run replaces these and touches nothing else
OUTPUT_NAMES = frozenset(
    ["summary.json", "solution.npz", "solution.xdmf", "solution.h5", "contact.xdmf",
     "contact.h5"] + [f"{name}.png" for name in PLOT_NAMES])


def holds_complete_run(out):
    """Whether folder ``out`` holds a complete run (its summary.json says so)."""
    document = read_json(Path(out) / "summary.json") if Path(out).is_dir() else None
    run = document.get("run") if isinstance(document, dict) else None
    return isinstance(run, dict) and run.get("status") == "complete"


@contextlib.contextmanager
def staged_output(out):
    """A staging folder for the outputs of ``out``, published into it when
    the block ends normally with a ``summary.json`` written and removed
    otherwise (:func:`adhesive_contact.folders.staged_folder`: a folder that
    held a whole run holds it or the new whole run after any failure, kill
    or full disk).

    Parameters
    ----------
    out : path of the output folder; its parents are created. Hold its
        lock (:func:`~.common.check_out`). In an existing folder only the
        files of :data:`OUTPUT_NAMES` are replaced; a user's other files
        stay. The staging folder (``<out>.tmp-*`` beside a new ``out``,
        ``.adhcontact.tmp-*`` inside an existing one) holds the marker file
        :data:`adhesive_contact.folders.MARKER`; those of killed runs are
        removed, or their publish finished, first.
    """
    out = Path(out).absolute()
    out.parent.mkdir(parents=True, exist_ok=True)
    with staged_folder(out, OUTPUT_NAMES) as tmp:
        yield tmp


def write_results(solution, folder, failures=None, source=None, lines=None):
    """Write summary.json, solution.npz and the plots of a solution into
    ``folder`` (the XDMF series are the recorder's); return their names. A
    plot that cannot be drawn is left out and named in ``failures`` (a
    list), if given; the data files are written all the same. ``source``:
    the scene's text and folder, ``lines`` the run's warnings if known
    (:func:`summary`)."""
    folder = Path(folder)
    history = energies(solution)   # once, for summary.json and the figures
    write_summary(solution, folder / "summary.json", source, history, lines)
    write_npz(solution, folder / "solution.npz")
    return ["summary.json", "solution.npz"] + write_plots(solution, folder, failures, history)


def write_outputs(solution, out, failures=None, source=None):
    """Write all outputs of a finished in-memory solution into ``out``,
    atomically; return the names of the files written."""
    with staged_output(out) as tmp:
        names = sorted(write_xdmf(solution, tmp)
                       + write_results(solution, tmp, failures, source))
    return names
