"""Quantities derived from a :class:`~adhesive_contact.Solution` for reports.

Only post-processing lives here (no numerics of the scheme): von Mises
stress, nodal contact tractions (normal and tangential), facet means of β,
padding to the three components ParaView expects, the smallness terms and
the per-level records of ``summary.json``.
"""

import math

import numpy as np


def stress_3x3(solution, n):
    """σ_n per cell as full 3 × 3 tensors (ncells, 3, 3): in plane strain the
    zz entry is the solution's σ_zz (λ tr ε with the memory's λ parts)."""
    s = solution.stress[n]
    if s.shape[-1] == 3:
        return s
    full = np.zeros(s.shape[:-2] + (3, 3))
    full[..., :2, :2] = s
    full[..., 2, 2] = solution.stress_zz[n]
    return full


def von_mises(stress):
    """Von Mises equivalent stress sqrt(3/2 s:s), s the deviator of the
    3 × 3 tensors ``stress`` (..., 3, 3) (see :func:`stress_3x3`)."""
    s = np.asarray(stress)
    dev = s - np.trace(s, axis1=-2, axis2=-1)[..., None, None] * np.eye(3) / 3.0
    return np.sqrt(1.5 * np.einsum("...ij,...ij->...", dev, dev))


def pad_vectors(v):
    """Vectors (..., d) padded with zeros to (..., 3)."""
    v = np.asarray(v, dtype=float)
    pad = [(0, 0)] * (v.ndim - 1) + [(0, 3 - v.shape[-1])]
    return np.pad(v, pad)


def normal_traction(solution):
    """Nodal normal traction on Γ_C, positive in compression, (N+1, nc).

    The normal component of the nodal contact force divided by the lumped
    nodal weight ∫_{Γ_C} φ_a, sign flipped (the force is negative in
    compression)."""
    boundary = solution.problem.boundary
    return -solution.contact_force[:, :, 0] / boundary.node_weights


def tangential_traction(solution):
    """Nodal tangential traction on Γ_C, (N+1, nc, d−1).

    The tangential components of the nodal force Γ_C exerts on the body, in
    the nodal tangent frames [τ (, τ')], divided by the lumped nodal weight."""
    boundary = solution.problem.boundary
    return solution.contact_force[:, :, 1:] / boundary.node_weights[None, :, None]


def tangent_direction(problem):
    """The common tangent τ of the contact nodes, or None if the frames differ.

    A straight contact side in 2D has one tangent; labels can then say
    along which axis a positive σ_τ points."""
    boundary = problem.boundary
    if boundary is None or boundary.nodes.size == 0 or problem.dim != 2:
        return None
    tau = boundary.frame[:, :, 1]
    if not np.allclose(tau, tau[0], atol=1e-9):
        return None
    return tau[0]


def along_axis(points):
    """The coordinate axis (0, 1, 2) along which points (d, n) spread most."""
    points = np.asarray(points)
    if points.shape[1] == 0:
        return 0
    return int(np.argmax(points.max(axis=1) - points.min(axis=1)))


def facet_midpoints(problem):
    """Midpoints (d, nf) of the contact facets."""
    boundary = problem.boundary
    return problem.mesh.p[:, boundary.facet_nodes].mean(axis=1)


def beta_mean(solution):
    """Facet-measure weighted mean of β per level (N+1,), or None (no facets)."""
    boundary = solution.problem.boundary
    if boundary is None or boundary.facets.size == 0:
        return None
    return solution.beta @ boundary.measure / boundary.measure.sum()


def json_number(value):
    """A finite float, or None for NaN and ±inf (JSON has neither)."""
    value = float(value) + 0.0   # no -0.0
    return value if math.isfinite(value) else None


def _vector(values):
    return [json_number(v) for v in np.ravel(values)]


def smallness_record(problem):
    """``problem.smallness`` as plain JSON (None without contact terms).

    The terms of MODEL.md §2's condition m_A > (m_τ + m_ν) c_e²‖γ‖²: numbers,
    and the booleans ``holds`` and ``step_energy_convex``."""
    small = problem.smallness
    if small is None:
        return None
    return {key: (bool(value) if isinstance(value, (bool, np.bool_)) else json_number(value))
            for key, value in small.items()}


def _count(values, n):
    return None if values is None else int(values[n])


def step_records(solution):
    """The per-level entries of ``summary.json``'s ``steps`` list.

    Each is ``{"t", "probes", "normal_force", "tangential_force", "beta_mean",
    "beta_min", "n_wall", "separated", "on_wall", "stick", "slip",
    "max_penetration", "iterations", "residual"}``: normal_force is the total
    force of Γ_C on the body, positive in compression; tangential_force its
    tangential part in the nodal frames, a number in 2D and a list of d − 1
    in 3D; beta_mean (weighted by the facet measures) and beta_min are None
    without contact facets; separated, on_wall, stick and slip count contact
    nodes (:meth:`~adhesive_contact.Solution.contact_states`; stick and slip
    are None without friction; n_wall = on_wall, kept for older readers);
    max_penetration is max_a (u_ν − g), None without a wall.
    """
    d = solution.u.shape[2]
    normal = solution.total_normal_force()
    tangential = solution.total_tangential_force()
    means = beta_mean(solution)
    violation = solution.gap_violation()
    states = solution.contact_states()
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
            "n_wall": int(solution.on_wall[n].sum()),
            "separated": _count(states["separated"], n),
            "on_wall": _count(states["on_wall"], n),
            "stick": _count(states.get("stick"), n),
            "slip": _count(states.get("slip"), n),
            "max_penetration": json_number(violation[n]),
            "iterations": int(solution.iterations[n]),
            "residual": json_number(solution.residual[n]),
        })
    return records
