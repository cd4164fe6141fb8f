"""Data in: a jittery time column, time units, resampling on request, metadata and units
rows, the pyarrow reader (exact values, messages naming the line, the column and the text),
and trace files with integers as integers."""

from __future__ import annotations

import json

import numpy as np
import pytest
from click.testing import CliRunner

import clpc
from clpc.appraiser.tracefile import TraceWriter, trace_columns
from clpc.cli import cli
from clpc.data import DataError
from clpc.data.time_units import time_unit
from clpc.data.timebase import check_time_base, measure_time_base, resample_to_grid
from clpc.io import iter_table_chunks, load_iodata, read_table, write_table

DT = 1e-3


def _jittery_time(n: int, rel: float, seed: int = 0) -> np.ndarray:
    rng = np.random.default_rng(seed)
    return np.arange(n) * DT + rng.uniform(-rel, rel, n) * DT / 2


def _write(path, header, rows):
    path.write_text(header + "".join(",".join(map(repr, r)) + "\n" for r in rows))


def test_real_jitter_is_accepted_and_measured(tmp_path):
    t = _jittery_time(5000, 4e-5)
    base = check_time_base(t, "t")
    assert abs(base.dt - DT) < 1e-9
    steps = np.diff(t)
    assert base.jitter == pytest.approx(np.max(np.abs(steps - np.median(steps))) / np.median(steps))
    assert 1e-5 < base.jitter < 1e-4
    u = np.sin(np.arange(5000) / 30.0)
    path = tmp_path / "log.csv"
    write_table(path, ["t", "u", "y"], np.column_stack([t, u, u]))
    assert load_iodata(path, "u", "y", time_column="t").dt == pytest.approx(DT, rel=1e-6)
    # the former default (1e-6) refuses it, and says what it measured
    with pytest.raises(DataError, match=r"largest step deviation \d\.\de-05 relative"):
        load_iodata(path, "u", "y", time_column="t", time_rtol=1e-6)


def test_irregular_time_is_refused(tmp_path):
    t = np.arange(100) * DT
    t[40:] += 0.5 * DT  # one step of 1.5 sample times: neither jitter nor dropped samples
    with pytest.raises(DataError, match=r"line 41 to line 42 .* time_rtol=0.01"):
        path = tmp_path / "gap.csv"
        write_table(path, ["t", "u", "y"], np.column_stack([t, t, t]))
        load_iodata(path, "u", "y", time_column="t")
    dropped = np.delete(np.arange(100) * DT, 40)  # one step doubled: a dropped sample, used
    base = measure_time_base(dropped)
    assert base.gaps == ((40, 1),) and base.dt == DT and base.drift < 1e-9
    drifting = np.cumsum(np.full(400, DT) * (1 + 0.008 * np.sign(np.arange(400) - 200)))
    base = measure_time_base(drifting)  # each step within 1 %, but the clock walks away
    assert base.jitter < 1e-2 and base.drift > 0.5
    with pytest.raises(DataError, match="drift"):
        check_time_base(drifting, "t")


def test_time_units_from_the_name_or_the_option(tmp_path):
    assert [time_unit(None, n) for n in ("t", "t_ms", "time[ms]", "stamp_us", "sec")] == [
        "s",
        "ms",
        "ms",
        "us",
        "s",
    ]
    t_ms = np.arange(300) * 10.0  # a 10 ms log in milliseconds
    u = np.cos(np.arange(300) / 7.0)
    path = tmp_path / "ms.csv"
    write_table(path, ["t_ms", "u", "y"], np.column_stack([t_ms, u, u]))
    assert load_iodata(path, "u", "y", time_column="t_ms").dt == pytest.approx(0.01)
    assert load_iodata(path, "u", "y", time_column="t_ms", time_unit="s").dt == 10.0
    plain = tmp_path / "plain.csv"
    write_table(plain, ["t", "u", "y"], np.column_stack([t_ms, u, u]))
    assert load_iodata(plain, "u", "y", time_column="t", time_unit="ms").dt == pytest.approx(0.01)
    with pytest.raises(DataError, match="time unit"):
        load_iodata(plain, "u", "y", time_column="t", time_unit="min")


def test_resample_on_request(tmp_path):
    rng = np.random.default_rng(1)
    t = np.arange(400) * DT + rng.uniform(-0.2, 0.2, 400) * DT  # 20 % jitter: refused
    x = np.column_stack([np.sin(40 * t), np.cos(25 * t)])
    path = tmp_path / "j.csv"
    write_table(path, ["t", "u", "y"], np.column_stack([t, x]))
    with pytest.raises(DataError, match="resample=True, --resample"):
        load_iodata(path, "u", "y", time_column="t")
    data = load_iodata(path, "u", "y", time_column="t", resample=True)
    step = (t[-1] - t[0]) / 399
    assert data.dt == pytest.approx(step, rel=1e-9)
    grid = t[0] + np.arange(data.n_samples) * data.dt
    np.testing.assert_allclose(data.u[:, 0], np.interp(grid, t, x[:, 0]), rtol=1e-12)
    np.testing.assert_allclose(data.y[:, 0], np.interp(grid, t, x[:, 1]), rtol=1e-12)
    assert resample_to_grid(t, x, 2 * DT)[1].shape[0] == int((t[-1] - t[0]) / (2 * DT)) + 1
    with pytest.raises(DataError, match="resample needs a time column"):
        load_iodata(path, "u", "y", resample=True)


def test_metadata_line_and_units_row(tmp_path):
    path = tmp_path / "units.csv"
    rows = [[0.01 * k, float(k % 3), float(k % 5), 0.5] for k in range(50)]
    _write(path, "logger v2.1 exported 2026-11-24\nt,x_ref,x,V\ns,m,m,V\n", rows)
    table = read_table(path, skip_rows=1)
    assert table.names == ["t", "x_ref", "x", "V"]
    np.testing.assert_array_equal(table.data, np.array(rows))
    assert table.row_label(0) == "line 4"
    with pytest.raises(DataError):
        read_table(path)  # the metadata line is not skipped by itself
    res = CliRunner().invoke(
        cli,
        [
            "identify",
            str(path),
            "-u",
            "x_ref",
            "-y",
            "x",
            "--time",
            "t",
            "--skip-rows",
            "1",
            "--order",
            "1",
            "--json",
        ],
    )
    assert res.exit_code == 0, res.output
    summary = json.loads(res.stdout)
    assert summary["n_samples"] == 50
    assert summary["dt"] == pytest.approx(0.01)


def _messy(tmp_path):
    rng = np.random.default_rng(2)
    values = rng.standard_normal((3000, 3)) * 10.0 ** rng.integers(-12, 12, (3000, 3))
    path = tmp_path / "v.csv"
    write_table(path, ["a", "b", "c"], values)
    return path, values


def test_the_reader_gives_the_written_values(tmp_path):
    path, values = _messy(tmp_path)
    np.testing.assert_array_equal(read_table(path).data, values)
    sel = read_table(path, columns=["c", "a"])
    np.testing.assert_array_equal(sel.data, values[:, [2, 0]])
    chunks = [v for _, v in iter_table_chunks(path, 700, columns=["b"])]
    assert [c.shape[0] for c in chunks] == [700, 700, 700, 700, 200]
    np.testing.assert_array_equal(np.concatenate(chunks)[:, 0], values[:, 1])


@pytest.mark.parametrize(
    ("line", "pattern"),
    [
        ("1.0,x,3.0", r"line 7, column 'b': 'x' is not a number"),
        ("1.0,,3.0", r"line 7, column 'b'"),
        ("1.0,2.0", r"line 7 has 2 field\(s\)"),
        ("1.0,nan,3.0", r"line 7, column 'b': 'nan'"),
    ],
)
def test_bad_cells_are_named_by_line_and_column(tmp_path, line, pattern):
    path = tmp_path / "bad.csv"
    good = "".join(f"{k}.0,{k}.5,{k}.25\n" for k in range(5))
    path.write_text("a,b,c\n" + good + line + "\n" + good)
    with pytest.raises(DataError, match=pattern):
        read_table(path)
    with pytest.raises(DataError, match=pattern):
        list(iter_table_chunks(path, 3))


#: cells pyarrow parses differently from clpc's one number syntax, and ordinary ones
SYNTAX_CELLS = [
    "1_000",
    "\u0661\u0662",
    "\uff11\uff12",
    "0x10",
    "1d5",
    "1.5f",
    "nan(1)",
    "1e400",
    "1e-400",
    "-inf",
    "Infinity",
    "nan",
    "+1.5",
    ".5",
    "5.",
    " 2.5",
    "0.1e+3",
    "00012",
    "",
]


@pytest.mark.parametrize("allow_missing", [False, True])
@pytest.mark.parametrize("cell", SYNTAX_CELLS)
def test_the_reader_applies_the_one_number_syntax(tmp_path, cell, allow_missing):
    """The text reader agrees with :func:`clpc.io.errors.parse_number` on every cell."""
    from clpc.io.errors import parse_number

    path = tmp_path / "s.csv"
    path.write_text("a,b\n1,2\n3,4\n5," + cell + "\n7,8\n", encoding="utf-8")
    try:
        value = parse_number(cell) if cell else np.nan  # an empty cell is a missing sample
    except ValueError:
        value = None
    refused = value is None or (not allow_missing and not np.isfinite(value))
    if refused:
        with pytest.raises(DataError, match=r"line 4, column 'b'"):
            read_table(path, allow_missing=allow_missing)
    else:
        got = read_table(path, allow_missing=allow_missing).data
        np.testing.assert_array_equal(got, [[1, 2], [3, 4], [5, value], [7, 8]])


def test_comments_and_blank_lines_keep_the_line_numbers(tmp_path):
    path = tmp_path / "c.csv"
    path.write_text("# a comment\na,b\n1,2\n\n3,4 # note\n# more\n5,6\n")
    table = read_table(path)
    np.testing.assert_array_equal(table.data, [[1, 2], [3, 4], [5, 6]])
    assert [table.row_label(i) for i in range(3)] == ["line 3", "line 5", "line 7"]


@pytest.mark.parametrize("fast_io", ["1", "0"])
def test_trace_csv_has_integers_as_integers(tmp_path, monkeypatch, fast_io):
    monkeypatch.setenv("CLPC_FAST_IO", fast_io)
    rng = np.random.default_rng(0)
    u = rng.standard_normal(3000)
    y = clpc.simulate_arx([1, -1.5, 0.7], [0.2, 0.5, 0.1], u) + 0.01 * rng.standard_normal(3000)
    trace = clpc.CLPC(order=2, window_size=101, cluster_size=12).run(u, y)
    path = tmp_path / "trace.csv"
    with TraceWriter(path) as writer:
        writer.write(trace)
    lines = path.read_text().splitlines()
    names = lines[0].split(",")
    first = dict(zip(names, lines[1].split(","), strict=True))
    for key in ("index", "rows", "not_enough_data", "accepted", "n_null", "determined"):
        assert "." not in first[key] and "e" not in first[key], (key, first[key])
    table = read_table(path)
    ref_names, ref = trace_columns(trace)
    assert table.names == ref_names
    np.testing.assert_array_equal(table.data, ref)


@pytest.mark.parametrize("text", ["a,b\n1,2\n\n3,4\n5,6\n", "a,b\n1,2\n3,4\n5,6\n\n\n"])
def test_blank_lines_keep_the_line_numbers(tmp_path, text):
    path = tmp_path / "blank.csv"
    path.write_text(text)
    table = read_table(path)
    np.testing.assert_array_equal(table.data, [[1, 2], [3, 4], [5, 6]])
    labels = [table.row_label(i) for i in range(3)]
    assert labels == (
        ["line 2", "line 4", "line 5"] if "\n\n3" in text else ["line 2", "line 3", "line 4"]
    )
