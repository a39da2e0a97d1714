"""PNG figures of a solve: deformed mesh, contact traction and bonding β.

:func:`write_plots` draws ``deformed.png`` always and, when the scene has a
contact boundary, ``contact_traction.png`` and ``beta.png``. The scene
carries no units, so axes are labelled in the scene's units (lengths as in
``mesh.size``, stresses as in ``material.E``). Matplotlib runs on the Agg
backend (no display needed).
"""

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.collections import LineCollection  # noqa: E402
from matplotlib.tri import Triangulation  # noqa: E402

from .postprocess import (along_axis, beta_mean, facet_midpoints, normal_traction,  # noqa: E402
                          von_mises)

AXES = "xyz"
DPI = 120


def sample_levels(steps, count=5):
    """About ``count`` time levels spread over 1..N, always including N."""
    levels = np.round(np.linspace(steps / count, steps, count)).astype(int)
    return np.unique(np.clip(levels, 0, steps))


def magnification(points, u):
    """A round factor making max |u| about 10% of the domain's largest extent.

    Parameters
    ----------
    points : (d, npoints) reference coordinates
    u : (npoints, d) displacements
    """
    extent = float((points.max(axis=1) - points.min(axis=1)).max())
    umax = float(np.linalg.norm(u, axis=1).max(initial=0.0))
    if umax == 0.0 or not np.isfinite(umax):
        return 1.0
    return float(f"{0.1 * extent / umax:.2g}")


def _title(solution):
    return solution.problem.scene.title


def _deformed_2d(fig, ax, solution, factor):
    mesh = solution.problem.mesh
    p = mesh.p + factor * solution.u[-1].T
    vm = von_mises(solution.stress[-1])
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
    ax.set_xlabel("x")
    ax.set_ylabel("y")
    ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.16), ncol=2, fontsize="small")
    fig.colorbar(image, ax=ax, shrink=0.8,
                 label="von Mises stress (in-plane σ; units of E)")


def _deformed_3d(fig, solution, factor):
    from mpl_toolkits.mplot3d.art3d import Poly3DCollection

    mesh = solution.problem.mesh
    ax = fig.add_subplot(projection="3d")
    p = mesh.p + factor * solution.u[-1].T
    faces = mesh.boundary_facets()
    vm = von_mises(solution.stress[-1])[mesh.f2t[0, faces]]
    norm = plt.Normalize(vm.min(), vm.max())
    polys = p[:, mesh.facets[:, faces]].transpose(2, 1, 0)
    ax.add_collection3d(Poly3DCollection(polys, facecolors=plt.cm.viridis(norm(vm)),
                                         edgecolors="k", linewidths=0.1))
    low, high = p.min(axis=1), p.max(axis=1)
    ax.set(xlim=(low[0], high[0]), ylim=(low[1], high[1]), zlim=(low[2], high[2]),
           xlabel="x", ylabel="y", zlabel="z")
    ax.set_box_aspect(high - low)
    mappable = plt.cm.ScalarMappable(norm=norm, cmap="viridis")
    fig.colorbar(mappable, ax=ax, shrink=0.7, label="von Mises stress (units of E)")
    return ax


def plot_deformed(solution, path):
    """The deformed mesh at the final time, coloured by von Mises stress."""
    mesh = solution.problem.mesh
    factor = magnification(mesh.p, solution.u[-1])
    fig = plt.figure(figsize=(9, 5))
    if mesh.dim() == 2:
        ax = fig.add_subplot()
        _deformed_2d(fig, ax, solution, factor)
    else:
        ax = _deformed_3d(fig, solution, factor)
    ax.set_title(f"{_title(solution)}\ndeformed mesh at t = {solution.t[-1]:g}, "
                 f"displacements magnified ×{factor:g}", fontsize="medium")
    fig.savefig(path, dpi=DPI, bbox_inches="tight")
    plt.close(fig)


def plot_contact_traction(solution, path):
    """Normal traction and normal displacement along Γ_C at a few levels."""
    problem = solution.problem
    boundary = problem.boundary
    x_nodes = problem.mesh.p[:, boundary.nodes]
    axis = along_axis(x_nodes)
    order = np.argsort(x_nodes[axis], kind="stable")
    x = x_nodes[axis, order]
    traction = normal_traction(solution)[:, order]
    un = solution.normal_displacement[:, order]
    wall = solution.on_wall[:, order]
    gap = None if problem.gap is None else problem.gap[:, order]
    style = "-" if problem.dim == 2 else "none"  # 3D: scattered nodes, no lines

    levels = sample_levels(solution.steps)
    colours = plt.cm.viridis(np.linspace(0.0, 0.9, levels.size))
    fig, (top, bottom) = plt.subplots(2, 1, sharex=True, figsize=(8, 7))
    for n, colour in zip(levels, colours):
        top.plot(x, traction[n], linestyle=style, marker=".", color=colour,
                 label=f"t = {solution.t[n]:g}")
        top.plot(x[wall[n]], traction[n, wall[n]], "o", color=colour, mfc="none")
        bottom.plot(x, un[n], linestyle=style, marker=".", color=colour)
        bottom.plot(x[wall[n]], un[n, wall[n]], "o", color=colour, mfc="none")
        if gap is not None:
            bottom.plot(x, gap[n], linestyle="--" if style == "-" else "none",
                        marker="" if style == "-" else "_", color=colour, alpha=0.7)
    top.axhline(0.0, color="0.6", linewidth=0.8)
    top.set_ylabel("normal traction −σ_ν\n(compression > 0; units of E)")
    what = "contact traction and gap" if gap is not None else "contact traction"
    top.set_title(f"{_title(solution)}\n{what} along Γ_C", fontsize="medium")
    top.legend(title="time level", fontsize="small", loc="upper left",
               bbox_to_anchor=(1.01, 1.0))
    bottom.plot([], [], linestyle=style, marker=".", color="k", label="u_ν")
    if gap is not None:
        bottom.plot([], [], "--", color="k", label="gap g (the wall)")
        bottom.plot([], [], "o", color="k", mfc="none", label="node on the wall\n(u_ν = g)")
    bottom.axhline(0.0, color="0.6", linewidth=0.8)
    bottom.set_ylabel("normal displacement u_ν\n(units of length)")
    bottom.set_xlabel(f"{AXES[axis]} along Γ_C (units of length)")
    bottom.legend(fontsize="small", loc="upper left", bbox_to_anchor=(1.01, 1.0))
    fig.savefig(path, dpi=DPI, bbox_inches="tight")
    plt.close(fig)


def plot_beta(solution, path):
    """β per contact facet along Γ_C at a few levels, and its mean and min in time."""
    problem = solution.problem
    mid = facet_midpoints(problem)
    axis = along_axis(mid)
    order = np.argsort(mid[axis], kind="stable")
    x = mid[axis, order]
    levels = np.unique(np.concatenate([[0], sample_levels(solution.steps)]))
    colours = plt.cm.viridis(np.linspace(0.0, 0.9, levels.size))
    fig, (left, right) = plt.subplots(1, 2, figsize=(11, 4.5),
                                      gridspec_kw={"width_ratios": [3, 2]})
    for n, colour in zip(levels, colours):
        if problem.dim == 2:
            left.plot(x, solution.beta[n, order], drawstyle="steps-mid", color=colour,
                      label=f"t = {solution.t[n]:g}")
        else:
            left.plot(x, solution.beta[n, order], ".", color=colour,
                      label=f"t = {solution.t[n]:g}")
    left.set(xlabel=f"{AXES[axis]} of the facet midpoint (units of length)",
             ylabel="bonding β (1 = fully bonded)", ylim=(-0.05, 1.05))
    left.set_title("β per contact facet", fontsize="medium")
    left.legend(fontsize="small")
    right.plot(solution.t, beta_mean(solution), "-", label="mean (weighted by |f|)")
    right.plot(solution.t, solution.beta.min(axis=1), "--", label="min")
    right.set(xlabel="time t", ylabel="β", ylim=(-0.05, 1.05))
    right.set_title("β over Γ_C in time", fontsize="medium")
    right.legend(fontsize="small")
    bonding = problem.scene.contact.bonding.law
    frozen = " (bonding law 'none': β frozen at β_0)" if bonding == "none" else ""
    fig.suptitle(f"{_title(solution)}{frozen}", fontsize="medium")
    fig.savefig(path, dpi=DPI, bbox_inches="tight")
    plt.close(fig)


def write_plots(solution, folder):
    """Draw the figures into ``folder``; return the names of the files written.

    The contact figures are skipped (not an error) when the scene has no
    contact boundary."""
    names = ["deformed.png"]
    plot_deformed(solution, folder / names[0])
    boundary = solution.problem.boundary
    if boundary is not None and boundary.facets.size:
        if boundary.nodes.size:
            names.append("contact_traction.png")
            plot_contact_traction(solution, folder / names[-1])
        names.append("beta.png")
        plot_beta(solution, folder / names[-1])
    return names
