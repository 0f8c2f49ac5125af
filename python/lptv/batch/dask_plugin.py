"""The Dask worker plugin lptv registers on a client before its first study there.

Its setup runs :func:`lptv.batch.warm.warm_up` once on every worker of the cluster, those that
join later included (the scheduler keeps the plugin and hands it to them): lptv's task modules
and ``scipy.signal`` imported, one BLAS thread. Without it the first chunk on each worker pays
the imports (about 0.5 s). The plugin is registered once per client (and the scheduler ignores
a second registration under its name, e.g. from another client), so a client of your own can be
passed to many studies at the cost of one registration. What it does to a worker is what lptv's
first task would do anyway; glibc's trimming is handled around each chunk instead
(:func:`lptv.batch.warm.malloc_kept`), so that the worker's other tasks keep Dask's setting.

Importing this module needs ``distributed`` (the ``batch`` extra).
"""
from __future__ import annotations

import weakref

from distributed.diagnostics.plugin import WorkerPlugin

NAME = "lptv-warm-up"

_registered = weakref.WeakSet()


class WarmUp(WorkerPlugin):
    """Runs :func:`lptv.batch.warm.warm_up` on each worker once."""

    name = NAME
    idempotent = True     # a second registration under the name leaves the first in place

    def setup(self, worker):
        from .warm import warm_up

        warm_up()


def register(client) -> bool:
    """Register :class:`WarmUp` on ``client``'s cluster unless this client did already; True if
    it was registered now."""
    if client in _registered:
        return False
    client.register_plugin(WarmUp(), name=NAME)
    _registered.add(client)
    return True
