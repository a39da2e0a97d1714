"""``contact_map.png`` (3D): colour maps of β, the normal traction and the
slip over Γ_C at several times."""

import matplotlib.pyplot as plt
import numpy as np
from matplotlib.tri import Triangulation

from ..postprocess import normal_traction
from .common import AXES, Units, save_figure, solution_title, tidy_3d_axes
from .levels import colour_limits, floored, plot_levels, run_scale, thinned


def plane_coordinates(points, tol=1e-9):
    """In-plane coordinates (2, n) and axis names of points (3, n) lying on
    one plane, or None when they do not (a curved Γ_C).

    An axis-aligned plane keeps the two other coordinate axes (bottom y = 0
    is drawn in (x, z)); a slanted one uses the plane's principal directions."""
    centred = points - points.mean(axis=1, keepdims=True)
    extent = float(np.abs(centred).max(initial=0.0))
    _, sing, vt = np.linalg.svd(centred.T, full_matrices=False)
    if extent == 0.0 or sing[-1] > tol * extent * np.sqrt(points.shape[1]):
        return None
    normal = vt[-1]
    axis = int(np.argmax(np.abs(normal)))
    if abs(abs(normal[axis]) - 1.0) < tol:
        keep = [a for a in range(3) if a != axis]
        return points[keep], [AXES[a] for a in keep]
    return vt[:2] @ centred, ["s₁ (in the plane of Γ_C)", "s₂ (in the plane of Γ_C)"]


def facet_values_of_nodes(problem, nodal):
    """Facet means (nf,) of values at the contact nodes, over the facet's
    contact nodes (clamped vertices carry none)."""
    boundary = problem.boundary
    local = np.full(problem.mesh.p.shape[1], -1)
    local[boundary.nodes] = np.arange(boundary.nodes.size)
    which = local[boundary.facet_nodes]                        # (d, nf)
    have = which >= 0
    values = np.where(have, np.asarray(nodal)[np.where(have, which, 0)], 0.0)
    count = have.sum(axis=0)
    return np.where(count > 0, values.sum(axis=0) / np.maximum(count, 1), np.nan)


#: the most levels (rows) the map draws
MAP_LEVELS = 4


def figure_contact_map(solution):
    """3D: β, the normal traction and the slip over Γ_C at several times.

    One row per level of :func:`~.levels.plot_levels` (at most
    MAP_LEVELS, the last included), three colour maps per row, one value
    per contact facet: β (its P0 value), the normal traction −σ_ν
    (compression > 0) and the slip |u_τ| (both nodal, averaged over the
    facet's contact nodes). Each column has one colour scale for all rows,
    set by the run's largest value over all its levels; values below
    :data:`~.levels.FLOOR` times it are drawn as zero (round-off). A plane
    Γ_C is drawn flat in its own coordinates, a curved one in 3D.

    Parameters
    ----------
    solution : adhesive_contact.Solution
        Of a 3D scene with contact facets.

    Returns
    -------
    matplotlib.figure.Figure
    """
    problem = solution.problem
    units = Units.of(solution)
    boundary = problem.boundary
    mesh = problem.mesh
    levels = thinned(plot_levels(solution, MAP_LEVELS), MAP_LEVELS)
    traction = normal_traction(solution)                                   # (M+1, nc)
    slip = np.linalg.norm(solution.frame_displacement[:, :, 1:], axis=2)   # (M+1, nc)
    # slips below FLOOR of the run's largest displacement at Γ_C are round-off
    reference = run_scale(solution.frame_displacement)
    scales = (1.0, run_scale(traction), max(run_scale(slip), 0.0))
    columns = [
        ("bonding β", lambda n: solution.beta[n], "viridis", (0.0, 1.0)),
        (f"normal traction −σ_ν\n(> 0 compression; {units.stress})",
         lambda n: facet_values_of_nodes(problem, floored(traction[n], scales[1])),
         "coolwarm", colour_limits(scales[1], symmetric=True)),
        (f"slip |u_τ| ({units.length})",
         lambda n: facet_values_of_nodes(problem, floored(slip[n], scales[2], reference)),
         "magma", colour_limits(scales[2], reference=reference)),
    ]
    used = np.unique(boundary.facet_nodes)
    flat = plane_coordinates(mesh.p[:, used])
    rows = levels.size
    fig = plt.figure(figsize=(15, 1.0 + 3.6 * rows), layout="constrained")
    grid = fig.add_gridspec(rows, 3)
    for j, (label, values_at, cmap, limits) in enumerate(columns):
        norm = plt.Normalize(*limits)
        axes = []
        for i, n in enumerate(levels):
            values = values_at(n)
            axes.append(_draw_facets(fig, grid[i, j], problem, flat, used, values, cmap,
                                     norm, units))
            axes[-1].set_title(f"t = {solution.t[n]:.4g}", fontsize="small")
        bar = fig.colorbar(plt.cm.ScalarMappable(norm=norm, cmap=cmap), ax=axes,
                           shrink=0.8, location="bottom", label=label)
        bar.formatter.set_useOffset(False)
        bar.update_ticks()
    shape = ("Γ_C flattened (a plane)" if flat is not None else
             f"Γ_C in 3D (curved; x, y, z in {units.length})")
    fig.suptitle(f"{solution_title(solution)}\non {shape}, one row per time level",
                 fontsize="medium")
    return fig


def _draw_facets(fig, cell, problem, flat, used, values, cmap, norm, units):
    """One colour map of facet ``values`` into the grid cell; its axes."""
    from mpl_toolkits.mplot3d.art3d import Poly3DCollection

    boundary, mesh = problem.boundary, problem.mesh
    filled = np.nan_to_num(values, nan=norm.vmin)
    if flat is not None:
        coords, names = flat
        position = np.full(mesh.p.shape[1], -1)
        position[used] = np.arange(used.size)
        ax = fig.add_subplot(cell)
        tri = Triangulation(coords[0], coords[1], position[boundary.facet_nodes].T)
        ax.tripcolor(tri, facecolors=filled, cmap=cmap, norm=norm, shading="flat")
        ax.triplot(tri, color="k", linewidth=0.15, alpha=0.3)
        ax.set(aspect="equal", xlabel=f"{names[0]} ({units.length})",
               ylabel=f"{names[1]} ({units.length})")
        return ax
    ax = fig.add_subplot(cell, projection="3d")
    polys = mesh.p[:, boundary.facet_nodes].transpose(2, 1, 0)
    colours = plt.get_cmap(cmap)(norm(filled))
    ax.add_collection3d(Poly3DCollection(polys, facecolors=colours, edgecolors="k",
                                         linewidths=0.05))
    low, high = mesh.p[:, used].min(axis=1), mesh.p[:, used].max(axis=1)
    ax.set(xlim=(low[0], high[0]), ylim=(low[1], high[1]), zlim=(low[2], high[2]))
    tidy_3d_axes(ax, nbins=3)   # three small panels side by side
    ax.set_box_aspect(np.maximum(high - low, 1e-3 * (high - low).max()))
    return ax


def plot_contact_map(solution, path):
    """``contact_map.png``: :func:`figure_contact_map` saved into ``path``
    (at the size of its constrained layout)."""
    save_figure(figure_contact_map(solution), path, bbox_inches=None)
