"""A fleet of records on a Dask cluster: ``clpc.track_many`` and ``clpc track-many``.

One Dask task per record: the task carries the record's path (or, for an :class:`IOData`,
its samples), the fleet's settings and the output folder; the worker reads the record,
runs ``clpc track``'s workflow into ``OUT/<record>/`` and sends back a summary row of a few
kB (:func:`clpc.workflows.fleet_record.track_record`). The client collects the rows as
they finish (one progress line each), then ranks the records and writes the fleet table and
report (:func:`clpc.workflows.fleet_table.finish_fleet`).

A worker that dies (killed, out of memory, its machine gone) loses no record: the scheduler
runs its tasks again on another worker (up to ``distributed.scheduler.allowed-failures``
times, 3 by default). A record's own errors never raise: they come back as its row's
``error``. The output folder must be at the same path on the client and every worker (one
machine, or a shared file system), as must the records' paths.
"""

from __future__ import annotations

import os
import secrets
from collections.abc import Callable
from typing import Any

from clpc.distributed.cluster import dask_client, require_distributed
from clpc.workflows.fleet_record import track_record
from clpc.workflows.fleet_settings import FleetSettings
from clpc.workflows.fleet_sources import expand_sources
from clpc.workflows.fleet_table import FleetResult, finish_fleet

__all__ = ["Progress", "track_many"]

#: called after each finished record with (records done, records in all, the record's row)
Progress = Callable[[int, int, dict[str, Any]], None]


def track_many(
    sources: Any,
    *,
    client: Any = None,
    out: str | os.PathLike[str] | None = None,
    scheduler: str | None = None,
    workers: int | None = None,
    progress: Progress | None = None,
    announce: Callable[[str], None] | None = None,
    **settings: Any,
) -> FleetResult:
    """Track every record of a fleet on a Dask cluster; rank the records against the median.

    Every record gets exactly what ``clpc track FILE --out OUT/<record>`` writes (trace,
    figures, report); a record whose folder holds a finished run with the same settings and
    source is not run again.

    Parameters
    ----------
    sources : str, os.PathLike, IOData, mapping or iterable of these
        Files, globs, folders, a partitioned Parquet dataset (``axis=.../part.parquet``:
        one record per partition), :class:`clpc.IOData` objects, or ``{name: file or
        IOData}`` (see :func:`clpc.workflows.fleet_sources.expand_sources`).
    client : distributed.Client, optional
        A client to use (left open).
    out : str or os.PathLike, optional
        The fleet's folder: ``OUT/<record>/``, ``OUT/fleet.parquet``, ``OUT/fleet.html``.
        ``None``: each record is tracked in a temporary folder on its worker and only the
        table is returned.
    scheduler : str, optional
        Address of a running scheduler (``tcp://host:8786``); ignored with ``client``.
    workers : int, optional
        Worker processes of the local cluster started when there is neither a client nor
        an address (default: the cores available); it is closed at the end.
    progress : callable, optional
        ``progress(done, total, row)`` after each finished record.
    announce : callable, optional
        Called with one line naming the cluster and its dashboard link.
    **settings
        ``clpc track``'s settings: ``inputs``, ``outputs``, ``dt``, ``time_col``,
        ``time_unit``, ``time_rtol``, ``skip_rows``, ``order``, ``na``, ``nb``, ``nk``,
        ``window_size``, ``cluster_size``, ``decimate_to``, ``method``, ``guard``, ``fmt``,
        ``chunk_rows``, ``figure_updates`` (see :meth:`FleetSettings.from_keywords`).

    Returns
    -------
    FleetResult
        The fleet table (one row per record, in the order of the sources), the band and
        the median model of the ranking, and the files written.

    Raises
    ------
    clpc.workflows.SettingsError
        Sources that name nothing (see :func:`expand_sources`) or contradictory settings.
    TypeError
        An unknown setting.

    Notes
    -----
    A local cluster's workers are started as new Python processes that import the calling
    script again: in a script, call ``track_many`` under ``if __name__ == "__main__":``.
    """
    distributed = require_distributed()
    fleet = FleetSettings.from_keywords(**settings)
    records = expand_sources(sources)
    out_dir = None if out is None else os.path.abspath(os.fspath(out))
    if out_dir is not None:
        os.makedirs(out_dir, exist_ok=True)
    token = secrets.token_hex(4)
    rows: dict[int, dict[str, Any]] = {}
    with dask_client(client, scheduler, workers, announce) as c:
        futures = []
        for k, record in enumerate(records):
            arg = c.scatter(record, hash=False) if record.data is not None else record
            futures.append(
                c.submit(
                    track_record,
                    arg,
                    fleet,
                    out_dir,
                    key=f"clpc-record-{token}-{k}",
                    pure=False,
                )
            )
        index = {f.key: k for k, f in enumerate(futures)}
        for future in distributed.as_completed(futures):
            k = index[future.key]
            try:
                row = future.result()
            except Exception as exc:  # the task's workers died too often (KilledWorker)
                row = {"name": records[k].name, "source": records[k].file or "<IOData>",
                       "error": f"{type(exc).__name__}: {exc}"}  # fmt: skip
            rows[k] = row
            if progress is not None:
                progress(len(rows), len(records), row)
    return finish_fleet([rows[k] for k in range(len(records))], fleet, out_dir)
