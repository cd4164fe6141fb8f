import errno
import re

import numpy as np
import pytest

import clpc
from clpc import CLPC
from clpc.appraiser.tracefile import ThinnedTrace, TraceWriter, trace_columns
from clpc.core.atomic import OutputError
from clpc.io import read_table


def parts_and_whole():
    rng = np.random.default_rng(0)
    u = rng.standard_normal(6000)
    y = clpc.simulate_arx([1, -1.5, 0.7], [0.2, 0.5, 0.1], u) + 0.01 * rng.standard_normal(6000)
    a = CLPC(order=2, window_size=101, cluster_size=12)
    parts = [a.push(u[i : i + 700], y[i : i + 700]) for i in range(0, 6000, 700)]
    return parts, CLPC(order=2, window_size=101, cluster_size=12).run(u, y)


@pytest.mark.parametrize("ext", ["csv", "parquet"])
def test_writer_appends_exactly_the_whole_trace(tmp_path, ext):
    parts, whole = parts_and_whole()
    path = tmp_path / f"trace.{ext}"
    with TraceWriter(path) as w:
        for part in parts:
            w.write(part)
    table = read_table(path)
    names, ref = trace_columns(whole)
    assert table.names == names
    np.testing.assert_array_equal(table.data, ref)


def test_thinned_trace_is_bounded_and_evenly_strided():
    parts, whole = parts_and_whole()
    kept = ThinnedTrace(max_updates=40)
    for part in parts:
        kept.add(part)
    thin = kept.trace()
    assert kept.seen == len(whole)
    assert len(thin) <= 80 and kept.stride > 1
    np.testing.assert_array_equal(thin.index, whole.index[:: kept.stride])
    np.testing.assert_array_equal(thin.theta, whole.theta[:: kept.stride])
    with pytest.raises(ValueError, match="max_updates"):
        ThinnedTrace(0)


def test_a_failed_background_write_is_raised_by_the_next_write_and_leaves_no_file(
    tmp_path, monkeypatch
):
    pa_csv = pytest.importorskip("pyarrow.csv")
    parts, _ = parts_and_whole()
    calls = []

    def broken(table, sink, options):
        calls.append(table.num_rows)
        raise OSError(errno.ENOSPC, "No space left on device")

    monkeypatch.setattr(pa_csv, "write_csv", broken)
    target = tmp_path / "trace.csv"
    w = TraceWriter(target)
    w.write(parts[0])  # handed to the writer's thread
    message = f"cannot write '{target}': No space left on device"
    with pytest.raises(OutputError, match=re.escape(message)):
        w.write(parts[1])  # waits for the first: its error surfaces here, naming the file
    assert calls == [len(parts[0])]  # the second part was not handed over
    assert list(tmp_path.iterdir()) == []  # the partial file is gone; no trace.csv
    with pytest.raises(OutputError, match=re.escape(message)):
        w.write(parts[2])  # the writer is spent: the same error, nothing written
    w.close()  # discarded: nothing more to raise
    assert calls == [len(parts[0])] and list(tmp_path.iterdir()) == []


def test_csv_trace_header_quotes_channel_names_with_commas(tmp_path):
    # issue 28 item 7: a name with a comma or a quote stays one column for any csv reader
    import pandas as pd

    rng = np.random.default_rng(3)
    u = rng.standard_normal(600)
    y = np.column_stack([np.convolve(u, [0, 0.5])[:600], np.convolve(u, [0, 0.3])[:600]])
    data = clpc.IOData(u, y, dt=0.01, input_names=["in,put"], output_names=["out,1", 'out"2'])
    trace = clpc.CLPC(order=1, window_size=101, cluster_size=10).run(data)
    path = tmp_path / "trace.csv"
    with TraceWriter(path) as writer:
        writer.write(trace)
    frame = pd.read_csv(path)
    names, _ = trace_columns(trace)
    assert list(frame.columns) == names and "out,1:a0" in names and 'out"2:a0' in names
    np.testing.assert_array_equal(frame["out,1:a0"].to_numpy(), trace.theta[:, 0, 0])
