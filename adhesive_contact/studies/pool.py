"""Running the runs of a study: in this process, in local worker processes,
or on any executor.

A run is ``compute(state, key)`` returning a plain-JSON record; ``state``
is what ``setup(*args)`` builds (the parsed scene, a reference solution)
once per process and keeps for every run that process computes. Workers
compute and return plain data; only the calling process writes files
(``on_record``), one finished run at a time.

The executor is pluggable: anything with ``submit(fn, *args)`` returning
futures, with an ``as_completed(futures)`` yielding them as they finish
(:mod:`concurrent.futures`, or :func:`~adhesive_contact.studies.executors.dask_executor`
for a ``dask.distributed`` cluster). An executor may also have
``install(token, context)`` and ``uninstall(token)`` (give its worker
processes the context once, like the local pool's initializer, instead of
sending it with every task), ``as_completed`` (used when none is given)
and ``lost_errors`` (the exception types of a task whose worker died).

A run whose worker died (a killed process, a lost machine) is *lost*, not
failed: it says nothing about the run, so it is never saved; the caller
decides whether it stops the study or is reported and retried later.
"""

import multiprocessing
import signal
import threading
from concurrent.futures import CancelledError, ProcessPoolExecutor
from concurrent.futures import as_completed as futures_completed
from concurrent.futures.process import BrokenProcessPool

from ..scheme import StepFailure

#: per process: token -> (setup, args) installed by the pool initializer,
#: and token -> state built from it on first use
_CONTEXTS = {}
_STATES = {}
_LOCK = threading.Lock()   # threaded workers build a state once too


def _install(token, setup, args):
    """Pool initializer: remember how to build the state (built on first
    use; a state built from an earlier install is dropped)."""
    with _LOCK:
        _CONTEXTS[token] = (setup, args)
        _STATES.pop(token, None)


def _worker_start(token, setup, args):
    """Initializer of a local worker process: Ctrl-C, which the terminal
    sends to the whole process group, is the calling process's to handle
    (it stops the study and ends the workers); then :func:`_install`."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    _install(token, setup, args)


def _state(token, context=None):
    """The process's state for ``token``, built once from its context."""
    with _LOCK:
        if token not in _STATES:
            setup, args = context if context is not None else _CONTEXTS[token]
            _STATES.clear()   # one study at a time per process
            _STATES[token] = setup(*args)
        return _STATES[token]


def attempt(compute, state, key):
    """(key, record, None), or (key, None, message) when the run's time loop
    failed (a step solve that did not converge); the one place a failure of
    the scheme is caught."""
    try:
        return key, compute(state, key), None
    except StepFailure as err:
        return key, None, str(err)


def run_task(token, compute, key, context=None):
    """One run in a worker: ``context`` (setup, args) is sent with each task
    by a generic executor and installed once per process by the local pool."""
    return attempt(compute, _state(token, context), key)


def lost_message(err):
    """One phrase for a run whose worker died (``err`` what the executor raised)."""
    what = " ".join(str(err).split()) or type(err).__name__
    return f"lost: the worker computing it died or was cut off ({type(err).__name__}: {what})"


def in_this_process(jobs, executor, count):
    """Whether :func:`execute` computes ``count`` runs here, one after the
    other (no executor, and one job or one run), where a run may report
    its own progress."""
    return executor is None and (jobs == 1 or count == 1)


def execute(keys, compute, context, on_record, *, token, jobs=1, executor=None,
            as_completed=None, on_lost=None):
    """Compute the runs ``keys``; call ``on_record(key, record)`` as each finishes.

    Parameters
    ----------
    keys : list of the runs to compute
    compute : module-level function (state, key) -> record
    context : (setup, args), setup(*args) -> state (both must pickle for
        worker processes)
    on_record : called in this process, one finished run at a time
    token : str naming the study (its sha256): a worker process keeps the
        state of one token
    jobs : int
        Without ``executor``: 1 computes in this process (state built once
        here); more starts that many local worker processes (spawned, each
        reused for many runs, the state built once per process).
    executor : object with ``submit(fn, *args)`` returning futures, optional
        Runs are submitted to it (``jobs`` ignored); its workers build the
        state once per process. With ``install``/``uninstall`` the context
        is installed in its workers around the study instead of being sent
        with every task.
    as_completed : callable yielding finished futures, optional
        Default: the executor's ``as_completed`` if it has one, else
        :func:`concurrent.futures.as_completed`.
    on_lost : callable (key, message), optional
        Called in this process for a run whose worker died (an exception of
        the executor's ``lost_errors``, a broken local pool, a task
        cancelled by the executor); the other runs go on. Without it a lost
        run is a failure like a step failure.

    Returns
    -------
    None, or (key, message) of the first run that failed: no other run is
    started after it, and the runs already running are finished and passed
    to ``on_record``.
    """
    keys = list(keys)
    if not keys:
        return None
    if in_this_process(jobs, executor, len(keys)):
        state = context[0](*context[1])
        for key in keys:
            key, record, message = attempt(compute, state, key)
            if message is not None:
                return key, message
            on_record(key, record)
        return None
    if executor is not None:
        completed = as_completed or getattr(executor, "as_completed", None) or futures_completed
        lost = (BrokenProcessPool, CancelledError, *getattr(executor, "lost_errors", ()))
        if not hasattr(executor, "install"):
            futures = {executor.submit(run_task, token, compute, key, context): key
                       for key in keys}
            return _collect(futures, completed, on_record, on_lost, lost)
        executor.install(token, context)
        try:
            futures = {executor.submit(run_task, token, compute, key): key for key in keys}
            return _collect(futures, completed, on_record, on_lost, lost)
        finally:
            executor.uninstall(token)
    pool = ProcessPoolExecutor(max_workers=min(jobs, len(keys)),
                               mp_context=multiprocessing.get_context("spawn"),
                               initializer=_worker_start, initargs=(token, *context))
    try:
        futures = {pool.submit(run_task, token, compute, key): key for key in keys}
        failure = _collect(futures, as_completed or futures_completed, on_record, on_lost,
                           (BrokenProcessPool, CancelledError))
    except BaseException:
        # an interrupt (or a record that could not be saved): the runs in
        # the workers are lost; end the workers now rather than after them
        _end_workers(pool)
        raise
    pool.shutdown()
    return failure


def _end_workers(pool):
    """Stop a local pool at once: the queued runs cancelled, the worker
    processes terminated (concurrent.futures has no public call for it
    before Python 3.14)."""
    processes = list((getattr(pool, "_processes", None) or {}).values())
    pool.shutdown(wait=False, cancel_futures=True)
    for process in processes:
        process.terminate()
    for process in processes:
        process.join(5)


def _collect(futures, as_completed, on_record, on_lost, lost):
    """Pass each finished run to ``on_record`` as it comes; see :func:`execute`.

    ``futures`` maps each future to its run's key. When anything raises here
    (``on_record``, an interrupt), the runs not started are cancelled."""
    failure = None
    try:
        for future in as_completed(list(futures)):
            if failure is not None and future.cancelled():
                continue                    # cancelled here, after the failure
            try:
                key, record, message = future.result()
            except lost as err:
                key, record, message = futures[future], None, lost_message(err)
                if on_lost is not None:
                    on_lost(key, message)
                    continue
            if message is None:
                on_record(key, record)
            elif failure is None:
                failure = (key, message)
                _cancel(futures)
    except BaseException:
        _cancel(futures)
        raise
    return failure


def _cancel(futures):
    for future in futures:
        future.cancel()
