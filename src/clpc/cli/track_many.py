"""``clpc track-many``: ``clpc track`` over a fleet of records on a Dask cluster, ranked."""

from __future__ import annotations

import dataclasses
from typing import Any

import click

from clpc.cli.errors import ClpcCommand
from clpc.cli.options import appraiser_options, appraiser_settings, format_option, out_dir_option
from clpc.cli.record_options import input_option, output_option, sampling_options
from clpc.workflows import AppraiserSettings

__all__ = ["track_many"]

#: characters of a record's verdict on its progress line
_VERDICT_CHARS = 80


def _line(done: int, total: int, row: dict[str, Any]) -> None:
    """One line per finished record on standard error."""
    head = f"[{done}/{total}] {row['name']}"
    if row.get("error"):
        click.echo(f"{head}: FAILED: {row['error']}", err=True)
        return
    fit = row.get("fit_percent") or []
    shown = ", ".join("-" if f is None else f"{f:.1f} %" for f in fit) or "-"
    again = " (finished earlier: reused)" if row.get("skipped") else ""
    verdict = str(row["verdict"])
    if len(verdict) > _VERDICT_CHARS:  # the whole verdict is in the table and the reports
        verdict = verdict[: _VERDICT_CHARS - 3] + "..."
    click.echo(
        f"{head}: {row['samples']} samples, {row['updates']} updates, fit {shown}, "
        f"{verdict}{again} [{row['seconds']:.1f} s]",
        err=True,
    )


@click.command(cls=ClpcCommand)
@click.argument("sources", nargs=-1, required=True, metavar="SOURCES...")
@input_option()
@output_option()
@out_dir_option(
    "Folder of the fleet: OUT/<record>/ as clpc track writes it, OUT/fleet.parquet and "
    "OUT/fleet.html."
)
@appraiser_options()
@sampling_options()
@format_option(["csv", "parquet"], "Format of each record's trace file.")
@click.option(
    "--chunk-rows",
    type=click.IntRange(min=1),
    default=100_000,
    show_default=True,
    help="Rows read from a file at a time.",
)
@click.option(
    "--scheduler",
    metavar="ADDRESS",
    default=None,
    help="Address of a running Dask scheduler (tcp://host:8786); default: start a local cluster.",
)
@click.option(
    "--workers",
    type=click.IntRange(min=1),
    default=None,
    help="Worker processes of the local cluster (default: the cores available).",
)
@appraiser_settings()
def track_many(
    sources: tuple[str, ...],
    out_dir: str,
    scheduler: str | None,
    workers: int | None,
    appraiser: AppraiserSettings,
    **record: Any,
) -> None:
    """Run clpc track on every record of a fleet, on a Dask cluster, and rank the records.

    SOURCES are files, globs, folders of data files, or a partitioned Parquet dataset (a
    folder of axis=NAME/ partitions, one record each). Every record is read on a worker
    and gets OUT/<record>/ exactly as clpc track writes it; OUT/fleet.parquet holds one
    row per record (model, fit %, verdict, convergence, gain drift, distance, or the
    error) and OUT/fleet.html ranks the records by the distance of their model's frequency
    response from the fleet median model's over the band the inputs excite. A record whose
    folder already holds a finished run with the same settings is not run again. Exits 1
    when a record failed (after writing the table and the report).

    \b
    Examples:
      clpc track-many logs/*.csv -u torque -y speed --time t --out fleet/
      clpc track-many line3/ -u u -y y --dt 0.001 --out fleet/ --scheduler tcp://10.0.0.5:8786
    """  # noqa: D301
    from clpc.distributed.fleet import track_many as run_fleet

    settings = {**record, **dataclasses.asdict(appraiser)}
    result = run_fleet(
        list(sources),
        out=out_dir,
        scheduler=scheduler,
        workers=workers,
        progress=_line,
        announce=lambda line: click.echo(line, err=True),
        **settings,
    )
    table = result.table
    ranked = table[table["rank"].notna()].sort_values("rank")
    if result.band_hz is not None and len(ranked):
        lo, hi = result.band_hz
        click.echo(f"farthest from the fleet median model ({lo:.4g} to {hi:.4g} Hz):")
        for _, r in ranked.head(5).iterrows():
            mark = " OUTLIER" if r["outlier"] else ""
            click.echo(f"  {int(r['rank'])}. {r['name']}: distance {r['distance']:.4g}{mark}")
    for f in result.files:
        click.echo(f"wrote {f}")
    failed = table[table["error"].notna()]
    if len(failed):
        raise click.ClickException(
            f"{len(failed)} of {len(table)} record(s) failed: "
            + "; ".join(f"{n}: {e}" for n, e in zip(failed["name"], failed["error"], strict=True))
            + " (the fleet table and report were written; the rows say why)."
        )
