"""``beta.png``: the bonding β along Γ_C at a few time levels, as a
space-time image, and its mean, min and max over Γ_C in time."""

import matplotlib.pyplot as plt
import numpy as np

from ..postprocess import beta_mean
from .common import AXES, Units, facet_midpoints, save_figure, solution_title
from .levels import automatic, contact_axis, plot_levels


def _time_edges(t):
    """Cell edges in time around the levels t_n (half a step beyond the ends)."""
    t = np.asarray(t, dtype=float)
    if t.size == 1:
        return np.array([t[0] - 0.5, t[0] + 0.5])
    mid = 0.5 * (t[1:] + t[:-1])
    return np.concatenate([[2 * t[0] - mid[0]], mid, [2 * t[-1] - mid[-1]]])


def beta_space_time(problem, beta, length="units of length"):
    """β on a space-time grid: (x edges, β image (N+1, nx), x label).

    2D: one column per contact facet, the facets ordered along the axis of
    largest spread; the columns are the facets' own intervals when these
    tile a segment (a straight side), else equal widths of the facet
    measures laid end to end (arc length in that order). 3D: the facets are
    binned by their midpoint along that axis and β is the measure-weighted
    mean over each bin (an average across the width of Γ_C). ``length``
    names the unit of length in the label."""
    boundary = problem.boundary
    mid = facet_midpoints(problem)
    axis = contact_axis(problem)
    name = AXES[axis]
    ends = problem.mesh.p[axis][boundary.facet_nodes]     # (d, nf)
    if problem.dim == 2:
        order = np.argsort(mid[axis], kind="stable")
        lo, hi = ends.min(axis=0)[order], ends.max(axis=0)[order]
        if np.allclose(hi[:-1], lo[1:]):
            edges = np.concatenate([lo[:1], hi])
            return edges, beta[:, order], f"{name} along Γ_C ({length})"
        edges = np.concatenate([[0.0], np.cumsum(boundary.measure[order])])
        return edges, beta[:, order], (f"arc length along Γ_C, facets ordered by {name} "
                                       f"({length})")
    lo, hi = ends.min(), ends.max()
    nbins = int(np.clip(round(np.sqrt(mid.shape[1])), 1, 60))
    edges = np.linspace(lo, hi, nbins + 1)
    which = np.clip(np.searchsorted(edges, mid[axis], side="right") - 1, 0, nbins - 1)
    weight = np.bincount(which, boundary.measure, minlength=nbins)
    levels = beta.shape[0]
    cells = np.arange(levels)[:, None] * nbins + which          # (N+1, nf): level and bin
    sums = np.bincount(cells.ravel(), (boundary.measure * beta).ravel(),
                       minlength=levels * nbins).reshape(levels, nbins)
    image = np.full((levels, nbins), np.nan)
    image[:, weight > 0] = sums[:, weight > 0] / weight[weight > 0]
    return edges, np.ma.masked_invalid(image), (f"{name} of the facet midpoint ({length}); "
                                                "β averaged across Γ_C")


def mean_label(dim):
    """What beta_mean is: the mean of β over Γ_C weighted by each facet's
    length (2D) or area (3D), Σ_f |f| β_f / Σ_f |f|."""
    return f"mean over Γ_C (weighted by facet {'length' if dim == 2 else 'area'})"


def figure_beta(solution):
    """β along Γ_C: curves at a few levels, a space-time image, mean and min in time.

    Left column (sharing the coordinate along Γ_C, the axis along which it
    extends most, :func:`~.levels.contact_axis`): β per facet at the levels
    of :func:`~.levels.plot_levels` (and t = 0 with "auto"), and below it β(x, t) as an image (x horizontally, t vertically,
    colour β in [0, 1]) with the β = 1/2 contour when debonding reaches it.
    Right column: the facet-measure weighted mean, the min and the max of β
    in time.

    Parameters
    ----------
    solution : adhesive_contact.Solution
        Of a scene with contact facets.

    Returns
    -------
    matplotlib.figure.Figure
    """
    problem = solution.problem
    units = Units.of(solution)
    mid = facet_midpoints(problem)
    axis = contact_axis(problem)
    order = np.argsort(mid[axis], kind="stable")
    x = mid[axis, order]
    levels = plot_levels(solution)
    if automatic(solution):   # β_0 too: what the glue starts from
        levels = np.unique(np.concatenate([[0], levels]))
    colours = plt.cm.viridis(np.linspace(0.0, 0.9, levels.size))
    fig = plt.figure(figsize=(12.5, 8.5))
    # columns: curves / image, colorbar, a spacer for its labels, history
    grid = fig.add_gridspec(2, 4, width_ratios=[3.0, 0.1, 0.45, 2.0], height_ratios=[1, 1.25],
                            wspace=0.05, hspace=0.3)
    curves = fig.add_subplot(grid[0, 0])
    image_ax = fig.add_subplot(grid[1, 0])
    bar_ax = fig.add_subplot(grid[1, 1])
    history = fig.add_subplot(grid[:, 3])
    edges, image, xlabel = beta_space_time(problem, solution.beta, units.length)
    tiled = problem.dim == 2 and "arc length" not in xlabel   # edges are coordinates
    for n, colour in zip(levels, colours):
        if tiled:
            # baseline None: no vertical lines down to 0 at the two ends
            curves.stairs(image[n], edges, baseline=None, color=colour, linewidth=1.5,
                          label=f"t = {solution.t[n]:.4g}")
        elif problem.dim == 2:
            curves.plot(x, solution.beta[n, order], drawstyle="steps-mid", color=colour,
                        label=f"t = {solution.t[n]:.4g}")
        else:
            curves.plot(x, solution.beta[n, order], ".", color=colour,
                        label=f"t = {solution.t[n]:.4g}")
    curves.set(ylabel="bonding β\n(1 = fully bonded, 0 = debonded)", ylim=(-0.05, 1.05))
    curves.set_xlabel(f"{AXES[axis]} along Γ_C ({units.length})" if tiled else
                      f"{AXES[axis]} of the facet midpoint ({units.length})")
    curves.set_title("β per contact facet at a few time levels", fontsize="medium")
    curves.legend(fontsize="small", title="time level", loc="lower left")
    curves.grid(True, color="0.9", linewidth=0.6)

    t_edges = _time_edges(solution.t)
    mesh = image_ax.pcolormesh(edges, t_edges, image, cmap="viridis", vmin=0.0, vmax=1.0,
                               shading="flat", rasterized=True)
    if tiled:
        curves.set_xlim(edges[0], edges[-1])   # the image's x range
    centres = 0.5 * (edges[1:] + edges[:-1])
    data = np.ma.filled(np.ma.asarray(image, dtype=float), np.nan)
    if (centres.size > 1 and solution.t.size > 1 and np.nanmin(data) < 0.5
            and np.nanmax(data) > 0.5):
        front = image_ax.contour(centres, solution.t, data, levels=[0.5], colors="w",
                                 linewidths=1.2)
        image_ax.clabel(front, fmt="β = 1/2", fontsize="small")
    image_ax.set(xlabel=xlabel, ylabel=units.time, ylim=(t_edges[0], t_edges[-1]))
    image_ax.set_title("β(x, t) on Γ_C (one row per time level)", fontsize="medium")
    fig.colorbar(mesh, cax=bar_ax, label="bonding β")

    history.plot(solution.t, beta_mean(solution), "-", label=mean_label(problem.dim))
    history.plot(solution.t, solution.beta.min(axis=1), "--", label="min over Γ_C")
    history.plot(solution.t, solution.beta.max(axis=1), ":", color="0.5",
                 label="max over Γ_C")
    history.set(xlabel=units.time, ylabel="bonding β", ylim=(-0.05, 1.05))
    history.yaxis.set_label_position("right")
    history.yaxis.tick_right()
    history.set_title("β over Γ_C in time", fontsize="medium")
    history.legend(fontsize="small", loc="lower left")
    history.grid(True, color="0.9", linewidth=0.6)
    bonding = problem.scene.contact.bonding.law
    frozen = " (bonding law 'none': β frozen at β_0)" if bonding == "none" else ""
    fig.suptitle(f"{solution_title(solution)}{frozen}\nbonding β along Γ_C",
                 fontsize="medium")
    return fig


def plot_beta(solution, path):
    """``beta.png``: :func:`figure_beta` saved into ``path``."""
    save_figure(figure_beta(solution), path)
