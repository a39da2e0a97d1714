"""``--scheduler``: the option of the study commands that sends their runs
to a dask.distributed cluster (:mod:`adhesive_contact.studies.executors`)."""

import click

from .common import CliError


def scheduler_option(what):
    """The ``--scheduler`` option of a study command (``what``: its runs)."""
    return click.option(
        "--scheduler", metavar="ADDRESS", default=None,
        help=f"Send the {what} to a running dask.distributed scheduler, e.g. "
             "tcp://host:8786 (start it with `dask scheduler`, and workers with `dask worker "
             "ADDRESS --nthreads 1` on machines that have the package installed). The "
             "results come back here and only this process writes the output folder. "
             "Without it the runs use local processes (--jobs).")


def open_executor(scheduler, jobs):
    """The executor of ``--scheduler`` (None without it). A one-line error,
    exit 2, when it is given with --jobs or no scheduler answers there
    (within a few seconds)."""
    if scheduler is None:
        return None
    if jobs is not None:
        raise CliError("--jobs: not with --scheduler (the cluster's workers run the runs; "
                       "start as many as wanted with `dask worker`)", 2)
    from adhesive_contact.studies.executors import ClusterError, dask_executor
    scheme = scheduler.partition("://")[0] if "://" in scheduler else "tcp"
    if scheme in ("inproc", "ucx"):   # another process's inproc is unreachable; no ucx here
        raise CliError(f"--scheduler {scheduler}: the scheme {scheme}:// cannot reach a "
                       "scheduler from this command; use tcp://host:8786 (or tls://, ws://, "
                       "wss://)", 2)
    try:
        return dask_executor(scheduler)
    except ClusterError as err:
        raise CliError(f"--scheduler {err.address}: {err.message}", 2) from None
