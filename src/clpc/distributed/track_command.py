"""``clpc track FILE --workers N`` / ``--scheduler ADDRESS``: a long record on a cluster.

:func:`track_settings` runs the command's settings through
:func:`clpc.distributed.track_long` (the workers write the trace as a Parquet dataset; the
summary is made of every update) and then writes ``clpc track``'s report, its figures drawn
by the same cluster's workers at once (:class:`.cluster_submit.ClusterSubmit`) instead of
one after the other on the client: the figures are the same files (tested byte for byte).
"""

from __future__ import annotations

import dataclasses
import json
from pathlib import Path
from typing import Any

from clpc.core.atomic import write_file
from clpc.data import DataError
from clpc.distributed.cluster import dask_client
from clpc.distributed.cluster_submit import ClusterSubmit
from clpc.distributed.long_track import LongTrack, track_long
from clpc.distributed.sources import open_source
from clpc.workflows import TrackSettings
from clpc.workflows.common import SettingsError
from clpc.workflows.track_report import TrackResult, write_report

__all__ = ["track_settings"]


def track_settings(
    settings: TrackSettings,
    *,
    client: Any = None,
    scheduler: str | None = None,
    workers: int | None = None,
) -> tuple[TrackResult, LongTrack]:
    """``clpc track`` with ``--workers``/``--scheduler``: :func:`track_long`, then the report.

    The record, its columns, ``--dt``, the appraiser's settings and ``--out`` are those of
    the command; ``OUT`` gets ``trace/`` (the dataset), ``summary.json``, the figures and
    ``report.html`` of :func:`clpc.workflows.track.write_report`, the figures drawn by the
    cluster's workers at once (:class:`clpc.distributed.cluster_submit.ClusterSubmit`).

    Raises
    ------
    SettingsError
        A time column (give ``--dt``), or a file that is not ``.npy`` or Parquet.
    """
    record = settings.record
    if record.time_col is not None:
        raise SettingsError(
            "a record split over workers needs a uniform sample time given with --dt "
            "(a time column is checked chunk by chunk on one machine: drop --workers/"
            "--scheduler, or give --dt instead of --time)."
        )
    try:
        keys = record.columns()  # digits as 0-based positions, as clpc track reads them
        n_in, n_out = len(record.inputs), len(record.outputs)
        source = open_source(record.file, tuple(keys[:n_in]), tuple(keys[n_in : n_in + n_out]))
    except DataError as exc:
        raise SettingsError(str(exc)) from None
    out = Path(settings.out_dir)
    with dask_client(client, scheduler, workers) as dask:
        done = track_long(
            settings.appraiser.build(record.dt),
            source,
            settings.out_dir,
            dt=record.dt,
            client=dask,
            figure_updates=settings.figure_updates,
        )
        try:  # the figures drawn by the workers, at once
            result = write_report(settings, done.appraised, done.dataset, out, ClusterSubmit(dask))
        finally:
            done.close()
    write_file(out / "summary.json", json.dumps(result.summary, indent=1))
    files = [*result.files, out / "summary.json"]
    return dataclasses.replace(result, files=files), done
