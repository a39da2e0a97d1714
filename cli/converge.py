"""``adhcontact converge``: a convergence study in h, k or both (SPEC.md,
"Command line (firm)"; MODEL.md §7).

The computation is :mod:`adhesive_contact.convergence`; this module decides
what to (re)compute, stores it and reports it. The output folder is the
study's state, so an interrupted study resumes where it stopped:

- ``study.json``: what the study is (the resolved scene, param, levels,
  reference kind, ref_h and ref_k) and the sha256 of exactly that; written
  first. A rerun whose study hashes the same resumes, any other is refused;
- ``reference.npz`` (``--reference fine``): the reference run's t, u, beta,
  facets, its refine and steps and its wall time, saved once computed;
- ``levels/level_NN.json``: one record of
  :func:`~adhesive_contact.convergence.run_level` per finished level, saved
  the moment the level finishes;
- ``errors.csv``, ``rates.json`` (firm keys), ``error_vs_h.png`` (or
  ``error_vs_k.png``) and ``work_precision.png``: rewritten from the saved
  records at the end of every completed run.

Every file is written to a temporary file beside it and renamed into place,
so a reader (or a rerun after a crash) never sees half a file.
"""

import csv
import hashlib
import json
import math
import multiprocessing
import sys
import textwrap
import zipfile
from concurrent.futures import ProcessPoolExecutor, as_completed
from dataclasses import replace
from pathlib import Path

import click
import matplotlib.pyplot as plt  # noqa: E402  (after .plots: the Agg backend)
import numpy as np
from matplotlib.ticker import NullFormatter  # noqa: E402

from adhesive_contact import StepFailure, parse_scene
from adhesive_contact.storage import plain, write_atomic, write_json
from adhesive_contact.convergence import (
    PARAMS,
    Reference,
    default_reference_refinement,
    pairwise_rates,
    rates,
    reference_scene,
    run_level,
    run_reference,
    with_discretisation,
)

from .common import CliError, echo_warnings, load_scene, read_scene
from .plots import DPI

STUDY = "study.json"
REFERENCE = "reference.npz"
LEVELS = "levels"
STUDY_KEYS = ("scene", "param", "levels", "reference", "ref_h", "ref_k")
FLOAT_KEYS = ("h", "k", "err_u", "err_beta", "E", "seconds")
RECORD_KEYS = ("level", "h", "k", "dofs", "steps", "err_u", "err_beta", "E", "seconds")
CSV_COLUMNS = ("level", "h", "k", "dofs", "steps", "err_u", "err_beta", "E", "rate_E",
               "seconds")
MEANINGFUL_LEVELS = 4   # MODEL.md §7: a rate is fitted over at least 4 levels


# ---------------------------------------------------------------- the study


def study_document(scene, param, levels, reference, ref_h, ref_k):
    """The ``study.json`` document: the study and the sha256 of it."""
    study = plain({"scene": scene.resolved, "param": param, "levels": levels,
                   "reference": reference, "ref_h": ref_h, "ref_k": ref_k})
    text = json.dumps(study, sort_keys=True, separators=(",", ":"), allow_nan=False)
    return {**study, "sha256": hashlib.sha256(text.encode("utf-8")).hexdigest()}


def _difference(stored, study):
    """What differs between a stored study and the one asked for (one phrase)."""
    if not isinstance(stored, dict):
        return f"its {STUDY} is unreadable"
    parts = [f"{key} {stored.get(key)!r} there, {study[key]!r} here"
             for key in STUDY_KEYS[1:] if stored.get(key) != study[key]]
    if stored.get("scene") != study["scene"]:
        parts.append("another scene")
    return "; ".join(parts) or f"its {STUDY} does not match"


def open_study(out, study):
    """Check ``--out`` against the study; True to resume a saved one.

    Writes nothing. Raises :class:`CliError` (exit 2) when ``out`` is a file,
    holds a different study, or is a non-empty folder without ``study.json``
    (whose files are never touched)."""
    if out.exists() and not out.is_dir():
        raise CliError(f"--out: {str(out)!r} exists and is not a folder", 2)
    if not out.is_dir():
        return False
    path = out / STUDY
    if path.is_file():
        try:
            stored = json.loads(path.read_text(encoding="utf-8"))
        except (OSError, ValueError):
            stored = None
        if isinstance(stored, dict) and stored.get("sha256") == study["sha256"]:
            return True
        raise CliError(f"--out {out} holds a different study ({_difference(stored, study)}); "
                       "use another --out or remove it", 2)
    if any(out.iterdir()):
        raise CliError(f"--out: {str(out)!r} is a non-empty folder that is not a "
                       f"convergence study (no {STUDY}); choose another folder", 2)
    return False


def level_path(out, level):
    return out / LEVELS / f"level_{level:02d}.json"


def _from_json(record):
    """A stored level record with null errors read back as NaN."""
    return {**record, **{key: (math.nan if record[key] is None else float(record[key]))
                         for key in FLOAT_KEYS}}


def load_levels(out, levels):
    """{level: record} of the levels saved in ``out`` (unreadable ones left out)."""
    records = {}
    for level in range(levels):
        path = level_path(out, level)
        if not path.is_file():
            continue
        try:
            record = json.loads(path.read_text(encoding="utf-8"))
        except (OSError, ValueError):
            continue
        if (isinstance(record, dict) and record.get("level") == level
                and all(key in record for key in RECORD_KEYS)):
            records[level] = _from_json(record)
    return records


def save_reference(path, reference):
    """``reference.npz``: the arrays of a :class:`Reference`, its refine, steps, seconds."""
    arrays = {"t": reference.t, "u": reference.u, "beta": reference.beta,
              "facets": np.asarray(reference.facets, dtype=np.int64),
              "refine": np.int64(reference.scene.mesh.refine),
              "steps": np.int64(reference.scene.steps),
              "seconds": np.float64(reference.seconds)}
    write_atomic(path, lambda f: np.savez_compressed(f, **arrays), binary=True)


def load_reference(path, scene, arrays=True):
    """The saved :class:`Reference` of reference scene ``scene``; None when
    ``path`` is missing, unreadable or of another refine or number of steps.

    With ``arrays=False`` only its seconds are read (t, u, beta, facets None):
    a study whose levels are all saved needs no more."""
    if not path.is_file():
        return None
    try:
        with np.load(path) as data:
            if int(data["refine"]) != scene.mesh.refine or int(data["steps"]) != scene.steps:
                return None
            seconds = float(data["seconds"])
            if not arrays:
                return Reference(scene, None, None, None, None, seconds)
            if data["t"].shape != (scene.steps + 1,) or data["u"].shape[0] != scene.steps + 1:
                return None
            return Reference(scene, data["t"], data["u"], data["beta"], data["facets"],
                             seconds)
    except (OSError, KeyError, ValueError, zipfile.BadZipFile):
        return None


# ---------------------------------------------------------------- running levels

_WORKER = {}


def _init_worker(text, base, param, levels, ref_h, ref_k, reference):
    """Set up a worker process: the scene is re-parsed from its TOML text (with
    the study's level-0 refine and steps) and the reference (sent without
    its scene) gets its scene back."""
    scene = with_discretisation(parse_scene(text), *base)
    if reference is not None:
        reference = replace(reference, scene=reference_scene(scene, param, levels, ref_h, ref_k))
    _WORKER.update(scene=scene, param=param, reference=reference)


def _run_level_in_worker(level):
    """(level, record, None), or (level, None, message) for a StepFailure (which
    does not survive pickling back to the parent)."""
    try:
        return level, run_level(_WORKER["scene"], _WORKER["param"], level,
                                _WORKER["reference"]), None
    except StepFailure as err:
        return level, None, str(err)


def run_missing(missing, save, scene, text, base, param, levels, ref_h, ref_k, reference,
                jobs):
    """Run the levels ``missing``, calling ``save(record)`` as each finishes.

    ``jobs`` > 1 runs them in that many worker processes (spawned). A
    StepFailure in any level becomes a :class:`CliError` (exit 1) once the
    levels already running have finished (and been saved)."""
    if jobs == 1 or len(missing) <= 1:
        for level in missing:
            try:
                record = run_level(scene, param, level, reference)
            except StepFailure as err:
                raise CliError(f"level {level}: {err}", 1) from None
            save(record)
        return
    light = None if reference is None else replace(reference, scene=None)
    failure = None
    with ProcessPoolExecutor(max_workers=min(jobs, len(missing)),
                             mp_context=multiprocessing.get_context("spawn"),
                             initializer=_init_worker,
                             initargs=(text, base, param, levels, ref_h, ref_k, light)) as pool:
        futures = [pool.submit(_run_level_in_worker, level) for level in missing]
        for future in as_completed(futures):
            if future.cancelled():
                continue
            level, record, message = future.result()
            if message is None:
                save(record)
            elif failure is None:
                failure = f"level {level}: {message}"
                for other in futures:
                    other.cancel()
    if failure is not None:
        raise CliError(failure, 1)


# ---------------------------------------------------------------- results


def results(records, param, reference_info):
    """The ``rates.json`` document (firm keys first)."""
    pairwise = pairwise_rates(records, param)
    levels = []
    for record, rate in zip(records, pairwise):
        levels.append({key: record[key] for key in ("h", "k", "dofs", "err_u", "err_beta",
                                                     "E", "seconds")}
                      | {"level": record["level"], "steps": record["steps"],
                         "refine": record.get("refine"), "rate_E": rate,
                         "newton_iterations": record.get("newton_iterations")})
    return {"param": param, "levels": levels, "rates": rates(records, param),
            "reference": reference_info}


def write_errors_csv(path, document):
    """``errors.csv``: one row per level; rate_E empty on the first level."""
    def write(f):
        writer = csv.writer(f, lineterminator="\n")
        writer.writerow(CSV_COLUMNS)
        for row in document["levels"]:
            writer.writerow(["" if row[key] is None else
                             (repr(float(row[key])) if isinstance(row[key], float) else row[key])
                             for key in CSV_COLUMNS])
    write_atomic(path, write)


def _fmt(value, spec=".3e", none="—"):
    if value is None or (isinstance(value, float) and not math.isfinite(value)):
        return none
    return format(value, spec)


def table(document):
    """The printed table of levels and the fitted rates (a list of lines)."""
    header = (f"{'level':>5} {'h':>10} {'k':>10} {'dofs':>8} {'‖ε(u−u_h)‖':>11} "
              f"{'‖β−β_h‖':>10} {'E':>10} {'rate E':>7} {'seconds':>8}")
    lines = [header]
    for row in document["levels"]:
        lines.append(f"{row['level']:>5} {_fmt(row['h']):>10} {_fmt(row['k']):>10} "
                     f"{row['dofs']:>8} {_fmt(row['err_u']):>11} {_fmt(row['err_beta']):>10} "
                     f"{_fmt(row['E']):>10} {_fmt(row['rate_E'], '.2f'):>7} "
                     f"{_fmt(row['seconds'], '.2f'):>8}")
    fit = document["rates"]
    size = "k" if document["param"] == "k" else "h"
    n = len(document["levels"])
    lines.append(f"least-squares rates over {n} levels (slope of log error against log "
                 f"{size}): u {_fmt(fit['u'], '.3f')}, β {_fmt(fit['beta'], '.3f')}, "
                 f"E {_fmt(fit['E'], '.3f')}"
                 + (f"  (only {n} levels: a meaningful rate needs >= {MEANINGFUL_LEVELS})"
                    if n < MEANINGFUL_LEVELS else ""))
    return lines


# ---------------------------------------------------------------- plots

ERRORS = (("err_u", "‖ε(u − u_h)‖", "u", "o"), ("err_beta", "‖β − β_h‖", "beta", "s"),
          ("E", "E = ‖ε(u − u_h)‖ + ‖β − β_h‖", "E", "^"))


def _positive(x, y):
    x, y = np.asarray(x, float), np.array([np.nan if v is None else v for v in y], float)
    ok = np.isfinite(y) & (y > 0) & (x > 0)
    return x[ok], y[ok]


def _reference_phrase(info):
    if info["kind"] == "exact":
        return "reference: the scene's exact solution"
    return (f"reference: fine run (refine {info['refine']}, {info['steps']} steps, "
            f"{info['seconds']:.3g} s)")


def _suptitle(fig, document, title):
    wrapped = textwrap.fill(title, 70)
    fig.suptitle(f"{wrapped}\n{document['param']}-refinement, {len(document['levels'])} "
                 f"levels; {_reference_phrase(document['reference'])}", fontsize="medium")


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


def plot_error_vs_size(path, document, title):
    """Errors against h (or k) log-log, with the fitted slopes in the legend."""
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
    ax.set_xlabel({"h": "mesh size h", "k": "time step k",
                   "hk": "mesh size h (time step k halved with h)"}[param])
    ax.set_ylabel("error, max over the time grid")
    _save(fig, ax, path, document, title)


def _save(fig, ax, path, document, title):
    """Grid, titles, and the PNG written atomically."""
    ax.grid(True, which="both", color="0.9", linewidth=0.6)
    _suptitle(fig, document, title)
    write_atomic(path, lambda f: fig.savefig(f, format="png", dpi=DPI, bbox_inches="tight"),
                 binary=True)
    plt.close(fig)


def plot_work_precision(path, document, title):
    """E against the wall time of each level's run, log-log."""
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
    _save(fig, ax, path, document, title)


def write_results(out, document, title):
    """Write errors.csv, rates.json and the two plots; return their names."""
    size = "k" if document["param"] == "k" else "h"
    names = ["errors.csv", "rates.json", f"error_vs_{size}.png", "work_precision.png"]
    write_errors_csv(out / names[0], document)
    write_json(out / names[1], document)
    plot_error_vs_size(out / names[2], document, title)
    plot_work_precision(out / names[3], document, title)
    return names


# ---------------------------------------------------------------- the command

#: the largest run a study may ask for (dofs); beyond it the set-up alone
#: (a Schur complement onto Γ_C) takes hours and tens of GB on this class
#: of machine (studies/README.md, Cost)
MAX_DOFS = 2_000_000


def check_size(scene, problem, param, levels, reference, ref_h, ref_k, base_refine):
    """Refuse (exit 2) a study whose finest level or reference is too large."""
    growth = 2 ** scene.dim            # dofs per uniform refinement
    base = problem.ndofs * growth ** ((base_refine or scene.mesh.refine) - scene.mesh.refine)
    extra = (levels - 1 if param in ("h", "hk") else 0) + (ref_h if reference == "fine" else 0)
    largest = base * growth ** extra
    if largest > MAX_DOFS:
        what = "the fine reference" if reference == "fine" and ref_h else "the finest level"
        raise CliError(f"--levels: {what} would have about {largest:.2g} dofs (more than "
                       f"{MAX_DOFS:.0e}); use fewer --levels, a smaller --ref-h, or a coarser "
                       "mesh for level 0", 2)



@click.command()
@click.argument("scene", type=click.Path(dir_okay=False, path_type=Path))
@click.option("--param", type=click.Choice(PARAMS), required=True,
              help="Refine in space (h: one uniform refinement per level), in time "
                   "(k: the step halved per level) or both (hk).")
@click.option("--levels", type=click.IntRange(min=2), default=5, show_default=True,
              help="Number of levels (>= 2; a meaningful rate needs >= 4).")
@click.option("--reference", type=click.Choice(("exact", "fine")), default=None,
              help="Measure against the scene's [exact] solution, or a fine reference "
                   "run. Default: exact if the scene has an [exact] table, else fine.")
@click.option("--jobs", type=click.IntRange(min=1), default=1, show_default=True,
              help="Run the levels in this many processes (the reference runs first, "
                   "alone).")
@click.option("--ref-h", type=click.IntRange(min=0), default=None,
              help="Extra mesh refinements of the fine reference beyond the finest level. "
                   "Default: 2 for --param h/hk, else 0.")
@click.option("--ref-k", type=click.IntRange(min=0), default=None,
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
def converge(scene, param, levels, reference, jobs, ref_h, ref_k, base_refine, base_steps,
             out):
    """Convergence study of SCENE (a TOML file) in h, k or both (MODEL.md §7).

    Prints a table of the errors ‖ε(u − u_h)‖, ‖β − β_h‖ and E (max over the
    time grid) per level with their least-squares rates, and writes
    errors.csv, rates.json, error_vs_h.png (error_vs_k.png for --param k)
    and work_precision.png into the output folder.

    The study resumes: the folder keeps study.json, each finished level
    (levels/level_NN.json) and the fine reference (reference.npz), and the
    same command run again computes only what is missing. Any other study
    (another scene, --param, --levels, --reference, --ref-h or --ref-k;
    more --levels too) is refused in that folder: use another --out.
    """
    name, text = read_scene(scene)
    parsed, problem = load_scene(text)
    base = (base_refine, base_steps)
    parsed = with_discretisation(parsed, *base)
    if reference is None:
        reference = "exact" if parsed.exact is not None else "fine"
    if reference == "exact" and parsed.exact is None:
        raise CliError("--reference: 'exact' needs an [exact] table in the scene; "
                       "allowed here: fine", 2)
    if reference == "fine" and parsed.dim == 3 and parsed.has_contact_terms:
        raise CliError("--reference: 'fine' carries β between nested meshes in 2D only; "
                       "allowed for this 3D scene: exact (add an [exact] table)", 2)
    if reference == "exact" and (ref_h is not None or ref_k is not None):
        raise CliError("--ref-h/--ref-k: refine the fine reference; allowed only with "
                       "--reference fine (the reference here is the exact solution)", 2)
    if reference == "fine":
        dh, dk = default_reference_refinement(param)
        ref_h = dh if ref_h is None else ref_h
        ref_k = dk if ref_k is None else ref_k
    check_size(parsed, problem, param, levels, reference, ref_h, ref_k, base_refine)
    out = Path(out) if out is not None else Path.cwd() / f"{name}-converge-{param}"
    study = study_document(parsed, param, levels, reference, ref_h, ref_k)
    resume = open_study(out, study)
    echo_warnings(problem)
    if levels < MEANINGFUL_LEVELS:
        click.echo(f"note: --levels {levels}: a least-squares rate is meaningful only over "
                   f">= {MEANINGFUL_LEVELS} levels (MODEL.md §7)", err=True)

    try:
        out.mkdir(parents=True, exist_ok=True)
        if not resume:
            write_json(out / STUDY, {**study, "scene_file": str(scene)})
        (out / LEVELS).mkdir(exist_ok=True)
    except OSError as err:
        raise CliError(f"--out: cannot write {str(out)!r}: {err}", 1) from None

    try:
        done = load_levels(out, levels)
        missing = [level for level in range(levels) if level not in done]
        fine, info = None, {"kind": reference}
        if reference == "fine":
            rscene = reference_scene(parsed, param, levels, ref_h, ref_k)
            fine = load_reference(out / REFERENCE, rscene, arrays=bool(missing))
            if fine is None:
                click.echo(f"reference: refine {rscene.mesh.refine}, {rscene.steps} steps ...",
                           err=True)
                try:
                    with click.progressbar(length=rscene.steps + 1, file=sys.stderr,
                                           label="reference run") as rbar:
                        fine = run_reference(parsed, param, levels, ref_h, ref_k,
                                             progress=lambda n, N: rbar.update(1))
                except StepFailure as err:
                    raise CliError(f"reference run: {err}", 1) from None
                save_reference(out / REFERENCE, fine)
            else:
                click.echo(f"reference: loaded from {out / REFERENCE}", err=True)
            info |= {"ref_h": ref_h, "ref_k": ref_k, "refine": rscene.mesh.refine,
                     "steps": rscene.steps, "k": rscene.k, "seconds": fine.seconds}
        with click.progressbar(length=levels, file=sys.stderr, show_pos=True,
                               label=f"{name}: {param}-study, {levels} levels") as bar:
            bar.update(len(done))

            def save(record):
                write_json(level_path(out, record["level"]), record)
                done[record["level"]] = record
                bar.update(1)

            run_missing(missing, save, parsed, text, base, param, levels, ref_h, ref_k, fine,
                        jobs)

        records = [done[level] for level in range(levels)]
        if reference == "fine":
            info["h"] = records[-1]["h"] / 2 ** ref_h
        document = results(records, param, info)
        files = write_results(out, document, parsed.title)
    except OSError as err:
        raise CliError(f"--out: cannot write {str(out)!r}: {err}", 1) from None

    click.echo(parsed.title)
    click.echo(f"  {_reference_phrase(info)}; {len(missing)} of {levels} levels computed "
               f"now, {levels - len(missing)} loaded")
    for line in table(document):
        click.echo("  " + line)
    click.echo(f"  wrote {out}/: {', '.join(files)}")
