"""The JSON records of ``summary.json``: the smallness terms and one record
per time level. The quantities come from :mod:`adhesive_contact.postprocess`;
this module only formats them.
"""

import numpy as np

from adhesive_contact.postprocess import (
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
from adhesive_contact.storage import json_number


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


def _debonding_at(area, damage, per_area, per_damage, front, n):
    """``steps[n].debonding``: the debonded area, the damage integral, the
    glue's dissipation per unit of each, the front's points (2D)."""
    return {"area": json_number(area[n]), "damage": json_number(damage[n]),
            "energy_per_area": json_number(per_area[n]) if per_area is not None else None,
            "energy_per_damage": (json_number(per_damage[n]) if per_damage is not None
                                  else None),
            "front": None if front is None else [_vector(p) for p in front[n]]}


def _count(values, n):
    return None if values is None else int(values[n])


def step_records(solution, history=None):
    """The per-level entries of ``summary.json``'s ``steps`` list.

    Each is ``{"t", "probes", "normal_force", "tangential_force", "beta_mean",
    "beta_min", "separated", "on_wall", "stick", "slip", "contact_measure",
    "max_penetration", "iterations", "residual"}``: normal_force is the total
    force of Γ_C on the body, positive in compression; tangential_force its
    tangential part in the nodal frames, a number in 2D and a list of d − 1
    in 3D; beta_mean (weighted by the facet measures) and beta_min are None
    without contact facets; separated, on_wall, stick and slip count contact
    nodes (:func:`~adhesive_contact.postprocess.contact_state_counts`; stick
    and slip are None without friction); contact_measure the width (2D) or
    area (3D) of Γ_C in contact
    (:func:`~adhesive_contact.postprocess.contact_measure`, None without
    contact nodes);
    max_penetration is the deepest penetration of a contact node
    (:func:`~adhesive_contact.postprocess.penetration`: into the foundation
    itself with ``[contact.foundation]``, else max_a (u_ν − g)), None without a wall; ``reactions``
    is {side: [F_x, F_y(, F_z)]}, the force each held side's support exerts
    on the body (:mod:`adhesive_contact.postprocess.reactions`), and ``contact_force``
    the total force of Γ_C on the body in global components (None without
    contact nodes).
    """
    d = solution.u.shape[2]
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
    history = energies(solution) if history is None else history
    debonding = None
    if boundary is not None and boundary.facets.size:
        area, damage = debonded_area(solution)
        glue = None if history is None else history.dissipated["debonding"]
        debonding = (area, damage,
                     None if glue is None else energy_per_area(glue, area),
                     None if glue is None else energy_per_area(glue, damage),
                     debond_fronts(solution) if d == 2 else None)
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
            "max_penetration": json_number(violation[n]),
            "iterations": int(solution.iterations[n]),
            "residual": json_number(solution.residual[n]),
            "reactions": {side: _vector(held[n, i]) for i, side in enumerate(sides)},
            "contact_force": None if contact is None else _vector(contact[n]),
            "energy": None if history is None else _energy_at(history, n),
            "debonding": None if debonding is None else _debonding_at(*debonding, n),
        })
    return records
