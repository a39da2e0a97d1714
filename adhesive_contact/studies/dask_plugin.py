"""The worker plugin that gives each dask worker process a study's context
(imported only with ``distributed``, by :mod:`.executors`)."""

from distributed.diagnostics.plugin import WorkerPlugin

from .pool import _install


class InstallContext(WorkerPlugin):
    """Install the context (setup, args) of study ``token`` in a worker
    process, as the local pool's initializer does: the process builds its
    state from it on its first run of the study and keeps it."""

    idempotent = False

    def __init__(self, token, context):
        self.token, self.context = token, context

    def setup(self, worker):
        _install(self.token, *self.context)
