"""``adhcontact``: the click front end (docs/outputs.md).

Exit codes: 0 success; 2 a bad scene or bad arguments (nothing written);
1 a run that failed (a step that did not converge or gave an invalid
state) or outputs that could not be written; 130 a run or a study stopped
by Ctrl-C (a study keeps its finished runs and resumes from them).
Every error is one line ``error: ...`` on stderr. The scene is parsed and
the problem built before any file is created; a run that fails or is
interrupted writes the levels it finished, marked partial in summary.json
(``run``). Outputs appear atomically (a new folder in one rename; into an
existing one file by file, touching no other file). What the theory does
not cover for a valid scene (``Problem.warnings()``) is reported as one
line ``warning: ...`` each on stderr before the time loop, and the run
goes on.

The figures are drawn by :mod:`adhesive_contact.visuals` into PNG files:
a command selects matplotlib's Agg backend (:func:`draw_to_files`), no
display is needed."""

import contextlib
import importlib
import io
import os
import signal
import sys
import threading
from pathlib import Path

import click

from .common import (
    CliError,
    check_out,
    echo_warnings,
    load_scene,
    read_scene,
    scene_folder,
    time_line,
)

#: commands imported only when run (the library, matplotlib and dask take a
#: second to import; ``adhcontact --help`` should not wait for them):
#: name -> (module, attribute, short help)
LAZY_COMMANDS = {
    "check": ("adhesive_contact_cli.check", "check",
              "Validate SCENE (the built-in default if omitted) and print what a run would be."),
    "converge": ("adhesive_contact_cli.converge", "converge",
                 "Convergence study of SCENE (a TOML file) in h, k or both."),
    "sweep": ("adhesive_contact_cli.sweep", "sweep",
              "Run SCENE (a TOML file) for every variant given by --set."),
}


def draw_to_files():
    """Select matplotlib's Agg backend for the figures of a command: PNG
    files, no display.

    The CLI does not import matplotlib: the choice is ``MPLBACKEND``, which
    matplotlib reads when it is first imported (by the library, when a
    command draws). A process that imported matplotlib before running a
    command in it (a notebook calling :func:`main`) keeps its own backend.
    """
    if "matplotlib" not in sys.modules:
        os.environ["MPLBACKEND"] = "Agg"


def end(code):
    """Exit with ``code``. After an HDF5 file failed to close (a full disk)
    the HDF5 library's own clean-up at exit crashes the process (a
    segmentation fault or an abort, io/h5.py): the outputs are then already
    removed and the message printed, so the process ends at once."""
    h5 = sys.modules.get("adhesive_contact.io.h5")   # never imported: nothing held
    code = code if isinstance(code, int) else (0 if code is None else 1)
    if h5 is not None and h5.held_open():
        sys.stdout.flush()
        sys.stderr.flush()
        os._exit(code)
    sys.exit(code)


class OneLineGroup(click.Group):
    """A click group whose errors (usage errors too) are one line on stderr."""

    def main(self, args=None, prog_name=None, complete_var=None, standalone_mode=True,
             **extra):
        """Run the group (figures drawn on the Agg backend, :func:`draw_to_files`);
        in standalone mode report errors as one line and exit."""
        draw_to_files()
        if not standalone_mode:
            return super().main(args, prog_name, complete_var, False, **extra)
        try:
            self._standalone(args, prog_name, complete_var, **extra)
        except SystemExit as done:
            end(done.code)

    def _standalone(self, args, prog_name, complete_var, **extra):
        try:
            code = super().main(args, prog_name, complete_var, False, **extra)
        except getattr(click.exceptions, "NoArgsIsHelpError", ()) as err:
            err.show()
            sys.exit(err.exit_code)
        except click.ClickException as err:
            message = " ".join(err.format_message().split())
            ctx = getattr(err, "ctx", None)
            if isinstance(err, click.UsageError) and ctx is not None:
                message += f" (see '{ctx.command_path} --help')"
            click.echo(f"error: {message}", err=True)
            sys.exit(err.exit_code)
        except click.Abort:   # Ctrl-C outside a time loop or a study's runs
            click.echo("error: interrupted", err=True)
            sys.exit(130)
        except MemoryError:
            click.echo("error: out of memory (the run needed more than the machine had; "
                       "the size check was skipped with --force or underestimated it)",
                       err=True)
            sys.exit(1)
        sys.exit(code if isinstance(code, int) else 0)


def level_status(level):
    """The progress bar's note on the last level: its t and Newton iterations."""
    if level is None:
        return None
    return f"t = {level.t:.4g}, {level.iterations} Newton iterations"


#: the signals that ask a run to stop at the end of its step, and the exit
#: code of a run they stopped (128 + the signal's number, as a shell reports)
STOP_SIGNALS = {signal.SIGINT: 130, signal.SIGTERM: 143}


def adaptive_pace(scene, folder, force):
    """The :class:`~adhesive_contact.resources.PaceGuard` of an adaptive
    run into ``folder`` (None for uniform steps or with ``--force``)."""
    if scene.adaptive is None or force:
        return None
    from adhesive_contact.resources import PaceGuard, estimate

    return PaceGuard(estimate(scene), scene.T, folder)


def folder_bytes(folder):
    """The bytes the files of ``folder`` hold (not its subfolders)."""
    return sum(entry.stat().st_size for entry in os.scandir(folder) if entry.is_file())


@contextlib.contextmanager
def interruptible():
    """A block in which Ctrl-C (SIGINT) or SIGTERM (what a batch system
    sends before it kills a job) asks the run to stop at the end of the
    current step instead of killing it: yields a function that returns the
    first such signal received (0 for none). A second one interrupts at
    once."""
    received = []

    def handler(signum, frame):
        if received:
            raise KeyboardInterrupt
        received.append(signum)

    if threading.current_thread() is not threading.main_thread():
        yield lambda: 0
        return
    previous = {sig: signal.signal(sig, handler) for sig in STOP_SIGNALS}
    try:
        yield lambda: received[0] if received else 0
    finally:
        for sig, action in previous.items():
            signal.signal(sig, action)


class LazyGroup(OneLineGroup):
    """A group whose commands of :data:`LAZY_COMMANDS` are imported when used;
    its help lists them with their short help without importing them."""

    def list_commands(self, ctx):
        return sorted([*super().list_commands(ctx), *LAZY_COMMANDS])

    def get_command(self, ctx, name):
        if name in LAZY_COMMANDS:
            module, attribute, _ = LAZY_COMMANDS[name]
            return getattr(importlib.import_module(module), attribute)
        return super().get_command(ctx, name)

    def format_commands(self, ctx, formatter):
        rows = [(name, LAZY_COMMANDS[name][2] if name in LAZY_COMMANDS else
                 super(LazyGroup, self).get_command(ctx, name).get_short_help_str(60))
                for name in self.list_commands(ctx)]
        with formatter.section("Commands"):
            formatter.write_dl(rows)


@click.group(cls=LazyGroup)
@click.version_option(package_name="adhesive_contact")
def main():
    """Quasistatic adhesive contact of a viscoelastic body with long memory."""


@main.command("solve")
@click.argument("scene", required=False,
                type=click.Path(dir_okay=False, path_type=Path))
@click.option("--out", type=click.Path(file_okay=False, path_type=Path),
              help="Output folder; in an existing one only the run's own files are replaced. "
                   "Default: ./<scene file stem>, ./default for the built-in scene.")
@click.option("--force", is_flag=True,
              help="Run even when the estimated memory, time or output size exceeds what "
                   "the machine has (summary.json records the estimate).")
@click.option("--quiet", "-q", is_flag=True,
              help="No warnings on stderr (they stay in summary.json) and no progress bar.")
def solve_command(scene, out, force, quiet):
    """Run SCENE (a TOML file; the built-in default scene if omitted).

    Writes summary.json, solution.npz, solution.xdmf/.h5 (ParaView) and PNG
    plots into the output folder.
    """
    from adhesive_contact import solve
    from adhesive_contact.io import StreamingRecorder
    from adhesive_contact.postprocess import beta_mean, contact_state_counts
    from adhesive_contact.problem.warnings import solution_warnings
    from adhesive_contact.scheme import STOPPED

    from adhesive_contact.io.folder import (holds_complete_run, output_names, staged_output,
                                            write_results)

    name, text = read_scene(scene)
    out = Path(out) if out is not None else Path.cwd() / name
    parsed, problem = load_scene(text, scene_folder(scene), force, out)
    check_out(out, output_names())
    if not quiet:
        echo_warnings(problem)
    base = scene_folder(scene)   # summary.json keeps the scene to rebuild the problem from
    source = {"text": text, "folder": None if base is None else str(base.resolve())}

    files, failures, kept, paced = [], [], False, []
    try:
        with staged_output(out) as folder:
            recorder = StreamingRecorder(problem, folder)   # levels to disk as computed
            pace = adaptive_pace(parsed, folder, force)

            def progress(n, N):
                bar.update(1, recorder.last)
                if pace is not None and not paced:
                    reason = pace.check(recorder.count, recorder.last.t,
                                        lambda: folder_bytes(folder))
                    if reason is not None:
                        paced.append(reason)
                return bool(interrupted()) or bool(paced)
            try:
                with click.progressbar(length=parsed.steps + 1,
                                       file=io.StringIO() if quiet else sys.stderr,
                                       label=(f"{name}: adaptive steps" if parsed.adaptive is not None
                                              else f"{name}: {parsed.steps} steps"),
                                       item_show_func=lambda level: level_status(level)) \
                        as bar, interruptible() as interrupted:
                    solution = solve(problem, recorder=recorder, progress=progress)
                    stopped_by = interrupted()
                # a partial run never replaces a complete earlier one
                kept = not solution.success and holds_complete_run(out)
                if solution.t.size and not kept:   # the levels that converged
                    lines = solution_warnings(solution)   # once: they read every level
                    for warning in lines:
                        if not quiet:
                            click.echo(f"warning: {warning}", err=True)
                    files = write_results(solution, folder, failures, source, lines,
                                          field_levels=recorder.field_levels())
            finally:
                recorder.close()
            files = sorted(files + recorder.names) if files else []
    except OSError as err:
        before = (" (the earlier run there is kept)" if holds_complete_run(out) else "")
        reason = err.strerror or err
        raise CliError(f"--out: cannot write {str(out)!r}: {reason}{before}", 1) from None
    for failure in failures:
        if not quiet:
            click.echo(f"warning: {failure}", err=True)
    not_written = (f"the {solution.t.size} levels done were not written: {out}/ holds a "
                   "complete earlier run, which is kept (use another --out to keep a "
                   "partial run)")
    if solution.status == STOPPED and paced and not stopped_by:
        raise CliError(f"stopped after step {solution.steps} (t = {solution.t[-1]:g}): "
                       f"{paced[0]}; "
                       + (not_written if kept else
                          f"the {solution.t.size} levels done were written to {out}/ "
                          "(summary.json: run.partial = true)")
                       + "; use a larger time.adaptive.tol or k_min, or --force to run on", 1)
    if solution.status == STOPPED:
        by = "" if stopped_by != signal.SIGTERM else " by SIGTERM"
        raise CliError(f"interrupted{by} after step {solution.steps} (t = {solution.t[-1]:g}); "
                       + (not_written if kept else
                          f"the {solution.t.size} levels done were written to {out}/ "
                          "(summary.json: run.partial = true)"), STOP_SIGNALS.get(stopped_by, 130))
    if not solution.success:
        written = (f"The {solution.t.size} levels before it were written to {out}/ "
                   "(summary.json: run.partial = true)." if files else
                   f"{not_written[0].upper()}{not_written[1:]}." if kept and solution.t.size
                   else "Nothing was written.")
        raise CliError(f"{solution.message}. {written}", 1)

    mesh, boundary = problem.mesh, problem.boundary
    contact = ("no contact boundary" if boundary is None else
               f"{boundary.facets.size} contact facets, {boundary.nodes.size} contact nodes")
    click.echo(f"{parsed.title}")
    click.echo(f"  mesh: {mesh.p.shape[1]} nodes, {mesh.t.shape[1]} cells, "
               f"{problem.ndofs} dofs ({problem.free.size} free), {contact}")
    click.echo(f"  time: {time_line(parsed, solution)}, "
               f"{int(solution.iterations.sum())} solver iterations, "
               f"{solution.timings['total']:.2f} s")
    if boundary is not None and boundary.facets.size:
        states = {key: int(value[-1]) for key, value in contact_state_counts(solution).items()}
        friction = (f", stick {states['stick']}, slip {states['slip']}"
                    if "stick" in states else "")
        click.echo(f"  Γ_C at t = {parsed.T:g}: β mean {beta_mean(solution)[-1]:.4g}, "
                   f"min {solution.beta[-1].min():.4g}; contact nodes separated "
                   f"{states['separated']}, on the wall {states['on_wall']}{friction}")
    click.echo(f"  wrote {out}/: {', '.join(files)}")


