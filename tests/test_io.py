"""Data files: text/Parquet/npy/npz readers, chunked reading, load_iodata, errors."""

from __future__ import annotations

import gzip
import tempfile
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from clpc.data import DataError, IOData
from clpc.io import (
    DataFileNotFoundError,
    Table,
    iter_table_chunks,
    load_iodata,
    read_table,
    write_table,
)

VALUES = np.array([[0.0, 1.5, -2.0], [0.1, 2.5, 3.25], [0.2, -1e-3, 4e5]])


def write(path: Path, text: str, newline: str = "\n") -> Path:
    path.write_bytes(text.replace("\n", newline).encode("utf-8"))
    return path


def chunks_concat(path: Path, chunk_rows: int, **kw) -> np.ndarray:
    parts = [c for _, c in iter_table_chunks(path, chunk_rows, **kw)]
    return np.concatenate(parts)


# ------------------------------------------------------------------ text dialects
@pytest.mark.parametrize(
    ("text", "names"),
    [
        ("t,u,y\n0,1.5,-2\n0.1,2.5,3.25\n0.2,-1e-3,4e5\n", ["t", "u", "y"]),
        ("t;u;y\n0;1.5;-2\n0.1;2.5;3.25\n0.2;-1e-3;4e5\n", ["t", "u", "y"]),
        ("t\tu\ty\n0\t1.5\t-2\n0.1\t2.5\t3.25\n0.2\t-1e-3\t4e5\n", ["t", "u", "y"]),
        ("t|u|y\n0|1.5|-2\n0.1|2.5|3.25\n0.2|-1e-3|4e5\n", ["t", "u", "y"]),
        ("t  u   y\n0 1.5  -2\n 0.1\t2.5 3.25\n0.2 -1e-3 4e5\n", ["t", "u", "y"]),
        ('"time [s]","u, V",y\n0,1.5,-2\n0.1,2.5,3.25\n0.2,-1e-3,4e5\n', ["time [s]", "u, V", "y"]),
        ('"time [s]" "u 1" y\n0 1.5 -2\n0.1 2.5 3.25\n0.2 -1e-3 4e5\n', ["time [s]", "u 1", "y"]),
        ("0,1.5,-2\n0.1,2.5,3.25\n0.2,-1e-3,4e5\n", ["col0", "col1", "col2"]),
        ("0 1.5 -2\n0.1 2.5 3.25\n0.2 -1e-3 4e5\n", ["col0", "col1", "col2"]),
        ("# t,u,y\n0,1.5,-2\n0.1,2.5,3.25\n0.2,-1e-3,4e5\n", ["t", "u", "y"]),  # savetxt
        ("# recorded 2024\n\nt, u, y\n0, 1.5, -2\n0.1, 2.5, 3.25\n\n0.2, -1e-3, 4e5\n\n", None),
        ('t,u,y\n"0","1.5","-2"\n0.1,2.5,3.25\n0.2,-1e-3,4e5 # last\n', ["t", "u", "y"]),
    ],
)
@pytest.mark.parametrize("newline", ["\n", "\r\n", "\r"])
def test_text_dialects(tmp_path, text, names, newline):
    path = write(tmp_path / "rec.csv", text, newline)
    table = read_table(path)
    assert table.names == (names or ["t", "u", "y"])
    np.testing.assert_array_equal(table.data, VALUES)
    assert table.data.dtype == np.float64
    for k in (1, 2, 5):
        np.testing.assert_array_equal(chunks_concat(path, k), VALUES)


def test_trailing_empty_lines_bom_and_gzip(tmp_path):
    body = "u,y\n1,2\n3,4\n\n\n"
    bom = tmp_path / "bom.csv"
    bom.write_bytes(b"\xef\xbb\xbf" + body.encode())
    assert read_table(bom).names == ["u", "y"]
    gz = tmp_path / "rec.csv.gz"
    with gzip.open(gz, "wt") as f:
        f.write(body)
    np.testing.assert_array_equal(read_table(gz).data, [[1, 2], [3, 4]])


def test_header_forced_and_explicit_delimiter(tmp_path):
    path = write(tmp_path / "nums.csv", "1,2\n3,4\n")
    assert read_table(path, header=True).names == ["1", "2"]
    assert read_table(path, header=True).data.tolist() == [[3, 4]]
    path = write(tmp_path / "semi.txt", "a;b\n1,5;2\n")  # forced ',': a ragged header
    assert read_table(path, delimiter=";", columns=["b"]).data.tolist() == [[2.0]]
    path = write(tmp_path / "one.csv", "time [s]\n0\n1\n")
    assert read_table(path).names == ["time [s]"]
    with pytest.raises(DataError, match="delimiter must be one character"):
        read_table(path, delimiter="::")


def test_column_selection_order_index_and_text_columns(tmp_path):
    path = write(tmp_path / "mixed.csv", "note,u,y\nstart,1,2\nmid,3,4\nend,5,6\n")
    table = read_table(path, columns=["y", 1])
    assert table.names == ["y", "u"]
    np.testing.assert_array_equal(table.data, [[2, 1], [4, 3], [6, 5]])
    np.testing.assert_array_equal(table["u"], [1, 3, 5])
    assert read_table(path, columns="y").names == ["y"]
    assert read_table(path, columns=[-1]).names == ["y"]
    with pytest.raises(DataError, match=r"line 2, column 'note': 'start' is not a number"):
        read_table(path)


def test_ragged_row_behind_text_column_is_caught(tmp_path):
    # an unquoted comma in the text column shifts the numbers: must not pass silently
    path = write(tmp_path / "shift.csv", "note,u,y\na,1,2\nb,c,3,4\n")
    with pytest.raises(DataError, match=r"line 3 has 4 field\(s\) but the header \(line 1\)"):
        read_table(path, columns=["u", "y"])


def test_allow_missing_keeps_nan(tmp_path):
    path = write(tmp_path / "gaps.csv", "u,y\n1,\n2,nan\n3,4\n")
    data = read_table(path, allow_missing=True).data
    assert np.isnan(data[:2, 1]).all() and data[2, 1] == 4


# ---------------------------------------------------------------- chunked reading
@pytest.fixture(scope="module")
def big_files(tmp_path_factory):
    base = tmp_path_factory.mktemp("big")
    gen = np.random.default_rng(7)
    arr = gen.standard_normal((1234, 3)) * np.array([1.0, 1e-8, 1e6])
    paths = {}
    for ext in ("csv", "tsv", "npy", "npz", "parquet"):
        paths[ext] = base / f"big.{ext}"
        write_table(paths[ext], ["a", "b", "c"], arr)
    return arr, paths


@settings(max_examples=25, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(chunk=st.integers(1, 1500), fmt=st.sampled_from(["csv", "tsv", "npy", "npz", "parquet"]))
def test_chunked_equals_whole_any_chunk_size(big_files, chunk, fmt):
    arr, paths = big_files
    whole = read_table(paths[fmt]).data
    np.testing.assert_array_equal(whole, arr)
    sizes = []
    parts = []
    for names, part in iter_table_chunks(paths[fmt], chunk):
        assert names == (["col0", "col1", "col2"] if fmt == "npy" else ["a", "b", "c"])
        sizes.append(part.shape[0])
        parts.append(part)
    assert max(sizes) <= chunk
    assert sizes[:-1] == [chunk] * (len(sizes) - 1)
    np.testing.assert_array_equal(np.concatenate(parts), whole)
    sub = np.concatenate([p for _, p in iter_table_chunks(paths[fmt], chunk, columns=[2, 0])])
    np.testing.assert_array_equal(sub, arr[:, [2, 0]])


@settings(max_examples=40, deadline=None)
@given(
    rows=st.lists(
        st.tuples(
            st.floats(allow_nan=False, allow_infinity=False, width=64),
            st.integers(-(10**6), 10**6),
        ),
        min_size=1,
        max_size=40,
    ),
    junk=st.lists(st.sampled_from(["", "   ", "# note"]), max_size=40),
    where=st.lists(st.integers(0, 40), max_size=40),
    chunk=st.integers(1, 50),
)
def test_chunked_text_with_blank_and_comment_lines(rows, junk, where, chunk):
    lines = [f"{a!r},{b}" for a, b in rows]
    for text, pos in zip(junk, where, strict=False):
        lines.insert(min(pos, len(lines)), text)
    expected = np.array(rows, dtype=np.float64)
    with tempfile.TemporaryDirectory() as tmp:
        path = write(Path(tmp) / "r.csv", "x,n\n" + "\n".join(lines) + "\n")
        np.testing.assert_array_equal(read_table(path).data, expected)
        np.testing.assert_array_equal(chunks_concat(path, chunk), expected)
        np.testing.assert_array_equal(chunks_concat(path, chunk, columns=["n"]), expected[:, 1:])


def test_error_line_numbers_are_file_lines_in_any_chunk(tmp_path):
    lines = ["u,y"] + [f"{k},{k}" for k in range(50)]
    lines[30] = "29,oops"  # file line 31
    lines.insert(10, "")  # a blank line before it: now file line 32
    lines.insert(5, "# comment")  # now file line 33
    path = write(tmp_path / "late.csv", "\n".join(lines) + "\n")
    for chunk in (1, 7, 100):
        with pytest.raises(DataError, match=r"line 33, column 'y': 'oops' is not a number"):
            chunks_concat(path, chunk)
    lines[32] = "29,nan"
    path = write(tmp_path / "late.csv", "\n".join(lines) + "\n")
    for chunk in (1, 7, 100):
        with pytest.raises(DataError, match=r"line 33, column 'y': 'nan' is not a finite"):
            chunks_concat(path, chunk)


def test_chunk_rows_validated(tmp_path):
    path = write(tmp_path / "a.csv", "u\n1\n")
    with pytest.raises(DataError, match="chunk_rows"):
        iter_table_chunks(path, 0)


# ------------------------------------------------------------------- round trips
@pytest.mark.parametrize("ext", ["csv", "tsv", "txt", "csv.gz", "parquet", "npz"])
def test_write_table_round_trip_exact(tmp_path, ext):
    gen = np.random.default_rng(3)
    arr = gen.standard_normal((200, 3)) * np.array([1e-300, 1.0, 1e300])
    arr[0] = [0.1, -0.0, 5e-324]
    names = ["time [s]", 'u "cmd"', "y,pos"]
    path = tmp_path / f"rt.{ext}"
    write_table(path, names, arr)
    table = read_table(path)
    assert table.names == names
    np.testing.assert_array_equal(table.data, arr)


def test_npy_round_trip_and_shapes(tmp_path):
    arr = np.arange(12.0).reshape(6, 2)
    write_table(tmp_path / "a.npy", ["u", "y"], arr)
    table = read_table(tmp_path / "a.npy")
    assert table.names == ["col0", "col1"]
    np.testing.assert_array_equal(table.data, arr)
    np.save(tmp_path / "one.npy", np.arange(5, dtype=np.int32))
    np.testing.assert_array_equal(read_table(tmp_path / "one.npy").data[:, 0], np.arange(5))
    rec = np.zeros(4, dtype=[("u", "f8"), ("y", "i4")])
    rec["y"] = [1, 2, 3, 4]
    np.save(tmp_path / "rec.npy", rec)
    assert read_table(tmp_path / "rec.npy", columns=["y"]).data[:, 0].tolist() == [1, 2, 3, 4]
    np.save(tmp_path / "cube.npy", np.zeros((2, 2, 2)))
    with pytest.raises(DataError, match="3-D array"):
        read_table(tmp_path / "cube.npy")


def test_npz_layouts(tmp_path):
    np.savez(tmp_path / "cols.npz", t=np.arange(3.0), u=np.ones(3), dt=np.float64(0.1))
    assert read_table(tmp_path / "cols.npz").names == ["t", "u"]
    np.savez(tmp_path / "tab.npz", data=np.eye(3), columns=np.array(["a", "b", "c"]))
    table = read_table(tmp_path / "tab.npz")
    assert table.names == ["a", "b", "c"]
    np.testing.assert_array_equal(table.data, np.eye(3))
    np.savez(tmp_path / "bad.npz", u=np.ones(3), y=np.ones(4))
    with pytest.raises(DataError, match="differ in length: 'y' has 4 rows but 'u' has 3"):
        read_table(tmp_path / "bad.npz")


def test_parquet_types_nulls_and_chunks(tmp_path):
    pa = pytest.importorskip("pyarrow")
    pq = pytest.importorskip("pyarrow.parquet")
    stamps = np.datetime64("2024-01-01T00:00:00", "ns") + np.arange(4) * np.timedelta64(10, "ms")
    table = pa.table(
        {
            "t": pa.array(stamps),
            "u": pa.array([1, 2, 3, 4], pa.int16()),
            "flag": pa.array([True, False, True, True]),
            "s": pa.array(["1.5", "2", "x", "4"]),
            "gap": pa.array([1.0, None, 3.0, 4.0]),
        }
    )
    path = tmp_path / "typed.parquet"
    pq.write_table(table, path, row_group_size=2)
    got = read_table(path, columns=["t", "u", "flag"])
    np.testing.assert_allclose(got.data[:, 0], [0.0, 0.01, 0.02, 0.03], rtol=0, atol=1e-15)
    np.testing.assert_array_equal(got.data[:, 1:], [[1, 1], [2, 0], [3, 1], [4, 1]])
    with pytest.raises(DataError, match=r"row 3, column 's': 'x' is not a number"):
        read_table(path, columns=["s"])
    with pytest.raises(DataError, match=r"row 2, column 'gap': empty cell"):
        read_table(path, columns=["gap"])
    data = load_iodata(path, "u", "flag", time_column="t")
    assert data.dt == 0.01
    chunks = [v for _, v in iter_table_chunks(path, 3, columns=["u", "flag"])]
    assert [c.shape[0] for c in chunks] == [3, 1]
    np.testing.assert_array_equal(np.concatenate(chunks), got.data[:, 1:])


# ------------------------------------------------------------------------ errors
@pytest.mark.parametrize(
    ("name", "text", "match"),
    [
        (
            "nonnum.csv",
            "u,y\n1,2\n3,abc\n",
            r"nonnum\.csv' line 3, column 'y': 'abc' is not a number",
        ),
        ("empty_cell.csv", "u,y\n1,2\n,4\n", r"line 3, column 'u': empty cell"),
        ("nan.csv", "u,y\n1,2\n3,NaN\n", r"line 3, column 'y': 'NaN' is not a finite number"),
        ("inf.csv", "u y\n1 2\n3 -inf\n", r"line 3, column 'y': '-inf' is not a finite number"),
        ("ragged.csv", "u,y\n1,2\n3,4,5\n6,7\n", r"line 3 has 3 field\(s\) but the header"),
        ("short.csv", "1,2\n3\n", r"line 2 has 1 field\(s\) but the first data row \(line 1\)"),
        ("empty.csv", "", r"empty\.csv' is empty"),
        ("blank.csv", "\n\n# only a comment\n", r"is empty \(only comment lines\)"),
        ("head.csv", "u,y\n\n", r"head\.csv' has a header but no data rows"),
        ("comma.csv", "u;y\n1,5;2\n", r"Decimal commas are not supported"),
    ],
)
def test_text_errors(tmp_path, name, text, match):
    path = write(tmp_path / name, text)
    with pytest.raises(DataError, match=match):
        read_table(path)
    with pytest.raises(DataError, match=match):
        chunks_concat(path, 1)


def test_error_messages_are_one_line(tmp_path):
    path = write(tmp_path / "a.csv", "u,y\n1,2\n3,x\n")
    with pytest.raises(DataError) as info:
        read_table(path)
    assert "\n" not in str(info.value)


def test_missing_file_names_the_path(tmp_path):
    missing = tmp_path / "nope.csv"
    with pytest.raises(DataFileNotFoundError, match=r"data file '.*nope\.csv' does not exist"):
        read_table(missing)
    with pytest.raises(FileNotFoundError):
        load_iodata(missing, "u", "y")
    with pytest.raises(DataError):
        iter_table_chunks(missing)
    with pytest.raises(DataError, match="is a directory"):
        read_table(tmp_path)


def test_unsupported_extension(tmp_path):
    for name, match in [("a.xlsx", r"'\.xlsx' .* Export the sheet as CSV"), ("a.json", "'.json'")]:
        path = write(tmp_path / name, "u,y\n1,2\n")
        with pytest.raises(DataError, match=rf"unsupported data file extension {match}"):
            read_table(path)
    with pytest.raises(DataError, match="unsupported"):
        write_table(tmp_path / "b.xlsx", ["u"], [1.0])


def test_unknown_ambiguous_and_out_of_range_columns(tmp_path):
    path = write(tmp_path / "a.csv", "time,u,y,y\n0,1,2,3\n")
    with pytest.raises(
        DataError,
        match=r"unknown column 'Y' in '.*a\.csv'; available columns: \['time', 'u', 'y', 'y'\]"
        r" \(did you mean 'y'\?\)",
    ):
        read_table(path, columns=["u", "Y"])
    with pytest.raises(DataError, match=r"'y' is ambiguous.*columns \[2, 3\]"):
        read_table(path, columns=["y"])
    with pytest.raises(DataError, match=r"column index 4 is out of range .* 4 column"):
        read_table(path, columns=[4])
    with pytest.raises(DataError, match="columns is empty"):
        read_table(path, columns=[])
    with pytest.raises(DataError, match="unknown column 'w'"):
        iter_table_chunks(path, columns=["w"])
    assert read_table(path, columns=[3]).data.tolist() == [[3.0]]


def test_binary_errors_name_row_and_column(tmp_path):
    arr = np.ones((5, 2))
    arr[3, 1] = np.nan
    np.save(tmp_path / "a.npy", arr)
    with pytest.raises(DataError, match=r"row 4, column 'col1': 'nan' is not a finite"):
        read_table(tmp_path / "a.npy")
    with pytest.raises(DataError, match=r"row 4, column 'col1'"):
        chunks_concat(tmp_path / "a.npy", 2)
    np.save(tmp_path / "empty.npy", np.zeros((0, 2)))
    with pytest.raises(DataError, match="is empty"):
        read_table(tmp_path / "empty.npy")
    np.save(tmp_path / "c.npy", np.ones(3) + 1j)
    with pytest.raises(DataError, match="only real numeric"):
        read_table(tmp_path / "c.npy")
    write(tmp_path / "junk.npy", "not an array")
    with pytest.raises(DataError, match=r"not a valid \.npy file"):
        read_table(tmp_path / "junk.npy")
    write(tmp_path / "junk.npz", "not a zip")
    with pytest.raises(DataError, match=r"not a valid \.npz"):
        read_table(tmp_path / "junk.npz")
    write(tmp_path / "junk.parquet", "not parquet")
    pytest.importorskip("pyarrow")
    with pytest.raises(DataError, match="not a readable Parquet file"):
        read_table(tmp_path / "junk.parquet")


def test_not_utf8(tmp_path):
    path = tmp_path / "latin.csv"
    path.write_bytes(b"u,y\n1,2\n" + "é,3\n".encode("latin-1"))
    with pytest.raises(DataError, match="not UTF-8 text"):
        read_table(path)


# ------------------------------------------------------------------- load_iodata
def test_load_iodata_time_column_and_names(tmp_path):
    t = np.arange(100) * 0.01
    arr = np.column_stack([t, np.sin(t), np.cos(t), 2 * t])
    path = tmp_path / "rec.csv"
    write_table(path, ["t", "u1", "u2", "y"], arr)
    data = load_iodata(path, ["u1", "u2"], "y", time_column="t")
    assert isinstance(data, IOData)
    assert data.dt == 0.01
    assert data.input_names == ("u1", "u2") and data.output_names == ("y",)
    np.testing.assert_array_equal(data.u, arr[:, 1:3])
    np.testing.assert_array_equal(data.y, arr[:, 3:])
    same = load_iodata(path, [1, 2], [3], dt=0.01, time_column=0)
    np.testing.assert_array_equal(same.u, data.u)
    assert load_iodata(path, "u1", "y").dt == 1.0
    assert load_iodata(path, "u1", "y", dt=0.5).dt == 0.5
    with pytest.raises(DataError, match=r"dt=0.02 s disagrees with time column 't'"):
        load_iodata(path, "u1", "y", dt=0.02, time_column="t")
    with pytest.raises(DataError, match="unknown column 'x'"):
        load_iodata(path, "x", "y")
    with pytest.raises(DataError, match="inputs is empty"):
        load_iodata(path, [], "y")


def test_load_iodata_non_uniform_time(tmp_path):
    t = np.arange(50) * 0.1
    t[20:] += 0.05  # a gap between rows 19 and 20: file lines 21 -> 22
    path = tmp_path / "gap.csv"
    write_table(path, ["t", "u", "y"], np.column_stack([t, t, t]))
    with pytest.raises(
        DataError,
        match=r"time column 't' .* not uniformly sampled: measured dt = .*largest step "
        r"deviation 0.5 relative.* the step from line 21 to line 22 is 0.15 s against a "
        r"typical \(median\) 0.1 s",
    ):
        load_iodata(path, "u", "y", time_column="t")
    assert load_iodata(path, "u", "y", time_column="t", time_rtol=1.0).n_samples == 50
    t2 = np.arange(10.0)
    t2[6] = t2[5]
    write_table(path, ["t", "u", "y"], np.column_stack([t2, t2, t2]))
    with pytest.raises(DataError, match=r"time column 't' .* is not increasing at line 8"):
        load_iodata(path, "u", "y", time_column="t")
    np.save(tmp_path / "g.npy", np.column_stack([t, t, t]))
    with pytest.raises(DataError, match=r"step from row 20 to row 21"):
        load_iodata(tmp_path / "g.npy", 1, 2, time_column=0)


def test_time_column_rounding_gives_clean_dt(tmp_path):
    t = np.arange(1000) * 0.001 + 1234.5  # an offset clock
    path = tmp_path / "clock.csv"
    write_table(path, ["t", "u", "y"], np.column_stack([t, t, t]))
    assert load_iodata(path, "u", "y", time_column="t").dt == 0.001


def test_load_shipped_dataset_file():
    from clpc import datasets

    path = Path(datasets.__file__).with_name("daisy_dryer.csv")
    data = load_iodata(path, "u", "y", dt=0.08)
    assert data.n_samples == 1000 and data.dt == 0.08


def test_table_basics():
    table = Table(["a", "b"], [[1, 2], [3, 4]])
    assert table.shape == (2, 2) and len(table) == 2
    assert table.index("b") == 1 and table.column(0).tolist() == [1, 3]
    assert table.row_label(0) == "row 1"
    assert "Table(n_rows=2" in repr(table)
    with pytest.raises(DataError, match="one name per column"):
        Table(["a"], [[1, 2]])


# ------------------------------------------------- the pyarrow reader's line numbers
@pytest.mark.parametrize(
    ("text", "match"),
    [
        ("u y\n1 2\n\n# c\n3\n", r"line 5 has 1 field\(s\) but the header \(line 1\)"),
        ("u,y\n# c,d\n1,2\n\n3,4,5\n", r"line 5 has 3 field\(s\)"),
        ("u y\n1 2\n  # note\n\n3 x\n", r"line 5, column 'y': 'x' is not a number"),
        ("u\n1\n\n   \n# c\nabc\n", r"line 6, column 'u': 'abc' is not a number"),
    ],
)
def test_blank_and_comment_lines_keep_error_lines(tmp_path, text, match):
    path = write(tmp_path / "w.txt", text)
    with pytest.raises(DataError, match=match):
        read_table(path)
    with pytest.raises(DataError, match=match):
        chunks_concat(path, 1)


def test_one_column_and_whitespace_files_skip_blank_and_comment_lines(tmp_path):
    path = write(tmp_path / "one.csv", "u\n1\n\n   \n# c\n2 # two\n")
    table = read_table(path)
    assert table.data[:, 0].tolist() == [1, 2]
    assert [table.row_label(i) for i in range(2)] == ["line 2", "line 6"]
    path = write(tmp_path / "ws.dat", "t u\n# c\n 0\t1.5 \n\n1   2.5\n")
    assert read_table(path).data.tolist() == [[0, 1.5], [1, 2.5]]


def test_bad_cell_in_a_later_block_names_its_line(tmp_path):
    n = 400_000  # more than one pyarrow block
    lines = [f"{k},{k}.5" for k in range(n)]
    lines[n - 10] = "1,bad"
    lines.insert(100, "# a comment")
    path = write(tmp_path / "big.csv", "u,y\n" + "\n".join(lines) + "\n")
    with pytest.raises(DataError, match=rf"line {n - 10 + 3}, column 'y': 'bad'"):
        read_table(path)
    lines[n - 9] = f"{n - 10},{n - 10}.5"
    path = write(tmp_path / "big.csv", "u,y\n" + "\n".join(lines) + "\n")
    table = read_table(path, allow_missing=True)
    assert table.n_rows == n and table.row_label(n - 1) == f"line {n + 2}"


# ------------------------------------------------------------------ MATLAB files
def test_mat_variables_are_columns(tmp_path):
    from scipy.io import savemat

    t = np.arange(6) * 0.1
    u = np.sin(t)
    y = np.arange(6, dtype=np.int16)
    path = tmp_path / "rec.mat"
    savemat(path, {"t": t, "u": u[:, None], "y": y, "dt": 0.1, "note": "bench run 3"})
    table = read_table(path)
    assert table.names == ["t", "u", "y"]  # scalar dt and text note left out
    np.testing.assert_array_equal(table.data, np.column_stack([t, u, y]))
    assert table.row_label(0) == "row 1"
    data = load_iodata(path, "u", "y", time_column="t")
    assert data.dt == pytest.approx(0.1)
    np.testing.assert_array_equal(chunks_concat(path, 4, columns=["y", "t"]), table.data[:, [2, 0]])


def test_mat_matrix_names_and_errors(tmp_path):
    from scipy.io import savemat

    arr = np.arange(12.0).reshape(4, 3)
    savemat(tmp_path / "m.mat", {"data": arr, "columns": np.array(["a", "b", "c"], dtype=object)})
    table = read_table(tmp_path / "m.mat", columns=["c", "a"])
    assert table.names == ["c", "a"]
    np.testing.assert_array_equal(table.data, arr[:, [2, 0]])
    savemat(tmp_path / "plain.mat", {"X": arr})
    assert read_table(tmp_path / "plain.mat").names == ["col0", "col1", "col2"]
    bad = arr.copy()
    bad[2, 1] = np.nan
    savemat(tmp_path / "nan.mat", {"u": bad[:, 0], "y": bad[:, 1]})
    with pytest.raises(DataError, match=r"row 3, column 'y': 'nan' is not a finite"):
        read_table(tmp_path / "nan.mat")
    savemat(tmp_path / "len.mat", {"u": np.ones(3), "y": np.ones(4)})
    with pytest.raises(DataError, match="differ in length: 'y' has 4 rows but 'u' has 3"):
        read_table(tmp_path / "len.mat")
    savemat(tmp_path / "mix.mat", {"u": np.ones(3), "X": np.ones((3, 2))})
    with pytest.raises(DataError, match="either one 2-D matrix or numeric vectors"):
        read_table(tmp_path / "mix.mat")
    savemat(tmp_path / "cplx.mat", {"u": np.ones(3) + 1j})
    with pytest.raises(DataError, match="complex"):
        read_table(tmp_path / "cplx.mat")
    write(tmp_path / "junk.mat", "not a mat file at all")
    with pytest.raises(DataError, match=r"not a valid \.mat file"):
        read_table(tmp_path / "junk.mat")
    hdf = tmp_path / "v73.mat"
    hdf.write_bytes(b"MATLAB 7.3 MAT-file, Platform: GLNXA64".ljust(116) + bytes(8) + b"\x00\x02IM")
    with pytest.raises(DataError, match=r"v7\.3"):
        read_table(hdf)


def test_mat_round_trip_and_names(tmp_path):
    arr = np.random.default_rng(4).standard_normal((50, 2))
    write_table(tmp_path / "r.mat", ["u", "y_pos"], arr)
    table = read_table(tmp_path / "r.mat")
    assert table.names == ["u", "y_pos"]
    np.testing.assert_array_equal(table.data, arr)
    with pytest.raises(DataError, match="MATLAB variable names"):
        write_table(tmp_path / "s.mat", ["time [s]", "u"], arr)


def test_long_lines_and_fields_give_short_messages(tmp_path):
    path = tmp_path / "long.csv"
    path.write_bytes(b"u,y\n" + b"1,2\n" * 40 + b"3," + b"4" * 500_000 + b"\n5,6\n")
    with pytest.raises(
        DataError,
        match=r"line 42, column 'y': '4{40}\.\.\. \(500,000 characters\)' is not a finite",
    ) as info:
        read_table(path)
    assert len(str(info.value)) < 300
    path.write_bytes(b"u,y\n1," + b"x" * 200_000 + b"\n")
    with pytest.raises(DataError, match=r"cannot be split into fields near line 1"):
        read_table(path)


def test_the_first_ragged_row_is_named_when_blocks_are_parsed_in_parallel(tmp_path):
    lines = [f"{k},{k}.5" for k in range(600_000)]
    lines[20] = "1,2,3"
    lines[500_000] = "4"
    path = write(tmp_path / "two.csv", "u,y\n" + "\n".join(lines) + "\n")
    for read in (read_table, lambda p: chunks_concat(p, 100_000)):
        with pytest.raises(DataError, match=r"line 22 has 3 field\(s\)"):
            read(path)
