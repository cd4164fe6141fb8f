"""Hostile files through ``clpc identify`` and ``clpc track``: bounded readers, one-line errors.

Issue 28, item 2. Every hostile file goes through both commands (the ``command`` fixture):
exit 1, one ``Error:`` line naming the file, no traceback; ``track`` leaves nothing in its
``--out`` folder that claims a complete run.
"""

from __future__ import annotations

import gzip
import time
import tracemalloc

import numpy as np
import pytest
from click.testing import CliRunner

from clpc.cli import cli
from clpc.core.output_folder import LOCK_NAME
from clpc.data import DataError
from clpc.io import iter_table_chunks, read_table
from clpc.io.budget import COLUMNS_ENV, LINE_ENV, MAX_COLUMNS, READ_ENV

#: the command a test's hostile files go through (see the ``command`` fixture)
_COMMAND = {"name": "identify"}


@pytest.fixture(params=["identify", "track"], autouse=True)
def command(request):
    """Run each test with its hostile files given to ``clpc identify``, then ``clpc track``."""
    _COMMAND["name"] = request.param
    yield request.param
    _COMMAND["name"] = "identify"


def _identify(path, *columns: str, named: bool = True) -> tuple[str, float]:
    """The command of a hostile file: exit 1, one ``Error:`` line; its text and time.

    For ``clpc track`` the ``--out`` folder must not claim a complete run: it holds at most
    the lock file (no run record, report, trace, figure or staging folder).
    """
    cols = columns or ("u", "y")
    args = [_COMMAND["name"], str(path), "-u", cols[0], "-y", cols[1]]
    out = path.parent / f"out-{path.name}"
    if _COMMAND["name"] == "track":
        args += ["--out", str(out)]
    start = time.perf_counter()
    res = CliRunner().invoke(cli, args)
    took = time.perf_counter() - start
    assert res.exit_code == 1, res.output
    assert isinstance(res.exception, SystemExit), repr(res.exception)
    lines = res.output.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("Error: "), res.output
    assert "Traceback" not in res.output and (path.name in lines[0] or not named)
    if out.exists():
        left = sorted(p.name for p in out.iterdir())
        assert set(left) <= {LOCK_NAME}, left  # no run record, trace, figure or staging
    return lines[0], took


def _rows(n: int) -> bytes:
    return b"u,y\n" + b"0,0\n" * n


def test_gzip_bomb_stops_at_the_read_limit_early_and_small(tmp_path, monkeypatch):
    path = tmp_path / "bomb.csv.gz"
    path.write_bytes(gzip.compress(_rows(2_500_000), 9))  # 10 MB of rows in about 10 kB
    assert path.stat().st_size < 30_000
    monkeypatch.setenv(READ_ENV, "1000000")
    tracemalloc.start()
    try:
        line, took = _identify(path)
        _, peak = tracemalloc.get_traced_memory()
    finally:
        tracemalloc.stop()
    assert "read limit of 1,000,000 bytes" in line and READ_ENV in line
    assert took < 10 and peak < 20e6, (took, peak)
    with pytest.raises(DataError, match=READ_ENV):
        for _ in iter_table_chunks(path, 1000):
            pass


def test_gzip_bomb_without_line_ends_stops_at_the_default_line_limit(tmp_path):
    path = tmp_path / "zeros.csv.gz"
    path.write_bytes(gzip.compress(b"u,y\n" + b"0" * 10_000_000, 9))
    line, took = _identify(path)
    assert "line 2 is longer than the line limit of 4,194,304 bytes" in line
    assert LINE_ENV in line and took < 10


def test_a_gzip_file_within_the_limits_reads_exactly(tmp_path, monkeypatch):
    data = np.random.default_rng(1).standard_normal((5000, 2))
    text = "u,y\n" + "".join(f"{a!r},{b!r}\n" for a, b in data.tolist())
    path = tmp_path / "ok.csv.gz"
    path.write_bytes(gzip.compress(text.encode()))
    monkeypatch.setenv(READ_ENV, str(len(text)))  # exactly its size is allowed
    np.testing.assert_array_equal(read_table(path).data, data)
    got = np.concatenate([v for _, v in iter_table_chunks(path, 777)])
    np.testing.assert_array_equal(got, data)
    monkeypatch.setenv(READ_ENV, str(len(text) - 1))
    with pytest.raises(DataError, match=READ_ENV):
        read_table(path)


def test_long_lines_give_one_line_errors(tmp_path, monkeypatch):
    data = b"".join(b"%d,%d\n" % (i % 7, i % 5) for i in range(200))
    head = tmp_path / "long_header.csv"
    head.write_bytes(b"u" * 200_000 + b",y\n" + data)
    middle = tmp_path / "long_line.csv"
    middle.write_bytes(b"u,y\n" + data + b"x" * 200_000 + b",1\n" + data)
    # within the default line limit: pyarrow and the csv module meet the line
    assert "cannot be split into fields near line 1" in _identify(head, "0", "1")[0]
    assert "line 202, column 'u'" in _identify(middle)[0]
    monkeypatch.setenv(LINE_ENV, "100000")
    line, _ = _identify(head, "0", "1")
    assert "line 1 is longer than the line limit of 100,000 bytes" in line and LINE_ENV in line
    assert "line 202 is longer than the line limit" in _identify(middle)[0]


def test_a_long_line_in_an_unselected_column_reads_when_the_limit_is_raised(tmp_path, monkeypatch):
    rows = [b"%d,%d,note\n" % (i % 7, i % 5) for i in range(100)]
    rows[60] = b'1,2,"' + b"x" * 5_000_000 + b'"\n'  # longer than pyarrow's 4 MiB block
    path = tmp_path / "note.csv"
    path.write_bytes(b"u,y,note\n" + b"".join(rows))
    with pytest.raises(DataError, match=f"line 62 is longer.*{LINE_ENV}"):
        read_table(path, columns=["u", "y"])
    monkeypatch.setenv(LINE_ENV, "6000000")
    assert read_table(path, columns=["u", "y"]).data[60].tolist() == [1.0, 2.0]


def test_too_many_columns_are_refused_by_default_and_by_the_variable(tmp_path, monkeypatch):
    wide = tmp_path / "wide.csv"
    n = 2 * MAX_COLUMNS
    wide.write_text(",".join(f"c{i}" for i in range(n)) + "\n" + ",".join(["1"] * n) + "\n")
    line, took = _identify(wide, "c0", "c1")
    assert f"{n:,} columns, more than the column limit of {MAX_COLUMNS:,}" in line
    assert COLUMNS_ENV in line and took < 10
    small = tmp_path / "small.csv"
    small.write_text("a,b,c\n" + "1,2,3\n" * 50)
    monkeypatch.setenv(COLUMNS_ENV, "2")
    assert "3 columns, more than the column limit of 2" in _identify(small, "a", "b")[0]


def test_npz_bomb_is_refused_from_its_headers(tmp_path, monkeypatch):
    path = tmp_path / "bomb.npz"
    np.savez_compressed(path, u=np.zeros(1_250_000), y=np.zeros(1_250_000))  # 20 MB in 40 kB
    assert path.stat().st_size < 100_000
    monkeypatch.setenv(READ_ENV, "1000000")
    tracemalloc.start()
    try:
        line, took = _identify(path)
        _, peak = tracemalloc.get_traced_memory()
    finally:
        tracemalloc.stop()
    assert "read limit of 1,000,000 bytes" in line and READ_ENV in line
    assert took < 10 and peak < 20e6, (took, peak)


def test_utf16_and_truncated_gzip_files(tmp_path):
    utf16 = tmp_path / "utf16.csv"
    utf16.write_text("u,y\n" + "1,2\n3,4\n" * 50, encoding="utf-16")
    assert "is not UTF-8 text" in _identify(utf16)[0]
    blob = gzip.compress(_rows(100_000))
    cut = tmp_path / "cut.csv.gz"
    cut.write_bytes(blob[: len(blob) // 2])
    assert "truncated" in _identify(cut)[0]


@pytest.mark.parametrize("env", [READ_ENV, LINE_ENV, COLUMNS_ENV])
@pytest.mark.parametrize("value", ["abc", "0", "-5"])
def test_a_bad_limit_variable_is_a_one_line_error(tmp_path, monkeypatch, env, value):
    path = tmp_path / "ok.csv.gz"
    path.write_bytes(gzip.compress(_rows(100)))
    monkeypatch.setenv(env, value)
    assert f"{env} must be a positive whole number" in _identify(path, named=False)[0]
