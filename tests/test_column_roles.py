"""Each column of a record has one role: a column named as input and output, or a time-stamp
column used as a signal, is refused by every command (issue 28, item 7), with a message that
names the column and what to do."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest
from click.testing import CliRunner

import clpc
from clpc.cli import cli
from clpc.data import DataError

N, DT = 400, 0.01


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    folder = tmp_path_factory.mktemp("roles")
    rng = np.random.default_rng(28)
    u = rng.standard_normal(N)
    y = np.convolve(u, [0.0, 0.5, 0.25])[:N] + 0.01 * rng.standard_normal(N)
    csv = folder / "log.csv"
    pd.DataFrame({"t": np.arange(N) * DT, "u": u, "y": y}).to_csv(csv, index=False)
    stamps = pd.date_range("2026-01-01", periods=N, freq="10ms")
    parquet = folder / "log.parquet"
    pd.DataFrame({"stamp": stamps, "u": u, "y": y}).to_parquet(parquet)
    return csv, parquet


def _invoke(args, stdin=None):
    return CliRunner().invoke(cli, args, input=stdin)


@pytest.mark.parametrize("command", ["identify", "track"])
def test_one_column_as_input_and_output_is_refused(files, command, tmp_path):
    csv, _ = files
    extra = ["--out", str(tmp_path / "out")] if command == "track" else []
    result = _invoke([command, str(csv), "-u", "u", "-y", "u", "--time", "t", *extra])
    assert result.exit_code == 1
    assert "column 'u' of" in result.output and "as input and as output" in result.output
    assert "Traceback" not in result.output


def test_the_time_column_as_a_signal_is_refused(files):
    csv, _ = files
    result = _invoke(["identify", str(csv), "-u", "t", "-y", "y", "--time", "t"])
    assert result.exit_code == 1 and "as input and as time column" in result.output


@pytest.mark.parametrize("role", ["-u", "-y"])
def test_a_parquet_timestamp_column_is_not_a_signal(files, role, tmp_path):
    _, parquet = files
    other = "-y" if role == "-u" else "-u"
    args = ["track", str(parquet), role, "stamp", other, "u", "--out", str(tmp_path / "o")]
    result = _invoke(args)
    assert result.exit_code == 1
    assert "column 'stamp'" in result.output and "holds time stamps" in result.output
    assert "--time stamp" in result.output  # what to do instead


def test_a_parquet_timestamp_column_is_a_good_time_column(files):
    _, parquet = files
    data = clpc.load_iodata(parquet, "u", "y", time_column="stamp")
    assert data.dt == pytest.approx(DT, rel=1e-12)
    with pytest.raises(DataError, match="holds time stamps"):
        clpc.load_iodata(parquet, "stamp", "y")


def test_stream_refuses_one_column_in_two_roles(files):
    csv, _ = files
    result = _invoke(["stream", "-u", "u", "-y", "u", "--time", "t"], stdin=csv.read_text())
    assert result.exit_code == 2
    assert "column 'u' is selected as input and as output" in result.output
