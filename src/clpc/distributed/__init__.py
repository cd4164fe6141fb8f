"""Work spread over a Dask cluster: fleets of records and records too long for one core.

Needs the ``distributed`` extra (``pip install ".[distributed]"`` from the source tree).
"""

from __future__ import annotations

from clpc.distributed.cluster import dask_client, default_workers, require_distributed

__all__ = ["dask_client", "default_workers", "require_distributed"]
