"""What the figures of a run draw: at which time levels, along which axis
of Γ_C, and on which colour scale.

- :func:`plot_levels`: the levels of ``[output] plot_times``, or by default
  ("auto") those where the run's activity is, and the last one. The
  activity of step n is

      a_n = Σ_f |f| |β_n − β_{n−1}|_f / |Γ_C|           (the glue breaking)
          + #{contact nodes whose state changes} / n_c    (contact states)
          + |r_n − r_{n−1}| / max_m |r_m|                 (the reactions)
          + |F_n − F_{n−1}| / max_m |F_m|                 (the contact forces),

  and the levels drawn are where its running sum crosses the quantiles
  (j − ½)/(count − 1) of its total, j = 1..count−1, plus the last level: a
  glue that breaks between t = 0.9 and 1.2 of T = 10 is drawn there, not at
  t = 2, 4, … 10. A run without any change gets evenly spread levels.
- :func:`contact_axis`: the coordinate axis along which Γ_C extends most,
  by the facet-measure weighted spread of its facets' midpoints (a few
  facets of a chamfer or a rounded edge do not decide it, as they would
  the range max − min).
- :func:`run_scale` and :func:`floored`: a colour scale set by the run's
  largest value over all levels, and values below FLOOR times it drawn
  as zero (round-off, not a field: a colour bar from 0 to 1e-10 with an
  offset text says nothing).
"""

import numpy as np

from ..postprocess import contact_state_codes

#: the levels a figure draws by default (the last included)
PLOT_LEVELS = 5
#: values below FLOOR times the run's largest are drawn as zero
FLOOR = 1e-8


def even_levels(steps, count=PLOT_LEVELS):
    """About ``count`` levels spread evenly over 1..N, N included."""
    levels = np.round(np.linspace(steps / count, steps, count)).astype(int)
    return np.unique(np.clip(levels, 0, steps))


def nearest_levels(t, times):
    """The level nearest to each of ``times`` among the computed ``t``
    (times beyond the last level computed, by more than half a step, are
    dropped: a run that stopped early)."""
    t = np.asarray(t, dtype=float)
    half = 0.5 * (t[1] - t[0]) if t.size > 1 else 0.0
    times = np.asarray([s for s in times if s <= t[-1] + half], dtype=float)
    if times.size == 0:
        return np.array([t.size - 1])
    return np.unique(np.abs(t[None, :] - times[:, None]).argmin(axis=1))


def _relative_change(values):
    """|v_n − v_{n−1}| / max_m |v_m| for n = 1..M (zero where v is zero)."""
    values = np.asarray(values, dtype=float).reshape(len(values), -1)
    size = np.linalg.norm(values, axis=1).max(initial=0.0)
    if values.shape[0] < 2 or size == 0.0:
        return np.zeros(max(values.shape[0] - 1, 0))
    return np.linalg.norm(np.diff(values, axis=0), axis=1) / size


def activity(solution):
    """a_n of the module docstring for n = 1..M, (M,)."""
    problem = solution.problem
    steps = solution.t.size - 1
    total = np.zeros(steps)
    if steps < 1:
        return total
    boundary = problem.boundary
    if boundary is not None and boundary.facets.size:
        measure = boundary.measure
        total += np.abs(np.diff(solution.beta, axis=0)) @ measure / measure.sum()
    if boundary is not None and boundary.nodes.size:
        codes = contact_state_codes(solution)
        total += (np.diff(codes, axis=0) != 0).mean(axis=1)
        total += _relative_change(solution.contact_force)
    if solution.reaction is not None and solution.reaction.shape[1]:
        total += _relative_change(solution.reaction)
    return total


def active_levels(solution, count=PLOT_LEVELS):
    """``count`` − 1 levels where the running sum of :func:`activity`
    crosses its quantiles, and the last level (evenly spread levels for a
    run without activity)."""
    steps = solution.t.size - 1
    a = activity(solution)
    if steps < 1 or not a.sum() > 0:
        return even_levels(steps, count)
    running = np.cumsum(a) / a.sum()
    quantiles = (np.arange(1, count) - 0.5) / max(count - 1, 1)
    picks = 1 + np.searchsorted(running, quantiles)       # a_n is step n = index + 1
    return np.unique(np.clip(np.append(picks, steps), 0, steps))


def plot_levels(solution, count=PLOT_LEVELS):
    """The levels a figure draws: those of the scene's ``output.plot_times``
    (:func:`nearest_levels`), or with "auto" :func:`active_levels`."""
    times = getattr(solution.problem.scene, "plot_times", "auto")
    if times == "auto":
        return active_levels(solution, count)
    return nearest_levels(solution.t, times)


def automatic(solution):
    """Whether the scene leaves its plot times to :func:`plot_levels`."""
    return getattr(solution.problem.scene, "plot_times", "auto") == "auto"


def thinned(levels, most):
    """At most ``most`` of ``levels``, evenly among them, the last kept."""
    levels = np.asarray(levels)
    if levels.size <= most:
        return levels
    return levels[np.unique(np.round(np.linspace(0, levels.size - 1, most)).astype(int))]


def contact_axis(problem):
    """The axis (0, 1, 2) along which Γ_C extends most: the largest
    facet-measure weighted standard deviation of the facet midpoints."""
    boundary = problem.boundary
    if boundary is None or boundary.facets.size == 0:
        return 0
    mid = problem.mesh.p[:, boundary.facet_nodes].mean(axis=1)      # (d, nf)
    weight = boundary.measure / boundary.measure.sum()
    mean = mid @ weight
    spread = ((mid - mean[:, None]) ** 2) @ weight
    return int(np.argmax(spread))


def run_scale(values):
    """The largest |value| over all levels of a run (NaN ignored): the
    scale a figure's colour bars share."""
    values = np.asarray(values, dtype=float)
    return float(np.abs(values[np.isfinite(values)]).max(initial=0.0))


def floored(values, largest, reference=0.0):
    """``values`` with every |v| below FLOOR · max(largest, reference) set
    to 0 (round-off drawn as zero; NaN kept)."""
    values = np.array(values, dtype=float)
    floor = FLOOR * max(largest, reference)
    values[np.abs(values) < floor] = 0.0
    return values


def colour_limits(largest, symmetric=False, reference=0.0):
    """(lo, hi) of a colour bar on the run's scale: [0, largest] or
    [−largest, largest]; a run whose largest value is below FLOOR times
    ``reference`` (round-off only) gets [0, FLOOR · reference] or [0, 1]."""
    top = largest if largest > FLOOR * reference else max(FLOOR * reference, 0.0)
    if top == 0.0:
        top = 1.0
    return (-top, top) if symmetric else (0.0, top)
