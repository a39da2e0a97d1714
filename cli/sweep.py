"""``adhcontact sweep``: a parameter sweep of a scene.

The sweep is :class:`adhesive_contact.studies.Sweep` (variants, validation,
the folder ``--out`` that keeps it, runs.csv); this module parses the
options, shows progress, prints one line per run and has
:mod:`adhesive_contact.visuals` draw one figure per swept key
(``by_<key>.png``).
"""

import sys
from pathlib import Path

import click

from adhesive_contact import SceneError, scene_from_dict
from adhesive_contact.storage import toml_value
from adhesive_contact.studies import Sweep
from adhesive_contact.studies.sweep import LOST, variant_document, variants
from adhesive_contact.visuals import write_sweep_plots

from .assignments import AssignmentError, parse_assignment
from .common import (
    CliError,
    check_out,
    guard,
    load_scene,
    open_study,
    read_scene,
    running_study,
    scene_folder,
    study_source,
)
from .scheduler import open_executor, scheduler_option


def _fmt(value, spec):
    return "—" if value is None else format(value, spec)


def table(rows, keys):
    """One line per run: its settings, outcome, time, iterations, β and force at T."""
    lines = []
    for row in rows:
        settings = ", ".join(f"{k}={toml_value(row[k])}" for k in keys)
        if row["outcome"] == "ok":
            result = (f"ok, {row['newton_total']} Newton its, β mean "
                      f"{_fmt(row['beta_mean_T'], '.4g')}, normal force "
                      f"{_fmt(row['normal_force_T'], '.4g')}")
        elif row["outcome"] == LOST:
            lines.append(f"run {row['run']:>3}: {settings}: LOST (its worker died; not saved: "
                         "the same command computes it again)")
            continue
        elif row["failed_step"] is None:   # a combination that is not a valid scene
            result = f"FAILED: {' '.join(str(row.get('message') or '').split())}"
        else:
            result = (f"FAILED at step {row['failed_step']} (t = {row['failed_t']:g}), "
                      f"residual {row['residual']:.2e}")
        lines.append(f"run {row['run']:>3}: {settings}: {result}; {row['seconds']:.2f} s")
    return lines


def guard_variants(source, settings, grid, force, base_dir=None):
    """Refuse (exit 2) a sweep with a variant larger than the machine, before
    any variant's mesh is built (:func:`~.common.guard`); ``source`` is the
    decoded scene document."""
    if force:
        return
    for values in variants(settings, "grid" if grid else "zip"):
        try:
            scene = scene_from_dict(variant_document(source, values), base_dir)
        except (SceneError, ValueError):
            continue   # the sweep names the setting at fault
        where = ", ".join(f"{k}={toml_value(v)}" for k, v in values.items())
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
                   "machine has, or when the settings give more than 1000 variants.")
def sweep(scene, assignments, grid, jobs, scheduler, out, force):
    """Run SCENE (a TOML file) for every variant given by --set.

    Every value of every --set is checked before anything runs (each
    applied to the first variant), and every variant's size; at most 1000
    variants unless --force. A combination of valid values that is not a
    valid scene is a failed row saying why. Writes runs.csv
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
    try:
        settings = [parse_assignment(a) for a in assignments]
    except AssignmentError as err:
        raise CliError(f"--{err}", 2) from None

    def make():
        source = study_source(text, scene_folder(scene))
        guard_variants(source, settings, grid, force, scene_folder(scene))
        return Sweep(source, settings, "grid" if grid else "zip", folder=out,
                     base_dir=scene_folder(scene), force=force)

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
            files = list(result.files) + write_sweep_plots(
                out, result.rows, keys, study.base.title, study.base.units, study.base.dim)

    seen = [(record.get("run"), w) for record in result.records
            for w in (record.get("warnings") or [])]
    for warning in dict.fromkeys(w for _, w in seen):   # what the runs showed
        runs = [str(i) for i, w in seen if w == warning]
        click.echo(f"warning: run {', '.join(runs)}: {' '.join(warning.split())}", err=True)
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
