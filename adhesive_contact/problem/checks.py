"""Every check that refuses a scene before a run, once the geometry is known.

The scene reader (:mod:`adhesive_contact.scene`) checks what a scene says
on its own; these checks need the mesh, and ``build_problem`` calls them
as it builds (each raises :class:`~adhesive_contact.scene.SceneError`
naming the key, the point and the time). Checks of a manufactured
solution's constraints are :mod:`adhesive_contact.verification.admissibility`;
checks of each level during a run are
:mod:`adhesive_contact.scheme.level_checks`; warnings are
:mod:`.warnings`.

Finite values. An expression can be well formed and still give ±inf or NaN (``9**9**9``,
``1e308*10``, ``sqrt(-1 - x)``, ``0/0``) at the points the scheme needs:
such a load or kernel would only fail inside the time loop, or worse, give
a quiet NaN. :func:`check_finite` evaluates an expression at given points
and every time level of the run (:func:`check_on_grid`: all pairs of
points and levels up to :data:`GRID_EVALUATIONS`, beyond that every level
at an even sample of the points and every point at a sample of the
levels) and raises :class:`~adhesive_contact.scene.SceneError` naming the
key, the point and the time of the first value that is not finite:
``1/(t - 0.01)`` with k = 0.01 is refused, not met at step 1.
:func:`check_loads`, :func:`check_displacements`, :func:`check_kernel` and
:func:`check_exact` apply it to the loads at the quadrature points of the
load map, the prescribed displacements at their nodes, the memory kernel
at the lags of the time grid, and the exact solution at the mesh nodes;
``build_problem`` calls them, since the points come from the geometry.

Held sides. :func:`check_prescribed`: sides that share a dof prescribe one
value there, a held component of a scene with [exact] equals u*.
:func:`check_rigid_motions`: the held components and the contact terms
leave no rigid motion free (docs/model.md, 'A body held by contact').

Geometry. :func:`check_gap`, :func:`check_outside_foundation`,
:func:`check_beta0` and :func:`check_probes`.
"""

import numpy as np

from ..expressions import coordinates
from ..fem.dirichlet import rigid_modes
from ..errors import SceneError, where
from ..scene.keys import MAX_HALVINGS

#: time levels sampled besides t = 0 and t = T (where not every level is)
TIME_SAMPLES = 16
#: evaluations (points × time levels) of one expression checked pair by pair
GRID_EVALUATIONS = 4 * 10**6
#: entries evaluated at once
_BLOCK = 2**16
#: lags of the memory kernel checked one by one (more are sampled)
KERNEL_LAGS = 10**6


def sample_times(times, count=TIME_SAMPLES):
    """t_0, t_N and about ``count`` evenly spaced levels between them."""
    n = times.size - 1
    picks = np.unique(np.round(np.linspace(0, n, min(n + 1, count + 2))).astype(np.int64))
    return times[picks]


def check_values(key, values, points, t, what="is not finite"):
    """Raise SceneError at the first entry of ``values`` (one per column of
    ``points`` (d, n)) that is not finite."""
    bad = ~np.isfinite(values)
    if bad.any():
        i = int(np.flatnonzero(bad)[0])
        raise SceneError(key, f"{what}: {values[i]:g} at {where(points, i, t)}")


def check_finite(key, field, points, times):
    """``field(x, y, z, t)`` finite at ``points`` (d, n) for every t in ``times``
    (only t = 0 when it does not depend on time).

    ``field`` is an Expression, or any callable of that signature giving
    an array of the shape of x, or (components, ...) for a vector field."""
    if getattr(field, "uses", None) is not None and not field.depends_on_time:
        times = times[:1]
    for t in times:
        values = np.asarray(field(*coordinates(points), t=t), dtype=float)
        values = values.reshape(-1, points.shape[1])
        for row in values:
            check_values(key, row, points, t)


def check_on_grid(key, expression, points, times):
    """A scalar Expression finite at ``points`` (d, n) at every level of
    ``times`` (the whole grid of the run), at most :data:`GRID_EVALUATIONS`
    evaluations: every (point, level) pair when they fit, else every level
    at an even sample of the points (one point when the levels alone pass
    the budget: the levels are never sampled) and every point at
    :func:`sample_times`. Evaluated in blocks, time along the columns."""
    if not expression.depends_on_time:
        times = times[:1]
    if not expression.depends_on_space:
        points = points[:, :1]
    n, m = points.shape[1], times.size
    if n * m <= GRID_EVALUATIONS:
        _check_pairs(key, expression, points, times)
        return
    picks = np.unique(np.linspace(0, n - 1, max(1, GRID_EVALUATIONS // m)).round()
                      .astype(np.int64))
    _check_pairs(key, expression, points[:, picks], times)
    _check_pairs(key, expression, points, sample_times(times))


def _check_pairs(key, expression, points, times):
    n = points.shape[1]
    columns = max(1, _BLOCK // n)
    for start in range(0, times.size, columns):
        t = times[start:start + columns]
        shape = (n, t.size)   # the expression gives the shape of x
        x = [None if c is None else np.broadcast_to(c[:, None], shape)
             for c in coordinates(points)]
        values = expression(*x, t=np.broadcast_to(t[None, :], shape))
        bad = ~np.isfinite(values)
        if bad.any():
            i, j = np.argwhere(bad)[np.argmin(np.argwhere(bad)[:, 1])]
            raise SceneError(key, f"is not finite: {values[i, j]:g} at "
                             f"{where(points, int(i), float(t[j]))}")


def check_loads(keyed_fields, loads, times):
    """The loads finite at the quadrature points of the load map (at one
    point for an expression that does not use x, y, z: its value is the
    same everywhere).

    ``keyed_fields`` lists, parallel to ``loads.parts``, the fields to check
    there as (key, field) pairs: a scene's expressions one component at a
    time, so that the key names the component."""
    for fields, (_, load) in zip(keyed_fields, loads.parts):
        for key, field in fields:
            points = load.points if getattr(field, "depends_on_space", True) else load.anchor
            points = points.reshape(points.shape[0], -1)
            if getattr(field, "uses", None) is not None:   # a scene's expression
                check_on_grid(key, field, points, times)
            else:
                check_finite(key, field, points, sample_times(times))


def check_adaptive_bound(scene, bonding):
    """With [time.adaptive] and the explicit bonding integrator every step,
    the doubled one included, is held below the explicit Euler bound k_E:
    the smallest pair 2 k_min must be within it (γ = 1e12 ran at k_min far
    beyond it until β left [0, 1])."""
    if (scene.adaptive is None or bonding is None or scene.contact.integrator != "explicit"
            or getattr(bonding, "rate_independent", False)):
        return
    bound = float(bonding.stable_step())
    k_min = scene.adaptive.k_min
    if 2.0 * k_min <= bound:
        return
    floor = scene.k * 2.0 ** -MAX_HALVINGS
    fix = (f"give time.adaptive.k_min <= {0.5 * bound:.4g}" if 2.0 * floor <= bound else
           f"no k_min reaches it (at least k_max 2^-{MAX_HALVINGS} = {floor:.4g}): use at "
           f"least time.steps = {int(np.ceil(scene.T / (bound * 2.0 ** (MAX_HALVINGS - 1))))} "
           f"with time.adaptive.k_min <= {0.5 * bound:.4g}")
    raise SceneError("time.adaptive.k_min", f"the adaptive steps' smallest pair 2 k_min = "
                     f"{2.0 * k_min:.4g} is beyond the explicit Euler bound k <= {bound:.4g} of "
                     f"the bonding law, which every step must keep (beta leaves [0, 1] beyond "
                     f"it); {fix}, or contact.bonding.integrator = 'implicit', "
                     "'exponential' or 'midpoint'")


def check_kernel(key, r, k, steps):
    """r(t) finite at every lag t = j k of the time grid (sampled beyond
    KERNEL_LAGS lags): the history sums k r(t_n − t_j) u_j."""
    lags = k * (np.arange(steps + 1) if steps <= KERNEL_LAGS else
                np.unique(np.linspace(0, steps, KERNEL_LAGS + 1).round()))
    values = np.asarray(r(lags, t=lags), dtype=float).ravel()
    bad = ~np.isfinite(values)
    if bad.any():
        i = int(np.flatnonzero(bad)[0])
        raise SceneError(key, f"is not finite: r({lags[i]:g}) = {values[i]:g}")


def check_exact(exact, points, times):
    """u*, β* and λ* of an [exact] table finite at the mesh nodes."""
    sample = sample_times(times)
    fields = [(f"exact.u[{i}]", e) for i, e in enumerate(exact.u)]
    fields += [(f"exact.{name}", e) for name, e in (("beta", exact.beta),
                                                    ("multiplier", exact.multiplier))
               if e is not None]
    for key, e in fields:
        check_finite(key, e, points, sample)


# ---------------------------------------------------------------- held sides


def check_displacements(rows, scene, mesh, times):
    """Every prescribed displacement finite at its nodes at every level."""
    d = mesh.dim()
    for s, c, dofs, expr, key in rows:
        if scene.held_sides[s] not in scene.dirichlet:
            check_on_grid(key, expr, mesh.p[:, dofs // d], times)


def check_prescribed(prescribed, scene, mesh):
    """The held components of a scene (a
    :class:`~adhesive_contact.fem.dirichlet.PrescribedDisplacement`) are
    consistent: one value at every dof held by several sides, u* on the
    held sides of a scene with [exact]."""
    times = scene.k * np.arange(scene.steps + 1)
    check_displacements(prescribed.entries, scene, mesh, times)
    _check_agreement(prescribed.entries, prescribed.fixed, prescribed.count, mesh, times)
    if scene.exact is not None:
        _check_exact_held(prescribed.entries, scene, mesh, times)


def _check_agreement(rows, fixed, count, mesh, times):
    """Every dof held by several sides gets one value from all of them."""
    shared = count > 1
    if not shared.any():
        return
    d = mesh.dim()
    first = {}
    for s, c, dofs, expr, key in rows:
        pos = np.searchsorted(fixed, dofs)
        keep = shared[pos]
        if not keep.any():
            continue
        x = mesh.p[:, dofs[keep] // d]
        values = np.array([np.broadcast_to(expr(*coordinates(x), t=t), x.shape[1])
                           for t in times])
        for p, column in zip(pos[keep], values.T):
            if p not in first:
                first[p] = (column, key)
                continue
            other, other_key = first[p]
            if np.abs(column - other).max() > 1e-12 * (1.0 + np.abs(other).max()):
                raise SceneError(key, f"holds the node {where(mesh.p, fixed[p] // d)} at "
                                 f"another value than "
                                 f"{other_key}; sides that share a node must prescribe "
                                 "the same value there (or leave it \"free\" on one)")


def _check_exact_held(rows, scene, mesh, times):
    """In a scene with [exact], a held component must equal u* on its side."""
    d = mesh.dim()
    for s, c, dofs, expr, key in rows:
        if scene.held_sides[s] in scene.dirichlet:
            continue
        x = mesh.p[:, dofs // d]
        for t in times:
            given = np.broadcast_to(expr(*coordinates(x), t=t), x.shape[1])
            exact = np.broadcast_to(scene.exact.u[c](*coordinates(x), t=t), x.shape[1])
            if np.abs(given - exact).max() > 1e-10 * (1.0 + np.abs(exact).max()):
                raise SceneError(key, f"must equal exact.u[{c}] on the side in a scene "
                                 f"with [exact] (differs at t = {t:g})")


def free_rigid_motions(modes, fixed):
    """An orthonormal basis (nmodes, k) of the rigid motions (coordinates in
    the columns of ``modes``, :func:`~adhesive_contact.fem.dirichlet.rigid_modes`)
    that vanish at the held dofs ``fixed``: those the held sides leave free."""
    return _null_space(modes[fixed], modes.shape[1])


def _null_space(B, n, rtol=1e-8, atol=0.0):
    """An orthonormal basis (n, k) of the null space of B (m, n): the
    singular values up to ``rtol`` times the largest, or up to ``atol``,
    count as zero."""
    if B.shape[0] == 0 or n == 0:
        return np.eye(n)
    _, sv, vt = np.linalg.svd(B, full_matrices=True)
    rank = int((sv > max(rtol * sv[0], atol, 1e-300)).sum()) if sv.size else 0
    return vt[rank:].T


def restraining_rows(modes, boundary, normal, wall, tangential):
    """The rows (m, nmodes) through which the contact terms see a rigid
    motion: u_ν of the motion at the quadrature points of Γ_C where a normal
    law acts (``normal``), its nodal u_ν where the wall acts (``wall``, a
    bool per contact node: a finite gap), and u_τ at the points where a
    friction law acts (``tangential``). A motion these rows map to zero
    changes none of the contact terms: nothing restrains it.

    Parameters
    ----------
    modes : (ndofs, nmodes), the rigid motions at every dof
    boundary : ContactBoundary
    normal, tangential : bool, whether a normal law / a friction law acts
    wall : (nc,) bool
    """
    d = boundary.dim
    at_nodes = modes[boundary.dofs.ravel()].reshape(boundary.nodes.size, d, -1)
    # the frame components z_a = R_aᵀ m_a of each motion, node-major (nc·d, nmodes)
    z = np.einsum("aic,aim->acm", boundary.frame, at_nodes).reshape(-1, modes.shape[1])
    rows = []
    if normal:
        rows.append(boundary.normal_trace @ z)
    if np.any(wall):
        rows.append(z[np.flatnonzero(wall) * d])
    if tangential:
        rows += [trace @ z for trace in boundary.tangential_trace]
    return np.concatenate(rows) if rows else np.zeros((0, modes.shape[1]))


def check_rigid_motions(mesh, fixed, sides, contact=None):
    """Refuse a scene that leaves a rigid motion of a part of the body free
    (:func:`_check_motions`), each connected part of the mesh on its own (a
    file mesh may have several: one that nothing holds makes the stiffness
    singular). ``contact``: (``rows``, the phrase naming the contact terms),
    ``rows(modes)`` the rows through which the contact terms see the rigid
    motions ``modes`` (:func:`restraining_rows`)."""
    parts = mesh_parts(mesh)
    if parts.max() == 0:
        _check_motions(rigid_modes(mesh.p), mesh.p, fixed, sides, contact)
        return
    d = mesh.dim()
    for part in range(parts.max() + 1):
        nodes = np.flatnonzero(parts == part)
        own = rigid_modes(mesh.p[:, nodes])                     # (len(nodes)·d, nmodes)
        modes = np.zeros((mesh.p.shape[1], d, own.shape[1]))    # the part's motions, 0 elsewhere
        modes[nodes] = own.reshape(nodes.size, d, -1)
        try:
            _check_motions(modes.reshape(-1, own.shape[1]), mesh.p[:, nodes], fixed, sides,
                           contact)
        except SceneError as err:
            centre = mesh.p[:, nodes].mean(axis=1)
            raise SceneError("boundary", f"the part of the mesh around {where(centre)} "
                             f"({nodes.size} nodes, not connected to the rest): "
                             f"{str(err).removeprefix('boundary: ')}") from None


def mesh_parts(mesh):
    """The connected part of each node (0, 1, ...; nodes of no cell apart)."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    t = mesh.t
    rows = np.repeat(t[:1], t.shape[0] - 1, axis=0).ravel()
    graph = coo_matrix((np.ones(rows.size), (rows, t[1:].ravel())),
                       shape=(mesh.p.shape[1],) * 2)
    return connected_components(graph, directed=False)[1]


def _check_motions(modes, points, fixed, sides, contact=None):
    """Refuse a rigid motion among ``modes`` (of the body, or of one part at
    ``points``) that vanishes at the held dofs ``fixed`` and, with
    ``contact`` (see :func:`check_rigid_motions`), changes none of the
    contact terms. The message lists exactly the motions left free
    (:func:`describe_motions`)."""
    free = free_rigid_motions(modes, fixed)
    if contact is not None and free.shape[1]:
        rows, terms = contact
        seen = rows(modes)
        free = free @ _null_space(seen @ free, free.shape[1])
    if free.shape[1] == 0:
        return
    motions = describe_motions(free, points)
    held = ", ".join(sides) or "none"
    if contact is None:
        start = f"the held sides ({held}) leave the body free to move rigidly"
        cure = ""
    else:
        start = (f"the held sides ({held}) and the contact terms on Γ_C ({contact[1]}) "
                 "leave the body free to move rigidly")
        cure = (", or add a contact term that restrains it (friction a tangential motion, "
                "a normal law or a wall a normal one)")
    raise SceneError("boundary", f"{start} ({', '.join(motions)}): hold more components, "
                     "e.g. list a side in boundary.dirichlet or give \"0\" for the missing "
                     f"component on a side of [boundary.displacement]{cure} (a single held "
                     "point does not stop a rotation: hold a component along a side)")


_AXES = "xyz"
#: a rotation part below this (mode coordinates: the displacement of the
#: farthest point per unit motion) is round-off, not a rotation
ROTATION_TOL = 1e-8


def _direction(v, digits=3):
    """'x' for ±e_x (likewise y, z), else the unit vector's components."""
    v = v / np.linalg.norm(v)
    k = int(np.argmax(np.abs(v)))
    if abs(abs(v[k]) - 1.0) < 1e-8:
        return _AXES[k]
    v = v * np.sign(v[k])
    return "(" + ", ".join(f"{c:.{digits}g}" for c in v) + ")"


def _point(p, scale):
    """A point's coordinates, round-off below 1e-10 of the body's size shown as 0."""
    p = np.where(np.abs(p) < 1e-10 * scale, 0.0, p)
    return "(" + ", ".join(f"{c + 0.0:.4g}" for c in p) + ")"


def describe_motions(free, points):
    """The rigid motions of the span of ``free`` (nmodes, k), coordinates of
    :func:`~adhesive_contact.fem.dirichlet.rigid_modes` at ``points``
    (d, m), in words, one per dimension of the span: first the
    translations in it, then its rotations, each about the point (2D) or
    the axis (3D) nearest the centroid; "rotation" alone when every
    translation is free too (any centre will do)."""
    d = points.shape[0]
    centre = points.mean(axis=1)
    scale = max(np.abs(points - centre[:, None]).max(), 1e-300)
    t, w = free[:d], free[d:] / scale   # u(x) = t + W (x − centre), W of w
    # the columns of ``free`` are unit vectors of mode coordinates, whose
    # rotations move the farthest point by their size: a rotation part of
    # round-off size (1e-16, what an SVD leaves of a pure translation) is
    # no rotation, whatever the largest rotation part of the span (a
    # relative test made it one, about an axis through a point 1e15 away)
    only_translations = _null_space(free[d:], free.shape[1], atol=ROTATION_TOL)   # (k, kt)
    translations = _orthonormal(t @ only_translations)
    words = [f"translation along {_direction(e)}" for e in translations.T]
    rest = (_null_space(only_translations.T, free.shape[1]) if only_translations.shape[1]
            else np.eye(free.shape[1]))
    if rest.shape[1] == 0:
        return words
    tr, wr = t @ rest, w @ rest
    # remove from each rotation the free translations (centre nearest the centroid)
    tr = tr - translations @ (translations.T @ tr) if translations.size else tr
    every = translations.shape[1] == d
    if d == 2:
        omega = wr[0, 0]
        if every:
            return words + ["rotation"]
        p = centre + np.array([-tr[1, 0], tr[0, 0]]) / omega
        return words + [f"rotation about {_point(p, scale)}"]
    axes = _orthonormal(wr)
    if every:
        return words + [f"rotation about {_direction(a)}" for a in axes.T]
    for a in axes.T:
        # the motion of this axis: the combination of rest whose w is a
        combo = np.linalg.lstsq(wr, a, rcond=None)[0]
        tv = tr @ combo
        p = centre + np.cross(a, tv)          # the point of the axis nearest the centre
        pitch = float(tv @ a)
        word = f"rotation about the axis along {_direction(a)} through {_point(p, scale)}"
        if abs(pitch) > 1e-8 * max(np.linalg.norm(tv), 1.0) * scale:
            word += f" with a shift {pitch:.3g} along it per radian"
        words.append(word)
    return words


def _orthonormal(v, rtol=1e-8):
    """An orthonormal basis of the span of the columns of v (d, k)."""
    if v.size == 0:
        return np.zeros((v.shape[0], 0))
    u, sv, _ = np.linalg.svd(v, full_matrices=False)
    keep = sv > rtol * max(sv[0], 1e-300)
    basis = u[:, keep]
    # prefer the coordinate axes when the span holds them (e.g. x and y, not their mix)
    picked = []
    for e in np.eye(v.shape[0]):
        inside = basis @ (basis.T @ e)
        if np.linalg.norm(inside - e) < 1e-8:
            picked.append(e)
    if len(picked) == basis.shape[1]:
        return np.stack(picked, axis=1)
    return basis


# ---------------------------------------------------------------- geometry


def check_gap(gap, x, times):
    """The gap expression's values (N+1, nc) at the contact nodes ``x`` (d, nc)
    are finite and ≥ 0."""
    bad = ~(np.isfinite(gap) & (gap >= 0))
    if bad.any():
        n, a = np.argwhere(bad)[0]
        raise SceneError("contact.gap", f"must be finite and >= 0 on Γ_C, got "
                         f"{gap[n, a]:g} at {where(x, a, times[n])}")


def check_outside_foundation(x, depth):
    """No contact node ``x`` (d, nc) starts inside the foundation (``depth``,
    the signed distance from its surface, negative inside)."""
    inside = depth < -1e-12 * (1.0 + np.abs(x).max())
    if inside.any():
        a = int(np.argmax(inside))
        raise SceneError("contact.foundation", f"the contact node {where(x, a)} lies inside "
                         "the foundation; the body must start outside it")


#: the largest sphere or cylinder radius over the body's diameter: its
#: distance |x − c| − r loses about r·1e-16 to round-off, which must stay
#: far below the contact states' tolerance of 1e-8 of the diameter
MAX_FOUNDATION_RADIUS = 1e6


def check_foundation_beside_body(spec, mesh, signed_distance):
    """The foundation ``spec`` lies beside the body, not in it: no node of
    the mesh inside it, and a sphere's or cylinder's centre point not inside
    a cell; its radius at most MAX_FOUNDATION_RADIUS diameters of the body
    (a sphere of radius 1e17 and a disc inside the body were accepted)."""
    p = mesh.p
    diameter = float(np.linalg.norm(p.max(axis=1) - p.min(axis=1)))
    if spec.shape != "plane" and spec.radius > MAX_FOUNDATION_RADIUS * diameter:
        raise SceneError("contact.foundation.radius", f"is {spec.radius:g}, more than "
                         f"{MAX_FOUNDATION_RADIUS:g} times the body's diameter {diameter:g}, "
                         "where the distance to it is lost to round-off; use shape = "
                         "\"plane\" for so flat a foundation")
    depth = signed_distance(spec, p)
    inside = depth < -1e-12 * (1.0 + np.abs(p).max())
    if inside.any():
        a = int(np.argmax(inside))
        raise SceneError("contact.foundation", f"the mesh node {where(p, a)} lies inside the "
                         "foundation; the body must start outside it")
    if spec.shape != "plane" and _in_a_cell(mesh, np.asarray(spec.point, dtype=float)):
        raise SceneError("contact.foundation.point", f"{where(np.asarray(spec.point))} lies "
                         "inside the body: the foundation must lie beside it, outside it")


def _in_a_cell(mesh, point):
    """Whether ``point`` (d,) lies in a simplex of ``mesh`` (barycentric
    coordinates ≥ 0 in one cell; vectorised over the cells)."""
    v = mesh.p[:, mesh.t]                           # (d, d+1, ncells)
    edges = v[:, 1:, :] - v[:, :1, :]                # (d, d, ncells)
    rhs = point[:, None] - v[:, 0, :]                # (d, ncells)
    with np.errstate(all="ignore"):
        lam = np.linalg.solve(np.moveaxis(edges, -1, 0), rhs.T[:, :, None])[:, :, 0]
    tol = 1e-12
    return bool(np.any((lam >= -tol).all(axis=1) & (lam.sum(axis=1) <= 1.0 + tol)))


def check_beta0(beta0):
    """β_0^h in [0, 1] on every contact facet."""
    if not np.all((beta0 >= 0) & (beta0 <= 1)):
        raise SceneError("contact.bonding.beta0", "must lie in [0, 1] on Γ_C")


def check_probes(basis, points):
    """Every probe point (d, nprobes) lies in the mesh of the scalar ``basis``."""
    for i in range(points.shape[1]):
        try:
            basis.probes(points[:, i:i + 1])
        except ValueError:
            raise SceneError(f"output.probes[{i}]", f"point {where(points, i)} "
                             "is outside the mesh") from None
