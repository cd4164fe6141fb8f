"""Figures drawn by forked processes (clpc.report.painter): the same files as drawn here,
failures redrawn here with their own error, nothing left running."""

from __future__ import annotations

import os
import sys
from pathlib import Path

import numpy as np
import pytest

from clpc.lpc import ARX
from clpc.plotting import plot_step, plot_trace
from clpc.report.painter import FigureJob, Painter, _share

pytestmark = pytest.mark.skipif(not hasattr(os, "fork"), reason="the painter forks (POSIX)")

PARENT = os.getpid()


def _write(path: Path, text: str) -> None:
    Path(path).write_text(text)


def _fail_when_forked(path: Path) -> None:
    if os.getpid() != PARENT:
        raise RuntimeError("only in the forked process")
    Path(path).write_text("drawn here")


def _always_fail(path: Path) -> None:
    raise ValueError(f"cannot draw {Path(path).name}")


def _model_and_trace():
    from clpc.appraiser import CLPC

    rng = np.random.default_rng(4)
    u = rng.standard_normal(1500)
    y = np.convolve(u, [0.0, 0.5, 0.25])[:1500] + 0.01 * rng.standard_normal(1500)
    model = ARX(order=2, nk=1, uncertainty=False, assess=False).fit(u, y)
    return model, CLPC(order=2, window_size=101, cluster_size=10).run(u, y)


def test_forked_figures_are_the_files_drawn_here(tmp_path):
    model, trace = _model_and_trace()

    def jobs(folder: Path) -> list[FigureJob]:
        return [
            FigureJob(plot_step, (model, folder / "step.png"), cost=0.5),
            FigureJob(plot_trace, (trace, folder / "trace.png"), {"title": "t"}, cost=2.0),
            FigureJob(_write, (folder / "note.txt", "x"), cost=0.1),
        ]

    here, there = tmp_path / "here", tmp_path / "there"
    with Painter(enabled=False) as painter:
        painter.draw(jobs(here))
        assert not painter.forked
    with Painter(enabled=True) as painter:
        painter.start()
        assert painter.forked
        painter.submit(jobs(there))
        painter.wait()
    for name in ("step.png", "trace.png", "note.txt"):
        assert (here / name).read_bytes() == (there / name).read_bytes(), name


def test_a_figure_failing_there_is_drawn_here_and_a_real_error_is_raised(tmp_path):
    with Painter(enabled=True) as painter:
        painter.start()
        painter.draw([FigureJob(_fail_when_forked, (tmp_path / "a.txt",))])
        assert (tmp_path / "a.txt").read_text() == "drawn here"
        with pytest.raises(ValueError, match=r"cannot draw b\.txt"):
            painter.draw(
                [
                    FigureJob(_write, (tmp_path / "ok.txt", "ok")),
                    FigureJob(_always_fail, (tmp_path / "b.txt",)),
                ]
            )
    assert (tmp_path / "ok.txt").read_text() == "ok"


def test_an_unpicklable_job_is_drawn_here(tmp_path):
    target = tmp_path / "lambda.txt"
    with Painter(enabled=True) as painter:
        painter.start()
        painter.draw([FigureJob(lambda p: Path(p).write_text("here"), (target,))])
        assert not painter.forked  # the process was ended when the job could not be sent
    assert target.read_text() == "here"


def test_the_forked_process_ends_with_the_painter_even_on_an_error():
    with pytest.raises(KeyError), Painter(enabled=True) as painter:
        painter.start()
        pid = painter._pid
        raise KeyError("the caller failed")
    with pytest.raises(ChildProcessError):  # reaped: no zombie, no orphan left
        os.waitpid(pid, os.WNOHANG)


def test_off_by_environment_or_argument_and_by_default_off_linux(monkeypatch):
    monkeypatch.setenv("CLPC_PAINTER", "0")
    assert not Painter().enabled
    monkeypatch.setenv("CLPC_PAINTER", "1")
    assert Painter().enabled
    monkeypatch.delenv("CLPC_PAINTER")
    assert Painter().enabled == sys.platform.startswith("linux")
    monkeypatch.setattr(sys, "platform", "darwin")
    assert not Painter().enabled
    assert not Painter(enabled=False).enabled


def test_jobs_are_shared_largest_first_to_the_lighter_process():
    jobs = [FigureJob(_write, ("x", ""), cost=c) for c in (1.0, 0.8, 0.5, 1.5, 0.5, 2.0)]
    first, second = _share(jobs)
    assert sorted(first + second) == list(range(6))
    loads = [sum(jobs[i].cost for i in g) for g in (first, second)]
    assert abs(loads[0] - loads[1]) <= 0.5  # 3.3 and 3.0 here
    assert first[0] == 5  # the largest starts first


def test_clpc_track_writes_the_same_files_with_and_without_the_painter(tmp_path):
    import subprocess
    import sys

    rng = np.random.default_rng(8)
    u = rng.standard_normal(30000)
    y = np.convolve(u, [0.0, 0.5, 0.25])[:30000] + 0.01 * rng.standard_normal(30000)
    record = tmp_path / "rec.csv"
    np.savetxt(record, np.column_stack([u, y]), delimiter=",", header="u,y", comments="")
    outs = {}
    for flag in ("1", "0"):
        out = tmp_path / f"painter{flag}"
        subprocess.run(
            [sys.executable, "-m", "clpc", "track", str(record), "-u", "u", "-y", "y", "--out",
             str(out), "--chunk-rows", "5000"],
            check=True, capture_output=True, env=dict(os.environ, CLPC_PAINTER=flag),
        )  # fmt: skip
        outs[flag] = {p.name: p.read_bytes() for p in sorted(out.iterdir())}
    assert set(outs["1"]) == {"trace.csv", "report.html", "trace.png", "fit.png", "data.png",
                              "step.png", "bode.png", "pz.png"}  # fmt: skip
    for name, content in outs["0"].items():
        assert outs["1"][name] == content, name


def test_a_failed_fork_draws_everything_here(tmp_path, monkeypatch):
    import clpc.report.painter as painter_module

    def no_fork() -> int:
        raise OSError("Resource temporarily unavailable")

    monkeypatch.setattr(painter_module, "_fork", no_fork)
    with Painter(enabled=True) as painter:
        painter.start()
        assert not painter.forked and not painter.enabled
        painter.draw([FigureJob(_write, (tmp_path / "here.txt", "x"))])
    assert (tmp_path / "here.txt").read_text() == "x"
