"""The figures of the studies: a convergence study's ``error_vs_h.png`` (or
``error_vs_k.png``), ``work_precision.png`` and, for a study of a scalar
quantity, ``quantity_vs_h.png`` (or ``_vs_k``), drawn from its results
document (``rates.json``), and a sweep's ``by_<key>.png``, one per swept
key, drawn from its rows (``runs.csv``)."""

import math
import textwrap
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np
from matplotlib.ticker import NullFormatter

from ..storage import toml_value
from .common import Units, plot_title, save_figure

# ---------------------------------------------------------------- convergence


def _fmt(value, spec, none):
    if value is None or (isinstance(value, float) and not math.isfinite(value)):
        return none
    return format(value, spec)


#: the errors drawn: (level key, label, key of the fitted rate, marker)
ERRORS = (("err_u", "‖ε(u − u_h)‖", "u", "o"), ("err_beta", "‖β − β_h‖", "beta", "s"),
          ("E", "E = ‖ε(u − u_h)‖ + ‖β − β_h‖", "E", "^"))


def _positive(x, y):
    x, y = np.asarray(x, float), np.array([np.nan if v is None else v for v in y], float)
    ok = np.isfinite(y) & (y > 0) & (x > 0)
    return x[ok], y[ok]


def reference_phrase(info):
    """What a convergence study measured against, in words (a figure's title,
    the command's report): ``info`` is the results document's ``reference``."""
    if info["kind"] == "exact":
        return "reference: the scene's exact solution"
    return (f"reference: fine run (refine {info['refine']}, {info['steps']} steps, "
            f"{info['seconds']:.3g} s)")


def _suptitle(fig, document, title):
    wrapped = textwrap.fill(plot_title(title), 70)
    fig.suptitle(f"{wrapped}\n{document['param']}-refinement, {len(document['levels'])} "
                 f"levels; {reference_phrase(document['reference'])}", fontsize="medium")


def _slope_one_triangle(ax, xs, ys):
    """A slope-1 triangle under the data, in the left half of the x range."""
    lo, hi = np.log(xs.min()), np.log(xs.max())
    if hi - lo < 1e-12:
        return
    x1, x2 = np.exp(lo + 0.15 * (hi - lo)), np.exp(lo + 0.5 * (hi - lo))
    y1 = 0.4 * ys.min()
    y2 = y1 * x2 / x1
    ax.plot([x1, x2, x2, x1], [y1, y1, y2, y1], "-", color="0.45", linewidth=1.0,
            label="slope 1 (guide)")
    ax.set_ylim(bottom=0.55 * y1)   # room for the label under the triangle
    ax.text(np.sqrt(x1 * x2), y1 * 0.85, "1", ha="center", va="top", color="0.35",
            fontsize="small")
    ax.text(x2 * 1.04, np.sqrt(y1 * y2), "1", ha="left", va="center", color="0.35",
            fontsize="small")


def figure_error_vs_size(document, title, units=None):
    """Errors against h (or k) log-log, with the fitted slopes in the legend.

    ‖ε(u − u_h)‖, ‖β − β_h‖ and E, each the max over the time grid, one
    line per error with a positive value, and a slope-1 guide triangle.

    Parameters
    ----------
    document : dict
        The results document of a convergence study (``rates.json``).
    title : str
        The scene's title.
    units : Units, optional
        The scene's units (:class:`~.common.Units`), naming the unit of h and k.

    Returns
    -------
    matplotlib.figure.Figure
    """
    units = units or Units()
    param = document["param"]
    size = "k" if param == "k" else "h"
    rows = document["levels"]
    fig, ax = plt.subplots(figsize=(7.0, 5.0))
    drawn = []
    for key, label, rate_key, marker in ERRORS:
        x, y = _positive([r[size] for r in rows], [r[key] for r in rows])
        if y.size == 0:
            continue
        slope = document["rates"][rate_key]
        ax.loglog(x, y, marker + "-", label=f"{label}   slope {_fmt(slope, '.2f', 'n/a')}")
        drawn.append((x, y))
    if drawn:
        _slope_one_triangle(ax, np.concatenate([d[0] for d in drawn]),
                            np.concatenate([d[1] for d in drawn]))
        ax.legend(fontsize="small", loc="best")
    else:
        ax.text(0.5, 0.5, "all errors are zero", transform=ax.transAxes, ha="center")
    ax.xaxis.set_minor_formatter(NullFormatter())   # minor labels overlap on short axes
    length, time = units.suffix("length"), units.suffix("time")
    ax.set_xlabel({"h": f"mesh size h{length}", "k": f"time step k{time}",
                   "hk": f"mesh size h{length} (time step k halved with h)"}[param])
    ax.set_ylabel("error, max over the time grid")
    _finish(fig, ax, document, title)
    return fig


def _finish(fig, ax, document, title):
    """Grid and titles."""
    ax.grid(True, which="both", color="0.9", linewidth=0.6)
    _suptitle(fig, document, title)


def plot_error_vs_size(path, document, title, units=None):
    """``error_vs_h.png`` (or ``error_vs_k.png``): :func:`figure_error_vs_size`
    saved into ``path``."""
    save_figure(figure_error_vs_size(document, title, units), path)


def figure_work_precision(document, title):
    """E against the wall time of each level's run, log-log.

    Each level annotated with its dofs and steps; a fine reference run's
    time as a dashed vertical line.

    Parameters
    ----------
    document : dict
        The results document of a convergence study (``rates.json``).
    title : str
        The scene's title.

    Returns
    -------
    matplotlib.figure.Figure
    """
    rows = document["levels"]
    info = document["reference"]
    fig, ax = plt.subplots(figsize=(7.0, 5.0))
    x, y = _positive([r["seconds"] for r in rows], [r["E"] for r in rows])
    if y.size:
        ax.loglog(x, y, "^-", label="E, max over the time grid")
        for r in rows:
            if r["E"] is not None and r["E"] > 0 and r["seconds"] > 0:
                ax.annotate(f"level {r['level']}\n{r['dofs']} dofs, {r['steps']} steps",
                            (r["seconds"], r["E"]), textcoords="offset points",
                            xytext=(6, 4), fontsize="x-small", color="0.3")
    if info["kind"] == "fine" and info["seconds"] > 0:
        ax.axvline(info["seconds"], linestyle="--", color="0.5",
                   label=f"reference run: {info['seconds']:.3g} s")
        ax.set_xscale("log")
    if y.size or info["kind"] == "fine":
        ax.legend(fontsize="small", loc="best")
    ax.margins(x=0.12, y=0.15)   # room for the annotations
    ax.xaxis.set_minor_formatter(NullFormatter())
    ax.set_xlabel("wall time of the level's run (s): assembly and time stepping")
    ax.set_ylabel("error E")
    _finish(fig, ax, document, title)
    return fig


def plot_work_precision(path, document, title):
    """``work_precision.png``: :func:`figure_work_precision` saved into ``path``."""
    save_figure(figure_work_precision(document, title), path)


def write_convergence_plots(out, document, title, units=None):
    """Draw the two figures of a convergence study into the folder ``out``;
    return their names.

    Parameters
    ----------
    out : str or pathlib.Path
        An existing folder; each file is written atomically.
    document : dict
        The study's results document (``rates.json``).
    title : str
        The scene's title.
    units : dict, optional
        The scene's ``[output] units``, naming the units of h and k.

    Returns
    -------
    list of str
        ``["error_vs_h.png", "work_precision.png"]`` (``error_vs_k.png``
        for a k-study).
    """
    out = Path(out)
    size = "k" if document["param"] == "k" else "h"
    names = [f"error_vs_{size}.png", "work_precision.png"]
    plot_error_vs_size(out / names[0], document, title, Units(units))
    plot_work_precision(out / names[1], document, title)
    if "quantity" in document:
        names.append(f"quantity_vs_{size}.png")
        save_figure(figure_quantity_vs_size(document, title, Units(units)), out / names[-1])
    return names


def figure_quantity_vs_size(document, title, units=None):
    """A study of a scalar quantity Q: Q_h per level against h (or k) with the
    reference's Q_ref as a dashed line (left), and |Q_h − Q_ref| log-log
    with its fitted slope and a slope-1 guide (right).

    Parameters
    ----------
    document : dict
        The results document of a convergence study of a quantity
        (``rates.json`` with ``"quantity"``).
    title : str
        The scene's title.
    units : Units, optional
        The scene's units, naming the unit of h and k.

    Returns
    -------
    matplotlib.figure.Figure
    """
    units = units or Units()
    param, name = document["param"], document["quantity"]["name"]
    size = "k" if param == "k" else "h"
    rows = document["levels"]
    fig, (left, right) = plt.subplots(1, 2, figsize=(10.0, 4.6))
    x = np.asarray([r[size] for r in rows], float)
    q = np.array([np.nan if r["quantity"] is None else r["quantity"] for r in rows], float)
    left.semilogx(x, q, "o-", label=f"{name}, level")
    reference = document["quantity"]["reference"]
    if reference is not None:
        left.axhline(reference, linestyle="--", color="0.5",
                     label=f"fine reference: {reference:.6g}")
    left.legend(fontsize="small", loc="best")
    unit = document["quantity"].get("unit")
    left.set_ylabel(f"{name} ({unit})" if unit else name)
    xe, ye = _positive(x, [r["err_q"] for r in rows])
    if ye.size:
        slope = _fmt(document["rates"].get("Q"), ".2f", "n/a")
        right.loglog(xe, ye, "D-", label=f"|Q_h − Q_ref|   slope {slope}")
        _slope_one_triangle(right, xe, ye)
        right.legend(fontsize="small", loc="best")
    else:
        right.text(0.5, 0.5, "no nonzero error", transform=right.transAxes, ha="center")
    right.set_ylabel(f"|Q_h − Q_ref| of {name}" + (f" ({unit})" if unit else ""))
    length, time = units.suffix("length"), units.suffix("time")
    label = {"h": f"mesh size h{length}", "k": f"time step k{time}",
             "hk": f"mesh size h{length} (k halved with h)"}[param]
    for ax in (left, right):
        ax.set_xlabel(label)
        ax.xaxis.set_minor_formatter(NullFormatter())
        ax.grid(True, which="both", color="0.9", linewidth=0.6)
    _suptitle(fig, document, title)
    return fig


# ---------------------------------------------------------------- sweep

#: the panels of each figure: (runs.csv column, axis label)
PANELS = (("seconds", "wall time of the run (s)"),
          ("newton_total", "Newton iterations, all steps"),
          ("beta_mean_T", "mean bonding β at T"),
          ("normal_force_T", "total normal contact force at T\n(> 0 compression{force})"))


def panel_label(label, units, dim):
    """A panel's axis label; the force's unit (``[output] units``) filled in:
    "; N", "; N/mm per unit thickness" in 2D, or nothing without units."""
    force, length = units.given.get("force"), units.given.get("length")
    if force is None:
        unit = ""
    elif dim == 3:
        unit = f"; {force}"
    else:
        unit = f"; {force}/{length}" if length else f"; {force} per unit thickness"
    return label.format(force=unit)


def _numbers(values):
    """The values as floats when all are numbers (not bools), else None."""
    if all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in values):
        return np.asarray(values, dtype=float)
    return None


def _value(row, column):
    value = row[column]
    return math.nan if value is None else float(value)


def figure_by_key(rows, keys, key, title, units=None, dim=2):
    """The measured quantities against one swept key, a line per setting of
    the others.

    Four panels: the wall time of each run (a failed run marked ×), its
    Newton iterations, the mean β at T and the total normal contact force
    at T. A numeric key spanning more than a decade is drawn on a log axis,
    a non-numeric one as categories.

    Parameters
    ----------
    rows : list of rows read by column (a sweep's ``SweepRow``, or dicts)
        The sweep's rows (``runs.csv``: the values set, ``outcome``,
        ``seconds``, ``newton_total``, ``beta_mean_T``, ``normal_force_T``).
    keys : list of str
        The swept keys.
    key : str
        The key along the horizontal axis.
    title : str
        The base scene's title.
    units : Units, optional
        The base scene's units (:class:`~.common.Units`), naming the force's unit.
    dim : int
        The dimension of the base scene (2: forces per unit thickness).

    Returns
    -------
    matplotlib.figure.Figure
    """
    units = units or Units()
    values = list(dict.fromkeys(toml_value(row[key]) for row in rows))
    raw = {toml_value(row[key]): row[key] for row in rows}
    numbers = _numbers([raw[v] for v in values])
    position = ({v: x for v, x in zip(values, numbers)} if numbers is not None
                else {v: i for i, v in enumerate(values)})
    others = [k for k in keys if k != key]
    groups = {}
    for row in rows:
        label = ", ".join(f"{k} = {toml_value(row[k])}" for k in others)
        groups.setdefault(label, []).append(row)
    fig, axes = plt.subplots(2, 2, figsize=(10.5, 7.5), sharex=True, layout="constrained")
    for (column, label), ax in zip(PANELS, axes.ravel()):
        for group, members in groups.items():
            members = sorted(members, key=lambda r: position[toml_value(r[key])])
            x = np.array([position[toml_value(r[key])] for r in members], dtype=float)
            ok = np.array([r["outcome"] == "ok" for r in members])
            y = np.array([_value(r, column) for r in members])
            ax.plot(x[ok], y[ok], "o-", label=group or None)
            if column == "seconds" and (~ok).any():
                ax.plot(x[~ok], y[~ok], "x", color="tab:red", markersize=9, mew=2)
        ax.set_ylabel(panel_label(label, units, dim))
        ax.grid(True, color="0.9", linewidth=0.6)
    if numbers is not None and numbers.min() > 0 and numbers.max() > 10 * numbers.min():
        axes[0, 0].set_xscale("log")
    if numbers is None:
        axes[1, 0].set_xticks(range(len(values)), values)
    for ax in axes[1]:
        ax.set_xlabel(key)
    handles = axes[0, 0].get_legend_handles_labels()[0]
    if any(label for label in groups) and handles:
        fit_legend(fig, handles, list(groups), title="other settings")
    failed = sum(row["outcome"] != "ok" for row in rows)
    note = f"; × on the time panel: {failed} failed run(s)" if failed else ""
    fig.suptitle(f"{plot_title(title)}\nsweep over {key}{note}", fontsize="medium")
    return fig


#: the longest line of a legend entry (longer ones are wrapped)
LEGEND_LINE = 60


def fit_legend(fig, handles, labels, title=None):
    """A legend below the panels of a constrained-layout figure that fits
    inside it: long labels wrapped at LEGEND_LINE characters, and as many
    columns (at most 3) as leave it no wider than the figure."""
    import textwrap

    labels = ["\n".join(textwrap.wrap(label, LEGEND_LINE)) or label for label in labels]
    renderer = fig.canvas.get_renderer()
    for ncols in range(min(3, len(labels)), 0, -1):
        legend = fig.legend(handles, labels, loc="outside lower center", fontsize="small",
                            title=title, ncols=ncols)
        if ncols == 1 or legend.get_window_extent(renderer).width <= 0.98 * fig.bbox.width:
            return legend
        legend.remove()
    return legend


def plot_by_key(path, rows, keys, key, title, units=None, dim=2):
    """``by_<key>.png``: :func:`figure_by_key` saved into ``path`` (at the
    size of its constrained layout)."""
    save_figure(figure_by_key(rows, keys, key, title, units, dim), path, bbox_inches=None)


def by_key_name(key):
    """The file name of the figure of a swept key: ``by_<key>.png``."""
    return f"by_{key}.png"


def write_sweep_plots(out, rows, keys, title, units=None, dim=2):
    """Draw one figure per swept key into the folder ``out``
    (:func:`figure_by_key`); return their names.

    Parameters
    ----------
    out : str or pathlib.Path
        An existing folder; each file is written atomically.
    rows, keys, title, dim
        As for :func:`figure_by_key`.
    units : dict, optional
        The base scene's ``[output] units``, naming the force's unit.

    Returns
    -------
    list of str
        ``by_<key>.png`` for each key, in the order of ``keys``.
    """
    out = Path(out)
    names = []
    for key in keys:
        names.append(by_key_name(key))
        plot_by_key(out / names[-1], rows, keys, key, title, Units(units), dim)
    return names
