"""The figures of one run, drawn into a folder: :func:`write_plots`."""

from pathlib import Path

import matplotlib.pyplot as plt

from .beta import plot_beta
from .contact_map import plot_contact_map
from ..postprocess import energies
from .debonding import plot_debonding
from .deformed import plot_deformed
from .energy import plot_energy
from .load import load_curves, plot_load_displacement
from .traction import plot_contact_traction

#: the figures :func:`write_plots` may draw, without the ``.png``
PLOT_NAMES = ("deformed", "contact_traction", "beta", "contact_map", "load_displacement",
              "energy", "debonding")


def write_plots(solution, folder, failures=None, history=None):
    """Draw the figures of a solution into ``folder``; return the names of
    the files written.

    ``deformed.png`` always; with a contact boundary ``contact_traction.png``
    (when it has contact nodes), ``beta.png`` and in 3D ``contact_map.png``
    (colour maps over Γ_C); ``load_displacement.png`` for scenes that move
    or load a side; ``energy.png`` where the run has an energy balance, and
    ``debonding.png`` with contact facets and a bonding law. A scene without contact facets skips the contact
    figures (not an error). A figure that cannot be drawn is left out and,
    when ``failures`` is a list, named there with the reason: the plots must
    never cost the run's data. ``history``: the run's
    :func:`~adhesive_contact.postprocess.energies`, when the caller has it.

    Parameters
    ----------
    solution : adhesive_contact.Solution
    folder : str or pathlib.Path
        An existing folder; each file is written atomically.
    failures : list, optional
        Receives one line per figure that was not drawn.

    Returns
    -------
    list of str
        The file names written, e.g. ``["deformed.png", "beta.png"]``.
    """
    folder = Path(folder)
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
    history = energies(solution) if history is None else history
    if history is not None:
        plots.append(("energy.png", lambda solution, path: plot_energy(solution, path, history)))
    if (boundary is not None and boundary.facets.size
            and solution.problem.bonding is not None):
        plots.append(("debonding.png",
                      lambda solution, path: plot_debonding(solution, path, history)))
    names = []
    for name, plot in plots:
        before = set(plt.get_fignums())
        try:
            plot(solution, folder / name)
            names.append(name)
        except Exception as err:   # noqa: BLE001  (any drawing failure: the data stays)
            for number in set(plt.get_fignums()) - before:   # the caller's figures stay
                plt.close(number)
            (folder / name).unlink(missing_ok=True)
            if failures is not None:
                failures.append(f"{name} was not drawn: {type(err).__name__}: "
                                f"{' '.join(str(err).split())[:200]}")
    return names
