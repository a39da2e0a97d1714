"""Studies: sets of independent runs of scene variants with a stable identity.

:mod:`.study` is the layer every kind of study shares (the identity in
``study.json``, one saved record per finished run, computing only what is
missing); :mod:`.pool` runs the runs in this process, in local worker
processes or on any executor; :mod:`.executors` is the executor of a
``dask.distributed`` cluster; :mod:`.convergence` is the convergence study
in h, k or both (a level and the reference run by :mod:`.levels`),
:mod:`.sweep` a parameter sweep.
"""

from .convergence import ConvergenceResult, ConvergenceStudy, LevelRow
from .executors import ClusterError, DaskExecutor, dask_executor
from .pool import execute
from .study import (
    RunFailed,
    RunStore,
    Study,
    StudyError,
    StudyFolderError,
    StudyMismatch,
    study_document,
)
from .sweep import Sweep, SweepResult, SweepRow

__all__ = ["ClusterError", "ConvergenceResult", "ConvergenceStudy", "LevelRow", "DaskExecutor",
           "dask_executor", "execute", "RunFailed", "RunStore",
           "Study", "StudyError", "StudyFolderError", "StudyMismatch", "study_document",
           "Sweep", "SweepResult", "SweepRow"]
