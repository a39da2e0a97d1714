"""An output folder of a run (docs/outputs.md), as ``adhcontact solve``
writes it; :func:`write_outputs` writes one from Python.

:func:`staged_output` gives a staging folder that the run writes into
and then publishes into place (:mod:`adhesive_contact.folders`), so a
folder that held a whole run holds it or the new whole run whatever
happens, and a user's own files in ``DIR`` are never touched.
A run streams its levels there as they are computed
(:class:`~.streaming.StreamingRecorder`); :func:`write_results` adds the
rest:

- ``summary.json`` (:mod:`.summary`);
- ``scalars.csv``: one row per level (:mod:`.scalars`);
- ``solution.npz``: points, cells, contact_facets, t, u, beta (firm keys; :mod:`.npz`);
- ``solution.xdmf`` + ``solution.h5`` and ``contact.xdmf`` + ``contact.h5``
  (:mod:`.xdmf`), written by the recorder;
- PNG plots (:func:`adhesive_contact.visuals.write_plots`).
"""

import contextlib
from pathlib import Path

from ..folders import FolderLock, staged_folder
from ..postprocess import energies
from ..postprocess.level_scalars import level_scalars
from ..scheme import SUCCESS
from ..storage import read_json
from ..threads import one_blas_thread
from .field_levels import field_levels
from .npz import write_npz
from .scalars import write_scalars_csv
from .summary import STATUS, write_summary
from .xdmf import write_xdmf

#: the data files a run may write (the figures are :func:`output_names`')
DATA_NAMES = ("summary.json", "scalars.csv", "solution.npz", "solution.xdmf", "solution.h5",
              "contact.xdmf", "contact.h5")


def output_names():
    """Every file name ``adhcontact solve`` may write; in an existing folder
    a run replaces these and touches nothing else."""
    from ..visuals import PLOT_NAMES   # matplotlib: imported when a run writes

    return frozenset(DATA_NAMES + tuple(f"{name}.png" for name in PLOT_NAMES))


def holds_complete_run(out):
    """Whether folder ``out`` holds a complete run (its summary.json says so)."""
    document = read_json(Path(out) / "summary.json") if Path(out).is_dir() else None
    run = document.get("run") if isinstance(document, dict) else None
    return isinstance(run, dict) and run.get("status") == STATUS[SUCCESS]


@contextlib.contextmanager
def staged_output(out):
    """A staging folder for the outputs of ``out``, published into it when
    the block ends normally with a ``summary.json`` written and removed
    otherwise (:func:`adhesive_contact.folders.staged_folder`: a folder that
    held a whole run holds it or the new whole run after any failure, kill
    or full disk).

    Parameters
    ----------
    out : path of the output folder; its parents are created. Hold its
        lock (:class:`adhesive_contact.folders.FolderLock`; the command line
        takes it before the solve). In an existing folder only the
        files of :func:`output_names` are replaced; a user's other files
        stay. The staging folder (``<out>.tmp-*`` beside a new ``out``,
        ``.adhcontact.tmp-*`` inside an existing one) holds the marker file
        :data:`adhesive_contact.folders.MARKER`; those of killed runs are
        removed, or their publish finished, first.
    """
    out = Path(out).absolute()
    out.parent.mkdir(parents=True, exist_ok=True)
    with staged_folder(out, output_names()) as tmp:
        yield tmp


def write_results(solution, folder, failures=None, source=None, lines=None,
                  field_levels=None):
    """Write summary.json, scalars.csv, solution.npz and the plots of a
    solution into ``folder`` (the XDMF series are the recorder's); return
    their names. ``field_levels``: the levels whose fields are written
    (:mod:`.field_levels`; default every level). A plot that cannot be
    drawn is left out and named in ``failures`` (a list), if given; the
    data files are written all the same. ``source``: the scene's text and
    folder, ``lines`` the run's warnings if known
    (:func:`~.summary.summary_document`)."""
    from ..visuals import write_plots   # matplotlib: imported when a run draws

    folder = Path(folder)
    with one_blas_thread():   # level-sized products (adhesive_contact.threads)
        history = energies(solution)   # once, for every file and figure
        columns = level_scalars(solution, history)
        write_summary(solution, folder / "summary.json", source, history, lines,
                      field_levels, columns)
        write_scalars_csv(folder / "scalars.csv", solution.problem, columns)
        write_npz(solution, folder / "solution.npz", field_levels, columns)
        return ["summary.json", "scalars.csv", "solution.npz"] + write_plots(
            solution, folder, failures, history)


def write_outputs(solution, out, failures=None, source=None):
    """Write all outputs of a finished in-memory solution into ``out`` as
    ``adhcontact solve`` does (its lock held, staged, published whole; the
    fields at the field levels of its scene's ``[output]``); return the
    names of the files written. A folder another process is writing raises
    :class:`adhesive_contact.folders.FolderLocked`."""
    problem = solution.problem
    every = problem.output.every if problem.output is not None else 1
    levels = field_levels(problem, solution.reaction, solution.contact_force, every)
    with FolderLock(out), staged_output(out) as tmp:
        names = sorted(write_xdmf(solution, tmp, levels)
                       + write_results(solution, tmp, failures, source, field_levels=levels))
    return names
