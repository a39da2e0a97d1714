"""Parameter sweeps: one scene run for every combination of a few settings.

A setting is a dotted TOML key and its values, e.g.
``("contact.normal.c", [1e2, 1e3])`` or ``("time.steps", [10, 20])``; an
integer part indexes an array of tables (``contact.friction.0.mu``). The
variants are the grid of all combinations (``mode="grid"``, the last key
varying fastest) or the settings taken in step (``"zip"``, equal lengths),
at most :data:`MAX_VARIANTS` unless forced. Each value of each setting is
validated (parsed and discretised) before anything runs; a combination of
valid values that is not a valid scene is a failed run.

A run that fails (a step solve that did not converge) is a result, not an
error: its record says where it stopped. A run whose worker died (a killed
process, a lost machine: outcome ``"lost"``) is a row of runs.csv too, but
it is not saved, so running the sweep again computes it. The folder:

- ``study.json``: the resolved base scene, the settings and the mode, and
  the sha256 of that (another sweep in the folder is refused);
- ``runs/run_NNN.json``: one record per finished run (:func:`run_variant`);
- ``runs.csv``: one row per run (:data:`CSV_COLUMNS`), rewritten at the end.

From Python::

    from pathlib import Path
    from adhesive_contact.studies import Sweep

    sweep = Sweep(Path("scene.toml"), [("contact.normal.c", [1e2, 1e3]),
                                       ("time.steps", [10, 20])], folder="out")
    result = sweep.run(jobs=2)      # result.records: one dict per run
"""

import copy
import hashlib
import math
import itertools
import resource
import time
from dataclasses import dataclass, field
from pathlib import Path

from ..errors import SceneError
from ..postprocess.scalars import quantity_kind, scalar_quantities, state_quantities
from ..postprocess.units import with_unit
from ..problem import build_problem
from ..problem.warnings import solution_warnings
from ..scene import scene_from_dict
from ..scheme import solve
from ..storage import plain, toml_value, write_csv
from .study import Study, StudyError, scene_identity, scene_source

MODES = ("grid", "zip")
#: the most variants a sweep has unless forced: each is a run (10⁴ variants
#: were minutes of validation alone, 10⁶ hours)
MAX_VARIANTS = 1000
OUTCOMES = ("ok", "failed")
#: the outcome of a run whose worker died: a row, never a saved record
LOST = "lost"
#: the measured columns of runs.csv, after "run" and the swept keys
MEASURED = ("outcome", "failed_step", "failed_t", "residual", "seconds", "newton_total",
            "newton_max", "worker_peak_rss_mib", "beta_min_T", "beta_mean_T",
            "max_un_minus_g", "separated_T", "on_wall_T", "compliance_T", "stick_T",
            "slip_T", "normal_force_T")
#: the columns of MEASURED a failure fills in
_FAILURE_COLUMNS = ("outcome", "failed_step", "failed_t")


# ---------------------------------------------------------------- settings


def with_value(document, key, value):
    """A deep copy of the TOML ``document`` with dotted ``key`` set to ``value``.

    Missing tables on the way are created; an integer part indexes an
    array of tables. Raises ValueError when a part is neither."""
    out = copy.deepcopy(document)
    node, parts = out, key.split(".")
    for depth, part in enumerate(parts):
        last = depth == len(parts) - 1
        where = ".".join(parts[:depth]) or "the scene"
        if isinstance(node, list):
            if not (part.isdigit() and int(part) < len(node)):
                raise ValueError(f"{where} is an array of {len(node)} tables; "
                                 f"{part!r} is not an index into it")
            index = int(part)
        elif isinstance(node, dict):
            index = part
        else:
            raise ValueError(f"{where} is a value, not a table")
        if last:
            node[index] = value
        else:
            if isinstance(node, dict) and index not in node:
                node[index] = {}
            node = node[index]
    return out


def variant_count(settings, mode="grid"):
    """How many variants the settings give (without making them)."""
    lengths = [len(list(values)) for _, values in settings]
    return (math.prod(lengths) if mode == "grid" else min(lengths)) if lengths else 0


def variants(settings, mode="grid", force=False):
    """The variants of a sweep: a list of {key: value}, in run order.

    Raises :class:`StudyError` for an unknown mode, no settings, a key set
    twice, (zip) lists of different lengths, or more than
    :data:`MAX_VARIANTS` variants unless ``force`` (counted before any is
    made)."""
    if mode not in MODES:
        raise StudyError("mode", f"must be grid or zip, got {mode!r}")
    settings = [(key, list(values)) for key, values in settings]
    if not settings:
        raise StudyError("set", "give at least one KEY=V1,V2,...")
    keys = [key for key, _ in settings]
    for key, values in settings:
        if keys.count(key) > 1:
            raise StudyError(f"set {key}", "set twice; give all its values in one --set")
        if not values:
            raise StudyError(f"set {key}", "no values")
    count = variant_count(settings, mode)
    if count > MAX_VARIANTS and not force and (mode == "grid" or len(
            {len(values) for _, values in settings}) == 1):
        sizes = " x ".join(str(len(values)) for _, values in settings)
        raise StudyError("set", f"gives {count:,} variants ({sizes}"
                         f"{'' if mode == 'grid' else ', zipped'}); at most {MAX_VARIANTS:,} "
                         "unless forced (--force): each variant is a run")
    if mode == "zip":
        length = len(settings[0][1])
        for key, values in settings[1:]:
            if len(values) != length:
                raise StudyError(f"set {key}", f"has {len(values)} values, "
                                 f"{settings[0][0]} has {length}; zip needs equal lengths")
        combos = zip(*(values for _, values in settings))
    else:
        combos = itertools.product(*(values for _, values in settings))
    return [dict(zip(keys, combo)) for combo in combos]


def file_sha256(given, base_dir=None):
    """The sha256 of the file ``given`` (relative to ``base_dir``), None when
    it cannot be read (the variant's check then names it)."""
    path = Path(given).expanduser()
    if not path.is_absolute():
        path = Path(base_dir if base_dir is not None else Path.cwd()) / path
    try:
        if not path.is_file():
            return None
        digest = hashlib.sha256()
        with open(path, "rb") as f:
            for block in iter(lambda: f.read(1 << 20), b""):
                digest.update(block)
        return digest.hexdigest()
    except (OSError, RuntimeError):
        return None


def variant_document(document, values):
    """The TOML document of one variant: ``document`` with every setting applied."""
    for key, value in values.items():
        document = with_value(document, key, value)
    return document


# ---------------------------------------------------------------- one run


def solve_or_failure(problem):
    """(solution, None), or (None, failure) when a step did not converge or
    gave an invalid state: the one place a sweep calls the scheme."""
    solution = solve(problem)
    return (solution, None) if solution.success else (None, solution.failure)


def peak_rss_mib():
    """Peak resident set size of this process so far (MiB), from getrusage.

    In a worker process reused for several runs it is the peak over every
    run that process has done, not of the last one alone."""
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0


def run_variant(document, values, base_dir=None):
    """Build and solve one variant; its record (plain JSON). A relative
    ``mesh.file`` is taken in ``base_dir`` (the scene file's folder).

    Keys: ``values`` ({key: value}), ``outcome`` ("ok" or "failed"),
    ``failure`` (None, or {step, t, residual, iterations, message}),
    ``seconds`` (wall time of build and solve), ``newton_total`` and
    ``newton_max`` (Newton iterations, summed and max over the steps),
    ``residual`` (max final relative residual over the steps; for a failure
    the one reached), ``worker_peak_rss_mib`` (:func:`peak_rss_mib`), and
    at the final time T: ``beta_min_T``, ``beta_mean_T`` (weighted by the
    facet lengths), the contact-node counts ``separated_T``, ``on_wall_T``,
    ``compliance_T``, ``stick_T``, ``slip_T`` (None without friction) and
    ``normal_force_T`` (the total normal force of Γ_C on the body, positive
    in compression); ``max_un_minus_g`` is max over all levels and contact
    nodes of u_ν − g (None without a wall); ``quantities`` the scalars of
    :func:`~adhesive_contact.postprocess.scalar_quantities` (the peak and
    final reaction of each held side, the energies and the debonded area at
    T); ``warnings`` what the solution shows
    (:func:`~adhesive_contact.problem.warnings.solution_warnings`).
    A failed run has None for what needs the solution.
    """
    t0 = time.perf_counter()
    record = {"values": values, "worker_peak_rss_mib": peak_rss_mib()}
    try:
        problem = build_problem(scene_from_dict(variant_document(document, values), base_dir))
    except (SceneError, ValueError) as err:   # a combination of values checked one by one
        return plain(record | {
            "outcome": "failed", "seconds": time.perf_counter() - t0, "residual": None,
            "failure": {"step": None, "t": None, "residual": None, "iterations": None,
                        "message": f"not a valid scene: {err}"}})
    solution, failure = solve_or_failure(problem)
    record |= {"seconds": time.perf_counter() - t0, "worker_peak_rss_mib": peak_rss_mib()}
    if failure is not None:
        result = failure.result
        return plain(record | {
            "outcome": "failed",
            "failure": {"step": failure.n, "t": failure.t, "residual": result.residual,
                        "iterations": result.nit, "message": str(failure)},
            "residual": result.residual})
    return plain(record | {
        "outcome": "ok", "failure": None,
        "residual": solution.residual.max(),
        "newton_total": solution.iterations.sum(), "newton_max": solution.iterations.max(),
        **state_quantities(solution),
        "quantities": scalar_quantities(solution),
        "warnings": solution_warnings(solution)})


def _setup(document, runs, base_dir=None):
    return document, runs, base_dir


def _compute_run(state, key):
    document, runs, base_dir = state
    return {"run": key} | run_variant(document, runs[key], base_dir)


# ---------------------------------------------------------------- rows


def quantity_columns(records):
    """The scalar quantities of the runs' records, in the order they first
    appear (the held sides may differ between variants)."""
    names = {}
    for record in records:
        names.update(dict.fromkeys(record.get("quantities") or {}))
    return list(names)


def csv_columns(keys, quantities=()):
    """The columns of runs.csv: run, the swept keys, :data:`MEASURED`, then
    the scalar ``quantities`` (:func:`quantity_columns`)."""
    return ["run", *keys, *MEASURED, *quantities]


@dataclass(frozen=True)
class SweepRow:
    """One run of a sweep as ``runs.csv`` shows it.

    Attributes
    ----------
    run : int, the run's number
    values : dict, {swept key: value}
    outcome : "ok", "failed" or :data:`LOST`
    failed_step, failed_t : the step and time a failed run stopped at (None
        for a run that did not fail, or a combination that is not a scene)
    measured : dict, the other :data:`MEASURED` columns, None where the
        run has no value
    quantities : dict, {scalar quantity column: value}, None where the run
        has none
    message : why the run failed or was lost (printed, not a column), or None

    ``row[column]`` (and ``row.get(column)``) is the cell of a column of
    :func:`csv_columns`, or the message: a row reads like the table.
    """

    run: int
    values: dict
    outcome: str
    failed_step: object = None
    failed_t: object = None
    measured: dict = field(default_factory=dict)
    quantities: dict = field(default_factory=dict)
    message: str = None

    @classmethod
    def of(cls, record, keys, quantities=()):
        """The row of a run's record (:func:`run_variant` with its ``run``,
        or :func:`lost_record`) for the swept ``keys`` and the
        ``quantities`` columns (:func:`quantity_columns`)."""
        failure = record.get("failure") or {}
        given = record.get("quantities") or {}
        return cls(run=record["run"], values={key: record["values"][key] for key in keys},
                   outcome=record.get("outcome"), failed_step=failure.get("step"),
                   failed_t=failure.get("t"),
                   measured={c: record.get(c) for c in MEASURED if c not in _FAILURE_COLUMNS},
                   quantities={c: given.get(c) for c in quantities},
                   message=failure.get("message"))

    def cells(self):
        """{column: value} of the row, and its ``"message"``."""
        return {"run": self.run, **self.values, "outcome": self.outcome,
                "failed_step": self.failed_step, "failed_t": self.failed_t, **self.measured,
                **self.quantities, "message": self.message}

    def __getitem__(self, column):
        return self.cells()[column]

    def get(self, column, default=None):
        return self.cells().get(column, default)

    def to_row(self, columns):
        """The cells of ``columns``, in their order (None where the row has none)."""
        cells = self.cells()
        return [cells.get(column) for column in columns]


def write_runs_csv(path, rows, keys, quantities=(), units=None, dim=2):
    """``runs.csv``: a header of :func:`csv_columns`, the measured
    quantities with their units where the base scene names them
    (``units``: ``[output.units]``, ``dim`` its dimension), one row per run
    (``rows``: :class:`SweepRow`, written by
    :func:`adhesive_contact.storage.write_csv`; None an empty cell)."""
    columns = csv_columns(keys, quantities)
    measured = set(MEASURED) | set(quantities)
    header = [with_unit(c, quantity_kind(c), units, dim) if c in measured and quantity_kind(c)
              else c for c in columns]
    write_csv(path, header, [row.to_row(columns) for row in rows])


# ---------------------------------------------------------------- the study


def lost_record(key, values, message):
    """The record of run ``key`` whose worker died (outcome :data:`LOST`)."""
    return plain({"run": key, "values": values, "outcome": LOST,
                  "failure": {"step": None, "t": None, "residual": None, "iterations": None,
                              "message": message}})


@dataclass
class SweepResult:
    """What :meth:`Sweep.run` found: ``records`` (one per run, in run order),
    ``rows`` (the runs.csv rows, a :class:`SweepRow` per run), ``computed``
    (runs computed now, lost ones excluded), ``files`` (names written) and
    ``lost`` (runs whose worker died: rows, not saved)."""

    records: list
    rows: list
    computed: list
    files: list
    lost: list = None


class Sweep(Study):
    """A parameter sweep of a scene, kept in ``folder``.

    Parameters
    ----------
    scene : str, os.PathLike or dict
        TOML text, a path of a TOML file, or a decoded TOML document.
    settings : sequence of (key, values)
        Dotted TOML keys and their values (see the module docstring).
    mode : {"grid", "zip"}
    folder : path of the sweep's folder
    base_dir : the folder a relative ``mesh.file`` (of the scene or of a
        setting) is taken in; by default the scene file's folder (the
        working directory for a text or a document)

    The study's identity holds the sha256 of every mesh file a variant
    reads, so a sweep whose mesh file changed is another sweep.

    force : allow more than :data:`MAX_VARIANTS` variants

    Raises
    ------
    SceneError for a bad base scene; StudyError naming the setting
    (``key`` ``"set KEY"``) when a value makes the scene invalid, before
    anything runs or is written. Each value of each setting is checked
    (applied to the first variant; in zip mode every variant is checked):
    as many builds as values, not as variants. A combination of valid
    values that is not a valid scene is found when it runs, and is a failed
    run saying why. ``warnings`` lists (variant, warning) of what the theory
    does not cover, for the variants checked.
    """

    kind = "parameter sweep"
    runs_folder = "runs"
    compute = _compute_run

    def __init__(self, scene, settings, mode="grid", *, folder, base_dir=None, force=False):
        super().__init__(folder)
        if base_dir is None and not isinstance(scene, (str, dict)):
            base_dir = Path(scene).absolute().parent
        self.base_dir = None if base_dir is None else str(Path(base_dir).absolute())
        self.source = scene_source(scene)
        self.base = scene_from_dict(self.source, self.base_dir)
        self.settings = [(key, list(values)) for key, values in settings]
        self.mode = mode
        self.runs = variants(self.settings, mode, force)
        self.keys_set = [key for key, _ in self.settings]
        self.warnings = []
        for index in self.checked():
            problem = self._check(self.runs[index])
            if problem is not None:
                self.warnings += [(index, str(w)) for w in problem.warnings()]

    def checked(self):
        """The indices of the variants checked before anything runs: in zip
        mode all; in grid mode, for each setting, the first variant taking
        each of its values (the first variant with that key changed), in
        run order."""
        if self.mode == "zip":
            return list(range(len(self.runs)))
        lengths = [len(values) for _, values in self.settings]
        strides = [math.prod(lengths[i + 1:]) for i in range(len(lengths))]
        return sorted({j * stride for length, stride in zip(lengths, strides)
                       for j in range(length)})

    def _check(self, values, alone=False):
        """The problem of one variant, or StudyError naming the setting at
        fault. A variant refused for a key it does not set is checked again
        one value at a time, each alone on the base scene: a value that is
        refused alone is the setting at fault; when each is valid alone the
        combination is not a scene, which is a failed run, not an error
        (None)."""
        document = self.source
        for key, value in values.items():
            try:
                document = with_value(document, key, value)
            except ValueError as err:
                raise StudyError(f"set {key}", str(err)) from None
        try:
            return build_problem(scene_from_dict(document, self.base_dir))
        except SceneError as err:
            if err.key in values:
                reason = str(err).removeprefix(f"{err.key}: ")
                raise StudyError(f"set {err.key}={toml_value(values[err.key])}", reason) from None
            where = ", ".join(f"{k}={toml_value(v)}" for k, v in values.items())
            if alone or len(values) == 1:
                raise StudyError(f"set {where}", f"is not valid in this scene: {err}") \
                    from None
        for key, value in values.items():
            self._check({key: value}, alone=True)
        return None   # each value valid alone: the combination is a failed run

    def identity(self):
        identity = {"scene": scene_identity(self.base),
                    "set": [[k, v] for k, v in self.settings], "mode": self.mode}
        files = self.files_read()
        return identity | ({"files": files} if files else {})

    def files_read(self):
        """[[value, sha256], ...] of the mesh files that the settings name
        (the base scene's own is in its resolved record), in the order set."""
        files = []
        for key, values in self.settings:
            if key == "mesh.file":
                for value in dict.fromkeys(v for v in values if isinstance(v, str)):
                    files.append([value, file_sha256(value, self.base_dir)])
        return files

    def keys(self):
        return list(range(len(self.runs)))

    def record_name(self, key):
        return f"run_{key:03d}.json"

    def valid(self, key, record):
        return (isinstance(record, dict) and record.get("run") == key
                and record.get("outcome") in OUTCOMES
                and record.get("values") == plain(self.runs[key]))

    def context(self):
        return _setup, (self.source, self.runs, self.base_dir)

    def run(self, jobs=1, executor=None, as_completed=None, progress=None):
        """Compute the runs not saved yet, then write ``runs.csv``.

        ``jobs``, ``executor`` and ``as_completed`` as in
        :func:`~adhesive_contact.studies.pool.execute`; ``progress(stage,
        done, total)`` is called with stage ``"runs"`` (first with the runs
        loaded from the folder, then after each finished run).

        Returns :class:`SweepResult`. Raises StudyFolderError or
        StudyMismatch when the folder is not this sweep's, OSError when it
        cannot be written; failed runs are results, and so are lost runs
        (their worker died; not saved, so the next run computes them).
        """
        progress = progress or (lambda stage, done, total: None)
        self.create()
        done = self.load()
        total = len(self.runs)
        lost = {}
        progress("runs", len(done), total)

        def on_lost(key, message):
            lost[key] = lost_record(key, self.runs[key], message)
            progress("runs", len(done) + len(lost), total)

        computed = self.run_missing(
            done, jobs=jobs, executor=executor, as_completed=as_completed,
            on_record=lambda key, record: progress("runs", len(done) + len(lost), total),
            label=lambda key: f"run {key}", on_lost=on_lost)
        records = [done[key] if key in done else lost[key] for key in self.keys()]
        quantities = quantity_columns(records)
        rows = [SweepRow.of(record, self.keys_set, quantities) for record in records]
        write_runs_csv(self.folder / "runs.csv", rows, self.keys_set, quantities,
                       self.base.units, self.base.dim)
        return SweepResult(records, rows, [key for key in computed if key not in lost],
                           ["runs.csv"], sorted(lost))

