"""PNG figures of a solve: deformed mesh, contact traction and bonding β.

:func:`write_plots` draws ``deformed.png`` always and, when the scene has a
contact boundary, ``contact_traction.png`` and ``beta.png`` (and in 3D
``contact_map.png``: β, the normal traction and the slip over Γ_C); and
``load_displacement.png`` when a side is moved or loaded (the reaction of a
side against its prescribed displacement, the applied force of a loaded
side against its mean displacement). The axes name the units of the
scene's ``[output] units`` (:class:`Units`); a scene without them is
labelled in its own units ("units of length" as in ``mesh.size``, "units
of E" for stresses as in ``material.E``). Each ``figure_*`` function
returns the matplotlib figure (tests read its labels), each ``plot_*``
draws it into a PNG. Matplotlib runs on the Agg backend (no display
needed).
"""

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.collections import LineCollection  # noqa: E402
from matplotlib.ticker import MaxNLocator  # noqa: E402
from matplotlib.tri import Triangulation  # noqa: E402

from adhesive_contact.postprocess import (  # noqa: E402
    beta_mean,
    cell_von_mises,
    normal_traction,
    tangential_traction,
)
from adhesive_contact.postprocess import (  # noqa: E402
    applied_traction,
    prescribed_history,
    reaction_sides,
    reactions,
    side_mean_displacement,
)

AXES = "xyz"
DPI = 120


def tangent_direction(problem):
    """The common tangent τ of the contact nodes, or None if the frames differ.

    A straight contact side in 2D has one tangent; labels can then say
    along which axis a positive σ_τ points."""
    boundary = problem.boundary
    if boundary is None or boundary.nodes.size == 0 or problem.dim != 2:
        return None
    tau = boundary.frame[:, :, 1]
    if not np.allclose(tau, tau[0], atol=1e-9):
        return None
    return tau[0]


def along_axis(points):
    """The coordinate axis (0, 1, 2) along which points (d, n) spread most."""
    points = np.asarray(points)
    if points.shape[1] == 0:
        return 0
    return int(np.argmax(points.max(axis=1) - points.min(axis=1)))


def facet_midpoints(problem):
    """Midpoints (d, nf) of the contact facets."""
    boundary = problem.boundary
    return problem.mesh.p[:, boundary.facet_nodes].mean(axis=1)


def sample_levels(steps, count=5):
    """About ``count`` time levels spread over 1..N, always including N."""
    levels = np.round(np.linspace(steps / count, steps, count)).astype(int)
    return np.unique(np.clip(levels, 0, steps))


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


#: the longest title drawn; a longer one is cut with an ellipsis
TITLE_CHARS = 120


def plot_title(title):
    """A scene title as matplotlib may draw it: ``$`` escaped (it would start
    mathtext, and "$x^$" cannot be parsed), cut to TITLE_CHARS characters."""
    title = " ".join(str(title).split())
    if len(title) > TITLE_CHARS:
        title = title[:TITLE_CHARS - 1] + "…"
    return title.replace("$", r"\$")


def _title(solution):
    return plot_title(solution.problem.scene.title)


class Units:
    """How the axes name a scene's units (``[output] units``, docs/scenes.md).

    ``length`` and ``stress`` are the unit names given, or "units of
    length" and "units of E" (the wording for a scene without units);
    :meth:`suffix` is " (unit)" for a quantity whose unit is given, else "".
    Names are escaped for matplotlib (a ``$`` would start mathtext).
    """

    def __init__(self, given=None):
        self.given = {key: value.replace("$", r"\$") for key, value in (given or {}).items()}

    @classmethod
    def of(cls, solution):
        """The units of the scene a solution solved."""
        return cls(solution.problem.scene.units)

    @property
    def length(self):
        return self.given.get("length", "units of length")

    @property
    def stress(self):
        return self.given.get("stress", "units of E")

    def suffix(self, quantity):
        """" (unit)" when ``quantity``'s unit is given, else ""."""
        unit = self.given.get(quantity)
        return f" ({unit})" if unit else ""

    @property
    def time(self):
        """The label of the time axis."""
        return "time t" + self.suffix("time")

    def force(self, dim):
        """The label of a total force on the body (per unit thickness in 2D)."""
        force, length = self.given.get("force"), self.given.get("length")
        if dim == 3:
            return "force on the body" + self.suffix("force")
        if force is None:
            return "force on the body (per unit thickness in 2D)"
        per = f"{force}/{length}" if length else f"{force} per unit thickness"
        return f"force on the body per unit thickness ({per})"


def tidy_3d_axes(ax, nbins=4):
    """Fewer, smaller ticks on the three axes of a 3D plot (their labels
    overlap otherwise) and short axis names x, y, z (the unit of length goes
    into the title: longer names run into each other)."""
    for axis in (ax.xaxis, ax.yaxis, ax.zaxis):
        axis.set_major_locator(MaxNLocator(nbins=nbins))
    ax.tick_params(labelsize="small", pad=1)
    ax.set_xlabel("x", labelpad=4)
    ax.set_ylabel("y", labelpad=4)
    ax.set_zlabel("z", labelpad=4)


def save_figure(fig, path):
    """Write a figure as a PNG and close it."""
    try:
        fig.savefig(path, dpi=DPI, bbox_inches="tight")
    finally:
        plt.close(fig)


#: the von Mises stress of the colour bars: of the whole 3 × 3 stress
VON_MISES = "von Mises stress"


def _deformed_2d(fig, ax, solution, factor, units):
    mesh = solution.problem.mesh
    p = mesh.p + factor * solution.u[-1].T
    vm = cell_von_mises(solution, -1)
    tri = Triangulation(p[0], p[1], mesh.t.T)
    image = ax.tripcolor(tri, facecolors=vm, cmap="viridis", shading="flat")
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
    fig.colorbar(image, ax=ax, location="bottom", shrink=0.7, pad=0.14, aspect=35,
                 label=f"{VON_MISES} (plane strain: σ_zz included; {units.stress})")


def _deformed_3d(fig, solution, factor, units):
    from mpl_toolkits.mplot3d.art3d import Poly3DCollection

    mesh = solution.problem.mesh
    ax = fig.add_subplot(projection="3d")
    p = mesh.p + factor * solution.u[-1].T
    faces = mesh.boundary_facets()
    vm = cell_von_mises(solution, -1)[mesh.f2t[0, faces]]
    norm = plt.Normalize(vm.min(), vm.max())
    polys = p[:, mesh.facets[:, faces]].transpose(2, 1, 0)
    ax.add_collection3d(Poly3DCollection(polys, facecolors=plt.cm.viridis(norm(vm)),
                                         edgecolors="k", linewidths=0.1))
    low, high = p.min(axis=1), p.max(axis=1)
    ax.set(xlim=(low[0], high[0]), ylim=(low[1], high[1]), zlim=(low[2], high[2]))
    tidy_3d_axes(ax)
    ax.set_box_aspect(high - low)
    mappable = plt.cm.ScalarMappable(norm=norm, cmap="viridis")
    fig.colorbar(mappable, ax=ax, shrink=0.7, pad=0.12,
                 label=f"{VON_MISES} ({units.stress})")
    return ax


def figure_deformed(solution):
    """The deformed mesh at the final time, coloured by the von Mises stress
    of σ (in 2D with the plane-strain σ_zz)."""
    mesh = solution.problem.mesh
    units = Units.of(solution)
    factor = magnification(mesh.p, solution.u[-1])
    fig = plt.figure(figsize=(9, 5))
    if mesh.dim() == 2:
        ax = fig.add_subplot()
        _deformed_2d(fig, ax, solution, factor, units)
    else:
        ax = _deformed_3d(fig, solution, factor, units)
    scale = ("displacements to scale" if factor == 1.0 else
             f"displacements magnified ×{factor:g}")
    coordinates = f"; x, y, z in {units.length}" if mesh.dim() == 3 else ""
    ax.set_title(f"{_title(solution)}\ndeformed mesh at t = {solution.t[-1]:g}, {scale}"
                 f"{coordinates}", fontsize="medium")
    return fig


def plot_deformed(solution, path):
    """``deformed.png``: :func:`figure_deformed`."""
    save_figure(figure_deformed(solution), path)


def _tangent_label(problem):
    """How a positive σ_τ points, for the axis label."""
    tau = tangent_direction(problem)
    if tau is None:
        return "along the nodal tangent τ"
    big = np.abs(tau) > 1e-9
    if big.sum() == 1:
        axis = int(np.flatnonzero(big)[0])
        return f"> 0 along {'+' if tau[axis] > 0 else '−'}{AXES[axis]}"
    return "along τ = (" + ", ".join(f"{c:.2g}" for c in tau) + ")"


def figure_contact_traction(solution):
    """Normal and tangential traction and the normal displacement along Γ_C.

    Three panels sharing the coordinate along Γ_C, one curve per sampled
    time level: the normal traction −σ_ν (compression > 0), the tangential
    traction σ_τ (2D: its component along the nodal tangent; 3D: |σ_τ|),
    both the nodal force of Γ_C on the body over the lumped nodal weight,
    and u_ν with the gap. Nodes on the wall are ringed; with a friction kink
    stuck nodes are marked by squares on the tangential panel."""
    problem = solution.problem
    units = Units.of(solution)
    boundary = problem.boundary
    x_nodes = problem.mesh.p[:, boundary.nodes]
    axis = along_axis(x_nodes)
    order = np.argsort(x_nodes[axis], kind="stable")
    x = x_nodes[axis, order]
    normal = normal_traction(solution)[:, order]
    shear = tangential_traction(solution)[:, order]
    shear = shear[:, :, 0] if problem.dim == 2 else np.linalg.norm(shear, axis=2)
    un = solution.normal_displacement[:, order]
    wall = solution.on_wall[:, order]
    separated = un < 0
    kinked = problem.friction is not None and problem.friction.has_kink
    stuck = solution.stuck[:, order] & ~separated
    gap = None if problem.gap is None else problem.gap[:, order]
    style = "-" if problem.dim == 2 else "none"  # 3D: scattered nodes, no lines

    levels = sample_levels(solution.steps)
    colours = plt.cm.viridis(np.linspace(0.0, 0.9, levels.size))
    fig, (top, middle, bottom) = plt.subplots(3, 1, sharex=True, figsize=(8.5, 9.5))
    for n, colour in zip(levels, colours):
        top.plot(x, normal[n], linestyle=style, marker=".", color=colour,
                 label=f"t = {solution.t[n]:.4g}")
        top.plot(x[wall[n]], normal[n, wall[n]], "o", color=colour, mfc="none")
        middle.plot(x, shear[n], linestyle=style, marker=".", color=colour)
        if kinked:
            middle.plot(x[stuck[n]], shear[n, stuck[n]], "s", color=colour, mfc="none",
                        markersize=6)
        bottom.plot(x, un[n], linestyle=style, marker=".", color=colour)
        bottom.plot(x[wall[n]], un[n, wall[n]], "o", color=colour, mfc="none")
        if gap is not None:
            bottom.plot(x, gap[n], linestyle="--" if style == "-" else "none",
                        marker="" if style == "-" else "_", color=colour, alpha=0.7)
    for ax in (top, middle, bottom):
        ax.axhline(0.0, color="0.6", linewidth=0.8)
        ax.grid(True, color="0.9", linewidth=0.6)
    top.set_ylabel(f"normal traction −σ_ν\n(> 0 compression, < 0 tension;\n{units.stress})")
    what = "contact traction and gap" if gap is not None else "contact traction"
    top.set_title(f"{_title(solution)}\n{what} along Γ_C", fontsize="medium")
    top.legend(title="time level", fontsize="small", loc="upper left",
               bbox_to_anchor=(1.01, 1.0))
    if problem.dim == 2:
        middle.set_ylabel(f"tangential traction σ_τ\n({_tangent_label(problem)};\n"
                          f"{units.stress})")
    else:
        middle.set_ylabel(f"tangential traction |σ_τ|\n({units.stress})")
    if problem.friction is None:
        middle.set_title("no friction law: σ_τ = 0", fontsize="small")
    if kinked:
        middle.plot([], [], "s", color="k", mfc="none", label="stuck node\n(ξ = 0 held\n"
                    "by friction)")
        middle.legend(fontsize="small", loc="upper left", bbox_to_anchor=(1.01, 1.0))
    bottom.plot([], [], linestyle=style, marker=".", color="k", label="u_ν")
    if gap is not None:
        bottom.plot([], [], "--", color="k", label="gap g (the wall)")
        bottom.plot([], [], "o", color="k", mfc="none", label="node on the wall\n(u_ν = g)")
    if gap is not None:
        _clip_gap_axis(bottom, un, gap)
    bottom.set_ylabel(f"normal displacement u_ν\n(> 0 towards the\nfoundation; {units.length})")
    bottom.set_xlabel(f"{AXES[axis]} along Γ_C ({units.length})")
    bottom.legend(fontsize="small", loc="upper left", bbox_to_anchor=(1.01, 1.0))
    fig.align_ylabels((top, middle, bottom))
    return fig


def plot_contact_traction(solution, path):
    """``contact_traction.png``: :func:`figure_contact_traction`."""
    save_figure(figure_contact_traction(solution), path)


def _clip_gap_axis(ax, un, gap):
    """Keep u_ν readable when the gap grows far away from Γ_C's contact zone
    (a curved side: g is the distance along ν, large where ν turns away)."""
    finite = gap[np.isfinite(gap)]
    if finite.size == 0:
        return
    span = max(float(un.max() - un.min()), float(np.ptp(finite)) * 1e-3, 1e-300)
    upper = max(float(un.max()), float(finite.min())) + 0.6 * span
    if finite.max() > upper:
        ax.set_ylim(float(min(un.min(), finite.min())) - 0.1 * span, upper)
        ax.set_title("the gap grows beyond the upper edge away from the contact zone",
                     fontsize="small")


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
    axis = along_axis(mid)
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
    image = np.full((beta.shape[0], nbins), np.nan)
    for n in range(beta.shape[0]):
        sums = np.bincount(which, boundary.measure * beta[n], minlength=nbins)
        image[n, weight > 0] = sums[weight > 0] / weight[weight > 0]
    return edges, np.ma.masked_invalid(image), (f"{name} of the facet midpoint ({length}); "
                                                "β averaged across Γ_C")


def mean_label(dim):
    """What beta_mean is: the mean of β over Γ_C weighted by each facet's
    length (2D) or area (3D), Σ_f |f| β_f / Σ_f |f|."""
    return f"mean over Γ_C (weighted by facet {'length' if dim == 2 else 'area'})"


def figure_beta(solution):
    """β along Γ_C: curves at a few levels, a space-time image, mean and min in time.

    Left column (sharing the coordinate along Γ_C): β per facet at a few
    levels, and below it β(x, t) as an image (x horizontally, t vertically,
    colour β in [0, 1]) with the β = 1/2 contour when debonding reaches it.
    Right column: the facet-measure weighted mean and the min of β in time."""
    problem = solution.problem
    units = Units.of(solution)
    mid = facet_midpoints(problem)
    axis = along_axis(mid)
    order = np.argsort(mid[axis], kind="stable")
    x = mid[axis, order]
    levels = np.unique(np.concatenate([[0], sample_levels(solution.steps)]))
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
    fig.suptitle(f"{_title(solution)}{frozen}\nbonding β along Γ_C", fontsize="medium")
    return fig


def plot_beta(solution, path):
    """``beta.png``: :func:`figure_beta`."""
    save_figure(figure_beta(solution), path)


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
    its own coordinates, a curved one in 3D."""
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
    fig.suptitle(f"{_title(solution)}\non {shape} at t = {solution.t[n]:g}",
                 fontsize="medium")
    return fig


def plot_contact_map(solution, path):
    """``contact_map.png``: :func:`figure_contact_map`."""
    save_figure(figure_contact_map(solution), path)


def load_curves(solution):
    """The curves of ``load_displacement.png``: (label, displacement, force)
    per moved component of a displacement side (its reaction against the
    mean prescribed value) and per loaded side (the applied force along its
    largest component against the side's mean displacement in it)."""
    problem = solution.problem
    curves = []
    held = reactions(solution)
    for i, side in enumerate(reaction_sides(problem)):
        if side not in problem.scene.displacement:
            continue
        moved = prescribed_history(solution, side)
        for c in range(problem.dim):
            if np.isfinite(moved[:, c]).all() and np.abs(moved[:, c]).max() > 0:
                curves.append((f"{side}: reaction R_{AXES[c]} against u_{AXES[c]} "
                               "(prescribed)", moved[:, c], held[:, i, c]))
    for side in problem.scene.traction:
        force = applied_traction(problem, side, solution.t)
        c = int(np.argmax(np.abs(force).max(axis=0)))
        if np.abs(force[:, c]).max() > 0:
            u = side_mean_displacement(solution, side)
            curves.append((f"{side}: applied force F_{AXES[c]} against mean u_{AXES[c]}",
                           u[:, c], force[:, c]))
    return curves


def figure_load_displacement(solution, curves=None):
    """Force against displacement of the moved or loaded sides, one curve each."""
    units = Units.of(solution)
    curves = load_curves(solution) if curves is None else curves
    fig, ax = plt.subplots(figsize=(7, 4.5))
    for label, u, force in curves:
        ax.plot(u, force, marker=".", markersize=3, label=label)
    ax.axhline(0.0, color="0.7", linewidth=0.8)
    ax.set_xlabel("displacement" + units.suffix("length"))
    ax.set_ylabel(units.force(solution.problem.dim))
    ax.legend(fontsize="small")
    ax.set_title(f"{_title(solution)}\nload against displacement, t = 0..{solution.t[-1]:g}",
                 fontsize="medium")
    return fig


def plot_load_displacement(solution, path, curves=None):
    """``load_displacement.png``: :func:`figure_load_displacement`."""
    save_figure(figure_load_displacement(solution, curves), path)


#: the figures :func:`write_plots` may draw, without the ``.png``
PLOT_NAMES = ("deformed", "contact_traction", "beta", "contact_map", "load_displacement")


def write_plots(solution, folder, failures=None):
    """Draw the figures into ``folder``; return the names of the files written.

    The contact figures are skipped (not an error) when the scene has no
    contact boundary; ``contact_map.png`` (colour maps over Γ_C) is drawn
    in 3D only, ``load_displacement.png`` for scenes that move or load a
    side. A figure that cannot be drawn is left out and, when ``failures``
    is a list, named there with the reason: the plots must never cost the
    run's data."""
    plots = [("deformed.png", plot_deformed)]
    boundary = solution.problem.boundary
    if boundary is not None and boundary.facets.size:
        if boundary.nodes.size:
            plots.append(("contact_traction.png", plot_contact_traction))
        plots.append(("beta.png", plot_beta))
        if solution.problem.dim == 3:
            plots.append(("contact_map.png", plot_contact_map))
    curves = load_curves(solution)
    if curves:
        plots.append(("load_displacement.png",
                      lambda solution, path: plot_load_displacement(solution, path, curves)))
    names = []
    for name, plot in plots:
        try:
            plot(solution, folder / name)
            names.append(name)
        except Exception as err:   # noqa: BLE001  (any drawing failure: the data stays)
            plt.close("all")
            (folder / name).unlink(missing_ok=True)
            if failures is not None:
                failures.append(f"{name} was not drawn: {type(err).__name__}: "
                                f"{' '.join(str(err).split())[:200]}")
    return names
