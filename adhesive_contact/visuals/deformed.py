"""``deformed.png``: the deformed mesh coloured by the von Mises stress, at
the final time in 2D and at the run's plot levels in 3D."""

import matplotlib.pyplot as plt
import numpy as np
from matplotlib.collections import LineCollection
from matplotlib.tri import Triangulation

from ..postprocess import cell_von_mises
from .common import Units, save_figure, solution_title, tidy_3d_axes
from .levels import floored, plot_levels, run_scale, thinned

#: the most levels (panels) the 3D view draws
DEFORMED_LEVELS = 4

#: the von Mises stress of the colour bars: of the whole 3 × 3 stress
VON_MISES = "von Mises stress"


def magnification(points, u):
    """A round factor making max |u| about 10% of the domain's largest extent
    (1 when the displacements are larger than that already).

    Parameters
    ----------
    points : (d, npoints) reference coordinates
    u : (npoints, d) displacements
    """
    extent = float((points.max(axis=1) - points.min(axis=1)).max())
    umax = float(np.linalg.norm(u, axis=1).max(initial=0.0))
    if umax == 0.0 or not np.isfinite(umax):
        return 1.0
    # large displacements are drawn as they are, never shrunk
    return max(1.0, float(f"{0.1 * extent / umax:.2g}"))


def _deformed_2d(fig, ax, solution, factor, units):
    mesh = solution.problem.mesh
    p = mesh.p + factor * solution.u[-1].T
    vm = cell_von_mises(solution, -1)
    tri = Triangulation(p[0], p[1], mesh.t.T)
    image = ax.tripcolor(tri, facecolors=vm, cmap="viridis", shading="flat")
    image.set_clim(*stress_limits(vm))
    ax.triplot(tri, color="k", linewidth=0.2, alpha=0.4)
    outline = mesh.p[:, mesh.facets[:, mesh.boundary_facets()]].transpose(2, 1, 0)
    ax.add_collection(LineCollection(outline, colors="0.4", linestyles="--", linewidths=0.8,
                                     label="reference configuration"))
    boundary = solution.problem.boundary
    if boundary is not None and solution.on_wall[-1].any():
        on = boundary.nodes[solution.on_wall[-1]]
        ax.plot(p[0, on], p[1, on], "o", color="tab:red", markersize=3,
                label="contact nodes on the wall")
    ax.set_aspect("equal")
    ax.set_xlabel(f"x ({units.length})")
    ax.set_ylabel(f"y ({units.length})")
    ax.legend(loc="upper left", bbox_to_anchor=(1.02, 1.0), fontsize="small")
    # below the axes: a colorbar as wide as a flat domain, never taller than it
    bar = fig.colorbar(image, ax=ax, location="bottom", shrink=0.7, aspect=35,
                       label=f"{VON_MISES} (plane strain: σ_zz included; {units.stress})")
    bar.formatter.set_useOffset(False)
    bar.update_ticks()


def _face_values(solution, n, faces, stressed):
    """The colour of each boundary face at level n: the von Mises stress of
    its cell where the level's stress is kept, else |u| at its nodes."""
    mesh = solution.problem.mesh
    if stressed:
        return cell_von_mises(solution, n)[mesh.f2t[0, faces]]
    u = np.linalg.norm(solution.displacement(n), axis=1)
    return u[mesh.facets[:, faces]].mean(axis=0)


def _with_fields(solution, levels):
    """The field levels nearest to ``levels`` (a run written with
    ``[output] every`` > 1 keeps the fields of some levels only), each once."""
    return np.unique([solution.nearest_field_level(n) for n in levels])


def _deformed_3d(fig, solution, factor, units):
    """One panel per level of :func:`~.levels.plot_levels` (at most
    DEFORMED_LEVELS, T last), one colour scale over them, floored at the
    run's largest value (round-off drawn as zero)."""
    from mpl_toolkits.mplot3d.art3d import Poly3DCollection

    mesh = solution.problem.mesh
    levels = thinned(plot_levels(solution), DEFORMED_LEVELS)
    # a streamed run keeps the stress of its last level only: then |u| at every level
    stressed = solution.stress is not None and np.shape(solution.stress)[0] == solution.t.size
    faces = mesh.boundary_facets()
    values = [_face_values(solution, n, faces, stressed) for n in levels]
    top = run_scale(np.concatenate(values))
    norm = plt.Normalize(*stress_limits(np.array([top])))
    axes = []
    for i, (n, value) in enumerate(zip(levels, values)):
        ax = fig.add_subplot(1, levels.size, i + 1, projection="3d")
        p = mesh.p + factor * solution.displacement(n).T
        polys = p[:, mesh.facets[:, faces]].transpose(2, 1, 0)
        colours = plt.cm.viridis(norm(floored(value, top)))
        ax.add_collection3d(Poly3DCollection(polys, facecolors=colours, edgecolors="k",
                                             linewidths=0.1))
        low, high = p.min(axis=1), p.max(axis=1)
        ax.set(xlim=(low[0], high[0]), ylim=(low[1], high[1]), zlim=(low[2], high[2]))
        tidy_3d_axes(ax)
        ax.set_box_aspect(high - low)
        ax.set_title(f"t = {solution.t[n]:.4g}", fontsize="small")
        axes.append(ax)
    mappable = plt.cm.ScalarMappable(norm=norm, cmap="viridis")
    label = (f"{VON_MISES} ({units.stress})" if stressed else
             f"|u| ({units.length}; the stress of a streamed run is kept at T only)")
    bar = fig.colorbar(mappable, ax=axes, shrink=0.7, pad=0.08, location="bottom",
                       label=label)
    bar.formatter.set_useOffset(False)
    bar.update_ticks()
    return axes


def stress_limits(vm):
    """The colour scale of the von Mises stress: from 0 to its largest, a
    scale of 1 when it is zero (no offset text over a nearly constant field)."""
    top = float(np.max(vm, initial=0.0))
    return 0.0, (top if top > 0 else 1.0)


def figure_deformed(solution):
    """The deformed mesh at the final time, coloured by the von Mises stress
    of σ (in 2D with the plane-strain σ_zz).

    2D: the cells at x + f u(T), the reference outline dashed and the
    contact nodes on the wall as red dots; 3D: the boundary faces of the
    deformed body at the levels of :func:`~.levels.plot_levels` (at most
    DEFORMED_LEVELS, one colour scale; |u| where a streamed run kept no
    stress). The factor f is :func:`magnification` (1: to scale), of the
    largest displacement over the levels drawn.

    Parameters
    ----------
    solution : adhesive_contact.Solution

    Returns
    -------
    matplotlib.figure.Figure
    """
    mesh = solution.problem.mesh
    units = Units.of(solution)
    scale_text = "displacements to scale"
    if mesh.dim() == 2:
        factor = magnification(mesh.p, solution.u[-1])
        fig = plt.figure(figsize=(9, 5), layout="constrained")
        ax = fig.add_subplot()
        _deformed_2d(fig, ax, solution, factor, units)
        if factor != 1.0:
            scale_text = f"displacements magnified ×{factor:g}"
        ax.set_title(f"{solution_title(solution)}\ndeformed mesh at t = {solution.t[-1]:g}, "
                     f"{scale_text}", fontsize="medium")
        return fig
    levels = _with_fields(solution, thinned(plot_levels(solution), DEFORMED_LEVELS))
    largest = max(levels, key=lambda n: float(np.abs(solution.displacement(n)).max()))
    factor = magnification(mesh.p, solution.displacement(largest))
    if factor != 1.0:
        scale_text = f"displacements magnified ×{factor:g}"
    fig = plt.figure(figsize=(4.5 * levels.size + 1.0, 5.5), layout="constrained")
    _deformed_3d(fig, solution, factor, units)
    fig.suptitle(f"{solution_title(solution)}\ndeformed mesh, {scale_text}; x, y, z in "
                 f"{units.length}", fontsize="medium")
    return fig


def plot_deformed(solution, path):
    """``deformed.png``: :func:`figure_deformed` saved into ``path``."""
    save_figure(figure_deformed(solution), path)
