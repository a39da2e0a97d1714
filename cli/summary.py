"""The JSON records of ``summary.json``: the smallness terms and one record
per time level. The quantities come from :mod:`adhesive_contact.postprocess`;
this module only formats them.
"""

import numpy as np

from adhesive_contact.postprocess import beta_mean, contact_state_counts, total_contact_force
from adhesive_contact.postprocess import reaction_sides, reactions
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


def _count(values, n):
    return None if values is None else int(values[n])


def step_records(solution):
    """The per-level entries of ``summary.json``'s ``steps`` list.

    Each is ``{"t", "probes", "normal_force", "tangential_force", "beta_mean",
    "beta_min", "separated", "on_wall", "stick", "slip",
    "max_penetration", "iterations", "residual"}``: normal_force is the total
    force of Γ_C on the body, positive in compression; tangential_force its
    tangential part in the nodal frames, a number in 2D and a list of d − 1
    in 3D; beta_mean (weighted by the facet measures) and beta_min are None
    without contact facets; separated, on_wall, stick and slip count contact
    nodes (:func:`~adhesive_contact.postprocess.contact_state_counts`; stick
    and slip are None without friction);
    max_penetration is max_a (u_ν − g), None without a wall; ``reactions``
    is {side: [F_x, F_y(, F_z)]}, the force each held side's support exerts
    on the body (:mod:`adhesive_contact.postprocess.reactions`), and ``contact_force``
    the total force of Γ_C on the body in global components (None without
    contact nodes).
    """
    d = solution.u.shape[2]
    normal = solution.total_normal_force()
    tangential = solution.total_tangential_force()
    means = beta_mean(solution)
    violation = solution.gap_violation()
    states = contact_state_counts(solution)
    sides = reaction_sides(solution.problem)
    held = reactions(solution)
    boundary = solution.problem.boundary
    contact = (total_contact_force(solution) if boundary is not None and boundary.nodes.size
               else None)
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
            "max_penetration": json_number(violation[n]),
            "iterations": int(solution.iterations[n]),
            "residual": json_number(solution.residual[n]),
            "reactions": {side: _vector(held[n, i]) for i, side in enumerate(sides)},
            "contact_force": None if contact is None else _vector(contact[n]),
        })
    return records
