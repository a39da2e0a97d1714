"""``summary.json``, written and read in one place (docs/outputs.md).

:data:`SCHEMA` is the version of its layout and :data:`STATUS` the words
of ``run.status``; :func:`summary_document` builds the document of a
solution (the resolved scene, mesh counts, how the run ended, the
smallness terms, warnings, timings, the linear backend, the estimated
resources beside those used, iterations and one record per time level,
:func:`step_records`), :func:`write_summary` writes it (strict JSON: no
NaN or infinity) and :func:`read_summary` reads one back, checking its
layout. The quantities come from :mod:`adhesive_contact.postprocess`; this
module only formats them.
"""

import json
import resource
from pathlib import Path

import numpy as np

from ..postprocess import (
    beta_mean,
    contact_measure,
    contact_state_counts,
    debond_fronts,
    debonded_area,
    energies,
    energy_per_area,
    energy_unavailable,
    penetration,
    reaction_sides,
    reactions,
    total_contact_force,
)
from ..postprocess.level_scalars import level_scalars
from ..problem.warnings import solution_warnings
from ..resources import estimate
from ..scheme import STEP_FAILED, STOPPED, SUCCESS
from ..storage import json_number, write_json
from .errors import OutputFolderError

#: the version of summary.json's layout (docs/outputs.md): raised when a key
#: changes meaning or goes; new keys do not change it
SCHEMA = 2

#: Solution.status -> summary.json's run.status
STATUS = {SUCCESS: "complete", STEP_FAILED: "step failed", STOPPED: "interrupted"}
#: summary.json's run.status -> Solution.status
STATUS_CODES = {word: code for code, word in STATUS.items()}


def summary_document(solution, source=None, history=None, lines=None, field_levels=None,
                     columns=None):
    """The ``summary.json`` document (a dict of plain JSON types).

    ``source``: ``{"text", "folder"}``, the scene's TOML text and the
    absolute folder its relative paths are taken in (None: the working
    directory), from which :func:`adhesive_contact.io.load_solution`
    rebuilds the problem. ``lines``: the run's
    :func:`~adhesive_contact.problem.warnings.solution_warnings`, when the
    caller has them already (they read every level's gradients).
    ``field_levels``: the levels whose fields were written (default every
    level); ``columns`` the run's level scalars, when the caller has them."""
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
        "output": output_record(solution, field_levels),
        "iterations": [int(i) for i in solution.iterations],
        "energy": energy_record(solution),
        "steps": step_records(solution, history, columns),
    }


def output_record(solution, field_levels=None):
    """What the run wrote: ``{"every", "fields", "field_levels"}``, the
    levels whose fields are in the files (``[output]``,
    :mod:`.field_levels`)."""
    output = solution.problem.output
    levels = (np.arange(solution.t.size) if field_levels is None
              else np.asarray(field_levels))
    return {"every": 1 if output is None else int(output.every),
            "fields": [] if output is None else list(output.fields),
            "field_levels": [int(n) for n in levels]}


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
        "status": STATUS[solution.status],
        "partial": bool(solution.t.size < solution.problem.options.steps + 1
                        if solution.adaptive is None else not solution.success),
        "levels": int(solution.t.size),
        "message": " ".join(solution.message.split()),
        "failed_step": None if failure is None else int(failure.n),
        "failed_t": None if failure is None else json_number(failure.t),
    }


def write_summary(solution, path, source=None, history=None, lines=None, field_levels=None,
                  columns=None):
    """Write ``summary.json`` (strict JSON: no NaN or infinity;
    :func:`summary_document`)."""
    write_json(path, summary_document(solution, source, history, lines, field_levels,
                                      columns))


def read_summary(path):
    """The ``summary.json`` document at ``path``, of this layout (schema :data:`SCHEMA`)."""
    try:
        document = json.loads(Path(path).read_text(encoding="utf-8"))
    except FileNotFoundError:
        raise OutputFolderError(path, "no such file; an output folder of 'adhcontact solve' "
                                "has one (docs/outputs.md)") from None
    except (OSError, UnicodeDecodeError) as err:
        raise OutputFolderError(path, f"cannot be read: {err}") from None
    except json.JSONDecodeError as err:
        raise OutputFolderError(path, f"not valid JSON ({err}): the file is damaged; run "
                                "the scene again") from None
    except RecursionError:
        raise OutputFolderError(path, "is nested too deeply to be a summary.json: the file "
                                "is damaged; run the scene again") from None
    if not isinstance(document, dict) or document.get("schema") != SCHEMA:
        found = document.get("schema") if isinstance(document, dict) else None
        raise OutputFolderError(path, f"has schema {found!r}; this version reads schema "
                                f"{SCHEMA}: run the scene again with it")
    for key in ("scene", "run", "steps"):
        if key not in document:
            raise OutputFolderError(path, f"has no {key!r}: the file is damaged")
    return document


def _vector(values):
    return [json_number(v) for v in np.ravel(values)]


def smallness_record(problem):
    """``problem.smallness`` as plain JSON (None without contact terms).

    The terms of docs/model.md §3's condition m_A > (m_τ + m_ν) c_e²‖γ‖²: numbers
    (null where they do not exist: a body held by contact), the booleans
    ``holds`` and ``step_energy_convex``, and the list ``held_by_contact``."""
    small = problem.smallness
    if small is None:
        return None

    def plain_value(value):
        if value is None or isinstance(value, list):
            return value
        if isinstance(value, (bool, np.bool_)):
            return bool(value)
        return json_number(value)
    return {key: plain_value(value) for key, value in small.items()}


def energy_record(solution):
    """The top-level ``energy`` of ``summary.json``: ``{"available", "reason"}``
    (reason null when available)."""
    reason = energy_unavailable(solution.problem)
    return {"available": reason is None, "reason": reason}


def _energy_at(history, n):
    """``steps[n].energy``: external_work, stored and dissipated (each with
    its parts and ``total``), balance (docs/outputs.md)."""
    stored = {key: json_number(v[n]) for key, v in history.stored.items()}
    stored["total"] = json_number(history.stored_total[n])
    dissipated = {key: json_number(v[n]) for key, v in history.dissipated.items()}
    dissipated["total"] = json_number(history.dissipated_total[n])
    return {"external_work": json_number(history.external_work[n]), "stored": stored,
            "dissipated": dissipated, "balance": json_number(history.balance[n])}


def _debonding_at(area, damage, new_area, new_damage, per_area, per_damage, front, n):
    """``steps[n].debonding``: the debonded area and the damage integral
    (pre-crack included), those of the run alone, the glue's dissipation
    per unit of the latter, the front's points (2D)."""
    return {"area": json_number(area[n]), "damage": json_number(damage[n]),
            "new_area": json_number(new_area[n]), "new_damage": json_number(new_damage[n]),
            "energy_per_area": json_number(per_area[n]) if per_area is not None else None,
            "energy_per_damage": (json_number(per_damage[n]) if per_damage is not None
                                  else None),
            "front": None if front is None else [_vector(p) for p in front[n]]}


def _count(values, n):
    return None if values is None else int(values[n])


def step_records(solution, history=None, columns=None):
    """The per-level entries of ``summary.json``'s ``steps`` list.

    Each is ``{"t", "probes", "normal_force", "tangential_force", "beta_mean",
    "beta_min", "separated", "on_wall", "stick", "slip", "contact_measure",
    "peak_pressure", "peak_pressure_at", "stick_measure", "slip_measure",
    "max_penetration", "iterations", "residual", "reactions", "contact_force",
    "energy", "debonding"}``: normal_force is the total
    force of Γ_C on the body, positive in compression; tangential_force its
    tangential part in the nodal frames, a number in 2D and a list of d − 1
    in 3D; beta_mean (weighted by the facet measures) and beta_min are None
    without contact facets; separated, on_wall, stick and slip count contact
    nodes (:func:`~adhesive_contact.postprocess.contact_state_counts`; stick
    and slip are None without friction); contact_measure the width (2D) or
    area (3D) of Γ_C in contact
    (:func:`~adhesive_contact.postprocess.contact_measure`, None without
    contact nodes), peak_pressure the largest nodal pressure and
    peak_pressure_at its node's coordinates, stick_measure and
    slip_measure the measure of the sticking and slipping nodes (None
    without friction);
    max_penetration is the deepest penetration of a contact node
    (:func:`~adhesive_contact.postprocess.penetration`: into the foundation
    itself with ``[contact.foundation]``, else max_a (u_ν − g)), None without a wall; ``reactions``
    is {side: [F_x, F_y(, F_z)]}, the force each held side's support exerts
    on the body (:mod:`adhesive_contact.postprocess.reactions`), and ``contact_force``
    the total force of Γ_C on the body in global components (None without
    contact nodes). ``columns``: the run's
    :func:`~adhesive_contact.postprocess.level_scalars.level_scalars`, when
    the caller has them.
    """
    d = solution.problem.dim
    history = energies(solution) if history is None else history
    columns = {c.name: c.values for c in (level_scalars(solution, history)
                                          if columns is None else columns)}
    measure = "width" if d == 2 else "area"
    normal = solution.total_normal_force()
    tangential = solution.total_tangential_force()
    means = beta_mean(solution)
    violation = penetration(solution)
    states = contact_state_counts(solution)
    sides = reaction_sides(solution.problem)
    held = reactions(solution)
    boundary = solution.problem.boundary
    has_nodes = boundary is not None and boundary.nodes.size > 0
    contact = total_contact_force(solution) if has_nodes else None
    in_contact = contact_measure(solution) if has_nodes else None
    debonding = None
    if boundary is not None and boundary.facets.size:
        area, damage = debonded_area(solution)
        new_area, new_damage = columns[f"debonded_{'length' if d == 2 else 'area'}"], \
            columns["damage"]
        glue = None if history is None else history.dissipated["debonding"]
        debonding = (area, damage, new_area, new_damage,
                     None if glue is None else energy_per_area(glue, new_area),
                     None if glue is None else energy_per_area(glue, new_damage),
                     debond_fronts(solution) if d == 2 else None)
    peak = columns.get("peak_pressure")
    peak_at = (np.stack([columns[f"peak_pressure_{c}"] for c in "xyz"[:d]], axis=1)
               if peak is not None else None)
    stick, slip = columns.get(f"stick_{measure}"), columns.get(f"slip_{measure}")
    records = []
    for n, t in enumerate(solution.t):
        has_beta = solution.beta.shape[1] > 0
        records.append({
            "t": json_number(t),
            "probes": [_vector(p) for p in solution.probes[n]],
            "normal_force": json_number(normal[n]),
            "tangential_force": (json_number(tangential[n, 0]) if d == 2
                                 else _vector(tangential[n])),
            "beta_mean": None if means is None else json_number(means[n]),
            "beta_min": json_number(solution.beta[n].min()) if has_beta else None,
            "separated": _count(states["separated"], n),
            "on_wall": _count(states["on_wall"], n),
            "stick": _count(states.get("stick"), n),
            "slip": _count(states.get("slip"), n),
            "contact_measure": None if in_contact is None else json_number(in_contact[n]),
            "peak_pressure": None if peak is None else json_number(peak[n]),
            "peak_pressure_at": None if peak_at is None else _vector(peak_at[n]),
            "stick_measure": None if stick is None else json_number(stick[n]),
            "slip_measure": None if slip is None else json_number(slip[n]),
            "max_penetration": json_number(violation[n]),
            "iterations": int(solution.iterations[n]),
            "residual": json_number(solution.residual[n]),
            "reactions": {side: _vector(held[n, i]) for i, side in enumerate(sides)},
            "contact_force": None if contact is None else _vector(contact[n]),
            "energy": None if history is None else _energy_at(history, n),
            "debonding": None if debonding is None else _debonding_at(*debonding, n),
        })
    return records
