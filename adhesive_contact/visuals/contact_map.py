"""``contact_map.png`` (3D): colour maps of β, the normal traction and the
slip over Γ_C at the final time."""

import matplotlib.pyplot as plt
import numpy as np
from matplotlib.tri import Triangulation

from ..postprocess import normal_traction
from .common import AXES, Units, save_figure, solution_title, tidy_3d_axes


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


def figure_contact_map(solution):
    """3D: β, the normal traction and the slip over Γ_C at the final time.

    Three colour maps, one value per contact facet: β (its P0 value), the
    normal traction −σ_ν (compression > 0) and the slip |u_τ| (both nodal,
    averaged over the facet's contact nodes). A plane Γ_C is drawn flat in
    its own coordinates, a curved one in 3D.

    Parameters
    ----------
    solution : adhesive_contact.Solution
        Of a 3D scene with contact facets.

    Returns
    -------
    matplotlib.figure.Figure
    """
    from mpl_toolkits.mplot3d.art3d import Poly3DCollection

    problem = solution.problem
    units = Units.of(solution)
    boundary = problem.boundary
    mesh = problem.mesh
    n = solution.t.size - 1
    fields = [
        ("bonding β", solution.beta[n], "viridis", (0.0, 1.0)),
        (f"normal traction −σ_ν\n(> 0 compression; {units.stress})",
         facet_values_of_nodes(problem, normal_traction(solution)[n]), "coolwarm", None),
        (f"slip |u_τ| ({units.length})",
         facet_values_of_nodes(problem, np.linalg.norm(
             solution.frame_displacement[n, :, 1:], axis=1)), "magma", None),
    ]
    used = np.unique(boundary.facet_nodes)
    flat = plane_coordinates(mesh.p[:, used])
    fig = plt.figure(figsize=(15, 4.8))
    for i, (label, values, cmap, limits) in enumerate(fields):
        finite = values[np.isfinite(values)]
        if limits is None:
            lo, hi = (finite.min(), finite.max()) if finite.size else (0.0, 1.0)
            if cmap == "coolwarm":
                lo = -max(abs(lo), abs(hi), 1e-300)
                hi = -lo
            limits = (lo, hi if hi > lo else lo + 1e-12)
        norm = plt.Normalize(*limits)
        if flat is not None:
            coords, names = flat
            position = np.full(mesh.p.shape[1], -1)
            position[used] = np.arange(used.size)
            ax = fig.add_subplot(1, 3, i + 1)
            tri = Triangulation(coords[0], coords[1], position[boundary.facet_nodes].T)
            image = ax.tripcolor(tri, facecolors=np.nan_to_num(values, nan=limits[0]),
                                 cmap=cmap, norm=norm, shading="flat")
            ax.triplot(tri, color="k", linewidth=0.15, alpha=0.3)
            ax.set(aspect="equal", xlabel=f"{names[0]} ({units.length})",
                   ylabel=f"{names[1]} ({units.length})")
        else:
            ax = fig.add_subplot(1, 3, i + 1, projection="3d")
            polys = mesh.p[:, boundary.facet_nodes].transpose(2, 1, 0)
            colours = plt.get_cmap(cmap)(norm(np.nan_to_num(values, nan=limits[0])))
            ax.add_collection3d(Poly3DCollection(polys, facecolors=colours, edgecolors="k",
                                                 linewidths=0.05))
            low, high = mesh.p[:, used].min(axis=1), mesh.p[:, used].max(axis=1)
            ax.set(xlim=(low[0], high[0]), ylim=(low[1], high[1]), zlim=(low[2], high[2]))
            tidy_3d_axes(ax, nbins=3)   # three small panels side by side
            ax.set_box_aspect(np.maximum(high - low, 1e-3 * (high - low).max()))
            image = plt.cm.ScalarMappable(norm=norm, cmap=cmap)
        fig.colorbar(image, ax=ax, shrink=0.8, location="bottom", pad=0.15, label=label)
    shape = ("Γ_C flattened (a plane)" if flat is not None else
             f"Γ_C in 3D (curved; x, y, z in {units.length})")
    fig.suptitle(f"{solution_title(solution)}\non {shape} at t = {solution.t[n]:g}",
                 fontsize="medium")
    return fig


def plot_contact_map(solution, path):
    """``contact_map.png``: :func:`figure_contact_map` saved into ``path``."""
    save_figure(figure_contact_map(solution), path)
