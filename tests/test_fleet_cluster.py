"""A fleet when a worker dies; a fleet on ``dask scheduler`` and ``dask worker`` processes."""

from __future__ import annotations

import json
import os
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import pandas as pd
import pytest

distributed = pytest.importorskip("distributed")

import clpc  # noqa: E402
from clpc import track_many  # noqa: E402
from clpc.workflows.fleet_record import ROW_NAME  # noqa: E402
from fleet_sim import write_csvs  # noqa: E402

SETTINGS = {"inputs": "u", "outputs": "y", "time_col": "t"}
RUN_COLUMNS = ["skipped", "seconds", "folder"]
#: a scheduler on localhost at a free port (written to --scheduler-file), no fixed dashboard
SCHEDULER_ARGS = ("--host", "127.0.0.1", "--port", "0", "--dashboard-address", ":0")
CLPC = (sys.executable, "-m", "clpc")


def test_a_worker_killed_mid_run_loses_no_record(tmp_path):
    files = write_csvs(tmp_path / "recs", 4, 2000)
    killed: dict = {}
    with (
        distributed.LocalCluster(
            n_workers=2, threads_per_worker=1, processes=True, dashboard_address=":0"
        ) as cluster,
        distributed.Client(cluster) as client,
    ):
        client.wait_for_workers(2)
        pids = client.run(os.getpid)  # worker address -> its process id

        def kill_a_busy_worker(done: int, total: int, row: dict) -> None:
            if killed:
                return
            busy = {a: keys for a, keys in client.processing().items() if keys and a in pids}
            if busy:
                address, keys = next(iter(busy.items()))
                os.kill(pids[address], signal.SIGKILL)
                killed.update(pid=pids[address], keys=list(keys))

        hurt = track_many(
            tmp_path / "recs",
            client=client,
            out=tmp_path / "hurt",
            progress=kill_a_busy_worker,
            **SETTINGS,
        )
        clean = track_many(tmp_path / "recs", client=client, out=tmp_path / "clean", **SETTINGS)
    assert killed, "no worker was busy when the first record finished"
    assert hurt.table["error"].isna().all() and len(hurt.table) == len(files)
    pd.testing.assert_frame_equal(
        hurt.table.drop(columns=RUN_COLUMNS), clean.table.drop(columns=RUN_COLUMNS)
    )
    # the records the killed worker was running were run again by another process
    rerun = [int(str(k).rsplit("-", 1)[1]) for k in killed["keys"]]
    for k in rerun:
        name = hurt.table["name"][k]
        row = json.loads((tmp_path / "hurt" / name / ROW_NAME).read_text())
        assert row["worker_pid"] != killed["pid"]
    for name in hurt.table["name"]:
        a = (tmp_path / "hurt" / name / "trace.csv").read_bytes()
        assert a == (tmp_path / "clean" / name / "trace.csv").read_bytes()


def _dask() -> str:
    found = shutil.which("dask", path=str(Path(sys.executable).parent)) or shutil.which("dask")
    assert found, "the dask command (dask[distributed]) is not installed"
    return found


def _env() -> dict[str, str]:
    """This process's environment, with the clpc under test first on the path."""
    env = dict(os.environ)
    src = str(Path(clpc.__file__).resolve().parent.parent)
    env["PYTHONPATH"] = os.pathsep.join(p for p in (src, env.get("PYTHONPATH")) if p)
    return env


def test_track_many_on_a_scheduler_and_two_workers_started_as_the_docs_say(tmp_path):
    write_csvs(tmp_path / "recs", 3, 2000)
    (tmp_path / "recs" / "broken.csv").write_text("t,u,y\n0,1,2\n1,x\n")
    log = (tmp_path / "cluster.log").open("w")
    dask, env = _dask(), _env()
    scheduler_file = tmp_path / "scheduler.json"
    procs = [
        subprocess.Popen(
            [dask, "scheduler", *SCHEDULER_ARGS, "--scheduler-file", str(scheduler_file)],
            stdout=log,
            stderr=subprocess.STDOUT,
            env=env,
        )
    ]
    try:
        deadline = time.monotonic() + 60
        while not scheduler_file.exists() and time.monotonic() < deadline:
            time.sleep(0.2)
        address = json.loads(scheduler_file.read_text())["address"]
        for _ in range(2):
            procs.append(
                subprocess.Popen(
                    [dask, "worker", address, "--nthreads", "1"],
                    stdout=log,
                    stderr=subprocess.STDOUT,
                    env=env,
                )
            )
        with distributed.Client(address) as probe:
            probe.wait_for_workers(2, timeout=60)
        out = tmp_path / "out"
        run = subprocess.run(
            [
                *CLPC,
                "track-many",
                str(tmp_path / "recs"),
                "--out",
                str(out),
                "--scheduler",
                address,
                *("-u", "u", "-y", "y", "--time", "t"),
            ],
            capture_output=True,
            text=True,
            env=env,
            timeout=600,
        )
    finally:
        for p in procs:
            p.terminate()
        for p in procs:
            try:
                p.wait(timeout=30)
            except subprocess.TimeoutExpired:
                p.kill()
        log.close()
    assert run.returncode == 1, run.stderr  # one record failed: the fleet is still written
    assert f"using the Dask scheduler at {address}; dashboard: http" in run.stderr
    lines = [ln for ln in run.stderr.splitlines() if ln.startswith("[")]
    assert len(lines) == 4 and sum("FAILED" in ln for ln in lines) == 1
    assert "1 of 4 record(s) failed: broken:" in run.stderr
    assert f"wrote {out / 'fleet.parquet'}" in run.stdout
    table = pd.read_parquet(out / "fleet.parquet")
    assert list(table["name"]) == ["axis0", "axis1", "axis2", "broken"]
    assert table["error"].notna().tolist() == [False, False, False, True]
    assert (out / "fleet.html").is_file()
    for name in ("axis0", "axis1", "axis2"):
        assert (out / name / "report.html").is_file() and (out / name / "trace.csv").is_file()
