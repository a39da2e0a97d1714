"""The figures of the package, drawn with matplotlib.

One module per figure of a run: :mod:`.deformed` (``deformed.png``),
:mod:`.traction` (``contact_traction.png``), :mod:`.beta` (``beta.png``),
:mod:`.contact_map` (``contact_map.png``, 3D), :mod:`.load`
(``load_displacement.png``), :mod:`.energy` (``energy.png``),
:mod:`.debonding` (``debonding.png``), and :func:`write_plots` (:mod:`.solution`)
drawing those a solution has into a folder; :mod:`.studies` draws the
figures of a convergence study and of a sweep; :mod:`.common` holds what
they share (:class:`Units`, titles, :func:`save_figure`) and :mod:`.levels`
which time levels, axis along Γ_C and colour scales a run's figures draw.

Each ``figure_*`` function returns a :class:`matplotlib.figure.Figure`
(made with :mod:`matplotlib.pyplot`), each ``plot_*`` function saves it
as a PNG, atomically, and closes it. Nothing here chooses a backend: a
notebook or a script keeps its own (the command line selects Agg).

For example::

    from adhesive_contact import visuals

    fig = visuals.figure_beta(solution)     # a Figure: show it, or save it
    visuals.write_plots(solution, "out")    # every figure of the run, as PNGs
"""

from .beta import beta_space_time, figure_beta, plot_beta
from .common import DPI, Units, plot_title, save_figure
from .contact_map import figure_contact_map, plot_contact_map
from .debonding import figure_debonding, plot_debonding
from .deformed import figure_deformed, magnification, plot_deformed
from .energy import figure_energy, plot_energy
from .levels import contact_axis, plot_levels
from .load import figure_load_displacement, load_curves, plot_load_displacement
from .solution import PLOT_NAMES, write_plots
from .studies import (
    figure_by_key,
    figure_error_vs_size,
    figure_work_precision,
    plot_by_key,
    plot_error_vs_size,
    plot_work_precision,
    write_convergence_plots,
    write_sweep_plots,
)
from .traction import figure_contact_traction, plot_contact_traction

__all__ = ["DPI", "Units", "plot_title", "save_figure", "figure_deformed", "plot_deformed",
           "magnification", "figure_contact_traction", "plot_contact_traction",
           "figure_beta", "plot_beta", "beta_space_time", "figure_contact_map",
           "plot_contact_map", "figure_load_displacement", "plot_load_displacement",
           "load_curves", "figure_energy", "plot_energy", "figure_debonding",
           "plot_debonding", "PLOT_NAMES", "write_plots", "figure_error_vs_size",
           "plot_error_vs_size", "figure_work_precision", "plot_work_precision",
           "write_convergence_plots", "figure_by_key", "plot_by_key", "write_sweep_plots",
           "contact_axis", "plot_levels"]
