"""``contact_traction.png``: the normal and tangential traction and the
normal displacement along Γ_C at a few time levels."""

import matplotlib.pyplot as plt
import numpy as np

from ..postprocess import contact_states, normal_traction, tangential_traction
from .common import AXES, Units, save_figure, solution_title, tangent_direction
from .levels import contact_axis, floored, plot_levels, run_scale


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

    Three panels sharing the coordinate along Γ_C (the axis along which it
    extends most, :func:`~.levels.contact_axis`), one curve per level of
    :func:`~.levels.plot_levels`: the normal traction −σ_ν (compression > 0), the tangential
    traction σ_τ (2D: its component along the nodal tangent; 3D: |σ_τ|),
    both the nodal force of Γ_C on the body over the lumped nodal weight,
    and u_ν with the gap. Nodes on the wall are ringed; with a friction kink
    stuck nodes are marked by squares on the tangential panel.

    Parameters
    ----------
    solution : adhesive_contact.Solution
        Of a scene with contact nodes.

    Returns
    -------
    matplotlib.figure.Figure
    """
    problem = solution.problem
    units = Units.of(solution)
    boundary = problem.boundary
    x_nodes = problem.mesh.p[:, boundary.nodes]
    axis = contact_axis(problem)
    order = np.argsort(x_nodes[axis], kind="stable")
    x = x_nodes[axis, order]
    normal = normal_traction(solution)[:, order]
    shear = tangential_traction(solution)[:, order]
    shear = shear[:, :, 0] if problem.dim == 2 else np.linalg.norm(shear, axis=2)
    # round-off drawn as zero, on the scale of the run's largest traction
    scale = max(run_scale(normal), run_scale(shear))
    normal, shear = floored(normal, scale), floored(shear, scale)
    un = solution.normal_displacement[:, order]
    wall = solution.on_wall[:, order]
    states = contact_states(solution)
    kinked = problem.friction is not None and problem.friction.has_kink
    stuck = states["stick"][:, order] if "stick" in states else np.zeros_like(wall)
    gap = None if solution.gap is None else solution.gap[:, order]
    style = "-" if problem.dim == 2 else "none"  # 3D: scattered nodes, no lines

    levels = plot_levels(solution)
    colours = plt.cm.viridis(np.linspace(0.0, 0.9, levels.size))
    fig, (top, middle, bottom) = plt.subplots(3, 1, sharex=True, figsize=(10, 9.5),
                                              layout="constrained")
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
        ax.ticklabel_format(axis="y", useOffset=False)
    top.set_ylabel(f"normal traction −σ_ν\n(> 0 compression, < 0 tension;\n{units.stress})")
    what = "contact traction and gap" if gap is not None else "contact traction"
    top.set_title(f"{solution_title(solution)}\n{what} along Γ_C", fontsize="medium")
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
    """``contact_traction.png``: :func:`figure_contact_traction` saved into ``path``."""
    save_figure(figure_contact_traction(solution), path, bbox_inches=None)


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
