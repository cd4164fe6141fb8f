"""Independent calls (a report's figures) run on a Dask cluster's workers, all at once.

:class:`ClusterSubmit` is the ``submit`` of :func:`clpc.report.write_track_report`: each
figure becomes a task, and the workers draw them at the same time instead of the client one
after the other. An argument larger than :data:`SCATTER_BYTES` (the thinned trace the
trace's, the quantities' and the tests' figures share) is sent to the cluster once
(``Client.scatter``) and named by the tasks that need it. The figures are written by the
workers: every worker must see the output folder at the same path (as for the trace's
dataset).
"""

from __future__ import annotations

import uuid
from collections.abc import Callable
from typing import Any

__all__ = ["SCATTER_BYTES", "ClusterSubmit"]

#: arguments larger than this (Dask's estimate, bytes) are scattered once, not sent per task
SCATTER_BYTES = 100_000


class ClusterSubmit:
    """``submit(function, *args, **kwargs)`` as a task of a Dask cluster (a future).

    Parameters
    ----------
    client : distributed.Client
    """

    def __init__(self, client: Any) -> None:
        self.client = client
        self._sent: dict[int, tuple[Any, Any]] = {}  # id(argument): (argument, its future)

    def __call__(self, function: Callable[..., Any], *args: Any, **kwargs: Any) -> Any:
        """The task ``function(*args, **kwargs)`` on a worker; its future (of ``None``).

        What ``function`` returns is dropped on the worker (a figure function returns its
        matplotlib figure: sending it back would cost more than drawing it). The task is
        named after ``function``.
        """
        sent = [self._scattered(a) for a in args]
        key = f"{getattr(function, '__name__', 'call')}-{uuid.uuid4().hex}"
        return self.client.submit(_dropped, function, *sent, key=key, **kwargs)

    def _scattered(self, arg: Any) -> Any:
        """A large argument as the future of its copy on the cluster (sent once)."""
        from dask.sizeof import sizeof

        if id(arg) in self._sent:
            return self._sent[id(arg)][1]
        if sizeof(arg) < SCATTER_BYTES:
            return arg
        future = self.client.scatter(arg, direct=True)
        self._sent[id(arg)] = (arg, future)  # the argument kept: its id stays its own
        return future


def _dropped(function: Callable[..., Any], *args: Any, **kwargs: Any) -> None:
    """``function(*args, **kwargs)``, its result let go (only its side effect, a file, counts)."""
    function(*args, **kwargs)
