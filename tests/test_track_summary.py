"""``clpc track`` summarises the whole record, never the thinned copy kept for figures."""

from __future__ import annotations

import numpy as np
import pytest
from scipy import signal

import clpc
import clpc.workflows as wf
from clpc.io import read_table, write_table
from clpc.report import steady_state


@pytest.fixture(scope="module")
def long_record(tmp_path_factory):
    rng = np.random.default_rng(11)
    n = 6000
    u = rng.standard_normal(n)
    y = signal.lfilter([0.0, 1.0, 0.3], [1.0, -1.5, 0.7], u) + 0.02 * rng.standard_normal(n)
    path = tmp_path_factory.mktemp("long") / "rec.csv"
    write_table(path, ["u", "y"], np.column_stack([u, y]))
    return str(path), u, y


def test_summary_counts_convergence_and_model_come_from_the_full_trace(long_record, tmp_path):
    pytest.importorskip("matplotlib")
    path, u, y = long_record
    appraiser = wf.AppraiserSettings(order=2, window_size=101, cluster_size=10, nk=1)
    settings = wf.TrackSettings(
        wf.RecordSpec(path, ("u",), ("y",)),
        str(tmp_path),
        appraiser,
        chunk_rows=700,
        figure_updates=40,  # the copy for figures is thinned (stride >= 8)
        save=str(tmp_path / "ss.json"),
    )
    result = wf.track_file(settings)
    full = clpc.CLPC(order=2, window_size=101, cluster_size=10, nk=1).run(u, y)
    assert len(full) > 8 * 40  # long enough to be thinned
    table = read_table(tmp_path / "trace.csv")
    assert table.n_rows == len(full)
    s = result.summary
    assert s["updates"] == len(full)
    assert s["accepted"] == int(full.accepted.sum())
    assert s["determined"] == int(full.determined.sum())
    assert s["not_enough_data"] == int(full.not_enough_data.sum())
    conv = full.convergence()
    assert s["convergence"]["converged"] == conv.converged
    assert conv.converged
    assert s["convergence"]["update"] == conv.update
    assert s["convergence"]["index"] == conv.index
    ref_model, ref_source = steady_state(full)
    assert result.model_source == ref_source
    np.testing.assert_allclose(result.model.theta, ref_model.theta, rtol=1e-12)
    saved = clpc.io.load_model(tmp_path / "ss.json")
    np.testing.assert_allclose(saved.theta, ref_model.theta, rtol=1e-12)
    # the report's model section shows the same model
    html = (tmp_path / "report.html").read_text()
    assert f'<td class="num">{len(full)}</td>' in html


def test_the_summary_memory_does_not_grow_with_the_record(long_record, tmp_path):
    # issue 28 item 2: the summary kept every update (104 bytes each); now the parts are
    # scanned once and only the rows after convergence are kept, in a scratch file
    import tracemalloc

    from clpc.appraiser.scanned import ScannedTrace

    _, u, y = long_record
    part = clpc.CLPC(order=2, window_size=101, cluster_size=10).run(u, y)

    def peak(n_parts: int) -> int:
        scanned = ScannedTrace(tmp_path)
        tracemalloc.start()
        for _ in range(n_parts):
            scanned.add(part)
        scanned.convergence()
        top = tracemalloc.get_traced_memory()[1]
        tracemalloc.stop()
        assert len(scanned) == n_parts * len(part)
        scanned.close()
        return top

    # both past one block of the second pass (BLOCK_ROWS rows after convergence)
    small, large = peak(40), peak(200)
    # 160 more parts of 595 updates: 9.9 MB if every update were kept at 104 bytes
    assert large < small + 200_000, (small, large)
