"""What the ``adhcontact`` commands share: one-line errors, reading a scene
file, parsing and validating it, refusing a run larger than the machine
(:func:`guard`), checking the output folder, and reporting the problem's
warnings.

Every command parses and validates its scene with these before it creates
any output, so a bad scene exits 2 with one line and writes nothing.
"""

import os
import tomllib
from contextlib import contextmanager
from importlib import resources
from pathlib import Path

import click
import numpy as np

DEFAULT_SCENE = "default_scene.toml"


class CliError(click.ClickException):
    """An error reported as one line ``error: message`` with an exit code."""

    def __init__(self, message, exit_code):
        super().__init__(" ".join(str(message).split()))
        self.exit_code = exit_code


def read_scene(path):
    """The scene's name and TOML text: from ``path``, or the built-in default.

    Raises :class:`CliError` (exit 2) when the file cannot be read."""
    if path is None:
        text = resources.files("adhesive_contact_cli").joinpath(DEFAULT_SCENE).read_text(
            encoding="utf-8")
        return "default", text
    from adhesive_contact.scene.parse import read_scene_text

    try:
        return path.stem, read_scene_text(path)
    except FileNotFoundError:
        raise CliError(f"SCENE: no such file {str(path)!r}", 2) from None
    except (OSError, UnicodeDecodeError) as err:
        reason = err.strerror if isinstance(err, OSError) and err.strerror else err
        raise CliError(f"SCENE: cannot read {str(path)!r}: {reason}", 2) from None


def scene_folder(path):
    """The folder a scene file's relative paths (``mesh.file``) are taken in:
    the file's own (the working directory for the built-in scene)."""
    return None if path is None else Path(path).parent


def load_scene(text, base_dir=None, force=False, out=None):
    """(scene, problem) of a TOML scene text whose relative paths are taken
    in ``base_dir`` (:func:`scene_folder`), as the library's
    ``load_scene(path)`` does; a bad scene is a :class:`CliError` (exit 2),
    and so is one larger than the machine unless ``force`` (:func:`guard`,
    before the mesh is built)."""
    from adhesive_contact import SceneError, build_problem, parse_scene

    try:
        scene = parse_scene(text, base_dir)
        guard(scene, force, out)
        return scene, build_problem(scene)
    except SceneError as err:
        raise CliError(str(err), 2) from None


def study_source(text, base_dir=None):
    """The decoded document of a valid scene text for a study, a relative
    ``mesh.file`` made absolute (a study's workers do not know the scene
    file's folder)."""
    document = tomllib.loads(text)
    mesh = document.get("mesh")
    if base_dir is not None and isinstance(mesh, dict) and isinstance(mesh.get("file"), str):
        path = Path(mesh["file"]).expanduser()
        if not path.is_absolute():
            mesh["file"] = str((Path(base_dir) / path).resolve())
    return document


#: the keys a run's size comes from, named when it is refused
SIZE_KEYS = "mesh.cells, mesh.refine, time.steps, boundary.contact"


def guard(scene, force=False, out=None, what="the scene"):
    """Refuse (exit 2) a run whose estimated memory, time or output
    (:mod:`adhesive_contact.resources`) exceeds what the machine has,
    unless ``force``; ``out`` is where the outputs go (its free disk is
    checked), None not to check the disk."""
    if force:
        return
    from adhesive_contact.resources import estimate, free_disk, mesh_file_refusal, refusal

    reason = mesh_file_refusal(scene)   # before the estimate reads the file
    if reason:
        raise CliError(f"mesh.file: {what} is too large for this machine: {reason}; use a "
                       "smaller mesh, or --force to read it anyway", 2)
    est = estimate(scene)
    reason = refusal(est, disk=None if out is None else free_disk(out))
    if reason:
        raise CliError(f"{SIZE_KEYS}: {what} is too large for this machine: {reason} "
                       f"(estimate: {est.describe()}); use a smaller scene, or --force "
                       "to run it anyway", 2)


def check_out(out, outputs=()):
    """Refuse (exit 2) an ``--out`` that cannot take the outputs, before the
    solve, then take its lock (:class:`adhesive_contact.folders.FolderLock`,
    held until the command ends): a second run into the same folder is
    refused, exit 2.

    An existing folder is fine: only the run's own files (``outputs``) are
    replaced in it, a user's other files stay; one of them that is a
    folder is refused."""
    from adhesive_contact.folders import FolderLock, FolderLocked

    text = str(out)
    if "\0" in text:
        raise CliError("--out: the path holds a NUL character", 2)
    out = Path(out)
    absolute = out.absolute()
    limit = _name_max(absolute)
    for part in absolute.parts[1:]:
        if len(os.fsencode(part)) > limit - 16:   # room for the staging and lock names
            raise CliError(f"--out: the name {part[:40]!r}... is {len(os.fsencode(part))} "
                           f"bytes long; at most {limit - 16} are allowed here", 2)
    for path in [absolute, *absolute.parents]:
        if path.is_symlink() and not path.exists():
            raise CliError(f"--out: {str(path)!r} is a symbolic link to nothing (or a loop "
                           "of links)", 2)
        if path.exists():
            break
    if out.exists() and not out.is_dir():
        raise CliError(f"--out: {str(out)!r} exists and is not a folder", 2)
    existing = next(p for p in [absolute, *absolute.parents] if p.exists())
    if not existing.is_dir() or not os.access(existing, os.W_OK | os.X_OK):
        raise CliError(f"--out: {str(out)!r} cannot be written ({str(existing)!r} is not "
                       "a writable folder)", 2)
    for name in sorted(outputs):
        if (out / name).is_dir() and not (out / name).is_symlink():
            raise CliError(f"--out: {str(out / name)!r} is a folder, where the run writes a "
                           "file; rename it or use another --out", 2)
    lock = FolderLock(out)
    try:
        lock.acquire()
    except FolderLocked as err:
        raise CliError(f"--out: {err}; wait for that run to end, or use another --out",
                       2) from None
    except OSError as err:
        raise CliError(f"--out: cannot lock {str(out)!r}: {err.strerror or err}", 2) from None
    ctx = click.get_current_context(silent=True)
    if ctx is not None:
        ctx.call_on_close(lock.release)
    return lock


def _name_max(path):
    """The longest file name (bytes) the file system of ``path`` allows."""
    existing = next(p for p in [path, *path.parents] if os.path.exists(p))
    try:
        return os.pathconf(existing, "PC_NAME_MAX")
    except (OSError, ValueError, AttributeError):
        return 255


def open_study(make, out, kind, option=lambda key: f"--{key}"):
    """``make()`` a study and open its folder ``out``; what the study layer
    refuses becomes one line, exit 2 (``option`` names a study argument as
    the command's option)."""
    from adhesive_contact import SceneError
    from adhesive_contact.studies import StudyError, StudyFolderError, StudyMismatch

    try:
        study = make()
        study.open()
    except StudyMismatch as err:
        raise CliError(f"--out {out} holds a different {kind} ({err.difference}); "
                       "use another --out or remove it", 2) from None
    except StudyFolderError as err:
        raise CliError(f"--out: {err.message}", 2) from None
    except StudyError as err:
        raise CliError(f"{option(err.key)}: {err.message}", 2) from None
    except SceneError as err:
        raise CliError(str(err), 2) from None
    return study


def echo_warnings(problem):
    """One line ``warning: ...`` on stderr per thing the theory does not cover."""
    for warning in problem.warnings():
        click.echo(f"warning: {' '.join(str(warning).split())}", err=True)


@contextmanager
def running_study(out, executor, saved):
    """Run a study's block: a lost scheduler or an unwritable ``out`` is a
    CliError (exit 1) saying the finished ``saved`` ("runs", "levels") are
    kept, Ctrl-C one with exit 130; the executor is closed whatever happens."""
    from adhesive_contact.studies.executors import ClusterError

    try:
        yield
    except KeyboardInterrupt:
        raise CliError(f"interrupted; the finished {saved} are saved in {out}/ and the same "
                       "command resumes from them", 130) from None
    except ClusterError as err:
        raise CliError(f"--scheduler {err.address}: {err.message}; the finished {saved} are "
                       "saved, the same command resumes", 1) from None
    except OSError as err:
        raise CliError(f"--out: cannot write {str(out)!r}: {err}", 1) from None
    finally:
        if executor is not None:
            executor.close()


def time_line(scene, solution=None):
    """The "time:" line of ``solve`` and ``check``: the uniform grid, or for
    ``[time.adaptive]`` the tolerance and, after a run, the steps it took."""
    scheme = "" if scene.scheme == "paper" else f" ({scene.scheme} scheme)"
    if scene.adaptive is None:
        return f"{scene.steps} steps of k = {scene.k:g} to T = {scene.T:g}{scheme}"
    if solution is None or solution.t.size < 2:
        return (f"adaptive steps (time.adaptive.tol = {scene.adaptive.tol:g}), k at most "
                f"{scene.k:g}, to T = {scene.T:g}{scheme}")
    k = np.diff(solution.t)
    rejected = (solution.adaptive or {}).get("rejected_pairs", 0)
    return (f"{k.size} adaptive steps (time.adaptive.tol = {scene.adaptive.tol:g}) of k = "
            f"{k.min():.3g} to {k.max():.3g}, {rejected} pairs rejected, to T = "
            f"{scene.T:g}{scheme}")
