"""What the figures share: the units on their axes, their titles, saving a
PNG atomically, tidy 3D axes and where Γ_C lies (the levels and colour
scales a figure draws are :mod:`.levels`).

Nothing here chooses a matplotlib backend: the figures are drawn with
whichever the caller's process uses (a notebook keeps its own; the
command line selects Agg).
"""

import matplotlib.pyplot as plt
import numpy as np
from matplotlib.ticker import MaxNLocator

from ..storage import write_atomic

#: the names of the coordinate axes
AXES = "xyz"

#: the resolution of the PNG files (dots per inch)
DPI = 120

#: the longest title drawn; a longer one is cut with an ellipsis
TITLE_CHARS = 120


def plot_title(title):
    """A scene title as matplotlib may draw it: ``$`` escaped (it would start
    mathtext, and "$x^$" cannot be parsed), cut to TITLE_CHARS characters."""
    title = " ".join(str(title).split())
    if len(title) > TITLE_CHARS:
        title = title[:TITLE_CHARS - 1] + "…"
    return title.replace("$", r"\$")


def solution_title(solution):
    """The title of the scene a solution solved, as :func:`plot_title` draws it."""
    return plot_title(solution.problem.scene.title)


class Units:
    """How the axes name a scene's units (``[output] units``, docs/scenes.md).

    ``length`` and ``stress`` are the unit names given, or "units of
    length" and "units of E" (the wording for a scene without units);
    :meth:`suffix` is " (unit)" for a quantity whose unit is given, else "".
    Names are escaped for matplotlib (a ``$`` would start mathtext).

    Parameters
    ----------
    given : dict or None
        {quantity: unit name} of ``output.units``; None for a scene without.
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


def save_figure(fig, path, bbox_inches="tight"):
    """Write a figure as a PNG of :data:`DPI` dots per inch, atomically, and close it.

    Parameters
    ----------
    fig : matplotlib.figure.Figure
    path : str or os.PathLike
        The file; it appears whole or not at all
        (:func:`adhesive_contact.storage.write_atomic`).
    bbox_inches : str or None
        As in :meth:`~matplotlib.figure.Figure.savefig`: "tight" crops the
        figure to what is drawn, None keeps its size (a constrained layout).
    """
    try:
        write_atomic(path, lambda f: fig.savefig(f, format="png", dpi=DPI,
                                                 bbox_inches=bbox_inches), binary=True)
    finally:
        plt.close(fig)


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


def facet_midpoints(problem):
    """Midpoints (d, nf) of the contact facets."""
    boundary = problem.boundary
    return problem.mesh.p[:, boundary.facet_nodes].mean(axis=1)
