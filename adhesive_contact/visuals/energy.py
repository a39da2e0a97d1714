"""``energy.png``: the energy balance of a run over time
(:mod:`adhesive_contact.postprocess.energy`)."""

import matplotlib.pyplot as plt
import numpy as np

from ..postprocess import DISSIPATED, STORED, energies
from .common import Units, save_figure, solution_title

#: the colours of the parts: stored in blues and greens, dissipated in warm tones
COLOURS = {"elastic": "#1f77b4", "memory": "#9ecae1", "layer": "#17becf", "glue": "#2ca02c",
           "friction": "#98df8a", "viscous": "#ff7f0e", "debonding": "#d62728",
           "numerical": "#7f7f7f"}


def energy_label(units):
    """The label of an energy axis (per unit thickness in 2D)."""
    force, length = units.given.get("force"), units.given.get("length")
    unit = f" ({force}·{length})" if force and length else ""
    return "energy" + unit


def figure_energy(solution, history=None):
    """The parts of the energy over time, stacked under the external work,
    and the balance W − S − D relative to the work.

    Parameters
    ----------
    solution : adhesive_contact.Solution
    history : EnergyHistory, optional
        :func:`~adhesive_contact.postprocess.energies` of the solution by default.

    Returns
    -------
    matplotlib.figure.Figure

    Raises
    ------
    ValueError
        When the run has no energy balance (no free energy exists).
    """
    history = energies(solution) if history is None else history
    if history is None:
        raise ValueError("this run has no energy balance (no free energy exists)")
    units = Units.of(solution)
    t = history.t
    fig, (ax, bx) = plt.subplots(1, 2, figsize=(11, 4.5), width_ratios=(2, 1))
    names = [n for n in STORED if np.any(history.stored[n] != 0)]
    parts = [history.stored[n] for n in names]
    lost = [n for n in DISSIPATED if np.any(history.dissipated[n] != 0)]
    parts += [history.dissipated[n] for n in lost]
    labels = [f"stored: {n}" for n in names] + [f"dissipated: {n}" for n in lost]
    if parts:
        ax.stackplot(t, *parts, labels=labels, colors=[COLOURS[n] for n in names + lost],
                     alpha=0.85)
    ax.plot(t, history.external_work, color="k", linewidth=1.5, label="external work W")
    ax.set_xlabel(units.time)
    ax.set_ylabel(energy_label(units) + (" per unit thickness" if solution.problem.dim == 2
                                         else ""))
    ax.legend(fontsize="small", loc="upper left")
    ax.set_title("work = stored + dissipated", fontsize="medium")
    scale = np.maximum(np.abs(history.external_work).max(initial=0.0), 1e-300)
    bx.plot(t, history.balance / scale, marker=".", markersize=3)
    bx.axhline(0.0, color="0.7", linewidth=0.8)
    bx.set_xlabel(units.time)
    bx.set_ylabel("balance (W − S − D) / max |W|")
    bx.set_title("balance", fontsize="medium")
    fig.suptitle(f"{solution_title(solution)}\nenergy, t = 0..{t[-1]:g}", fontsize="medium")
    fig.tight_layout()
    return fig


def plot_energy(solution, path, history=None):
    """``energy.png``: :func:`figure_energy` saved into ``path``."""
    save_figure(figure_energy(solution, history), path)
