"""The gap from the geometry of a rigid foundation (``[contact.foundation]``).

At each contact node x_a with unit outward normal ν_a (the averaged nodal
normal of Γ_C), the gap is the distance to the foundation along the
normal,

    g_a = min { s ≥ 0 : x_a + s ν_a ∈ ∂F },

and g_a = +∞ (no wall at that node) when the ray misses F. The body lies
outside the foundation F:

- ``plane``: F = {y : (y − p)·n ≤ 0}, n the unit normal pointing out of
  the foundation towards the body. With δ = (x − p)·n ≥ 0,
  g = δ / (−ν·n) if ν·n < 0, else +∞.
- ``sphere`` (a disc in 2D): F = {|y − c| ≤ r}. With w = x − c,
  s² + 2 (ν·w) s + |w|² − r² = 0 and g its smaller root when real and
  ≥ 0.
- ``cylinder`` (3D): F = {|P(y − p)| ≤ r} with P = I − a aᵀ the projection
  across the unit axis a; the same quadratic for the projected w = P(x − p)
  and direction P ν.
"""

import numpy as np


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
    """Gaps (n,) at points x (d, n) with unit outward normals ``normal``
    (d, n) to the foundation ``spec`` (a
    :class:`~adhesive_contact.scene.FoundationSpec`).

    Also returns the signed distance of each point from the foundation's
    surface (negative inside F), so that the caller can refuse a body that
    starts inside it."""
    d = x.shape[0]
    point = np.asarray(spec.point, dtype=float)[:, None]
    if spec.shape == "plane":
        n = np.asarray(spec.normal, dtype=float)
        n = (n / np.linalg.norm(n))[:, None]
        depth = np.sum((x - point) * n, axis=0)
        toward = np.sum(normal * n, axis=0)
        with np.errstate(divide="ignore", invalid="ignore", over="ignore"):   # unselected
            gap = np.where(toward < -1e-12, depth / np.where(toward < 0, -toward, 1.0), np.inf)
        return np.maximum(gap, 0.0), depth
    w, direction = x - point, normal
    if spec.shape == "cylinder" and d == 3:
        a = np.asarray(spec.axis, dtype=float)
        a = (a / np.linalg.norm(a))[:, None]
        w = w - a * np.sum(a * w, axis=0)
        direction = direction - a * np.sum(a * direction, axis=0)
    gap = _first_hit(direction, w, spec.radius)
    return np.maximum(gap, 0.0), np.linalg.norm(w, axis=0) - spec.radius
