"""Checks that a scene's expressions are finite where the scheme uses them.

An expression can be well formed and still give ±inf or NaN (``9**9**9``,
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
"""

import numpy as np

from ..expressions import coordinates
from ..scene import SceneError

#: time levels sampled besides t = 0 and t = T
TIME_SAMPLES = 16
#: lags of the memory kernel checked one by one (more are sampled)
KERNEL_LAGS = 10**6


def sample_times(times, count=TIME_SAMPLES):
    """t_0, t_N and about ``count`` evenly spaced levels between them."""
    n = times.size - 1
    picks = np.unique(np.round(np.linspace(0, n, min(n + 1, count + 2))).astype(np.int64))
    return times[picks]


def _where(points, index):
    return ", ".join(f"{c:g}" for c in points[:, index])


def check_values(key, values, points, t, what="is not finite"):
    """Raise SceneError at the first entry of ``values`` (one per column of
    ``points`` (d, n)) that is not finite."""
    bad = ~np.isfinite(values)
    if bad.any():
        i = int(np.flatnonzero(bad)[0])
        raise SceneError(key, f"{what}: {values[i]:g} at ({_where(points, i)}), t = {t:g}")


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
