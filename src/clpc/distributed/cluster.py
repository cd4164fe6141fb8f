"""Where distributed work runs: a Dask client for one call.

Three ways, in this order of precedence:

* a ``distributed.Client`` the caller already holds (used, never closed);
* the address of a running scheduler (``dask scheduler`` and ``dask worker ADDRESS`` started
  as the docs tell; connected for the call, then disconnected; the cluster keeps running);
* neither: a ``distributed.LocalCluster`` of worker **processes**, one thread each (the
  appraiser's kernel holds the GIL only briefly, but one process per core keeps numba, BLAS
  and the Python parts of a record from contending), started for the call and closed after.

``dask[distributed]`` is an optional extra (``pip install ".[distributed]"`` from the source
tree); importing this module does not import it, so ``import clpc`` stays cheap.
"""

from __future__ import annotations

import os
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from typing import Any

INSTALL_HINT = (
    'clpc\'s distributed features need Dask: pip install "dask[distributed]" '
    '(from a clone of clpc: pip install ".[distributed]")'
)


#: Dask's statistical profiler samples each worker's stack every 10 ms (for the dashboard's
#: profile page); on clpc's records it costs about a tenth of a worker's CPU, so the local
#: clusters clpc starts run without it (``DASK_DISTRIBUTED__WORKER__PROFILE__ENABLED=False``
#: does the same for ``dask worker``; see docs/distributed.md)
NO_PROFILER = {"distributed.worker.profile.enabled": False}


def require_distributed() -> Any:
    """Import and return ``distributed``, or raise ImportError saying how to install it."""
    try:
        import distributed
    except ImportError as exc:  # pragma: no cover - the extra is installed in the test env
        raise ImportError(INSTALL_HINT) from exc
    return distributed


def default_workers() -> int:
    """Worker processes of a local cluster when none is asked for: the usable cores."""
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except AttributeError:  # pragma: no cover - not on Linux
        return max(1, os.cpu_count() or 1)


@contextmanager
def dask_client(
    client: Any = None,
    scheduler: str | None = None,
    workers: int | None = None,
    announce: Callable[[str], None] | None = None,
) -> Iterator[Any]:
    """A ``distributed.Client`` for the body of a ``with`` block.

    Parameters
    ----------
    client : distributed.Client, optional
        Used as it is and left open.
    scheduler : str, optional
        Address of a running scheduler, e.g. ``"tcp://10.0.0.5:8786"``; ignored with ``client``.
    workers : int, optional
        Worker processes of the local cluster started when neither ``client`` nor
        ``scheduler`` is given; default: the cores available (:func:`default_workers`).
    announce : callable, optional
        Called with one line naming the cluster and its dashboard link (the CLI prints it).

    Yields
    ------
    distributed.Client
    """
    distributed = require_distributed()
    if client is not None:
        yield client
        return
    if scheduler is not None:
        with distributed.Client(scheduler) as connected:
            if announce is not None:
                link = connected.dashboard_link
                announce(f"using the Dask scheduler at {scheduler}; dashboard: {link}")
            yield connected
        return
    n_workers = default_workers() if workers is None else int(workers)
    if n_workers < 1:
        raise ValueError(f"workers must be at least 1, got {workers}")
    import dask

    with (
        dask.config.set(NO_PROFILER),  # the nannies hand this config to their workers
        distributed.LocalCluster(
            n_workers=n_workers,
            threads_per_worker=1,
            processes=True,
            dashboard_address=":0",
        ) as cluster,
        # results straight from the workers (by default they pass through the scheduler)
        distributed.Client(cluster, direct_to_workers=True) as local,
    ):
        if announce is not None:
            announce(
                f"started a local Dask cluster of {n_workers} worker process(es); "
                f"dashboard: {local.dashboard_link}"
            )
        yield local
