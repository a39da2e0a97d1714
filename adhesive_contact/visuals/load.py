"""``load_displacement.png``: the force on each moved or loaded side against
its displacement."""

import matplotlib.pyplot as plt
import numpy as np

from ..postprocess import (
    applied_traction,
    prescribed_history,
    reaction_sides,
    reactions,
    side_mean_displacement,
)
from .common import AXES, Units, save_figure, solution_title


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
    """Force against displacement of the moved or loaded sides, one curve each.

    Parameters
    ----------
    solution : adhesive_contact.Solution
    curves : list of (label, displacement, force), optional
        The curves drawn; :func:`load_curves` of the solution by default.

    Returns
    -------
    matplotlib.figure.Figure
    """
    units = Units.of(solution)
    curves = load_curves(solution) if curves is None else curves
    fig, ax = plt.subplots(figsize=(7, 4.5))
    for label, u, force in curves:
        ax.plot(u, force, marker=".", markersize=3, label=label)
    ax.axhline(0.0, color="0.7", linewidth=0.8)
    ax.set_xlabel("displacement" + units.suffix("length"))
    ax.set_ylabel(units.force(solution.problem.dim))
    ax.legend(fontsize="small")
    ax.set_title(f"{solution_title(solution)}\nload against displacement, "
                 f"t = 0..{solution.t[-1]:g}", fontsize="medium")
    return fig


def plot_load_displacement(solution, path, curves=None):
    """``load_displacement.png``: :func:`figure_load_displacement` saved into ``path``."""
    save_figure(figure_load_displacement(solution, curves), path)
