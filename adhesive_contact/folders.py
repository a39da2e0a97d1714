"""Output folders that never lose a whole run: a lock per folder, a
staging folder recognised by the marker file inside it, and a publish
that a failure, a kill or a full disk cannot leave half done.

A run that writes a set of files into folder ``DIR`` (a solve's outputs,
docs/outputs.md) does so in three steps:

1. it takes the folder's lock (:class:`FolderLock`): a file holding the
   owner's pid, locked with ``flock``, which the system releases when the
   owner ends however it ends (a killed run's lock is taken over). A
   second run into the same folder is refused (:class:`FolderLocked`);
2. it writes its files into a staging folder, beside a new ``DIR`` or
   inside an existing one, whose file :data:`MARKER` says what it is, for
   which folder, and in which state ("writing" or "publishing");
3. it publishes (:func:`publish`): a new ``DIR`` is the staging folder
   renamed, in one step. Into an existing ``DIR`` holding an earlier run,
   the marker is first set to "publishing" with the new set of names;
   the earlier run's files are moved into the staging folder (kept), the
   new ones moved in, ``summary.json`` last, and only then is the staging
   folder (with the earlier files) removed. An error on the way moves
   everything back: ``DIR`` holds the earlier run again. A kill on the
   way leaves a staging folder marked "publishing" whose new set is
   complete, and the next run into ``DIR`` (under the lock) finishes that
   publish first (:func:`recover`), so ``DIR`` then holds the new whole
   run. Staging folders marked "writing" (a run killed before its files
   were complete) are removed. A folder without the marker is never
   touched, whatever its name.

The moves are :func:`os.replace` within one file system, which neither
allocate nor fail for a full disk: a full disk (or a file-size limit) is
met while the staging folder is written, where the earlier run is not
involved.
"""

import contextlib
import os
import re
import stat
import shutil
import tempfile
from pathlib import Path

from .storage import pid_alive, read_json, remove_stale_temporaries, write_json

#: the file inside a staging folder that makes it one
MARKER = ".adhcontact-staging"
_KIND = "adhcontact staging folder"
#: the name of the run's summary: the last file moved in, the first moved out
SUMMARY = "summary.json"
_BACKUP = ".previous"


class FolderLocked(OSError):
    """``folder`` is being written by another process (``pid``, None when
    the lock file does not say)."""

    def __init__(self, folder, lock_path, pid):
        self.folder, self.lock_path, self.pid = Path(folder), Path(lock_path), pid
        owner = "another process" if pid is None else f"another process (pid {pid})"
        super().__init__(f"{str(self.folder)!r} is being written by {owner}; its lock is "
                         f"{str(self.lock_path)!r}")


class ForeignLockFile(OSError):
    """The lock file's name is taken by something that is no lock of ours (a
    user's own file, a folder, a link): it is never truncated nor removed."""

    def __init__(self, lock_path):
        self.lock_path = Path(lock_path)
        super().__init__(f"{str(self.lock_path)!r} exists and is not a lock of adhcontact "
                         "(a lock holds one process id): it is left as it is; move it, or "
                         "use another --out")


class PublishError(OSError):
    """A publish that could not be done; ``kept`` says what ``target`` holds."""


# ---------------------------------------------------------------- the lock


def lock_path(folder):
    """The lock file of ``folder``: ``.<name>.lock`` beside it, or
    ``.adhcontact.lock`` inside an existing folder whose parent cannot be
    written."""
    folder = Path(folder).absolute()
    parent = folder.parent
    if folder.is_dir() and parent.is_dir() and not os.access(parent, os.W_OK | os.X_OK):
        return folder / ".adhcontact.lock"
    return parent / f".{folder.name}.lock"


class FolderLock:
    """The lock of one folder (module docstring), held from :meth:`acquire`
    to :meth:`release` (or as a context manager).

    The lock file's parents are created if missing, and removed again on
    release when they are still empty. Without ``fcntl`` (not POSIX) the
    lock is the file itself, created exclusively, taken over when the pid
    it holds is no longer alive.
    """

    def __init__(self, folder):
        self.folder = Path(folder).absolute()
        self.path = lock_path(self.folder)
        self.fd = None
        self.created = []

    def acquire(self):
        """Take the lock or raise :class:`FolderLocked` (at once: no waiting)."""
        missing = [p for p in [self.path.parent, *self.path.parent.parents] if not p.exists()]
        self.path.parent.mkdir(parents=True, exist_ok=True)
        self.created = missing
        try:
            self.fd = _lock_file(self.path)
        except BaseException:
            self._remove_created()
            raise
        if self.fd is None:
            self._remove_created()
            raise FolderLocked(self.folder, self.path, _read_pid(self.path))
        return self

    def release(self):
        """Give the lock up and remove its file."""
        if self.fd is None:
            return
        with contextlib.suppress(OSError):
            os.unlink(self.path)
        with contextlib.suppress(OSError):
            os.close(self.fd)
        self.fd = None
        self._remove_created()

    def _remove_created(self):
        for path in self.created:   # the deepest first
            with contextlib.suppress(OSError):
                path.rmdir()
        self.created = []

    def __enter__(self):
        return self.acquire()

    def __exit__(self, *exc):
        self.release()


def _read_pid(path):
    try:
        text = Path(path).read_text(encoding="ascii", errors="replace").strip()
    except OSError:
        return None
    return int(text) if text.isdigit() else None


def _lock_file(path):
    """An open, locked descriptor of ``path`` holding this pid, or None when
    another live process holds it."""
    try:
        import fcntl
    except ImportError:   # pragma: no cover - not POSIX
        return _lock_file_exclusive(path)
    while True:
        try:   # never through a link, never a folder or a device
            fd = os.open(path, os.O_RDWR | os.O_CREAT | os.O_NOFOLLOW | os.O_NONBLOCK, 0o644)
        except OSError as err:
            if os.path.lexists(path) and not stat.S_ISREG(os.lstat(path).st_mode):
                raise ForeignLockFile(path) from None
            raise err
        if not _ours(fd):
            os.close(fd)
            raise ForeignLockFile(path)
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            os.close(fd)
            return None
        except BaseException:
            os.close(fd)
            raise
        try:   # its previous owner may have removed the file before we locked it
            same = os.stat(path).st_ino == os.fstat(fd).st_ino
        except FileNotFoundError:
            same = False
        if same:
            os.ftruncate(fd, 0)
            os.write(fd, f"{os.getpid()}\n".encode("ascii"))
            return fd
        os.close(fd)


def _ours(fd):
    """Whether the open file ``fd`` can be a lock file of ours: a regular
    file that is empty (created, not yet written) or holds one pid line."""
    info = os.fstat(fd)
    if not stat.S_ISREG(info.st_mode) or info.st_size > 32:
        return False
    text = os.pread(fd, 33, 0)
    return text == b"" or re.fullmatch(rb"[0-9]+\n?", text) is not None


def _lock_file_exclusive(path):   # pragma: no cover - not POSIX
    for _ in range(2):
        try:
            fd = os.open(path, os.O_RDWR | os.O_CREAT | os.O_EXCL, 0o644)
        except FileExistsError:
            pid = _read_pid(path)
            if pid is not None and pid_alive(pid):
                return None
            with contextlib.suppress(OSError):
                os.unlink(path)
            continue
        os.write(fd, f"{os.getpid()}\n".encode("ascii"))
        return fd
    return None


# ---------------------------------------------------------------- staging


def _write_marker(staging, target, outputs, state="writing", names=()):
    write_json(Path(staging) / MARKER, {
        "kind": _KIND, "target": target, "pid": os.getpid(), "state": state,
        "outputs": sorted(outputs), "names": list(names)})


def read_marker(folder):
    """The marker document of a staging folder, or None when ``folder`` is
    not one (no marker, or not ours)."""
    path = Path(folder) / MARKER
    if not path.is_file() or path.stat().st_size > 1 << 16:
        return None
    document = read_json(path)
    if not isinstance(document, dict) or document.get("kind") != _KIND:
        return None
    if not all(isinstance(document.get(key), list) for key in ("outputs", "names")):
        return None
    return document


def _staging_folders(target):
    """The staging folders for ``target``: (folder, marker) of each
    subfolder of ``target`` and of each ``<name>.*`` beside it whose marker
    names ``target``."""
    found = []
    candidates = []
    if target.is_dir():
        with contextlib.suppress(OSError):
            candidates += [(Path(e.path), "..") for e in os.scandir(target)
                           if e.is_dir(follow_symlinks=False)]
    with contextlib.suppress(OSError):
        candidates += [(Path(e.path), target.name) for e in os.scandir(target.parent)
                       if e.name.startswith(target.name + ".")
                       and e.is_dir(follow_symlinks=False)]
    for folder, name in candidates:
        marker = read_marker(folder)
        if marker is not None and marker.get("target") == name:
            found.append((folder, marker))
    return found


def recover(target):
    """Under ``target``'s lock: finish the publishes into ``target`` that a
    kill interrupted (staging folders marked "publishing"), remove the
    staging folders of runs killed while writing, and the temporary files
    of killed atomic writes; return the names of the staging folders
    removed. A marker left at ``target``'s top (a kill just after a new
    folder was renamed into place) is removed."""
    target = Path(target).absolute()
    removed = []
    for folder, marker in _staging_folders(target):
        if marker.get("state") == "publishing" and target.is_dir():
            _roll_forward(folder, target, marker)
        else:
            shutil.rmtree(folder, ignore_errors=True)
        removed.append(folder.name)
    if target.is_dir():
        with contextlib.suppress(OSError):
            (target / MARKER).unlink(missing_ok=True)
        remove_stale_temporaries(target)
    return removed


@contextlib.contextmanager
def staged_folder(target, outputs):
    """A staging folder for the files of ``target``, published into it when
    the block ends normally with a ``summary.json`` written
    (:func:`publish`), removed otherwise.

    Parameters
    ----------
    target : path of the output folder (its parent must exist). Hold its
        :class:`FolderLock`: this first calls :func:`recover`.
    outputs : every file name a run may write into ``target``: those of an
        earlier run that this one does not write are removed on publish;
        any other file in ``target`` stays.
    """
    target = Path(target).absolute()
    recover(target)
    if target.is_dir():   # staged inside: the moves stay on one file system
        staging = Path(tempfile.mkdtemp(prefix=".adhcontact.tmp-", dir=target))
        _write_marker(staging, "..", outputs)
    else:
        staging = Path(tempfile.mkdtemp(prefix=f"{target.name}.tmp-", dir=target.parent))
        _write_marker(staging, target.name, outputs)
    try:
        yield staging
        if (staging / SUMMARY).exists():
            publish(staging, target, outputs)
        else:   # nothing to show: no level was computed
            shutil.rmtree(staging)
    except BaseException:
        marker = read_marker(staging) if staging.is_dir() else None
        if marker is None or marker.get("state") != "publishing":
            shutil.rmtree(staging, ignore_errors=True)
        raise


def _sync(path):
    """Flush a file's data to the disk (so that a publish after a crash of
    the machine moves whole files)."""
    with contextlib.suppress(OSError):
        fd = os.open(path, os.O_RDONLY)
        try:
            os.fsync(fd)
        finally:
            os.close(fd)


def _ordered(names):
    """``names`` with ``summary.json`` last."""
    return sorted(n for n in names if n != SUMMARY) + ([SUMMARY] if SUMMARY in names else [])


def publish(staging, target, outputs):
    """Move the files of ``staging`` (of :data:`outputs`) into ``target``
    (module docstring): a new ``target`` is ``staging`` renamed; into an
    existing one the earlier outputs are kept in ``staging`` until the new
    set is in place, ``summary.json`` last. Raises :class:`PublishError`
    with ``target`` as it was when a file cannot be moved."""
    staging, target = Path(staging), Path(target)
    outputs = set(outputs)
    names = _ordered([p.name for p in staging.iterdir() if p.name in outputs])
    for name in names:
        _sync(staging / name)
    if not target.exists():
        for path in staging.iterdir():   # nothing but the outputs moves in
            if path.name not in outputs and path.name != MARKER:
                shutil.rmtree(path) if path.is_dir() else path.unlink()
        os.chmod(staging, 0o755)   # mkdtemp makes it private
        try:
            os.rename(staging, target)
        except OSError:
            if not target.is_dir():   # not a folder made meanwhile: nothing changed
                raise
        else:
            (target / MARKER).unlink(missing_ok=True)
            return
    for name in sorted(outputs):   # before anything moves
        path = target / name
        if path.is_dir() and not path.is_symlink():
            raise PublishError(f"{str(path)!r} is a folder, where the run writes a file; "
                               f"the earlier files in {str(target)!r} are kept")
    _write_marker(staging, read_marker(staging)["target"], outputs, "publishing", names)
    backup = staging / _BACKUP
    backup.mkdir()
    moved_out, moved_in = [], []
    try:
        for name in _ordered([n for n in outputs if os.path.lexists(target / n)])[::-1]:
            os.replace(target / name, backup / name)   # summary.json first
            moved_out.append(name)
        for name in names:
            os.replace(staging / name, target / name)  # summary.json last
            moved_in.append(name)
    except BaseException as err:
        try:
            for name in moved_in[::-1]:
                os.replace(target / name, staging / name)
            for name in moved_out[::-1]:
                os.replace(backup / name, target / name)
        except OSError:   # left for the next run into target to finish (recover)
            raise PublishError(f"cannot move the files into {str(target)!r} ({err}); the "
                               "next run into it completes the move") from None
        shutil.rmtree(staging, ignore_errors=True)
        if isinstance(err, OSError):
            raise PublishError(f"cannot move the files into {str(target)!r} ({err}); the "
                               "earlier files there are kept") from None
        raise
    shutil.rmtree(staging, ignore_errors=True)


def _roll_forward(staging, target, marker):
    """Finish a publish that was interrupted: every new file is either still
    in ``staging`` or already in ``target``, since the marker was set to
    "publishing" only once the new set was complete."""
    outputs = {n for n in marker["outputs"] if isinstance(n, str) and _plain_name(n)}
    names = [n for n in marker["names"] if n in outputs]
    for name in outputs - set(names):
        path = target / name
        if not path.is_dir():
            with contextlib.suppress(OSError):
                path.unlink(missing_ok=True)
    for name in _ordered(names):
        if os.path.lexists(staging / name):
            os.replace(staging / name, target / name)
    shutil.rmtree(staging, ignore_errors=True)


def _plain_name(name):
    """A file name without a folder part (what a marker may name)."""
    return name not in ("", ".", "..") and os.sep not in name and "/" not in name
