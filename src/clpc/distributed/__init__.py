"""Work spread over a Dask cluster: fleets of records and records too long for one core.

Needs the ``distributed`` extra (``pip install ".[distributed]"`` from the source tree).
Importing this package lets :meth:`clpc.CLPC.run` take a ``dask.array``
(:func:`run_long`); Dask itself is imported only when a cluster is used.
"""

from __future__ import annotations

from clpc.distributed.cluster import dask_client, default_workers, require_distributed
from clpc.distributed.long_record import run_long
from clpc.distributed.long_track import LongTrack, track_long
from clpc.distributed.sources import NpySource, ParquetSource, open_source

__all__ = [
    "LongTrack",
    "NpySource",
    "ParquetSource",
    "dask_client",
    "default_workers",
    "open_source",
    "require_distributed",
    "run_long",
    "track_long",
]
