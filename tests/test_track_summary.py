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


def test_the_whole_record_is_kept_in_104_bytes_per_update(long_record):
    from clpc.workflows.track import _SummaryTrace

    _, u, y = long_record
    full = clpc.CLPC(order=2, window_size=101, cluster_size=10).run(u, y)
    kept = _SummaryTrace()
    kept.add(full)
    whole = kept.trace()

    def size(t):
        per = [t.index, t.time, t.rows, t.not_enough_data, *t.arrays.values()]
        return sum(a.nbytes for a in per) / len(t)

    assert size(whole) == 104  # one output, 6 parameters: the figure in the docstring
    assert size(whole) < size(full) / 2.9
