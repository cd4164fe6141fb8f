"""``clpc track --workers``: the report's figures drawn by the cluster's workers at once.

The same files as ``clpc track`` in one process draws one after the other, byte for byte;
a figure's error is not lost. The reference is the single-process ``clpc track``.
"""

from __future__ import annotations

from concurrent.futures import ThreadPoolExecutor

import numpy as np
import pytest
from scipy import signal

pytest.importorskip("distributed")

import clpc.workflows as wf
from clpc.distributed.track_command import track_settings
from clpc.report.drawing import Drawing


def _settings(path, out, **kw):
    record = wf.RecordSpec(str(path), ("0",), ("1",), dt=0.01)
    appraiser = wf.AppraiserSettings(window_size=120, cluster_size=10)
    return wf.TrackSettings(record, str(out), appraiser, **kw)


def test_the_workers_draw_the_figures_clpc_track_draws_byte_for_byte(client, tmp_path):
    import distributed

    rng = np.random.default_rng(3)
    u = rng.standard_normal(24_001)
    y = signal.lfilter([0.5, 0.3, 0.1], [1.0, -1.5, 0.7], u) + 0.02 * rng.standard_normal(u.size)
    np.save(tmp_path / "rec.npy", np.column_stack([u, y]))
    one = wf.track_file(_settings(tmp_path / "rec.npy", tmp_path / "one", fmt="parquet"))
    with distributed.get_task_stream(client) as stream:
        two, _ = track_settings(_settings(tmp_path / "rec.npy", tmp_path / "two"), client=client)
    ran = {str(t["key"]).split("-")[0].strip("('") for t in stream.data}
    drawn = {"plot_trace", "plot_track_quantities", "plot_fit", "plot_iodata", "plot_step",
             "plot_bode", "plot_pz"}  # fmt: skip
    assert drawn <= ran  # every figure was a task of the cluster
    names = [p.name for p in one.files if p.suffix in (".png", ".html")]
    assert [p.name for p in two.files if p.suffix in (".png", ".html")] == names
    assert len(names) == len(drawn) + 1
    for name in names:  # the same bytes (the report names the same record)
        mine = (tmp_path / "two" / name).read_bytes()
        assert mine == (tmp_path / "one" / name).read_bytes(), name


def test_a_figure_that_fails_fails_the_report_after_the_others_were_drawn(tmp_path):
    drawn = []

    def ok(path):
        drawn.append(path)

    def broken(path):
        raise OSError(f"{path}: disk full")

    with ThreadPoolExecutor(2) as pool:
        draw = Drawing(pool.submit)
        draw(ok, "a.png")
        draw(broken, "b.png")
        draw(ok, "c.png")
        with pytest.raises(OSError, match=r"b\.png: disk full"):
            draw.wait()
    assert sorted(drawn) == ["a.png", "c.png"] and draw.pending == []
    here = Drawing()  # without submit: drawn at once, here
    here(ok, "d.png")
    assert drawn[-1] == "d.png"
