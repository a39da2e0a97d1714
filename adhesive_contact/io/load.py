"""A finished output folder of ``adhcontact solve`` read back as the
:class:`~adhesive_contact.Solution` that :func:`adhesive_contact.solve`
returns (docs/python.md, "Reading an output folder").

``summary.json`` gives how the run ended, its timings and linear backend,
and the scene's text, from which the problem is rebuilt (or the caller
gives the problem); ``solution.npz`` gives every array
(:mod:`.npz`). The stress is that of the last level only, as with the
:class:`~.streaming.StreamingRecorder` the command line solves with.
"""

import json
import zipfile
from pathlib import Path

import numpy as np

from ..scheme import STEP_FAILED, STOPPED, SUCCESS, Solution
from ..storage import plain
from .npz import SOLUTION_KEYS

#: summary.json's run.status -> Solution.status
STATUS = {"complete": SUCCESS, "step failed": STEP_FAILED, "interrupted": STOPPED}
#: the summary.json layout this reads
SCHEMA = 1


class OutputFolderError(ValueError):
    """A folder that cannot be read back: ``path`` names the file at fault,
    ``str(err)`` is ``"<path>: what is wrong"``."""

    def __init__(self, path, message):
        self.path = Path(path)
        super().__init__(f"{self.path}: {message}")


def read_summary(path):
    """The ``summary.json`` document at ``path``, of this layout (schema 1)."""
    try:
        document = json.loads(Path(path).read_text(encoding="utf-8"))
    except FileNotFoundError:
        raise OutputFolderError(path, "no such file; an output folder of 'adhcontact solve' "
                                "has one (docs/outputs.md)") from None
    except (OSError, UnicodeDecodeError) as err:
        raise OutputFolderError(path, f"cannot be read: {err}") from None
    except json.JSONDecodeError as err:
        raise OutputFolderError(path, f"not valid JSON ({err}): the file is damaged; run "
                                "the scene again") from None
    if not isinstance(document, dict) or document.get("schema") != SCHEMA:
        found = document.get("schema") if isinstance(document, dict) else None
        raise OutputFolderError(path, f"has schema {found!r}; this version reads schema "
                                f"{SCHEMA}")
    for key in ("scene", "run", "steps"):
        if key not in document:
            raise OutputFolderError(path, f"has no {key!r}: the file is damaged")
    return document


def read_arrays(path, names):
    """{name: array} of ``names`` from the npz file ``path``."""
    try:
        with np.load(path, allow_pickle=False) as data:
            missing = [name for name in names if name not in data.files]
            if missing:
                raise OutputFolderError(path, f"has no {missing[0]!r}: it was written by an "
                                        "older version; run the scene again to read it back")
            return {name: data[name] for name in names}
    except FileNotFoundError:
        raise OutputFolderError(path, "no such file; an output folder of 'adhcontact solve' "
                                "has one (docs/outputs.md)") from None
    except (OSError, ValueError, EOFError, zipfile.BadZipFile) as err:
        raise OutputFolderError(path, f"cannot be read ({type(err).__name__}: {err}): the "
                                "file is damaged; run the scene again") from None


def rebuild_problem(path, document):
    """The problem of the scene text that summary.json (at ``path``) keeps."""
    from ..problem.build import build_problem
    from ..scene import SceneError, parse_scene

    source = document.get("source")
    if not isinstance(source, dict) or not isinstance(source.get("text"), str):
        raise OutputFolderError(path, "keeps no scene text (written by an older version); "
                                "pass problem=build_problem(load_scene(...)) of its scene")
    try:
        return build_problem(parse_scene(source["text"], source.get("folder")))
    except SceneError as err:
        raise OutputFolderError(path, f"its scene cannot be built here: {err}") from None


def _differing_key(a, b, prefix=""):
    """The first dotted key where two JSON documents differ (None if equal)."""
    if isinstance(a, dict) and isinstance(b, dict):
        for key in sorted(set(a) | set(b)):
            found = _differing_key(a.get(key), b.get(key), f"{prefix}{key}.")
            if found:
                return found
        return None
    return None if a == b else prefix.rstrip(".") or "scene"


def load_solution(folder, problem=None):
    """The :class:`~adhesive_contact.Solution` of an output folder of
    ``adhcontact solve``.

    Parameters
    ----------
    folder : path of the folder (``summary.json`` and ``solution.npz``)
    problem : Problem, optional
        The problem that was solved; by default it is rebuilt from the scene
        text kept in ``summary.json`` (a relative ``mesh.file`` is taken in
        the scene file's folder, as when it was run). It must be of the
        scene ``summary.json`` records.

    Returns
    -------
    Solution
        As :func:`adhesive_contact.solve` returned it: t, u, beta,
        contact_force, frame_displacement, on_wall, stuck, probes,
        iterations, residual, reaction per level; status, message, timings,
        linear. ``stress`` (and ``stress_zz`` in 2D) holds the last level
        only, shape (1, ...); ``failure`` is None (the failed step and its
        time are ``message`` and summary.json's ``run``).

    Raises
    ------
    OutputFolderError
        A file is missing, damaged, of another layout or of another scene
        than ``problem``; the message names the file.
    """
    folder = Path(folder)
    summary_path, npz_path = folder / "summary.json", folder / "solution.npz"
    document = read_summary(summary_path)
    if problem is None:
        problem = rebuild_problem(summary_path, document)
    recorded = json.loads(json.dumps(plain(problem.scene.resolved)))
    key = _differing_key(recorded, document["scene"])
    if key:
        raise OutputFolderError(summary_path, f"records another scene than the problem's "
                                f"(they differ at {key})")
    names = ("points", "t", "u", "beta", "held_reaction", "stress_last") + SOLUTION_KEYS
    names += ("stress_zz_last",) if problem.dim == 2 else ()
    arrays = read_arrays(npz_path, names)
    if arrays["points"].shape != problem.mesh.p.T.shape or not np.array_equal(
            arrays["points"], problem.mesh.p.T):
        raise OutputFolderError(npz_path, "holds another mesh than the problem's")
    run = document["run"]
    if run.get("status") not in STATUS or arrays["t"].shape != (run.get("levels"),):
        raise OutputFolderError(summary_path, "its run record does not match solution.npz")
    zz = arrays.get("stress_zz_last")
    return Solution(
        problem=problem, status=STATUS[run["status"]], message=run["message"], failure=None,
        t=arrays["t"], u=arrays["u"], beta=arrays["beta"],
        stress=arrays["stress_last"][None], stress_zz=None if zz is None else zz[None],
        contact_force=arrays["contact_force"],
        frame_displacement=arrays["frame_displacement"], on_wall=arrays["on_wall"],
        stuck=arrays["stuck"], probes=arrays["probes"], iterations=arrays["iterations"],
        residual=arrays["residual"], reaction=arrays["held_reaction"],
        timings={k: (float("nan") if v is None else v)
                 for k, v in document.get("timings", {}).items()},
        linear=dict(document.get("linear", {})))
