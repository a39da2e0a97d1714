"""``adhcontact sweep``: a parameter sweep of a scene.

The sweep is :class:`adhesive_contact.studies.Sweep` (variants, validation,
the folder ``--out`` that keeps it, runs.csv); this module parses the
options, shows progress, prints one line per run and draws one figure per
swept key (``by_<key>.png``), each written atomically.
"""

import math
import sys
from pathlib import Path

import click
import matplotlib.pyplot as plt  # noqa: E402  (after .plots: the Agg backend)
import numpy as np

from adhesive_contact import SceneError, scene_from_dict
from adhesive_contact.storage import write_atomic
from adhesive_contact.studies import (
    Sweep,
    parse_assignment,
)
from adhesive_contact.studies.sweep import LOST, show, variant_document, variants

from .common import (
    check_out,
    guard,
    load_scene,
    open_study,
    read_scene,
    running_study,
    scene_folder,
    study_source,
)
from .plots import DPI, Units, plot_title
from .scheduler import open_executor, scheduler_option

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


def figure_key(rows, keys, key, title, units=None, dim=2):
    """The measured quantities against one swept key, a line per setting of
    the others; ``units`` (:class:`~.plots.Units`) of the base scene, of
    dimension ``dim``, name the force's unit."""
    units = units or Units()
    values = list(dict.fromkeys(show(row[key]) for row in rows))
    raw = {show(row[key]): row[key] for row in rows}
    numbers = _numbers([raw[v] for v in values])
    position = ({v: x for v, x in zip(values, numbers)} if numbers is not None
                else {v: i for i, v in enumerate(values)})
    others = [k for k in keys if k != key]
    groups = {}
    for row in rows:
        label = ", ".join(f"{k} = {show(row[k])}" for k in others)
        groups.setdefault(label, []).append(row)
    fig, axes = plt.subplots(2, 2, figsize=(10.5, 7.5), sharex=True, layout="constrained")
    for (column, label), ax in zip(PANELS, axes.ravel()):
        for group, members in groups.items():
            members = sorted(members, key=lambda r: position[show(r[key])])
            x = np.array([position[show(r[key])] for r in members], dtype=float)
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
        fig.legend(handles, list(groups), loc="outside lower center", fontsize="small",
                   title="other settings", ncols=min(3, len(groups)))
    failed = sum(row["outcome"] != "ok" for row in rows)
    note = f"; × on the time panel: {failed} failed run(s)" if failed else ""
    fig.suptitle(f"{plot_title(title)}\nsweep over {key}{note}", fontsize="medium")
    return fig


def plot_key(path, rows, keys, key, title, units=None, dim=2):
    """``by_<key>.png``: :func:`figure_key`, written atomically."""
    fig = figure_key(rows, keys, key, title, units, dim)
    try:
        write_atomic(path, lambda f: fig.savefig(f, format="png", dpi=DPI), binary=True)
    finally:
        plt.close(fig)


def plot_name(key):
    return f"by_{key}.png"


def _fmt(value, spec):
    return "—" if value is None else format(value, spec)


def table(rows, keys):
    """One line per run: its settings, outcome, time, iterations, β and force at T."""
    lines = []
    for row in rows:
        settings = ", ".join(f"{k}={show(row[k])}" for k in keys)
        if row["outcome"] == "ok":
            result = (f"ok, {row['newton_total']} Newton its, β mean "
                      f"{_fmt(row['beta_mean_T'], '.4g')}, normal force "
                      f"{_fmt(row['normal_force_T'], '.4g')}")
        elif row["outcome"] == LOST:
            lines.append(f"run {row['run']:>3}: {settings}: LOST (its worker died; not saved: "
                         "the same command computes it again)")
            continue
        else:
            result = (f"FAILED at step {row['failed_step']} (t = {row['failed_t']:g}), "
                      f"residual {row['residual']:.2e}")
        lines.append(f"run {row['run']:>3}: {settings}: {result}; {row['seconds']:.2f} s")
    return lines


def guard_variants(source, settings, grid, force):
    """Refuse (exit 2) a sweep with a variant larger than the machine, before
    any variant's mesh is built (:func:`~.common.guard`); ``source`` is the
    decoded scene document."""
    if force:
        return
    for values in variants(settings, "grid" if grid else "zip"):
        try:
            scene = scene_from_dict(variant_document(source, values))
        except (SceneError, ValueError):
            continue   # the sweep names the setting at fault
        where = ", ".join(f"{k}={show(v)}" for k, v in values.items())
        guard(scene, what=f"the variant {where}")


@click.command()
@click.argument("scene", type=click.Path(dir_okay=False, path_type=Path))
@click.option("--set", "assignments", multiple=True, required=True, metavar="KEY=V1,V2,...",
              help="A dotted scene key and its values, e.g. contact.normal.c=1e2,1e3 or "
                   "time.steps=10,20 (TOML values; a bare word is a string; an integer "
                   "part indexes an array of tables: contact.friction.0.mu=0.2,0.4). "
                   "Repeat for more keys.")
@click.option("--grid/--zip", default=True, show_default=True,
              help="Every combination of the values (grid), or the i-th values of every "
                   "key together (zip: equal lengths).")
@click.option("--jobs", type=click.IntRange(min=1), default=None,
              help="Run the variants in this many local processes.  [default: 1]")
@scheduler_option("variants")
@click.option("--out", type=click.Path(file_okay=False, path_type=Path),
              help="Output folder. Default: ./<scene file stem>-sweep.")
@click.option("--force", is_flag=True,
              help="Run even when a variant's estimated memory or time exceeds what the "
                   "machine has.")
def sweep(scene, assignments, grid, jobs, scheduler, out, force):
    """Run SCENE (a TOML file) for every variant given by --set.

    Every variant's scene is checked before anything runs. Writes runs.csv
    (one row per run: the values set, outcome ok or failed with the step,
    time and residual, wall seconds, Newton iterations total and max per
    step, the worker's peak resident memory so far, β min and mean at T,
    max u_ν − g, contact node counts and the total normal contact force at
    T) and one figure by_<key>.png per swept key. A run that does not
    converge is a row, not an error. The sweep resumes: each finished run is
    saved in runs/ and the same command run again computes only what is
    missing; another sweep is refused in that folder. With --scheduler the
    runs go to a dask cluster; a run whose worker died (after the
    scheduler's retries) is a row "lost", not saved, computed again by the
    next run of the command.
    """
    name, text = read_scene(scene)
    load_scene(text, scene_folder(scene), force)
    out = Path(out) if out is not None else Path.cwd() / f"{name}-sweep"
    check_out(out)
    def make():
        settings = [parse_assignment(a) for a in assignments]
        source = study_source(text, scene_folder(scene))
        guard_variants(source, settings, grid, force)
        return Sweep(source, settings, "grid" if grid else "zip", folder=out)

    study = open_study(make, out, "sweep")
    executor = open_executor(scheduler, jobs)
    for warning in dict.fromkeys(w for _, w in study.warnings):
        runs = [str(i) for i, w in study.warnings if w == warning]
        click.echo(f"warning: run {', '.join(runs)}: {' '.join(warning.split())}", err=True)

    total = len(study.runs)
    keys = study.keys_set
    with click.progressbar(length=total, file=sys.stderr, show_pos=True,
                           label=f"{name}: sweep of {total} runs") as bar:
        def progress(stage, done, total):
            bar.update(done - bar.pos)
        with running_study(out, executor, "runs"):
            result = study.run(jobs=jobs or 1, executor=executor, progress=progress)
            files = list(result.files)
            for key in keys:
                files.append(plot_name(key))
                plot_key(out / files[-1], result.rows, keys, key, study.base.title,
                         Units(study.base.units), study.base.dim)

    failed = sum(row["outcome"] == "failed" for row in result.rows)
    lost = len(result.lost)
    computed = len(result.computed)
    click.echo(study.base.title)
    click.echo(f"  {total} runs ({'grid' if grid else 'zip'} over {', '.join(keys)}): "
               f"{computed} computed now, {total - computed - lost} loaded; "
               f"{total - failed - lost} ok, {failed} failed"
               + (f", {lost} lost (run the command again to compute them)" if lost else ""))
    for line in table(result.rows, keys):
        click.echo("  " + line)
    click.echo(f"  wrote {out}/: {', '.join(files)}")
