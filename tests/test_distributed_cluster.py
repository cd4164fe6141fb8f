"""clpc.distributed.cluster: a real LocalCluster of worker processes, or a given client."""

from __future__ import annotations

import os

import pytest

distributed = pytest.importorskip("distributed")

from clpc.distributed import dask_client  # noqa: E402


def _pid() -> int:
    return os.getpid()


def test_a_local_cluster_of_worker_processes_is_started_announced_and_closed():
    lines: list[str] = []
    with dask_client(workers=1, announce=lines.append) as client:
        worker_pid = client.submit(_pid, pure=False).result()
        cluster = client.cluster
    assert worker_pid != os.getpid()  # a process, not a thread of this one
    assert len(lines) == 1 and "1 worker process" in lines[0] and "dashboard: http" in lines[0]
    assert cluster.status.name == "closed"


def test_a_given_client_is_used_and_left_open():
    with distributed.LocalCluster(n_workers=1, processes=True, dashboard_address=":0") as cluster:
        with distributed.Client(cluster) as client:
            with dask_client(client=client) as used:
                assert used is client
            assert client.status == "running"


def test_zero_workers_is_refused():
    with pytest.raises(ValueError, match="at least 1"):
        with dask_client(workers=0):
            pass


def _profiling() -> bool:
    import dask

    return bool(dask.config.get("distributed.worker.profile.enabled"))


def test_the_local_cluster_runs_its_workers_without_the_statistical_profiler():
    with dask_client(workers=1) as client:
        assert list(client.run(_profiling).values()) == [False]
