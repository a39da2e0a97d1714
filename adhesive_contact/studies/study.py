"""A study: a set of independent runs of scene variants with a stable identity.

The study's folder is its state, so an interrupted study resumes where it
stopped:

- ``study.json``: what the study is (:meth:`Study.identity`, plain JSON)
  and the sha256 of exactly that; written first. A folder whose
  ``study.json`` hashes the same is resumed, any other study is refused
  (:class:`StudyMismatch`, naming what differs);
- one JSON record per finished run (:class:`RunStore`), written atomically
  the moment the run finishes, so a killed study loses nothing finished and
  a rerun computes only the runs without a record.

A kind of study (a convergence study, a parameter sweep) subclasses
:class:`Study`: it says what it is, which runs it has, how a worker builds
its state once and how it computes one run. :meth:`Study.run_missing`
does the rest with :func:`~adhesive_contact.studies.pool.execute`.
"""

import hashlib
import json
import tomllib
from abc import ABC, abstractmethod
from pathlib import Path

from ..scene import SceneError
from ..storage import plain, read_json, remove_stale_temporaries, write_json
from .pool import execute

STUDY_FILE = "study.json"


class StudyError(ValueError):
    """A study that cannot be set up as asked.

    ``key`` names the argument at fault (e.g. ``"levels"``), ``message``
    says what is wrong and what is allowed."""

    def __init__(self, key, message):
        self.key, self.message = key, message
        super().__init__(f"{key}: {message}")


class StudyFolderError(StudyError):
    """The folder cannot hold the study (a file, or another study's or a
    user's folder); nothing in it is touched."""

    def __init__(self, folder, message):
        self.folder = Path(folder)
        super().__init__("folder", message)


class StudyMismatch(StudyFolderError):
    """The folder holds another study; ``difference`` names what differs."""

    def __init__(self, folder, difference):
        self.difference = difference
        super().__init__(folder, f"{str(folder)!r} holds a different study ({difference})")


class RunFailed(RuntimeError):
    """A run whose failure stops the study (its ``label`` and the reason)."""

    def __init__(self, label, message):
        self.label, self.message = label, message
        super().__init__(f"{label}: {message}")


def scene_source(scene):
    """The decoded TOML document of a scene given as TOML text (str), a path
    of a TOML file (os.PathLike) or an already decoded dict.

    Raises :class:`~adhesive_contact.SceneError` for text that is not TOML."""
    if isinstance(scene, dict):
        return scene
    text = Path(scene).read_text(encoding="utf-8") if not isinstance(scene, str) else scene
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as err:
        raise SceneError("", f"not valid TOML: {err}") from None


def scene_identity(scene):
    """What a scene contributes to a study's identity: its resolved record
    without ``solver.linear``, ``output.units`` and ``output.plot_times``.
    The linear backend changes how the linear systems are solved, not the
    discrete solution (every backend solves to round-off or its
    tolerance), and the units and plot times change the plots only, so a
    study may resume with other ones."""
    resolved = dict(scene.resolved)
    resolved["solver"] = {k: v for k, v in resolved["solver"].items() if k != "linear"}
    resolved["output"] = {k: v for k, v in resolved["output"].items()
                          if k not in ("units", "plot_times")}
    return resolved


def study_document(identity):
    """``identity`` as plain JSON with its sha256 (of the sorted, compact JSON)."""
    study = plain(identity)
    text = json.dumps(study, sort_keys=True, separators=(",", ":"), allow_nan=False)
    return {**study, "sha256": hashlib.sha256(text.encode("utf-8")).hexdigest()}


def difference(stored, document, scene_key="scene"):
    """What differs between a stored study document and ``document`` (one phrase).

    Every differing key is named with both values, except the scene, which
    is said to be another one."""
    if not isinstance(stored, dict):
        return f"its {STUDY_FILE} is unreadable"
    keys = [key for key in document if key not in ("sha256", scene_key)]
    parts = [f"{key} {stored.get(key)!r} there, {document[key]!r} here"
             for key in keys if stored.get(key) != document[key]]
    if scene_key in document and stored.get(scene_key) != document[scene_key]:
        parts.append("another scene")
    return "; ".join(parts) or f"its {STUDY_FILE} does not match"


class RunStore:
    """Finished runs, one JSON file each, in one folder.

    Parameters
    ----------
    folder : path of the folder holding the records
    name : callable, key -> file name of that run's record
    """

    def __init__(self, folder, name):
        self.folder = Path(folder)
        self.name = name

    def path(self, key):
        return self.folder / self.name(key)

    def save(self, key, record):
        """Write the record of run ``key`` (strict JSON, atomically)."""
        self.folder.mkdir(parents=True, exist_ok=True)
        write_json(self.path(key), record)

    def load(self, keys, valid=lambda key, record: isinstance(record, dict)):
        """{key: record} of the runs of ``keys`` with a readable, valid record."""
        records = {}
        for key in keys:
            record = read_json(self.path(key))
            if record is not None and valid(key, record):
                records[key] = record
        return records


class Study(ABC):
    """Base class of a study kept in ``folder`` (see the module docstring).

    A subclass sets :attr:`kind` (a name for messages) and :attr:`runs_folder`
    and defines :meth:`identity`, :meth:`keys`, :meth:`record_name`,
    :meth:`context` and :attr:`compute`; it may refine :meth:`valid`.
    """

    kind = "study"
    runs_folder = "runs"
    #: compute(state, key) -> record (plain JSON): a module-level function,
    #: so that worker processes can import it
    compute = None

    def __init__(self, folder):
        self.folder = Path(folder)

    # -- what a kind of study defines

    @abstractmethod
    def identity(self):
        """What the study is, as a dict of JSON values (hashed into its identity)."""

    @abstractmethod
    def keys(self):
        """The runs of the study, in order (ints or strs)."""

    def record_name(self, key):
        """The file name of run ``key``'s record."""
        return f"run_{key}.json"

    def valid(self, key, record):
        """Whether a stored record can be used as the result of run ``key``."""
        return isinstance(record, dict)

    @abstractmethod
    def context(self):
        """(setup, args): each process computing runs calls ``setup(*args)``
        once for its state (the parsed scene, …); both must pickle."""

    # -- what every study does

    @property
    def document(self):
        """The ``study.json`` document: the identity and its sha256."""
        return study_document(self.identity())

    @property
    def store(self):
        return RunStore(self.folder / self.runs_folder, self.record_name)

    def open(self):
        """Check the folder against the study; True when it holds this study.

        Writes nothing. Raises :class:`StudyFolderError` when the folder is a
        file or a non-empty folder without ``study.json`` (whose files are
        never touched), :class:`StudyMismatch` when it holds another study."""
        out = self.folder
        if out.exists() and not out.is_dir():
            raise StudyFolderError(out, f"{str(out)!r} exists and is not a folder")
        if not out.is_dir():
            return False
        document = self.document
        if (out / STUDY_FILE).is_file():
            stored = read_json(out / STUDY_FILE)
            if isinstance(stored, dict) and stored.get("sha256") == document["sha256"]:
                return True
            raise StudyMismatch(out, difference(stored, document))
        if any(out.iterdir()):
            raise StudyFolderError(out, f"{str(out)!r} is a non-empty folder that is not a "
                                   f"{self.kind} (no {STUDY_FILE}); choose another folder")
        return False

    def create(self, extra=None):
        """Open the folder (see :meth:`open`) and, for a new study, write
        ``study.json`` (with the ``extra`` entries, not hashed); make the
        folder of the run records. The temporary files that a killed study's
        atomic writes left are removed
        (:func:`~adhesive_contact.storage.remove_stale_temporaries`). True
        when a saved study is resumed."""
        resume = self.open()
        self.folder.mkdir(parents=True, exist_ok=True)
        for folder in (self.folder, self.folder / self.runs_folder):
            remove_stale_temporaries(folder)   # of a killed study's atomic writes
        if not resume:
            write_json(self.folder / STUDY_FILE, {**self.document, **(extra or {})})
        (self.folder / self.runs_folder).mkdir(exist_ok=True)
        return resume

    def load(self):
        """{key: record} of the finished runs saved in the folder."""
        return self.store.load(self.keys(), self.valid)

    def run_missing(self, done, *, jobs=1, executor=None, as_completed=None,
                    on_record=None, label=str, context=None, on_lost=None):
        """Compute the runs not in ``done`` and save each the moment it finishes.

        ``done`` (a dict key -> record) gets the new records; ``on_record(key,
        record)`` is called after each is saved. See
        :func:`~adhesive_contact.studies.pool.execute` for ``jobs``,
        ``executor`` and ``as_completed``. A run that raises a step failure
        stops the study: no other run starts,
        those running are finished and saved, then :class:`RunFailed` is
        raised naming ``label(key)``. ``context`` replaces :meth:`context`.
        A run whose worker died is never saved: it is passed to
        ``on_lost(key, message)`` when given (the others go on), else it
        stops the study like a failure.

        Returns the keys computed now.
        """
        missing = [key for key in self.keys() if key not in done]
        store = self.store

        def save(key, record):
            store.save(key, record)
            done[key] = record
            if on_record is not None:
                on_record(key, record)

        context = self.context() if context is None else context
        failure = execute(missing, type(self).compute, context, save,
                          token=self.document["sha256"], jobs=jobs, executor=executor,
                          as_completed=as_completed, on_lost=on_lost)
        if failure is not None:
            raise RunFailed(label(failure[0]), failure[1])
        return missing
