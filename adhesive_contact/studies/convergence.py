"""Convergence studies in h, k or both, kept in a folder (docs/verification.md).

The computation of one level and of the fine reference is :mod:`.levels`;
:class:`ConvergenceStudy` is the study on top of
:class:`~adhesive_contact.studies.study.Study`. Its folder:

- ``study.json``: the resolved scene (level 0), param, levels, reference
  kind, ref_h and ref_k, and the sha256 of exactly that;
- ``reference.npz`` (reference ``"fine"``): the reference run's t, u, beta,
  facets, its refine and steps and its wall time, saved once computed;
- ``levels/level_NN.json``: one record of :func:`~.levels.run_level` per
  finished level;
- ``errors.csv`` and ``rates.json`` (:func:`results`): rewritten from the
  saved records at the end of every completed run.

A study of a scalar quantity (``quantity``, a name of
:func:`~adhesive_contact.postprocess.scalars.quantity_names`, e.g. the
peak reaction of a held side) also fits the rate of |Q_h − Q_ref| against
the fine reference's Q. Every level record and the reference keep all
the run's scalar quantities; the quantity studied is part of the study's
identity (another quantity is another study, in another folder), and a
saved level or reference without it is recomputed.

From Python::

    from pathlib import Path
    from adhesive_contact.studies import ConvergenceStudy

    study = ConvergenceStudy(Path("scene.toml"), param="h", levels=4,
                             reference="exact", folder="out")
    result = study.run(jobs=2)
    result.document["rates"]     # {"u": ..., "beta": ..., "E": ...}
"""

import json
import math
import zipfile
from dataclasses import dataclass, replace
from pathlib import Path
from types import SimpleNamespace

import numpy as np

from ..postprocess.scalars import (quantity_kind, quantity_names, quantity_unavailable,
                                   study_quantities)
from ..postprocess.units import unit_of
from ..problem.build import build_problem
from ..verification.rates import pairwise_rates, rates
from ..fem.meshes import build_mesh
from ..scene import SceneError, scene_from_dict
from ..scene.materials import check_relaxation_step
from ..storage import write_atomic, write_csv, write_json
from .levels import (
    PARAMS,
    Reference,
    default_reference_refinement,
    level_scene,
    needed_levels,
    reference_scene,
    run_level,
    run_reference,
    with_discretisation,
)
from .pool import attempt, in_this_process
from .study import RunFailed, Study, StudyError, scene_identity, scene_source

REFERENCE = "reference.npz"
LEVELS = "levels"
FLOAT_KEYS = ("h", "k", "err_u", "err_beta", "E", "seconds")
#: the relative errors of a level; a level saved before they existed has
#: none (null in rates.json), and stays valid: a study resumes as it was
RELATIVE_KEYS = ("rel_u", "rel_beta", "rel_E")
RECORD_KEYS = ("level", "h", "k", "dofs", "steps", "err_u", "err_beta", "E", "seconds")
CSV_COLUMNS = ("level", "h", "k", "dofs", "steps", "err_u", "err_beta", "E", "rate_E",
               "seconds", *RELATIVE_KEYS)
#: the columns a study of a quantity adds: Q_h, |Q_h − Q_ref|, that over
#: |Q_ref|, and the pairwise rate of |Q_h − Q_ref|
QUANTITY_COLUMNS = ("quantity", "err_q", "rel_q", "rate_q")
#: docs/verification.md: a rate is fitted over at least 4 levels
MEANINGFUL_LEVELS = 4
#: the largest run a study may ask for (dofs); beyond it the set-up alone
#: (a Schur complement onto Γ_C) takes hours and tens of GB on a workstation
MAX_DOFS = 2_000_000


# ---------------------------------------------------------------- the reference file


def save_reference(path, reference):
    """``reference.npz``: the arrays of a :class:`Reference` (u and β at
    the levels its errors read, ``kept``; stored uncompressed: zlib shrinks
    floating-point fields by a few per cent, slowly), its refine, steps,
    seconds and quantities."""
    arrays = {"t": reference.t, "u": reference.u, "beta": reference.beta,
              "facets": np.asarray(reference.facets, dtype=np.int64),
              "refine": np.int64(reference.scene.mesh.refine),
              "steps": np.int64(reference.scene.steps),
              "seconds": np.float64(reference.seconds)}
    if reference.kept is not None:
        arrays["kept"] = np.asarray(reference.kept, dtype=np.int64)
    if reference.quantities is not None:
        arrays["quantities"] = np.array(json.dumps(reference.quantities))
    write_atomic(path, lambda f: np.savez(f, **arrays), binary=True)


def load_reference(path, scene, arrays=True, quantity=None, kept=None):
    """The saved :class:`Reference` of reference scene ``scene``; None when
    ``path`` is missing, unreadable or of another refine or number of steps,
    with a ``quantity`` name, when it has no value of that quantity (a
    reference saved before its quantities were kept), or when it lacks a
    level of ``kept`` (the levels the study's errors read; None: every one).

    With ``arrays=False`` only its seconds are read (t, u, beta, facets None):
    a study whose levels are all saved needs no more."""
    path = Path(path)
    if not path.is_file():
        return None
    try:
        with np.load(path) as data:
            if int(data["refine"]) != scene.mesh.refine or int(data["steps"]) != scene.steps:
                return None
            seconds = float(data["seconds"])
            quantities = (json.loads(str(data["quantities"])) if "quantities" in data.files
                          else None)
            if quantity is not None and quantity not in (quantities or {}):
                return None
            if not arrays:
                return Reference(scene, None, None, None, None, seconds, quantities)
            held = (data["kept"] if "kept" in data.files
                    else np.arange(scene.steps + 1))
            wanted = np.arange(scene.steps + 1) if kept is None else np.asarray(kept)
            if (data["t"].shape != (scene.steps + 1,) or data["u"].shape[0] != held.size
                    or not np.isin(wanted, held).all()):
                return None
            return Reference(scene, data["t"], data["u"], data["beta"], data["facets"],
                             seconds, quantities, None if "kept" not in data.files else held)
    except (OSError, KeyError, ValueError, TypeError, zipfile.BadZipFile):
        return None


# ---------------------------------------------------------------- results


#: a level's entries in rates.json, in their order (:meth:`LevelRow.as_dict`)
LEVEL_KEYS = ("h", "k", "dofs", "err_u", "err_beta", "E", "seconds", *RELATIVE_KEYS, "level",
              "steps", "refine", "rate_E", "newton_iterations")


@dataclass(frozen=True)
class LevelRow:
    """One level of a convergence study: an entry of rates.json's
    ``levels`` and a row of errors.csv.

    Attributes
    ----------
    level, refine, steps : the level, its mesh refinement and its steps
    h, k, dofs : its mesh size, step and degrees of freedom
    err_u, err_beta, E : its errors (:func:`~.levels.run_level`)
    rel_u, rel_beta, rel_E : the errors relative to the solution's norms
        (None for a level saved without them, or a zero solution)
    rate_E : the pairwise rate of E from the level before (None on the first)
    seconds, newton_iterations : its wall time and Newton iterations
    quantity, err_q, rel_q, rate_q : in a study of a quantity, Q_h, its
        error, relative error (:func:`quantity_errors`) and pairwise rate;
        else None
    """

    level: int
    refine: int
    steps: int
    h: float
    k: float
    dofs: int
    err_u: float
    err_beta: float
    E: float
    rel_u: float
    rel_beta: float
    rel_E: float
    rate_E: float
    seconds: float
    newton_iterations: object = None
    quantity: float = None
    err_q: float = None
    rel_q: float = None
    rate_q: float = None

    @classmethod
    def of(cls, record, rate_E, rate_q=None):
        """The row of a level record (with :func:`quantity_errors`' entries
        in a study of a quantity) and its pairwise rates."""
        return cls(**{key: record[key] for key in ("level", "steps", "h", "k", "dofs", "err_u",
                                                    "err_beta", "E", "seconds")},
                   refine=record.get("refine"),
                   **{key: _finite(record.get(key)) for key in RELATIVE_KEYS},
                   rate_E=rate_E, newton_iterations=record.get("newton_iterations"),
                   **{key: _finite(record.get(key)) for key in ("quantity", "err_q", "rel_q")},
                   rate_q=rate_q)

    def as_dict(self, quantity=False):
        """The level as rates.json holds it (:data:`LEVEL_KEYS`, then
        :data:`QUANTITY_COLUMNS` in a study of a ``quantity``)."""
        keys = LEVEL_KEYS + (QUANTITY_COLUMNS if quantity else ())
        return {key: getattr(self, key) for key in keys}

    def to_row(self, columns):
        """The cells of ``columns`` (of :func:`csv_columns`), in their order."""
        return [getattr(self, column) for column in columns]


def quantity_errors(records, name, reference_value):
    """The records with a study of quantity ``name``'s entries: ``quantity``
    Q_h (the level's value), ``err_q`` = |Q_h − Q_ref| and ``rel_q`` =
    err_q / |Q_ref| (None where Q_h or Q_ref is None, rel_q also where
    Q_ref = 0)."""
    out = []
    for record in records:
        value = (record.get("quantities") or {}).get(name)
        err = (None if value is None or reference_value is None
               else abs(float(value) - float(reference_value)))
        rel = (None if err is None or reference_value == 0
               else err / abs(float(reference_value)))
        out.append({**record, "quantity": value, "err_q": err, "rel_q": rel})
    return out


def results(records, param, reference_info, quantity=None):
    """The ``rates.json`` document.

    Firm keys: ``{"param", "levels": [{"h", "k", "dofs", "err_u", "err_beta",
    "E", "seconds", ...}], "rates": {"u", "beta", "E"}}``; each level also
    has its level, steps, refine, the relative errors rel_u, rel_beta,
    rel_E (None for a level saved without them, or a zero solution), the
    pairwise rate_E and its Newton iterations, and ``"reference"``
    describes the reference.

    With ``quantity`` (its name; ``reference_info["quantity"]`` then holds
    Q_ref) each level also has ``quantity``, ``err_q``, ``rel_q`` (see
    :func:`quantity_errors`) and the pairwise ``rate_q``, ``rates`` has
    "Q", and the document ``"quantity": {"name", "reference"}``."""
    if quantity is not None:
        records = quantity_errors(records, quantity, reference_info.get("quantity"))
    pairwise = pairwise_rates(records, param)
    pairwise_q = (pairwise_rates(records, param, key="err_q") if quantity is not None
                  else [None] * len(records))
    levels = [LevelRow.of(record, rate, rate_q).as_dict(quantity is not None)
              for record, rate, rate_q in zip(records, pairwise, pairwise_q)]
    document = {"param": param, "levels": levels,
                "rates": rates(records, param, quantity=quantity is not None),
                "reference": reference_info}
    if quantity is not None:
        document["quantity"] = {"name": quantity, "reference": reference_info.get("quantity")}
    return document


def _finite(value):
    """A float, or None for a missing, null or NaN value."""
    return None if value is None or not math.isfinite(value) else float(value)


#: pairwise rates further apart than this, or any below 0, make a fit doubtful
RATE_SPREAD = 0.5


def trust(document):
    """Why the study's fitted rates should not be trusted, one sentence each
    (empty when nothing is wrong): errors E that do not decrease from a
    level to the next, pairwise rates that scatter (one below 0, or further
    apart than :data:`RATE_SPREAD`), a fine reference too close to the
    finest level (fewer than 2 extra refinements in h, 4× the steps in k)."""
    out = []
    levels = document["levels"]
    checked = [("E", "E", "rate_E")]
    if "quantity" in document:
        checked.append((f"|Q − Q_ref| of {document['quantity']['name']}", "err_q", "rate_q"))
    for label, key, rate_key in checked:
        for a, b in zip(levels[:-1], levels[1:]):
            if not (b[key] is not None and a[key] is not None and b[key] < a[key]):
                out.append(f"{label} does not decrease from level {a['level']} to "
                           f"{b['level']} ({_fmt_error(a[key])} to {_fmt_error(b[key])})")
        pairwise = [row[rate_key] for row in levels if row[rate_key] is not None]
        if pairwise and (min(pairwise) < 0 or max(pairwise) - min(pairwise) > RATE_SPREAD):
            out.append(f"the pairwise rates of {label} scatter from {min(pairwise):.2f} to "
                       f"{max(pairwise):.2f}: the fitted rate is not a trustworthy summary")
    ref = document.get("reference") or {}
    if ref.get("kind") == "fine":
        if document["param"] in ("h", "hk") and (ref.get("ref_h") or 0) < 2:
            out.append(f"the fine reference is refined only {ref.get('ref_h')} more times than "
                       "the finest level: its own error biases the finest errors (use "
                       "--ref-h 2 or more)")
        if document["param"] in ("k", "hk") and (ref.get("ref_k") or 0) < 2:
            out.append(f"the fine reference has only 2**{ref.get('ref_k')} times the steps of "
                       "the finest level: its own error biases the finest errors (use "
                       "--ref-k 2 or more)")
    return out


def _fmt_error(value):
    return "none" if value is None else f"{value:.3g}"


def csv_columns(document):
    """The columns of ``errors.csv``: :data:`CSV_COLUMNS`, and
    :data:`QUANTITY_COLUMNS` for a study of a quantity."""
    return CSV_COLUMNS + (QUANTITY_COLUMNS if "quantity" in document else ())


def csv_header(document):
    """:func:`csv_columns` with their units where the scene names them
    (``document["units"]``: h, k, and the quantity and its error)."""
    units = document.get("units") or {}
    unit = {"h": units.get("length"), "k": units.get("time")}
    if "quantity" in document:
        unit["quantity"] = unit["err_q"] = document["quantity"].get("unit")
    return [f"{c} [{unit[c]}]" if unit.get(c) else c for c in csv_columns(document)]


def write_errors_csv(path, document):
    """``errors.csv``: a header of :func:`csv_columns`, then one row per
    level (its :class:`LevelRow`, of the :func:`results` document's entry,
    written by :func:`adhesive_contact.storage.write_csv`: None — a rate_E on
    the first level, a relative error of a zero solution or of a level
    saved without it — an empty cell)."""
    columns = csv_columns(document)
    write_csv(path, csv_header(document),
              [LevelRow(**level).to_row(columns) for level in document["levels"]])


# ---------------------------------------------------------------- in a worker


def _setup(source, base, param, levels, ref_h, ref_k, reference):
    """A worker's state: the scene parsed once (with the study's level-0
    refine and steps) and the reference (sent without its scene) given its
    scene back."""
    scene = with_discretisation(scene_from_dict(source), *base)
    if reference is not None:
        reference = replace(reference, scene=reference_scene(scene, param, levels, ref_h, ref_k))
    return SimpleNamespace(scene=scene, param=param, reference=reference)


def _compute_level(state, level):
    report = getattr(state, "progress", None)   # set only where the level runs here
    on_step = None
    if report is not None:
        stage = f"level {level}"
        report(stage, 0, level_scene(state.scene, state.param, level).steps + 1)

        def on_step(n, N):
            report(stage, min(n, N) + 1, N + 1)
    return run_level(state.scene, state.param, level, state.reference, progress=on_step,
                     measure=study_quantities)


def _reporting(setup, progress):
    """``setup`` whose state also carries ``progress``: for levels computed in
    this process, which then report their steps (not for workers: a
    callback of this process does not reach them)."""
    def build(*args):
        state = setup(*args)
        state.progress = progress
        return state
    return build


# ---------------------------------------------------------------- the study


@dataclass
class ConvergenceResult:
    """What :meth:`ConvergenceStudy.run` found.

    Attributes
    ----------
    document : dict, the ``rates.json`` document (:func:`results`)
    records : list of the level records, by level
    computed : list of the levels computed by this run (the others were loaded)
    reference_loaded : True when the fine reference was read from the
        folder, False when computed now, None for an exact reference
    files : names of the result files written (errors.csv, rates.json)
    """

    document: dict
    records: list
    computed: list
    reference_loaded: object
    files: list


class ConvergenceStudy(Study):
    """A convergence study of a scene in h, k or both, kept in ``folder``.

    Parameters
    ----------
    scene : str, os.PathLike or dict
        TOML text, a path of a TOML file, or a decoded TOML document.
    param : {"h", "k", "hk"}
        Refine in space (one uniform refinement per level), in time (the
        step halved per level) or both.
    levels : int >= 2
        Number of levels (a least-squares rate is meaningful over >= 4).
    reference : {"exact", "fine"}, optional
        The scene's exact solution, or a fine reference run; default exact
        if the scene has an [exact] table, else fine.
    folder : path of the study's folder
    ref_h, ref_k : int, optional
        The fine reference has ``ref_h`` more mesh refinements and
        ``2**ref_k`` times the steps of the finest level
        (default :func:`~.levels.default_reference_refinement`);
        only with ``reference="fine"``.
    refine, steps : int, optional
        Mesh refinement and steps of level 0 instead of the scene's.
    scene_file : str, optional
        Recorded in ``study.json`` (not part of the identity); the path by
        default when ``scene`` is one.
    quantity : str, optional
        A scalar quantity whose error |Q_h − Q_ref| against the fine
        reference is fitted beside the norms (a name of
        :func:`~adhesive_contact.postprocess.scalars.quantity_names`);
        needs reference "fine" (the default then).

    Raises
    ------
    SceneError for a bad scene; StudyError naming the argument
    (``key``) for a study that cannot be run. Nothing is written before
    :meth:`run`.
    """

    kind = "convergence study"
    runs_folder = LEVELS
    compute = _compute_level

    def __init__(self, scene, param, levels=5, reference=None, *, folder, ref_h=None,
                 ref_k=None, refine=None, steps=None, scene_file=None, quantity=None):
        super().__init__(folder)
        if scene_file is None and not isinstance(scene, (str, dict)):
            scene_file = str(scene)
        self.scene_file = scene_file
        self.source = scene_source(scene)
        given = scene_from_dict(self.source)
        if param not in PARAMS:
            raise StudyError("param", f"must be one of {', '.join(PARAMS)}, got {param!r}")
        if not isinstance(levels, int) or levels < 2:
            raise StudyError("levels", f"must be an integer >= 2, got {levels!r}")
        if given.adaptive is not None and param != "k":
            raise StudyError("param", f"{param!r} with [time.adaptive]: a study of an adaptive "
                             "scene refines time.adaptive.tol (--param k); for h use the scene "
                             "without [time.adaptive]")
        self.base = (refine, steps)
        self.scene = with_discretisation(given, refine, steps)
        memory = self.scene.memory
        if steps is not None and memory is not None and memory.kernel == "relaxation":
            try:   # level 0 has the largest step: the scene's own check, for it
                check_relaxation_step(memory, self.scene.dim, self.scene.k)
            except SceneError as err:
                raise StudyError("steps", str(err).removeprefix(f"{err.key}: ")) from None
        self.param, self.levels = param, levels
        if reference is None:
            reference = ("exact" if self.scene.exact is not None and quantity is None
                         else "fine")
        if quantity is not None:
            allowed = quantity_names(build_problem(self.scene))
            if quantity not in allowed:
                raise StudyError("quantity", f"no quantity {quantity!r} in this scene; "
                                 f"allowed: {', '.join(allowed)}")
            missing = quantity_unavailable(build_problem(self.scene), quantity)
            if missing is not None:
                raise StudyError("quantity", f"{quantity!r} has no value in this scene: "
                                 f"{missing}")
            if reference == "exact":
                raise StudyError("quantity", f"{quantity!r} is not computable from the "
                                 "scene's [exact] solution (it gives u and β, not reactions "
                                 "or energies); allowed with a quantity: reference fine")
        self.quantity = quantity
        if reference not in ("exact", "fine"):
            raise StudyError("reference", f"must be exact or fine, got {reference!r}")
        if reference == "exact" and self.scene.exact is None:
            raise StudyError("reference", "'exact' needs an [exact] table in the scene; "
                             "allowed here: fine")
        if reference == "exact" and (ref_h is not None or ref_k is not None):
            raise StudyError("ref_h/ref_k", "refine the fine reference; allowed only with "
                             "reference fine (the reference here is the exact solution)")
        if reference == "fine":
            dh, dk = default_reference_refinement(param)
            ref_h = dh if ref_h is None else ref_h
            ref_k = dk if ref_k is None else ref_k
        self.reference, self.ref_h, self.ref_k = reference, ref_h, ref_k
        largest = self.largest_dofs(given)
        if largest > MAX_DOFS:
            what = ("the fine reference" if reference == "fine" and ref_h
                    else "the finest level")
            raise StudyError("levels", f"{what} would have about {largest:.2g} dofs (more "
                             f"than {MAX_DOFS:.0e}); use fewer levels, a smaller reference "
                             "refinement, or a coarser mesh for level 0")

    # -- identity and runs

    def identity(self):
        identity = {"scene": scene_identity(self.scene), "param": self.param,
                    "levels": self.levels, "reference": self.reference, "ref_h": self.ref_h,
                    "ref_k": self.ref_k}
        if self.quantity is not None:   # absent without one: older studies keep their sha
            identity["quantity"] = self.quantity
        return identity

    def keys(self):
        return list(range(self.levels))

    def record_name(self, level):
        return f"level_{level:02d}.json"

    def valid(self, level, record):
        return (isinstance(record, dict) and record.get("level") == level
                and all(key in record for key in RECORD_KEYS)
                and (self.quantity is None
                     or self.quantity in (record.get("quantities") or {})))

    def load(self):
        """{level: record} of the saved levels, null errors read back as NaN."""
        return {level: {**record, **{key: (math.nan if record[key] is None
                                           else float(record[key])) for key in FLOAT_KEYS}}
                for level, record in super().load().items()}

    def context(self, reference=None):
        light = None if reference is None else replace(reference, scene=None)
        return _setup, (self.source, self.base, self.param, self.levels, self.ref_h,
                        self.ref_k, light)

    def largest_dofs(self, given=None):
        """About how many dofs the largest run (finest level or reference) has:
        the scene's dofs times 2^dim per extra uniform refinement."""
        given = given if given is not None else scene_from_dict(self.source)
        dofs = given.dim * build_mesh(given.mesh).p.shape[1]
        growth = 2 ** given.dim
        extra = (self.scene.mesh.refine - given.mesh.refine
                 + (self.levels - 1 if self.param in ("h", "hk") else 0)
                 + (self.ref_h if self.reference == "fine" else 0))
        return dofs * growth ** extra

    @property
    def reference_scene(self):
        """The scene of the fine reference run (None for an exact reference)."""
        if self.reference != "fine":
            return None
        return reference_scene(self.scene, self.param, self.levels, self.ref_h, self.ref_k)

    # -- running

    def _fine_reference(self, arrays, progress):
        """(reference, loaded): from ``reference.npz``, else run and saved."""
        rscene = self.reference_scene
        fine = load_reference(self.folder / REFERENCE, rscene, arrays=arrays,
                              quantity=self.quantity,
                              kept=needed_levels(self.scene, self.param, self.levels, rscene))
        if fine is not None:
            return fine, True
        total = rscene.steps + 1
        progress("reference", 0, total)

        def compute(state, key):
            return run_reference(self.scene, self.param, self.levels, self.ref_h, self.ref_k,
                                 progress=lambda n, N: progress("reference", n + 1, total),
                                 measure=study_quantities)

        _, fine, message = attempt(compute, None, "reference")
        if message is not None:
            raise RunFailed("reference run", message)
        save_reference(self.folder / REFERENCE, fine)
        return fine, False

    def run(self, jobs=1, executor=None, as_completed=None, progress=None):
        """Compute what is missing, then write ``errors.csv`` and ``rates.json``.

        Parameters
        ----------
        jobs, executor, as_completed : how the levels run
            (:func:`~adhesive_contact.studies.pool.execute`); the fine
            reference runs first, alone, in this process.
        progress : callable (stage, done, total), optional
            Called with stage ``"reference"`` (done = time levels of the
            reference run, from 0), ``"levels"`` (done = finished levels,
            first with those loaded from the folder) and, when the levels
            run in this process (no executor, and ``jobs`` 1 or one level
            missing), ``"level L"`` for each level L computed (done = its
            time levels, from 0, of total = its steps + 1), between the
            ``"levels"`` calls before and after it.

        Returns
        -------
        ConvergenceResult

        Raises
        ------
        StudyFolderError, StudyMismatch
            The folder is not this study's (nothing written).
        RunFailed
            A level or the reference did not converge; the finished levels
            stay saved.
        OSError
            The folder cannot be written.
        """
        progress = progress or (lambda stage, done, total: None)
        self.create({"scene_file": self.scene_file} if self.scene_file else None)
        done = self.load()
        missing = [level for level in self.keys() if level not in done]
        fine, loaded, info = None, None, {"kind": self.reference}
        if self.reference == "fine":
            fine, loaded = self._fine_reference(bool(missing), progress)
            rscene = fine.scene
            info |= {"ref_h": self.ref_h, "ref_k": self.ref_k, "refine": rscene.mesh.refine,
                     "steps": rscene.steps, "k": rscene.k, "seconds": fine.seconds}
            if self.quantity is not None:
                info["quantity"] = fine.quantities[self.quantity]
        progress("levels", len(done), self.levels)
        setup, args = self.context(fine)
        if in_this_process(jobs, executor, len(missing)):
            setup = _reporting(setup, progress)
        computed = self.run_missing(
            done, jobs=jobs, executor=executor, as_completed=as_completed,
            on_record=lambda level, record: progress("levels", len(done), self.levels),
            label=lambda level: f"level {level}", context=(setup, args))
        records = [done[level] for level in self.keys()]
        if self.reference == "fine":
            info["h"] = records[-1]["h"] / 2 ** self.ref_h
        document = results(records, self.param, info, self.quantity)
        document["units"] = dict(self.scene.units)
        if self.quantity is not None:
            kind = quantity_kind(self.quantity)
            document["quantity"]["unit"] = (None if kind is None else
                                            unit_of(kind, self.scene.units, self.scene.dim))
        document["warnings"] = trust(document)
        document["trustworthy"] = not document["warnings"]
        files = ["errors.csv", "rates.json"]
        write_errors_csv(self.folder / files[0], document)
        write_json(self.folder / files[1], document)
        return ConvergenceResult(document, records, computed, loaded, files)

