"""Running a study's runs on a ``dask.distributed`` cluster.

:func:`dask_executor` connects to a running scheduler (or wraps a
``distributed.Client``) and returns what
:func:`~adhesive_contact.studies.pool.execute` needs: ``submit``,
``as_completed``, ``install``/``uninstall`` and ``lost_errors``. The
workers need only the installed package: a task is
:func:`~adhesive_contact.studies.pool.run_task` with the study's
module-level ``compute``; the context (the scene, the settings, a fine
reference) is given to every worker process once, by a worker plugin (so a
worker started or restarted later gets it too); each builds its state from
it once and keeps it for every run it computes. The runs are tasks without
dependencies: the scheduler hands a worker one run per thread at a time,
so a worker that dies takes only its own runs with it. Records come back to
the calling process, which alone writes the study's folder.

A worker that dies is replaced by its nanny and its run is retried by the
scheduler (``distributed.scheduler.allowed-failures``, 3 by default); a run
that kills its worker every time comes back as lost
(``distributed.KilledWorker``). Waiting never hangs: when the cluster has
had no worker for ``patience`` seconds, or the scheduler is gone,
:class:`ClusterError` is raised.

``distributed`` is imported only when a study is sent to a cluster; it is
not in the package's default install but in its extra ``dask``
(``pip install ".[dask]"``), which :data:`NOT_INSTALLED` names.

From Python::

    from adhesive_contact.studies import Sweep
    from adhesive_contact.studies.executors import dask_executor

    with dask_executor("tcp://host:8786") as executor:
        Sweep(scene, settings, folder="out").run(executor=executor)
"""

import socket
import struct
import threading
import time

#: seconds to wait for a scheduler before giving up
CONNECT_TIMEOUT = 5.0
#: seconds between two looks at the cluster while waiting for runs
POLL = 2.0
#: the address schemes of the form host:port, the only ones a study may use
HOST_PORT_SCHEMES = ("tcp", "tls", "ws", "wss")
#: the largest first message (bytes) a scheduler's handshake may have
HANDSHAKE_BYTES = 1 << 20
#: seconds between two looks for finished runs
WAKE = 0.02
#: what a study sent to a cluster says where ``distributed`` is not installed
NOT_INSTALLED = ('needs the package distributed, which the default install leaves out: '
                 'install the extra "dask", pip install ".[dask]" from the repository (or '
                 'pip install "distributed>=2024.1")')


def _plugin_name(token):
    return f"adhesive-contact-study-{token}"


class ClusterError(RuntimeError):
    """The cluster cannot run the study: unreachable, gone, or without workers.

    ``address`` is the scheduler's address, ``message`` says what happened."""

    def __init__(self, address, message):
        self.address, self.message = address, message
        super().__init__(f"{address}: {message}")


class DaskExecutor:
    """A ``distributed.Client`` as an executor of study runs (see the module
    docstring); a context manager that closes the client it opened.

    Parameters
    ----------
    client : distributed.Client
    own : bool
        Close the client on :meth:`close` (True when it was opened here).
    patience : float
        Seconds without any worker after which waiting gives up.
    """

    def __init__(self, client, own=False, patience=60.0):
        import distributed

        self.client, self.own, self.patience = client, own, patience
        self.address = client.scheduler.address
        self.lost_errors = (distributed.KilledWorker,)
        self._distributed = distributed

    def install(self, token, context):
        """Give every worker, present and future (a restarted one too), the
        context of study ``token``: a worker plugin, sent once per worker."""
        from .dask_plugin import InstallContext

        self.client.register_plugin(InstallContext(token, context), name=_plugin_name(token))

    def uninstall(self, token):
        """Forget the context of study ``token`` on the workers."""
        try:
            self.client.unregister_worker_plugin(_plugin_name(token))
        except (OSError, TimeoutError, ValueError):
            pass            # the cluster is gone, or never had it

    def submit(self, fn, *args):
        """``fn(*args)`` on a worker: one task per run (never merged with
        another: ``pure=False``), no retry beyond the scheduler's own."""
        return self.client.submit(fn, *args, pure=False)

    def workers(self):
        """The number of workers the scheduler has now."""
        try:
            return len(self.client.nthreads())
        except (OSError, TimeoutError) as err:
            raise ClusterError(self.address, f"lost the scheduler ({err})") from None

    def as_completed(self, futures):
        """Yield the futures as they finish (cancelled ones too);
        :class:`ClusterError` when the cluster has had no worker for
        ``patience`` seconds or the scheduler is gone."""
        finished = self._distributed.as_completed(futures, loop=self.client.loop)
        look, idle = time.monotonic() + POLL, None
        while not finished.is_empty():
            if finished.has_ready():
                yield from finished.next_batch(block=False)
                continue
            time.sleep(WAKE)
            if time.monotonic() < look:
                continue
            look = time.monotonic() + POLL
            if self.workers():
                idle = None
                continue
            idle = idle or time.monotonic()
            if time.monotonic() - idle > self.patience:
                for future in futures:
                    future.cancel()
                raise ClusterError(self.address, f"no worker for {self.patience:g} s; start "
                                   f"one with: dask worker {self.address}")

    def close(self):
        if self.own:
            self.client.close()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()


def dask_executor(scheduler, *, timeout=None, patience=60.0):
    """An executor of study runs on a ``dask.distributed`` cluster.

    Parameters
    ----------
    scheduler : str or distributed.Client
        The scheduler's address (``tcp://host:8786``) or a connected client
        (kept open by :meth:`DaskExecutor.close`).
    timeout : float, optional
        Seconds to wait for the scheduler to answer (default
        :data:`CONNECT_TIMEOUT`).
    patience : float
        Seconds a study waits while the cluster has no worker before giving up.

    Returns
    -------
    DaskExecutor, to pass as ``executor=`` to a study's ``run``.

    Raises
    ------
    ClusterError
        ``distributed`` is not installed (:data:`NOT_INSTALLED`: the extra
        ``dask``), the address is malformed, or no
        scheduler answered there within ``timeout`` seconds.
    """
    if not isinstance(scheduler, str):
        return DaskExecutor(scheduler, own=False, patience=patience)
    timeout = CONNECT_TIMEOUT if timeout is None else timeout
    try:
        import distributed
    except ImportError:
        raise ClusterError(scheduler, NOT_INSTALLED) from None
    try:
        scheme, location = distributed.comm.parse_address(scheduler)
        distributed.comm.registry.get_backend(scheme)
        if scheme in HOST_PORT_SCHEMES:
            host, port = distributed.comm.addressing.parse_host_port(location)
    except (ValueError, TypeError) as err:
        raise ClusterError(scheduler, f"not a scheduler address ({err}); expected e.g. "
                           "tcp://host:8786") from None
    deadline = time.monotonic() + timeout
    if scheme in HOST_PORT_SCHEMES:   # inproc:// (this process) and ucx:// are not probed
        probe_scheduler(scheduler, scheme, host, port, timeout)
    return DaskExecutor(_client(distributed, scheduler, deadline, timeout), own=True,
                        patience=patience)


def _no_answer(scheduler, timeout):
    return ClusterError(scheduler, f"no dask scheduler answered there within {timeout:g} s")


def probe_scheduler(scheduler, scheme, host, port, timeout):
    """Check within ``timeout`` seconds that a dask scheduler listens at
    ``host:port``: the connection is accepted and (``tcp``) the first
    message of the handshake, which a scheduler sends at once, arrives: an
    8-byte length of at most :data:`HANDSHAKE_BYTES`, then that many bytes.
    A closed port, a listener that stays silent (an HTTP server waits for a
    request) or one that sends anything else is a :class:`ClusterError`."""
    deadline = time.monotonic() + timeout
    try:
        sock = socket.create_connection((host, port), timeout=timeout)
    except (OSError, ValueError, OverflowError):
        raise _no_answer(scheduler, timeout) from None
    try:
        if scheme != "tcp":   # TLS and websockets: the client's bounded wait below
            return
        try:
            (size,) = struct.unpack("Q", _receive(sock, 8, deadline))   # as distributed
            if not 0 < size <= HANDSHAKE_BYTES:
                raise ClusterError(scheduler, "something answers there, but not a dask "
                                   "scheduler (its first message is not a handshake)")
            _receive(sock, size, deadline)
        except (OSError, EOFError):
            raise ClusterError(scheduler, "something accepts connections there but does "
                               f"not answer as a dask scheduler within {timeout:g} s") from None
    finally:
        sock.close()


def _receive(sock, count, deadline):
    """``count`` bytes from ``sock`` before ``deadline`` (socket.timeout or
    EOFError otherwise)."""
    data = bytearray()
    while len(data) < count:
        left = deadline - time.monotonic()
        if left <= 0:
            raise socket.timeout("handshake")
        sock.settimeout(left)
        chunk = sock.recv(min(count - len(data), 1 << 16))
        if not chunk:
            raise EOFError("closed")
        data += chunk
    return bytes(data)


def _client(distributed, scheduler, deadline, timeout):
    """A ``distributed.Client`` of ``scheduler``, connected before
    ``deadline`` (and a few seconds' grace) or a :class:`ClusterError`:
    the client is made in a daemon thread, so whatever answers, waiting is
    bounded."""
    box = {}

    def connect():
        try:
            box["client"] = distributed.Client(
                scheduler, timeout=max(deadline - time.monotonic(), 0.5),
                set_as_default=False)
        except BaseException as err:   # reported below, in the caller's thread
            box["error"] = err

    thread = threading.Thread(target=connect, name="adhcontact-connect", daemon=True)
    thread.start()
    thread.join(max(deadline - time.monotonic(), 0.0) + 5.0)
    if thread.is_alive() or "client" not in box:
        error = box.get("error")
        if error is None or isinstance(error, (OSError, TimeoutError)):
            raise _no_answer(scheduler, timeout)
        raise ClusterError(scheduler, "the connection failed "
                           f"({type(error).__name__}: {' '.join(str(error).split())[:200]})")
    return box["client"]
