"""``adhcontact converge``: a convergence study in h, k or both (docs/scenes.md,
"Command line (firm)"; docs/verification.md).

The study is :class:`adhesive_contact.studies.ConvergenceStudy` (what to
(re)compute, the folder ``--out`` that keeps it, errors.csv and
rates.json); this module parses the options, shows progress, prints the
table and has :mod:`adhesive_contact.visuals` draw ``error_vs_h.png`` (or
``error_vs_k.png``) and ``work_precision.png`` from the results document.
"""

import math
import sys
from pathlib import Path

import click

from adhesive_contact.studies import (
    ConvergenceStudy,
    RunFailed,
)
from adhesive_contact.studies.convergence import MEANINGFUL_LEVELS
from adhesive_contact.studies.levels import PARAMS, level_scene
from adhesive_contact.visuals import write_convergence_plots
from adhesive_contact.visuals.studies import reference_phrase

from .common import (
    CliError,
    check_out,
    echo_warnings,
    guard,
    load_scene,
    open_study,
    read_scene,
    running_study,
    scene_folder,
    study_source,
)
from .scheduler import open_executor, scheduler_option

# ---------------------------------------------------------------- the table


def _fmt(value, spec=".3e", none="—"):
    if value is None or (isinstance(value, float) and not math.isfinite(value)):
        return none
    return format(value, spec)


def norms_legend(document):
    """What the table's columns are (lines printed above it): the norms,
    over which times, against what, and which h."""
    against = ("u, β: the scene's exact solution" if document["reference"]["kind"] == "exact"
               else "u, β: the fine reference run, u_h carried to its mesh (exact nested "
                    "P1 prolongation) and β_h to its facets")
    return [
        "errors, each the max over the time levels t_n of the level "
        "(docs/verification.md):",
        "  ‖ε(u−u_h)‖ = ‖ε(u(t_n)) − ε(u_h^n)‖ in L²(Ω);  ‖β−β_h‖ = ‖β(t_n) − β_h^n‖ in "
        "L²(Γ_C);  E = max of their sum",
        f"  {against}",
        "  rel = the error over the same norm of u, β (its max over t_n; for E the sum "
        "of both);  h = the largest edge length (cell diameter) of the mesh, k = T/N",
    ]


def table(document):
    """The printed table of levels and the fitted rates (a list of lines):
    :func:`norms_legend`, then per level the absolute and relative errors."""
    header = (f"{'level':>5} {'h':>9} {'k':>9} {'dofs':>7} {'‖ε(u−u_h)‖':>10} {'rel':>7} "
              f"{'‖β−β_h‖':>9} {'rel':>7} {'E':>9} {'rel':>7} {'rate E':>6} {'seconds':>7}")
    lines = norms_legend(document) + [header]
    for row in document["levels"]:
        lines.append(f"{row['level']:>5} {_fmt(row['h'], '.2e'):>9} {_fmt(row['k'], '.2e'):>9} "
                     f"{row['dofs']:>7} {_fmt(row['err_u'], '.3e'):>10} "
                     f"{_fmt(row.get('rel_u'), '.1e'):>7} "
                     f"{_fmt(row['err_beta'], '.2e'):>9} {_fmt(row.get('rel_beta'), '.1e'):>7} "
                     f"{_fmt(row['E'], '.2e'):>9} {_fmt(row.get('rel_E'), '.1e'):>7} "
                     f"{_fmt(row['rate_E'], '.2f'):>6} {_fmt(row['seconds'], '.2f'):>7}")
    fit = document["rates"]
    size = "k" if document["param"] == "k" else "h"
    n = len(document["levels"])
    lines += quantity_table(document)
    lines.append(f"least-squares rates over {n} levels (slope of log error against log "
                 f"{size}): u {_fmt(fit['u'], '.3f')}, β {_fmt(fit['beta'], '.3f')}, "
                 f"E {_fmt(fit['E'], '.3f')}"
                 + (f", Q {_fmt(fit['Q'], '.3f')}" if "Q" in fit else "")
                 + (f"  (only {n} levels: a meaningful rate needs >= {MEANINGFUL_LEVELS})"
                    if n < MEANINGFUL_LEVELS else ""))
    return lines


def quantity_table(document):
    """The lines of a study of a quantity (none without one): per level Q_h,
    |Q_h − Q_ref|, that relative to |Q_ref| and the pairwise rate."""
    if "quantity" not in document:
        return []
    q = document["quantity"]
    lines = [f"quantity {q['name']}: Q_ref = {_fmt(q['reference'], '.6g')} (the fine "
             "reference run's value)",
             f"{'level':>5} {'Q_h':>13} {'|Q_h−Q_ref|':>12} {'rel':>7} {'rate':>6}"]
    for row in document["levels"]:
        lines.append(f"{row['level']:>5} {_fmt(row['quantity'], '.6g'):>13} "
                     f"{_fmt(row['err_q'], '.3e'):>12} {_fmt(row['rel_q'], '.1e'):>7} "
                     f"{_fmt(row['rate_q'], '.2f'):>6}")
    return lines


# ---------------------------------------------------------------- the command


def option_name(key):
    """The option of a study argument: "ref_h/ref_k" -> "--ref-h/--ref-k"."""
    names = {"folder": "out", "refine": "refine", "steps": "steps"}
    return "/".join("--" + names.get(part, part).replace("_", "-") for part in key.split("/"))


@click.command()
@click.argument("scene", type=click.Path(dir_okay=False, path_type=Path))
@click.option("--param", type=click.Choice(PARAMS), required=True,
              help="Refine in space (h: one uniform refinement per level), in time "
                   "(k: the step halved per level) or both (hk).")
@click.option("--levels", type=click.IntRange(min=2, max=20), default=5, show_default=True,
              help="Number of levels (2..20; a meaningful rate needs >= 4).")
@click.option("--reference", type=click.Choice(("exact", "fine")), default=None,
              help="Measure against the scene's [exact] solution, or a fine reference "
                   "run. Default: exact if the scene has an [exact] table, else fine.")
@click.option("--jobs", type=click.IntRange(min=1), default=None,
              help="Run the levels in this many local processes (the reference runs "
                   "first, alone, here).  [default: 1]")
@scheduler_option("levels (the fine reference runs first, here)")
@click.option("--ref-h", type=click.IntRange(min=0, max=12), default=None,
              help="Extra mesh refinements of the fine reference beyond the finest level. "
                   "Default: 2 for --param h/hk, else 0.")
@click.option("--ref-k", type=click.IntRange(min=0, max=30), default=None,
              help="The fine reference takes 2**REF_K times the steps of the finest level. "
                   "Default: 4 for --param k, 2 for hk, else 0.")
@click.option("--refine", "base_refine", type=click.IntRange(min=0, max=12), default=None,
              help="Mesh refinement of level 0 instead of the scene's mesh.refine "
                   "(e.g. a fine mesh for a k-study).")
@click.option("--steps", "base_steps", type=click.IntRange(min=1), default=None,
              help="Steps of level 0 instead of the scene's time.steps (e.g. many steps "
                   "for an h-study, so that the time error stays below the space error).")
@click.option("--out", type=click.Path(file_okay=False, path_type=Path),
              help="Output folder. Default: ./<scene file stem>-converge-<param>.")
@click.option("--quantity", default=None, metavar="NAME",
              help="Also fit the rate of this scalar quantity's error |Q_h − Q_ref| "
                   "against the fine reference (e.g. reaction_top_y_peak, debonding_T; "
                   "the names of a sweep's runs.csv, docs/outputs.md).")
@click.option("--force", is_flag=True,
              help="Run even when the largest run's estimated memory or time exceeds what "
                   "the machine has.")
def converge(scene, param, levels, reference, jobs, scheduler, ref_h, ref_k, base_refine,
             base_steps, out, quantity, force):
    """Convergence study of SCENE (a TOML file) in h, k or both (docs/verification.md).

    Prints a table of the errors ‖ε(u − u_h)‖, ‖β − β_h‖ and E (max over the
    time grid) per level with their least-squares rates, and writes
    errors.csv, rates.json, error_vs_h.png (error_vs_k.png for --param k)
    and work_precision.png into the output folder.

    The study resumes: the folder keeps study.json, each finished level
    (levels/level_NN.json) and the fine reference (reference.npz), and the
    same command run again computes only what is missing. Any other study
    (another scene, --param, --levels, --reference, --ref-h, --ref-k or
    --quantity; more --levels too) is refused in that folder: use another --out.

    With --quantity NAME the table also has the quantity Q_h per level, its
    error against the fine reference's value and their rates, and
    quantity_vs_h.png (or _vs_k) is drawn.
    """
    name, text = read_scene(scene)
    _, problem = load_scene(text, scene_folder(scene), force)
    out = Path(out) if out is not None else Path.cwd() / f"{name}-converge-{param}"
    check_out(out)
    study = open_study(lambda: ConvergenceStudy(
        study_source(text, scene_folder(scene)), param, levels, reference, folder=out,
        ref_h=ref_h, ref_k=ref_k, refine=base_refine, steps=base_steps,
        scene_file=str(scene), quantity=quantity), out, "study", option_name)
    guard(study.reference_scene or level_scene(study.scene, param, levels - 1), force,
          what="the largest run of the study")
    executor = open_executor(scheduler, jobs)
    echo_warnings(problem)
    if levels < MEANINGFUL_LEVELS:
        click.echo(f"note: --levels {levels}: a least-squares rate is meaningful only over "
                   f">= {MEANINGFUL_LEVELS} levels (docs/verification.md)", err=True)

    bars = Progress(name, study, per_level=executor is None and (jobs or 1) == 1)
    try:
        with running_study(out, executor, "levels"):
            result = study.run(jobs=jobs or 1, executor=executor, progress=bars)
            files = result.files + write_convergence_plots(
                out, result.document, study.scene.title, study.scene.units)
    except RunFailed as err:
        raise CliError(str(err), 1) from None
    finally:
        bars.close()

    document = result.document
    computed = len(result.computed)
    if result.reference_loaded:
        click.echo(f"reference: loaded from {out / 'reference.npz'}", err=True)
    click.echo(study.scene.title)
    click.echo(f"  {reference_phrase(document['reference'])}; {computed} of {levels} levels "
               f"computed now, {levels - computed} loaded")
    for line in table(document):
        click.echo("  " + line)
    for warning in document.get("warnings", []):
        click.echo(f"warning: {warning}", err=True)
    click.echo(f"  wrote {out}/: {', '.join(files)}")


class Progress:
    """The study's progress callback (stderr): a bar for the reference run;
    then, when the levels run here (``per_level``), a line naming the study
    and a bar per level over its steps, labelled with the level, its
    refinement and steps; else (local workers, a cluster, whose runs cannot
    report to this process) one bar of the finished levels."""

    def __init__(self, name, study, per_level=False):
        self.name, self.study, self.per_level = name, study, per_level
        self.bar, self.stage = None, None

    def __call__(self, stage, done, total):
        if stage == "levels" and (self.per_level or self.stage and self.stage.startswith(
                "level ")):
            if self.stage != "levels":
                self.close()
                if self.stage is None or self.stage == "reference":
                    loaded = f", {done} loaded from the folder" if done else ""
                    click.echo(f"{self.name}: {self.study.param}-study, {total} levels"
                               f"{loaded}", err=True)
                self.stage = "levels"
            return
        if stage != self.stage:
            self.close()
            self.stage = stage
            if stage == "reference":
                rscene = self.study.reference_scene
                click.echo(f"reference: refine {rscene.mesh.refine}, {rscene.steps} steps ...",
                           err=True)
                label = "reference run"
            elif stage.startswith("level "):
                level = int(stage.split()[1])
                lscene = level_scene(self.study.scene, self.study.param, level)
                label = (f"level {level} ({level + 1} of {self.study.levels}): refine {lscene.mesh.refine}, "
                         f"{lscene.steps} steps")
            else:
                label = f"{self.name}: {self.study.param}-study, {total} levels"
            self.bar = click.progressbar(length=total, file=sys.stderr, label=label,
                                         show_pos=stage == "levels")
            self.bar.__enter__()
        self.bar.update(done - self.bar.pos)

    def close(self):
        if self.bar is not None:
            self.bar.__exit__(None, None, None)
            self.bar = None
