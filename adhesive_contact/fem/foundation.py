"""The geometry of a rigid foundation F (``[contact.foundation]``).

Node to surface, as contact codes measure it: a contact node x_a is
paired with the closest point y_a of the foundation's surface ∂F, and the
normal, the gap and the constraint of the node are those of the
foundation there,

    ν_a = −n_F(y_a),   g_a = |x_a − y_a| = d_F(x_a),

n_F the unit normal of ∂F pointing out of F (towards the body) and d_F
the signed distance from ∂F (negative inside F). ν_a points from the body
into the foundation, like the body's outward normal where the body faces
it; u_ν = u·ν_a ≤ g_a is then the linearised non-penetration
d_F(x_a + u_a) ≥ 0, exact for a plane (docs/model.md §1). The body lies
outside F:

- ``plane``: F = {y : (y − p)·n ≤ 0}, n the unit normal pointing out of
  the foundation towards the body: d_F(x) = (x − p)·n, n_F = n;
- ``sphere`` (a disc in 2D): F = {|y − c| ≤ r}: with w = x − c,
  d_F = |w| − r, n_F = w/|w|;
- ``cylinder`` (3D): F = {|P(y − p)| ≤ r}, P = I − a aᵀ the projection
  across the unit axis a: the same with w = P(x − p).

:func:`foundation_normal` gives ν_a and d_F at the nodes, :func:`signed_distance`
d_F at any points (the penetration of the deformed body is −d_F(x + u)),
and :func:`foundation_gap` the distance along a given direction (the gap
of a node whose frame normal is not the foundation's, docs/conventions.md).
"""

import numpy as np


def _unit(vector):
    v = np.asarray(vector, dtype=float)
    return (v / np.linalg.norm(v))[:, None]


def _radial(spec, x):
    """w (d, n): x − c for a sphere, P(x − p) for a cylinder."""
    w = x - np.asarray(spec.point, dtype=float)[:, None]
    if spec.shape == "cylinder" and x.shape[0] == 3:
        a = _unit(spec.axis)
        w = w - a * np.sum(a * w, axis=0)
    return w


def signed_distance(spec, x):
    """d_F (n,) at points x (d, n): the distance from the foundation's
    surface, negative inside the foundation."""
    x = np.asarray(x, dtype=float)
    if spec.shape == "plane":
        return np.sum((x - np.asarray(spec.point, dtype=float)[:, None]) * _unit(spec.normal),
                      axis=0)
    return np.linalg.norm(_radial(spec, x), axis=0) - spec.radius


def foundation_normal(spec, x):
    """ν (d, n) = −n_F at the closest points of ∂F to the points x (d, n),
    unit vectors pointing into the foundation, and d_F (n,) at x.

    At a point on the axis of a sphere or cylinder (w = 0, no closest point)
    ν is −e_y, or −e_x if the cylinder's axis is along y (any direction
    across the axis is as close)."""
    x = np.asarray(x, dtype=float)
    d, n = x.shape
    if spec.shape == "plane":
        return np.broadcast_to(-_unit(spec.normal), (d, n)).copy(), signed_distance(spec, x)
    w = _radial(spec, x)
    length = np.linalg.norm(w, axis=0)
    fallback = np.zeros(d)
    fallback[1] = 1.0
    if spec.shape == "cylinder" and d == 3 and abs(_unit(spec.axis)[1, 0]) > 0.9:
        fallback = np.array([1.0, 0.0, 0.0])
    on_axis = length <= 1e-14 * (1.0 + np.abs(x).max())
    outward = np.where(on_axis, fallback[:, None], w / np.where(on_axis, 1.0, length))
    return -outward, length - spec.radius


def _first_hit(direction, w, radius):
    """Smallest s ≥ 0 with |w + s direction| = radius (columns), +∞ if none."""
    A = np.sum(direction * direction, axis=0)
    b = np.sum(direction * w, axis=0)
    c = np.sum(w * w, axis=0) - radius ** 2
    disc = b * b - A * c
    hit = (A > 1e-14) & (disc >= 0) & (b < 0)
    return np.where(hit, (-b - np.sqrt(np.maximum(disc, 0.0))) / np.where(hit, A, 1.0),
                    np.inf)


def foundation_gap(spec, x, normal):
    """The distance (n,) from points x (d, n) to the foundation ``spec``
    (a :class:`~adhesive_contact.scene.FoundationSpec`) along the unit
    directions ``normal`` (d, n),

        g = min { s ≥ 0 : x + s ν ∈ ∂F },   +∞ where the ray misses F,

    and the signed distance d_F (n,) of each point (negative inside F).
    Along ν = −n_F of :func:`foundation_normal` g = d_F: a plane gives
    g = d_F / (−ν·n) for ν·n < 0, a sphere or cylinder the smaller root of
    |w + s Pν|² = r²."""
    x = np.asarray(x, dtype=float)
    depth = signed_distance(spec, x)
    if spec.shape == "plane":
        toward = np.sum(normal * _unit(spec.normal), axis=0)
        with np.errstate(divide="ignore", invalid="ignore", over="ignore"):   # unselected
            gap = np.where(toward < -1e-12, depth / np.where(toward < 0, -toward, 1.0), np.inf)
        return np.maximum(gap, 0.0), depth
    direction = normal
    if spec.shape == "cylinder" and x.shape[0] == 3:
        a = _unit(spec.axis)
        direction = direction - a * np.sum(a * direction, axis=0)
    gap = _first_hit(direction, _radial(spec, x), spec.radius)
    return np.maximum(gap, 0.0), depth
