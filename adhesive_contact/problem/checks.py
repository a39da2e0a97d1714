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
and a sample of the time levels (:func:`sample_times`: t = 0, t = T and
evenly spaced levels between) and raises
:class:`~adhesive_contact.scene.SceneError` naming the key, the point and
the time of the first value that is not finite. :func:`check_loads`,
:func:`check_kernel` and :func:`check_exact` apply it to the loads at the
quadrature points of the load map, the memory kernel at the lags of the
time grid, and the exact solution at the mesh nodes; ``build_problem``
calls them, since the points come from the geometry.

Held sides. :func:`check_prescribed`: sides that share a dof prescribe one
value there, a held component of a scene with [exact] equals u*, and the
held components leave no rigid motion free (:func:`check_rigid_motions`).

Geometry. :func:`check_gap`, :func:`check_outside_foundation`,
:func:`check_beta0` and :func:`check_probes`.
"""

import numpy as np

from ..expressions import coordinates
from ..fem.dirichlet import rigid_modes
from ..scene.errors import SceneError, where

#: time levels sampled besides t = 0 and t = T
TIME_SAMPLES = 16
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


def check_loads(keyed_fields, loads, times):
    """The loads finite at the quadrature points of the load map (at one
    point for an expression that does not use x, y, z: its value is the
    same everywhere).

    ``keyed_fields`` lists, parallel to ``loads.parts``, the fields to check
    there as (key, field) pairs: a scene's expressions one component at a
    time, so that the key names the component."""
    sample = sample_times(times)
    for fields, (_, load) in zip(keyed_fields, loads.parts):
        for key, field in fields:
            points = load.points if getattr(field, "depends_on_space", True) else load.anchor
            check_finite(key, field, points.reshape(points.shape[0], -1), sample)


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


def check_prescribed(prescribed, scene, mesh):
    """The held components of a scene (a
    :class:`~adhesive_contact.fem.dirichlet.PrescribedDisplacement`) are
    consistent: one value at every dof held by several sides, u* on the
    held sides of a scene with [exact], no rigid motion left free."""
    times = scene.k * np.arange(scene.steps + 1)
    _check_agreement(prescribed.entries, prescribed.fixed, prescribed.count, mesh, times)
    if scene.exact is not None:
        _check_exact_held(prescribed.entries, scene, mesh, times)
    check_rigid_motions(mesh, prescribed.fixed, prescribed.sides)


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


_MOTIONS = {2: ("translation along x", "translation along y", "rotation"),
            3: ("translation along x", "translation along y", "translation along z",
                "rotation about x", "rotation about y", "rotation about z")}


def check_rigid_motions(mesh, fixed, sides):
    """Refuse held dofs ``fixed`` that leave a rigid motion of the body free:
    the rank of the rigid modes restricted to them must be 3 in 2D (two
    translations and the rotation) and 6 in 3D."""
    d = mesh.dim()
    modes = rigid_modes(mesh.p)
    held = modes[fixed]
    nmodes = modes.shape[1]
    if fixed.size:
        _, sv, vt = np.linalg.svd(held, full_matrices=True)
        rank = int((sv > 1e-8 * sv[0]).sum()) if sv.size else 0
    else:
        rank, vt = 0, np.eye(nmodes)
    if rank == nmodes:
        return
    free_modes = vt[rank:]                 # the rigid motions the held dofs leave
    names = [name for k, name in enumerate(_MOTIONS[d])
             if np.abs(free_modes[:, k]).max() > 1e-6]
    raise SceneError("boundary", "the held sides (" + (", ".join(sides) or "none") + ") leave "
                     "the body free to move rigidly (" + ", ".join(names) + "): hold more "
                     "components, e.g. list a side in boundary.dirichlet or give \"0\" for "
                     "the missing component on a side of [boundary.displacement] (a single "
                     "held point does not stop a rotation: hold a component along a side)")


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
