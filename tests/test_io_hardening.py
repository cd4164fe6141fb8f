"""Careless and hostile files given to the readers (issue 15)."""

from __future__ import annotations

import gzip
import os
import threading
import tracemalloc

import numpy as np
import pytest
from click.testing import CliRunner

from clpc.cli import cli
from clpc.data import DataError
from clpc.io import iter_table_chunks, read_table, write_table
from clpc.io.npz_members import LIMIT_ENV


@pytest.fixture
def csv_text():
    rng = np.random.default_rng(3)
    data = rng.standard_normal((3000, 2))
    return "u,y\n" + "".join(f"{float(a)!r},{float(b)!r}\n" for a, b in data), data


def test_truncated_gzip_names_the_file(tmp_path, csv_text):
    text, _ = csv_text
    blob = gzip.compress(text.encode())
    path = tmp_path / "cut.csv.gz"
    path.write_bytes(blob[: len(blob) // 2])
    with pytest.raises(DataError, match=r"cut\.csv\.gz.*truncated"):
        read_table(path)
    res = CliRunner().invoke(cli, ["identify", str(path), "-u", "u", "-y", "y"])
    assert res.exit_code == 1 and "cut.csv.gz" in res.output and "Aborted" not in res.output


def test_plain_text_named_gz_names_the_file(tmp_path, csv_text):
    text, _ = csv_text
    path = tmp_path / "plain.csv.gz"
    path.write_text(text)
    with pytest.raises(DataError, match=r"plain\.csv\.gz.*not a valid gzip"):
        read_table(path)


@pytest.mark.parametrize("cell", ["1_000", "\u0661\u0662", "\uff11", "0x10", "1e", "--1"])
def test_cells_that_float_would_take_are_refused_by_every_path(tmp_path, cell):
    fast = tmp_path / "fast.csv"
    fast.write_text(f"u,y\n1,2\n{cell},3\n4,5\n")
    slow = tmp_path / "slow.csv"  # a quoted cell sends the batch to the Python parser
    slow.write_text(f'u,y\n"1",2\n{cell},3\n4,5\n')
    for path in (fast, slow):
        with pytest.raises(DataError, match=r"line 3, column 'u'"):
            read_table(path)
        with pytest.raises(DataError, match=r"line 3, column 'u'"):
            list(iter_table_chunks(path, 2))


@pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="needs named pipes")
def test_named_pipe_is_read_without_loss(tmp_path, csv_text):
    text, data = csv_text
    fifo = tmp_path / "pipe.csv"
    os.mkfifo(fifo)

    def feed():
        with open(fifo, "w") as fh:
            fh.write(text)

    t = threading.Thread(target=feed)
    t.start()
    table = read_table(fifo)
    t.join()
    np.testing.assert_array_equal(table.data, data)


@pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="needs named pipes")
def test_a_pipe_beyond_the_read_limit_is_refused_and_its_copy_removed(tmp_path, monkeypatch):
    # issue 28 item 2: a FIFO was copied to the temporary folder without limit
    import tempfile

    monkeypatch.setenv("CLPC_MAX_READ_BYTES", "100000")
    spool = tmp_path / "spool"
    spool.mkdir()
    monkeypatch.setattr(tempfile, "tempdir", str(spool))
    fifo = tmp_path / "endless.csv"
    os.mkfifo(fifo)
    row = "1.0,2.0\n" * 1000

    def feed():
        try:
            with open(fifo, "w") as fh:
                fh.write("u,y\n")
                for _ in range(100):  # 800 kB, eight times the limit
                    fh.write(row)
        except BrokenPipeError:
            pass  # the reader stopped at its limit and closed the pipe

    t = threading.Thread(target=feed)
    t.start()
    with pytest.raises(DataError, match=r"endless\.csv' streams more than the read limit of "
                       r"100,000 bytes.*CLPC_MAX_READ_BYTES"):  # fmt: skip
        read_table(fifo)
    t.join()
    assert list(spool.iterdir()) == []  # the partial copy is gone


def _bomb(path, n, compressed=True):
    save = np.savez_compressed if compressed else np.savez
    save(path, u=np.zeros(n), y=np.ones(n))


def test_npz_larger_than_the_limit_is_refused_before_loading(tmp_path, monkeypatch):
    path = tmp_path / "bomb.npz"
    _bomb(path, 2_000_000)
    assert path.stat().st_size < 100_000  # compressed: tiny on disk
    monkeypatch.setenv(LIMIT_ENV, str(8 * 1_000_000))
    tracemalloc.start()
    with pytest.raises(DataError, match=r"bomb\.npz.*4,000,000 values.*CLPC_MAX_LOAD_BYTES"):
        read_table(path)
    peak = tracemalloc.get_traced_memory()[1]
    tracemalloc.stop()
    assert peak < 2_000_000  # nothing was decompressed
    monkeypatch.setenv(LIMIT_ENV, "nonsense")
    with pytest.raises(DataError, match="positive number of bytes"):
        read_table(path)


@pytest.mark.parametrize("compressed", [True, False])
def test_npz_chunks_are_decompressed_a_chunk_at_a_time(tmp_path, compressed):
    n = 3_000_000  # 2 columns: 48 MB as float64
    path = tmp_path / "big.npz"
    _bomb(path, n, compressed)
    tracemalloc.start()
    rows = 0
    for names, values in iter_table_chunks(path, 100_000, columns=["y", "u"]):
        assert names == ["y", "u"]
        assert values[0, 0] == 1.0 and values[0, 1] == 0.0
        rows += values.shape[0]
    peak = tracemalloc.get_traced_memory()[1]
    tracemalloc.stop()
    assert rows == n
    assert peak < 12_000_000  # a few chunks (1.6 MB each), never the 48 MB of the columns


def test_npz_layouts_still_read_the_same(tmp_path):
    rng = np.random.default_rng(1)
    table = rng.standard_normal((50, 3))
    np.savez(tmp_path / "c.npz", table=table, columns=np.array(["a", "b", "c"]))
    np.savez(tmp_path / "f.npz", table=np.asfortranarray(table))
    np.savez_compressed(tmp_path / "cols.npz", a=table[:, 0], b=table[:, 1], n=np.int64(3))
    t = read_table(tmp_path / "c.npz", columns=["c", "a"])
    np.testing.assert_array_equal(t.data, table[:, [2, 0]])
    np.testing.assert_array_equal(read_table(tmp_path / "f.npz").data, table)
    got = np.vstack([v for _, v in iter_table_chunks(tmp_path / "f.npz", 7)])
    np.testing.assert_array_equal(got, table)
    t = read_table(tmp_path / "cols.npz")
    assert t.names == ["a", "b"]
    np.testing.assert_array_equal(t.data, table[:, :2])


def test_npy_larger_than_the_limit_is_refused(tmp_path, monkeypatch):
    path = tmp_path / "big.npy"
    np.save(path, np.zeros((100_000, 2)))
    monkeypatch.setenv(LIMIT_ENV, "80000")
    with pytest.raises(DataError, match="load limit"):
        read_table(path)
    assert sum(v.shape[0] for _, v in iter_table_chunks(path, 30_000)) == 100_000


def test_truncated_npz_member_is_a_clear_error(tmp_path):
    path = tmp_path / "cut.npz"
    _bomb(path, 100_000, compressed=False)
    blob = path.read_bytes()
    path.write_bytes(blob[: len(blob) - 400_000])
    with pytest.raises(DataError, match=r"cut\.npz"):
        read_table(path)


def test_write_table_round_trip_unchanged(tmp_path):
    data = np.arange(12.0).reshape(6, 2)
    write_table(tmp_path / "r.npz", ["u", "y"], data)
    np.testing.assert_array_equal(read_table(tmp_path / "r.npz").data, data)
