"""clpc.track_many on a real LocalCluster of worker processes: a simulated fleet of 20 axes.

One cluster (two worker processes) and one fleet run serve the module: the odd axis
ranked first, every record equal to its own ``clpc track``, the table written and read
back, a re-run that reuses finished records, a corrupt file, IOData sources.
"""

from __future__ import annotations

import json
import os

import numpy as np
import pandas as pd
import pytest

distributed = pytest.importorskip("distributed")

from clpc import track_many  # noqa: E402
from clpc.core.output_folder import RECORD_NAME  # noqa: E402
from clpc.io import load_iodata  # noqa: E402
from clpc.workflows.fleet_record import ROW_NAME  # noqa: E402
from clpc.workflows.fleet_settings import FleetSettings  # noqa: E402
from fleet_sim import write_partitioned  # noqa: E402

SETTINGS = {"inputs": "u", "outputs": "y", "time_col": "t"}
N_AXES, N_SAMPLES, ODD = 20, 2500, 13
#: columns that say how and where a row was made, not what it found
RUN_COLUMNS = ["skipped", "seconds", "folder"]


@pytest.fixture(scope="module")
def client():
    with (
        distributed.LocalCluster(
            n_workers=2, threads_per_worker=1, processes=True, dashboard_address=":0"
        ) as cluster,
        distributed.Client(cluster) as c,
    ):
        yield c


@pytest.fixture(scope="module")
def fleet(client, tmp_path_factory):
    root = tmp_path_factory.mktemp("fleet")
    names = write_partitioned(root / "ds", N_AXES, N_SAMPLES, ODD, gain=0.8)
    lines: list[tuple[int, int, str]] = []
    result = track_many(
        root / "ds",
        client=client,
        out=root / "out",
        progress=lambda done, total, row: lines.append((done, total, row["name"])),
        **SETTINGS,
    )
    return root, names, result, lines


def test_the_axis_with_a_fifth_less_gain_is_ranked_first_and_the_only_outlier(fleet):
    _, names, result, lines = fleet
    table = result.table
    assert list(table["name"]) == names  # one row per partition, in order
    assert table["error"].isna().all()
    first = table.loc[table["rank"] == 1].iloc[0]
    assert first["name"] == names[ODD] and bool(first["outlier"])
    assert table["outlier"].sum() == 1
    # its distance is close to the 0.2 of the true plants' responses (estimation noise aside)
    assert 0.15 < first["distance"] < 0.25
    others = table.drop(index=ODD)
    assert others["distance"].max() < 0.05
    assert sorted(table["rank"]) == list(range(1, N_AXES + 1))
    # a line per finished record
    assert [d for d, _, _ in lines] == list(range(1, N_AXES + 1))
    assert sorted(n for _, _, n in lines) == sorted(names)
    lo, hi = result.band_hz
    assert 0 < lo < 10 and 100 < hi <= 500  # a random +-1 input held 10 samples at 1 kHz


def test_every_record_equals_its_own_clpc_track(fleet, tmp_path):
    from clpc.workflows import track_file

    root, names, result, _ = fleet
    settings = FleetSettings.from_keywords(**SETTINGS)
    for k in (0, ODD):
        source = root / "ds" / names[k] / "part.parquet"
        direct = track_file(settings.track_settings(str(source), str(tmp_path / names[k])))
        ours = root / "out" / names[k]
        assert (ours / "trace.csv").read_bytes() == (tmp_path / names[k] / "trace.csv").read_bytes()
        row = result.table.iloc[k]
        assert np.array_equal(np.stack(row["den"]), direct.model.denominators)
        assert row["fit_percent"][0] == direct.fit[0]
        assert row["samples"] == N_SAMPLES == direct.samples
        assert row["updates"] == direct.summary["updates"]
        names_written = {p.name for p in ours.iterdir()} - {ROW_NAME, RECORD_NAME, ".clpc.lock"}
        assert names_written == {f.name for f in direct.files}


def test_the_table_and_the_report_are_written(fleet):
    root, names, result, _ = fleet
    out = root / "out"
    back = pd.read_parquet(out / "fleet.parquet")
    assert list(back["name"]) == names
    for col in ("distance", "rank", "samples", "converged", "verdict", "gain_drift"):
        assert back[col].tolist() == result.table[col].tolist()
    assert all((out / f).is_file() for f in back["drift_figure"])
    page = (out / "fleet.html").read_text(encoding="utf-8")
    lo, hi = result.band_hz
    assert f"from {lo:.4g} to {hi:.4g} Hz" in page and "relative RMS distance" in page
    assert f"{names[ODD]}</a> (outlier)" in page
    assert {p.name for p in result.files} == {
        "fleet.parquet",
        "fleet_bode.png",
        "fleet_drift.png",
        "fleet.html",
    }


def test_a_rerun_reuses_finished_records_and_reruns_changed_or_half_written_ones(fleet, client):
    root, names, result, _ = fleet
    out = root / "out"
    changed, half, missing = names[1], names[2], names[3]
    source = root / "ds" / changed / "part.parquet"
    os.utime(source, ns=(source.stat().st_atime_ns, source.stat().st_mtime_ns + 10**9))
    (out / half / ROW_NAME).unlink()  # as if killed after its files, before its row
    (out / missing / "trace.png").unlink()  # a listed file gone: not complete
    again = track_many(root / "ds", client=client, out=out, **SETTINGS)
    skipped = dict(zip(again.table["name"], again.table["skipped"], strict=True))
    assert not skipped[changed] and not skipped[half] and not skipped[missing]
    assert sum(skipped.values()) == N_AXES - 3
    pd.testing.assert_frame_equal(
        again.table.drop(columns=RUN_COLUMNS), result.table.drop(columns=RUN_COLUMNS)
    )
    assert (out / missing / "trace.png").is_file()


def test_a_corrupt_file_is_a_row_with_its_error_and_the_others_are_right(fleet, client, tmp_path):
    root, names, result, _ = fleet
    bad = tmp_path / "bad.parquet"
    bad.write_bytes(b"PAR1 this is not a parquet file")
    sources = {names[0]: root / "ds" / names[0] / "part.parquet", "bad": bad}
    mixed = track_many(sources, client=client, out=tmp_path / "out", **SETTINGS)
    row_bad = mixed.table.iloc[1]
    assert row_bad["name"] == "bad" and "bad.parquet" in row_bad["error"]
    assert pd.isna(row_bad["rank"]) and pd.isna(row_bad["samples"])
    good = mixed.table.iloc[0]
    same = result.table.iloc[0]
    for col in ("samples", "updates", "accepted", "converged", "verdict", "gain_drift"):
        assert good[col] == same[col]
    assert np.array_equal(np.stack(good["num"][0]), np.stack(same["num"][0]))
    page = (tmp_path / "out" / "fleet.html").read_text(encoding="utf-8")
    assert "Failed records" in page and "bad failed:" in page
    assert not (tmp_path / "out" / "bad" / ROW_NAME).exists()


def test_iodata_sources_are_tracked_as_their_samples_written_to_a_file(fleet, client):
    root, names, result, _ = fleet
    data = load_iodata(root / "ds" / names[ODD] / "part.parquet", ["u"], ["y"], time_column="t")
    got = track_many({"odd": data}, client=client, **SETTINGS)
    row = got.table.iloc[0]
    assert row["error"] is None and row["folder"] is None and got.files == []
    same = result.table.iloc[ODD]
    assert np.array_equal(np.stack(row["den"]), np.stack(same["den"]))
    assert row["fit_percent"][0] == same["fit_percent"][0]


def test_summary_rows_are_small(fleet):
    root, names, _, _ = fleet
    sizes = [len((root / "out" / n / ROW_NAME).read_bytes()) for n in names]
    assert max(sizes) < 8000
    row = json.loads((root / "out" / names[0] / ROW_NAME).read_text())
    assert len(row["drift_time"]) <= 100


def test_no_sample_is_read_by_the_client(fleet, client, monkeypatch):
    import clpc.io
    import clpc.workflows.track

    def refuse(*args, **kwargs):
        raise AssertionError("the client read a record")

    for module in (clpc.io, clpc.workflows.track):  # this process only; workers are others
        monkeypatch.setattr(module, "iter_table_chunks", refuse)
    monkeypatch.setattr(clpc.io, "read_table", refuse)
    root, names, result, _ = fleet
    got = track_many(root / "ds" / names[0] / "part.parquet", client=client, **SETTINGS)
    assert got.table["error"].isna().all()
    assert np.array_equal(np.stack(got.table["den"][0]), np.stack(result.table["den"][0]))
