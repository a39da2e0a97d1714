"""Is a manufactured solution a solution of the problem at all?

The data of docs/verification.md (:mod:`adhesive_contact.verification.manufactured`) make u*,
β*, λ* satisfy the equations with an extra surface load and a bonding
source, but not the constraints: those the scene's author must get right,
and a run that violates them converges to something else, quietly. Before
a run, at every time level t_n and at the points of the mesh where each
condition lives, :func:`check_manufactured` verifies

1. u* = 0 on the clamped sides Γ_D (at their vertices and facet Gauss points);
2. u*_ν ≤ g on Γ_C (the wall, where the scene has one);
3. λ* ≥ 0 where u*_ν = g, the contact set found with a tolerance
   (:func:`on_wall`), not by exact equality;
4. 0 ≤ β* ≤ 1 on Γ_C;
5. stick/slip consistency of friction data with a kink: the load takes the
   friction force 0 where u*_τ = 0 (inside ∂j_τ(β*, 0)) and ∇j_τ(β*, u*_τ)
   elsewhere, of size φ'(β*, 0+) = κ at once for a law with a kink; a
   |u*_τ| below the tolerance but not zero (round-off in the expression)
   would put a full-size friction force in a direction set by round-off.
   Such points must be exactly stuck or clearly slipping.

Each is checked to ``TOLERANCE`` relative to the size of the data (u*,
g); a violation raises :class:`~adhesive_contact.scene.SceneError` naming
the condition, the point and the time.
"""

import numpy as np

from ..fem.contact_boundary import facet_normals, facet_points, tangent_frame
from ..expressions import coordinates
from .manufactured import TOLERANCE, on_wall
from ..errors import SceneError, where


#: relative tolerance of the checks, and of the contact and stick sets
def _points(mesh, facets):
    """Vertices and Gauss points (d, n) of a set of boundary facets."""
    nodes = mesh.facets[:, facets]
    gauss, _ = facet_points(mesh, nodes, "gauss", 4)
    return np.hstack([mesh.p[:, np.unique(nodes)], gauss.reshape(mesh.dim(), -1)])


def _contact_points(mesh, facets):
    """The vertices and Gauss points (d, n) of each contact facet, with that
    facet's outward normal (d, n) and tangents (m, d, n) there (sides may
    be curved: a vertex is checked with each of its facets' normals)."""
    nodes = mesh.facets[:, facets]                                       # (d, nf)
    gauss, _ = facet_points(mesh, nodes, "gauss", 4)                     # (d, nf, nq)
    vertices = mesh.p[:, nodes].transpose(0, 2, 1)                       # (d, nf, d)
    points = np.concatenate([vertices, gauss], axis=2)
    normals, _ = facet_normals(mesh, facets)                             # (d, nf)
    d, nf, npts = points.shape
    normal = np.repeat(normals, npts, axis=1)
    tangents = tangent_frame(normal)[:, :, 1:].transpose(2, 1, 0)        # (m, d, n)
    return points.reshape(d, -1), normal, tangents


def check_manufactured(scene, mesh, exact, times, gap, clamped_facets, contact_facets):
    """Raise SceneError unless u*, β*, λ* satisfy the constraints (module doc).

    Parameters
    ----------
    scene : Scene with ``exact``
    mesh : the scene's mesh
    exact : ManufacturedSolution
    times : (N+1,) the time levels
    gap : the scene's gap Expression or None
    clamped_facets, contact_facets : mesh facet indices of Γ_D and Γ_C
    """
    clamped = _points(mesh, clamped_facets)
    contact = {}
    if len(contact_facets):
        contact["Γ_C"] = _contact_points(mesh, contact_facets)
    # the size of u* over the body: the scale of "vanishes" and of the gap test
    size = max(float(np.abs(exact.displacement(*coordinates(x), t=t)).max(initial=0.0))
               for x in [mesh.p, clamped, *(c[0] for c in contact.values())] for t in times)
    for t in times:
        u = exact.displacement(*coordinates(clamped), t=t)
        worst = int(np.argmax(np.abs(u).max(axis=0))) if u.size else 0
        if u.size and np.abs(u[:, worst]).max() > TOLERANCE * max(size, 1e-300):
            raise SceneError("exact.u", f"must vanish on the clamped sides "
                             f"({', '.join(scene.dirichlet)}); u* = "
                             f"({', '.join(f'{v:.3g}' for v in u[:, worst])}) at "
                             f"{where(clamped, worst, t, digits=4)}")
    friction = exact.friction
    for x, normal, tangent in contact.values():
        for t in times:
            u = exact.displacement(*coordinates(x), t=t)
            r = np.sum(normal * u, axis=0)
            beta = exact.beta(*coordinates(x), t=t) * np.ones(r.shape)
            if beta.min() < -TOLERANCE or beta.max() > 1 + TOLERANCE:
                i = int(np.argmin(beta) if beta.min() < -TOLERANCE else np.argmax(beta))
                raise SceneError("exact.beta", f"must lie in [0, 1] on Γ_C; β* = "
                                 f"{beta[i]:.4g} at {where(x, i, t, digits=4)}")
            if gap is not None:
                g = gap(*coordinates(x), t=t) * np.ones(r.shape)
                excess = r - g
                i = int(np.argmax(excess))
                if excess[i] > TOLERANCE * (size + abs(g[i])):
                    raise SceneError("exact.u", f"must satisfy u*_nu <= g on Γ_C; u*_nu - g = "
                                     f"{excess[i]:.3g} at {where(x, i, t, digits=4)}")
                touching = on_wall(r, g)
                if touching.any() and exact.has_multiplier:
                    lam = exact.multiplier(*coordinates(x), t=t) * np.ones(r.shape)
                    bad = touching & (lam < 0)
                    if bad.any():
                        i = int(np.flatnonzero(bad)[0])
                        raise SceneError("exact.multiplier", f"must be >= 0 where u*_nu = g; "
                                         f"lambda* = {lam[i]:.4g} at {where(x, i, t, digits=4)}")
            if friction is not None and friction.has_kink:
                xi = np.stack([np.sum(u * tt, axis=0) for tt in tangent], axis=-1)
                s = np.linalg.norm(xi, axis=-1)
                ambiguous = (s > 0) & (s <= TOLERANCE * max(size, 1e-300))
                if ambiguous.any():
                    i = int(np.flatnonzero(ambiguous)[0])
                    raise SceneError("exact.u", f"stick/slip is ambiguous on Γ_C: |u*_tau| = "
                                     f"{s[i]:.3g}, round-off rather than 0 or a slip, at "
                                     f"{where(x, i, t, digits=4)}; the friction force there would "
                                     f"point where round-off says. Make u*_tau exactly 0 "
                                     f"in the stick zone (e.g. with where(...))")
