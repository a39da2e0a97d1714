"""``debonding.png``: where the glue let go, how much, and at what energy
(:mod:`adhesive_contact.postprocess.fracture`)."""

import matplotlib.pyplot as plt
import numpy as np

from ..postprocess import (debond_fronts, debonded_area, energies, energy_per_area,
                           new_debonding)
from .common import AXES, Units, save_figure, solution_title
from .levels import contact_axis
from .energy import energy_label


def figure_debonding(solution, history=None):
    """Three panels over time: the debond front (where β crosses ½) along
    the axis Γ_C spreads most along; the debonded area (β < ½) and
    ∫_{Γ_C} (1 − β); the glue's dissipated energy per unit of each.

    Parameters
    ----------
    solution : adhesive_contact.Solution (with contact facets)
    history : EnergyHistory, optional
        :func:`~adhesive_contact.postprocess.energies` by default; the third
        panel is empty when the run has no energy balance.

    Returns
    -------
    matplotlib.figure.Figure
    """
    problem = solution.problem
    history = energies(solution) if history is None else history
    units = Units.of(solution)
    t = solution.t
    fig, (ax, bx, cx) = plt.subplots(1, 3, figsize=(13, 4))
    axis = contact_axis(problem)
    fronts = debond_fronts(solution)
    times = np.concatenate([np.full(len(f), tn) for f, tn in zip(fronts, t)])
    where = np.concatenate([f[:, axis] for f in fronts]) if times.size else np.zeros(0)
    ax.plot(times, where, ".", markersize=4)
    ax.set_xlabel(units.time)
    ax.set_ylabel(f"front position {AXES[axis]}" + units.suffix("length"))
    ax.set_title("debond front (β = ½)", fontsize="medium")
    area, damage = debonded_area(solution)
    measure = "length" if problem.dim == 2 else "area"
    bx.plot(t, area, label=f"{measure} with β < ½")
    bx.plot(t, damage, "--", label="∫ (1 − β)")
    bx.set_xlabel(units.time)
    bx.set_ylabel(f"debonded {measure}" + units.suffix("length"))
    bx.legend(fontsize="small")
    bx.set_title("debonded", fontsize="medium")
    if history is not None:   # per the area the run debonded: a pre-crack dissipates nothing
        glue = history.dissipated["debonding"]
        new_area, new_damage = new_debonding(solution)
        cx.plot(t, energy_per_area(glue, new_area), label=f"per {measure} debonded in the run")
        cx.plot(t, energy_per_area(glue, new_damage), "--", label="per ∫ (β₀ − β)")
        cx.legend(fontsize="small")
    cx.set_xlabel(units.time)
    cx.set_ylabel(energy_label(units) + f" per unit debonded {measure}")
    cx.set_title("glue's dissipated energy per unit debonded " + measure, fontsize="medium")
    fig.suptitle(f"{solution_title(solution)}\ndebonding, t = 0..{t[-1]:g}",
                 fontsize="medium")
    fig.tight_layout()
    return fig


def plot_debonding(solution, path, history=None):
    """``debonding.png``: :func:`figure_debonding` saved into ``path``."""
    save_figure(figure_debonding(solution, history), path)
