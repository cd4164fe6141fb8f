"""Transactional outputs (issue 28, item 3): every file whole or absent, one run per folder.

Each defect of the issue is reproduced here: a killed ``clpc track`` leaving a clean-looking
partial trace, a failed re-run leaving the old report beside a new trace, a full disk
leaving a trace cut mid-row with an error naming no file, stale figures, two runs into one
``--out``, ``CLPC.save`` killed mid-write, files written through a planted symbolic link,
``save_model`` changing the umask.
"""

from __future__ import annotations

import errno
import hashlib
import json
import os
import re
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner

import clpc
from clpc.cli import cli
from clpc.core.atomic import OutputError, atomic_file, write_file
from clpc.core.output_folder import LOCK_NAME, RECORD_NAME, OutputFolder
from clpc.model import LinearModel, Structure

TRACK = ["-u", "u", "-y", "y", "--window-size", "101", "--cluster-size", "25"]


def _record(path: Path, n: int, seed: int = 0) -> Path:
    rng = np.random.default_rng(seed)
    u = rng.standard_normal(n)
    y = clpc.simulate_arx([1, -1.2, 0.5], [0, 0.5, 0.2], u) + 0.01 * rng.standard_normal(n)
    np.savetxt(path, np.column_stack([u, y]), delimiter=",", header="u,y", comments="", fmt="%.6g")
    return path


@pytest.fixture(scope="module")
def short(tmp_path_factory) -> Path:
    return _record(tmp_path_factory.mktemp("rec") / "short.csv", 1500)


def _run(*args: object) -> object:
    return CliRunner().invoke(cli, [str(a) for a in args])


def _visible(folder: Path) -> dict[str, str]:
    """The folder's files (not clpc's hidden lock and record) and their digests."""
    return {
        p.name: hashlib.sha256(p.read_bytes()).hexdigest()
        for p in folder.iterdir()
        if not p.name.startswith(".")
    }


def _one_line_error(result: object, *needles: str) -> str:
    assert result.exit_code == 1, result.output
    lines = result.output.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("Error: "), result.output
    assert "Traceback" not in result.output
    for needle in needles:
        assert needle in lines[0], lines[0]
    return lines[0]


def test_a_track_run_owns_its_folder_and_replaces_the_previous_runs_files(tmp_path, short):
    out = tmp_path / "out"
    out.mkdir()
    for stale in ("residuals.png", "report.html"):  # an earlier run's (no record of it)
        (out / stale).write_text("stale")
    (out / "notes.txt").write_text("mine")  # not clpc's: kept
    done = _run("track", short, *TRACK, "--out", out)
    assert done.exit_code == 0, done.output
    record = json.loads((out / RECORD_NAME).read_text())
    assert record["complete"] and record["files"][-1] == "report.html"
    assert set(_visible(out)) == {*record["files"], "notes.txt"}  # residuals.png is gone
    assert "stale" not in (out / "report.html").read_text()
    wrote = [line.removeprefix("wrote ") for line in done.output.splitlines() if "wrote" in line]
    assert {Path(w).name for w in wrote} == set(record["files"])
    assert all(Path(w).parent == out for w in wrote)  # the final names, not the staged ones
    # a run that leaves fewer files removes the rest of the previous run's set
    write_file(out / RECORD_NAME, json.dumps({"files": [*record["files"], "old.png"]}))
    (out / "old.png").write_text("from a run with more figures")
    assert _run("track", short, *TRACK, "--out", out).exit_code == 0
    assert not (out / "old.png").exists() and (out / "notes.txt").exists()


def test_a_failed_rerun_leaves_the_previous_runs_files_untouched(tmp_path, short, monkeypatch):
    out = tmp_path / "out"
    assert _run("track", short, *TRACK, "--out", out).exit_code == 0
    before = _visible(out)

    def broken(*args, **kwargs):
        raise np.linalg.LinAlgError("Singular matrix")

    monkeypatch.setattr("clpc.report.track.plot_trace", broken)
    assert _run("track", short, *TRACK, "--out", out).exit_code == 1
    assert _visible(out) == before
    assert sorted(p.name for p in out.iterdir()) == sorted([*before, LOCK_NAME, RECORD_NAME])


def test_a_full_disk_names_the_trace_and_leaves_no_partial_file(tmp_path, short, monkeypatch):
    out = tmp_path / "out"

    def full(self, part):  # part of a row reaches the disk, then the disk is full
        if self._target is None:
            self._target = clpc.core.atomic.atomic_path(self.path)
            self._fh = self._target.__enter__().open("w")
        self._fh.write("index,time,rows,not_enough_data,a1\n0,0.0,1")
        raise OSError(errno.ENOSPC, "No space left on device")

    monkeypatch.setattr("clpc.appraiser.tracefile.TraceWriter._write", full)
    done = _run("track", short, *TRACK, "--out", out)
    _one_line_error(done, f"cannot write '{out / 'trace.csv'}'", "No space left on device")
    assert sorted(p.name for p in out.iterdir()) == [LOCK_NAME]  # no partial, no staging


def test_a_full_disk_while_drawing_names_the_figure(tmp_path, short, monkeypatch):
    out = tmp_path / "out"
    assert _run("track", short, *TRACK, "--out", out).exit_code == 0
    before = _visible(out)
    from matplotlib.figure import Figure

    def full(self, fh, **kwargs):
        fh.write(b"\x89PNG\r\n")
        raise OSError(errno.ENOSPC, "No space left on device")

    monkeypatch.setattr(Figure, "savefig", full)
    done = _run("track", short, *TRACK, "--out", out)
    line = _one_line_error(done, "No space left on device")
    named = re.search(r"cannot write '([^']+)'", line)
    assert named is not None and Path(named.group(1)).parent == out, line
    assert Path(named.group(1)).suffix == ".png"
    assert _visible(out) == before  # the previous run's set, whole


@pytest.mark.parametrize("name", ["trace.csv", "report.html", "step.png"])
def test_a_symlink_planted_in_out_is_refused(tmp_path, short, name):
    out, victim = tmp_path / "out", tmp_path / "victim.txt"
    out.mkdir()
    victim.write_text("precious")
    (out / name).symlink_to(victim)
    done = _run("track", short, *TRACK, "--out", out)
    _one_line_error(done, f"'{out / name}'", "symbolic link")
    assert victim.read_text() == "precious" and (out / name).is_symlink()


def test_a_second_run_into_a_locked_folder_is_refused(tmp_path, short):
    out = tmp_path / "out"
    with OutputFolder(out):  # a run in progress (another process in practice)
        done = _run("track", short, *TRACK, "--out", out)
        _one_line_error(done, f"'{out}'", "another clpc run is writing into this folder")
        report = _run("identify", short, "-u", "u", "-y", "y", "--report", out)
        _one_line_error(report, "another clpc run", "--report")
    assert _run("track", short, *TRACK, "--out", out).exit_code == 0  # the lock is gone


def test_save_model_keeps_the_umask_and_gives_opens_mode(tmp_path, monkeypatch):
    model = LinearModel(np.array([[0.0, 0.6, 0.8, 0.0]]), Structure(1, 1), 1, "siso", [0.0])
    old = os.umask(0o027)
    try:
        calls = []
        monkeypatch.setattr(os, "umask", lambda mask: calls.append(mask) or 0o027)
        clpc.save_model(model, tmp_path / "m.json")
        clpc.CLPC(order=1, window_size=51).save(str(tmp_path / "state.json"))
        monkeypatch.undo()
        assert calls == []  # never changed, not even for a moment
        assert os.umask(0o027) == 0o027
    finally:
        os.umask(old)
    for name in ("m.json", "state.json"):
        assert (tmp_path / name).stat().st_mode & 0o777 == 0o640
    assert sorted(p.name for p in tmp_path.iterdir()) == ["m.json", "state.json"]


def test_single_files_refuse_links_and_leave_no_partial_file(tmp_path):
    target = tmp_path / "t.json"
    target.write_text("old")
    with pytest.raises(OutputError, match="No space left"), atomic_file(target) as fh:
        fh.write("half")
        raise OSError(errno.ENOSPC, "No space left on device")
    assert target.read_text() == "old" and [p.name for p in tmp_path.iterdir()] == ["t.json"]
    (tmp_path / "link.csv").symlink_to(target)
    with pytest.raises(OutputError, match="symbolic link"):
        clpc.write_table(tmp_path / "link.csv", ["u"], np.zeros(3))
    assert target.read_text() == "old"


def _env() -> dict[str, str]:
    return {**os.environ, "OPENBLAS_NUM_THREADS": "1"}


def _wait_for(predicate, proc: subprocess.Popen, what: str) -> None:
    deadline = time.monotonic() + 120
    while not predicate():
        if proc.poll() is not None:
            raise AssertionError(f"the process ended before {what}: {proc.stderr.read()}")
        assert time.monotonic() < deadline, f"no {what} after 120 s"
        time.sleep(0.05)


def test_track_killed_mid_run_leaves_nothing_claiming_completeness(tmp_path, short):
    out = tmp_path / "out"
    assert _run("track", short, *TRACK, "--out", out).exit_code == 0
    before = _visible(out)
    long = _record(tmp_path / "long.csv", 100_000, seed=2)
    cmd = [sys.executable, "-m", "clpc", "track", str(long), *TRACK, "--out", str(out)]
    proc = subprocess.Popen(
        [*cmd, "--chunk-rows", "2000"],
        env=_env(),
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
        text=True,
    )
    try:
        _wait_for(lambda: any(out.glob(".clpc-run-*/.clpc-tmp-*-trace.csv")), proc, "a trace")
        second = subprocess.run(cmd, env=_env(), capture_output=True, text=True, timeout=120)
        assert second.returncode == 1  # two runs into one --out: the second is refused
        assert second.stderr.count("\n") == 1 and "another clpc run" in second.stderr
        assert str(out) in second.stderr
    finally:
        proc.send_signal(signal.SIGKILL)
        proc.wait()
        proc.stderr.close()
    assert _visible(out) == before  # the previous run's complete set, untouched
    assert _run("track", short, *TRACK, "--out", out).exit_code == 0  # a re-run succeeds
    assert not list(out.glob(".clpc-*-*"))  # the killed run's staging folder is removed


_SAVER = """
import sys
import numpy as np
import clpc

rng = np.random.default_rng(0)
appraiser = clpc.CLPC(order=2, window_size=2001, cluster_size=50)
u = rng.standard_normal(2_000_000)
appraiser.push(u[:3000], u[:3000])
appraiser.save(sys.argv[1])
print("saved", flush=True)
k = 3000
while True:
    appraiser.push(u[k : k + 50], u[k : k + 50])
    k += 50
    appraiser.save(sys.argv[1])
"""


def test_clpc_save_killed_mid_write_keeps_the_previous_state(tmp_path):
    path = tmp_path / "state.json"
    script = tmp_path / "saver.py"
    script.write_text(_SAVER)
    rng = np.random.default_rng(28)
    for _ in range(5):
        proc = subprocess.Popen(
            [sys.executable, str(script), str(path)], env=_env(), stdout=subprocess.PIPE, text=True
        )
        assert proc.stdout.readline() == "saved\n"
        time.sleep(rng.uniform(0.05, 0.5))  # somewhere in the loop of saves
        proc.send_signal(signal.SIGKILL)
        proc.wait()
        proc.stdout.close()
        assert clpc.CLPC.load(str(path)).n_samples >= 3000  # whole, loads
