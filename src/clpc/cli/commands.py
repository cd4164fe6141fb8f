"""The ``clpc`` command line: a thin layer of parsing and printing over the public API.

Commands: ``identify`` (batch LPC), ``track`` (the CLPC appraiser over a file, read in
chunks), ``stream`` (the appraiser on standard input, one JSON line per update),
``simulate``, ``compare``, ``datasets`` and ``demo``. Run ``clpc COMMAND --help``.

Exit codes: 0 success, 1 a data or model error (one line on standard error, no traceback),
2 a usage error (unknown option, bad option value).
"""

from __future__ import annotations

import dataclasses
import io
import json
import math
import os
import sys
from collections.abc import Iterator, Sequence
from pathlib import Path
from typing import Any

import click
import numpy as np

from clpc import datasets as _datasets
from clpc._version import __version__
from clpc.appraiser.facade import CLPC
from clpc.appraiser.tracefile import ThinnedTrace, TraceWriter
from clpc.data import DataError, IOData
from clpc.io import iter_table_chunks, load_iodata, read_table, write_table
from clpc.io.model_files import load_model, save_model
from clpc.lpc.estimator import LPC
from clpc.lpc.order import select_order
from clpc.model import LinearModel, ModelError
from clpc.report import (
    format_fit,
    format_model_summary,
    jsonable,
    model_response,
    model_summary,
    steady_state,
    trace_summary,
    update_records,
    write_track_report,
)

__all__ = ["cli", "main"]

_USER_ERRORS = (DataError, ModelError, OSError, ValueError, ImportError)


def _one_line(exc: BaseException) -> str:
    text = " ".join(str(exc).split())
    return text or type(exc).__name__


class _Group(click.Group):
    """The top-level group: the one place where library errors become one-line messages."""

    def invoke(self, ctx: click.Context) -> Any:
        try:
            return super().invoke(ctx)
        except (click.ClickException, click.exceptions.Exit, click.exceptions.Abort):
            raise
        except BrokenPipeError:  # the reader went away (e.g. `clpc simulate ... | head`)
            _silence_stdout()
            ctx.exit(1)
        except _USER_ERRORS as exc:  # DataError, ModelError, FileNotFoundError, ValueError
            raise click.ClickException(_one_line(exc)) from None


def _silence_stdout() -> None:
    """Point stdout at /dev/null so that the interpreter's final flush does not fail."""
    try:
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
    except (OSError, ValueError, io.UnsupportedOperation):  # no real file descriptor
        pass


class _OrderType(click.ParamType):
    """``auto`` or an int >= 1."""

    name = "N|auto"

    def convert(self, value: Any, param: Any, ctx: Any) -> int | str:
        if isinstance(value, int) and not isinstance(value, bool):
            order = value
        elif str(value).strip().lower() == "auto":
            return "auto"
        else:
            try:
                order = int(str(value))
            except ValueError:
                self.fail(f"must be an int >= 1 or 'auto'; got {value!r}.", param, ctx)
        if order < 1:
            self.fail(f"must be an int >= 1 or 'auto'; got {order}.", param, ctx)
        return order


# =============================================================================== helpers
def _check_dt_time(dt: float | None, time: str | None) -> None:
    if dt is not None and time is not None:
        raise click.UsageError("pass either --dt or --time, not both.")


def _keys(cols: Sequence[str]) -> list[str | int]:
    """Column keys: names, or 0-based indices when written as plain digits."""
    return [int(c) if c.isdigit() else c for c in cols]


def _key(col: str | None) -> str | int | None:
    return None if col is None else _keys([col])[0]


def _load(file: str, inputs: Sequence[str], outputs: Sequence[str], dt: Any, time: Any) -> IOData:
    _check_dt_time(dt, time)
    return load_iodata(file, _keys(inputs), _keys(outputs), dt=dt, time_column=_key(time))


def _echo_json(obj: Any) -> None:
    click.echo(json.dumps(jsonable(obj), allow_nan=False))


def _model_columns(model: LinearModel, given: Sequence[str], kind: str, option: str) -> list[str]:
    names = list(model.input_names if kind == "input" else model.output_names)
    if not given:
        return names
    if len(given) != len(names):
        raise click.UsageError(
            f"the model has {len(names)} {kind}(s) {names}; {option} was given "
            f"{len(given)} time(s): {list(given)}."
        )
    return list(given)


# ============================================================================ options
def _options(*decorators: Any) -> Any:
    """Several click options as one decorator (applied in the order given)."""

    def apply(func: Any) -> Any:
        for decorator in reversed(decorators):
            func = decorator(func)
        return func

    return apply


_DT = click.option(
    "--dt",
    type=click.FloatRange(min=0, min_open=True),
    default=None,
    help="Sample time of the data [s] (default 1, or from --time).",
)
_SAMPLING = _options(
    _DT,
    click.option(
        "--time",
        "time_col",
        metavar="COL",
        default=None,
        help="Column of sample times [s]; must be uniformly spaced.",
    ),
)
_COLUMNS = _options(
    click.option(
        "--input",
        "-u",
        "inputs",
        multiple=True,
        required=True,
        metavar="COL",
        help="Input column (name, or 0-based index); repeat for several inputs.",
    ),
    click.option(
        "--output",
        "-y",
        "outputs",
        multiple=True,
        required=True,
        metavar="COL",
        help="Output column; repeat for several outputs.",
    ),
)
_METHOD = click.option(
    "--method",
    type=click.Choice(["robust", "paper"]),
    default="robust",
    show_default=True,
    help="LPC solution (see clpc.LPC).",
)
_APPRAISER = _options(
    click.option(
        "--parameters-size",
        "-p",
        type=click.IntRange(min=2),
        default=3,
        show_default=True,
        help="Size of a and of b (N + 1).",
    ),
    click.option(
        "--window",
        "-w",
        type=click.IntRange(min=2),
        default=201,
        show_default=True,
        help="Lag vectors per LPC window.",
    ),
    click.option(
        "--cluster",
        "-c",
        type=click.IntRange(min=1),
        default=12,
        show_default=True,
        help="Lag vectors between updates.",
    ),
    click.option(
        "--nk",
        type=click.IntRange(min=0),
        default=0,
        show_default=True,
        help="Input delay in samples.",
    ),
    click.option(
        "--sample-time",
        type=click.FloatRange(min=0, min_open=True),
        default=None,
        help="Sample time [s] the appraiser works at: an integer multiple of the "
        "data's (the data are low-pass filtered and decimated).",
    ),
    _METHOD,
    click.option("--gate", is_flag=True, help="Accept only estimates the window determines."),
)
_JSON = click.option("--json", "as_json", is_flag=True, help="Print one JSON object.")


# ============================================================================ the group
@click.group(cls=_Group, context_settings={"help_option_names": ["-h", "--help"]})
@click.version_option(__version__, "-V", "--version", prog_name="clpc")
def cli() -> None:
    """System identification with LPC (batch) and CLPC (the windowed appraiser).

    \b
    Examples:
      clpc datasets
      clpc identify dryer.csv --input u --output y --order auto --dt 0.08
      clpc track run.csv --input u --output y --out results/
      my_daq | clpc stream --window 201 --cluster 12
    """  # noqa: D301


# ============================================================================ identify
@cli.command()
@click.argument("file", type=click.Path(dir_okay=False))
@_COLUMNS
@click.option(
    "--order",
    "-n",
    type=_OrderType(),
    default="2",
    show_default=True,
    help="Model order N (na = nb = N), or 'auto' (see --criterion, over 1..--max-order).",
)
@click.option(
    "--max-order",
    type=click.IntRange(min=1),
    default=6,
    show_default=True,
    help="Largest order tried by --order auto.",
)
@click.option(
    "--criterion",
    type=click.Choice(["validation", "bic", "aic", "remark1"]),
    default="validation",
    show_default=True,
    help="How --order auto chooses: held-out 10-step prediction fit on the last third "
    "(validation), BIC, AIC or the paper's Remark 1.",
)
@click.option(
    "--nk", type=click.IntRange(min=0), default=0, show_default=True, help="Input delay in samples."
)
@_METHOD
@click.option(
    "--mimo",
    type=click.Choice(["miso", "paired"]),
    default=None,
    help="Multi-channel structure (default miso; paired = output j on input j).",
)
@_SAMPLING
@_JSON
@click.option(
    "--save",
    type=click.Path(dir_okay=False),
    default=None,
    metavar="MODEL.json",
    help="Save the model (load it again with clpc simulate/compare).",
)
def identify(
    file: str,
    inputs: tuple[str, ...],
    outputs: tuple[str, ...],
    order: int | str,
    max_order: int,
    criterion: str,
    nk: int,
    method: str,
    mimo: str | None,
    dt: float | None,
    time_col: str | None,
    as_json: bool,
    save: str | None,
) -> None:
    """Identify a linear model -B(z)/A(z) from a record with batch LPC.

    Prints the monic transfer function (powers of z^-1), poles and stability, the degree of
    linearity D, the fit % of the free-run simulation and of 1- and 10-step predictions on
    the same data, and whether the data determine the model.

    \b
    Examples:
      clpc identify dryer.csv --input u --output y --order 2 --dt 0.08
      clpc identify run.csv -u torque -y position --order auto --time t --save m.json
      clpc identify arm.csv -u u1 -u u2 -y y1 -y y2 --json
    """  # noqa: D301
    data = _load(file, inputs, outputs, dt, time_col)
    estimator = LPC(nk=nk, method=method, mimo=mimo)  # type: ignore[arg-type]
    selection = None
    if order == "auto":
        selection = select_order(
            data, orders=range(1, max_order + 1), criterion=criterion, estimator=estimator
        )
        order = selection.best
    model = dataclasses.replace(estimator, order=int(order)).fit(data)
    summary = model_summary(model, data)
    if selection is not None:
        summary["order_selection"] = jsonable(
            {
                "criterion": criterion,
                "orders": selection.orders,
                "bic": selection.bic,
                "validation_fit": selection.validation_fit,
                "best": selection.best,
            }
        )
    if save:
        save_model(model, save)
        summary["saved"] = save
    if as_json:
        _echo_json(summary)
        return
    if selection is not None:
        if criterion == "validation":
            values, what = selection.validation_fit, "held-out 10-step fit %, higher is better"
        else:
            values = {"bic": selection.bic, "aic": selection.aic, "remark1": selection.J}[criterion]
            what = f"{criterion.upper()}, lower is better"
        table = ", ".join(f"N={o}: {v:.1f}" for o, v in zip(selection.orders, values, strict=True))
        click.echo(f"order selection ({what}): {table} -> N={selection.best}")
    click.echo(format_model_summary(summary))
    if save:
        click.echo(f"model saved to {save}")


# ============================================================================ track
def _count_rows(path: str) -> int | None:
    """Data lines of an uncompressed text file (for the progress bar), else None."""
    p = Path(path)
    if p.suffix.lower() not in (".csv", ".tsv", ".tab", ".txt", ".dat"):
        return None
    lines = 0
    with p.open("rb") as fh:
        for block in iter(lambda: fh.read(1 << 20), b""):
            lines += block.count(b"\n")
    return max(lines - 1, 1)


class _Clock:
    """Sample time from a time column read in chunks (uniform within ``rtol``)."""

    def __init__(self, name: str, rtol: float = 1e-6) -> None:
        self.name, self.rtol = name, rtol
        self.last: float | None = None
        self.first: float | None = None
        self.dt: float | None = None
        self.seen = 0

    def feed(self, t: np.ndarray) -> None:
        if t.size == 0:
            return
        full = t if self.last is None else np.concatenate([[self.last], t])
        offset = self.seen - (0 if self.last is None else 1)
        steps = np.diff(full)
        if self.dt is None and steps.size:
            self.dt = float(np.median(steps))
        if self.dt is not None and steps.size:
            bad = np.flatnonzero(~(np.abs(steps - self.dt) <= self.rtol * abs(self.dt)))
            if bad.size or self.dt <= 0:
                k = int(bad[0]) if bad.size else 0
                raise DataError(
                    f"time column {self.name!r} is not uniformly increasing at data row "
                    f"{offset + k + 2} ({full[k]:.12g} -> {full[k + 1]:.12g}; expected a step "
                    f"of {self.dt:.12g} s); resample the record onto a uniform grid or use --dt."
                )
        self.first = float(t[0]) if self.first is None else self.first
        self.last = float(t[-1])
        self.seen += t.size


def _record_chunks(
    file: str, columns: list[str | int], chunk_rows: int, show: bool
) -> Iterator[tuple[list[str], np.ndarray]]:
    chunks = iter_table_chunks(file, chunk_rows, columns=columns)
    if not show:
        yield from chunks
        return
    with click.progressbar(length=_count_rows(file) or 0, label="tracking", file=sys.stderr) as bar:
        for names, values in chunks:
            yield names, values
            bar.update(values.shape[0])


@cli.command()
@click.argument("file", type=click.Path(dir_okay=False))
@_COLUMNS
@click.option(
    "--out",
    "out_dir",
    type=click.Path(file_okay=False),
    required=True,
    help="Folder for trace, figures and report (created).",
)
@_APPRAISER
@_SAMPLING
@click.option(
    "--format",
    "fmt",
    type=click.Choice(["csv", "parquet"]),
    default="csv",
    show_default=True,
    help="Format of the trace file.",
)
@click.option(
    "--chunk-rows",
    type=click.IntRange(min=1),
    default=100_000,
    show_default=True,
    help="Rows read from the file at a time.",
)
@click.option(
    "--progress/--no-progress",
    default=None,
    help="Progress bar on standard error (default: only on a terminal).",
)
@click.option(
    "--save",
    type=click.Path(dir_okay=False),
    default=None,
    metavar="MODEL.json",
    help="Save the steady-state model.",
)
def track(
    file: str,
    inputs: tuple[str, ...],
    outputs: tuple[str, ...],
    out_dir: str,
    parameters_size: int,
    window: int,
    cluster: int,
    nk: int,
    sample_time: float | None,
    dt: float | None,
    time_col: str | None,
    method: str,
    gate: bool,
    fmt: str,
    chunk_rows: int,
    progress: bool | None,
    save: str | None,
) -> None:
    """Run the CLPC appraiser over a record (read in chunks) and write a trace and a report.

    Writes OUT/trace.csv (one row per cluster update: theta, monic den/num, D, flags),
    OUT/trace.png, OUT/pz.png, OUT/bode.png and OUT/report.html.

    \b
    Examples:
      clpc track servo.csv -u torque -y position --time t --out run1/
      clpc track big.parquet -u u -y y --dt 0.001 --sample-time 0.01 --out run2/ --progress
    """  # noqa: D301
    _check_dt_time(dt, time_col)
    columns = _keys([*inputs, *outputs, *([time_col] if time_col else [])])
    n_in, n_out = len(inputs), len(outputs)
    show = progress if progress is not None else sys.stderr.isatty()
    clock = _Clock(time_col) if time_col else None
    appraiser: CLPC | None = None
    out = Path(out_dir)
    trace_file = out / f"trace.{fmt}"
    kept = ThinnedTrace()  # bounded memory whatever the record's length
    n_raw = 0
    names: list[str] = []
    with TraceWriter(trace_file) as writer:
        for chunk_names, values in _record_chunks(file, columns, chunk_rows, show):
            names = chunk_names
            if clock is not None:
                clock.feed(values[:, n_in + n_out])
                if appraiser is None and clock.dt is None:
                    raise DataError(
                        f"time column {time_col!r}: the first chunk has one sample; use a "
                        "larger --chunk-rows or --dt."
                    )
            if appraiser is None:
                data_dt = clock.dt if clock is not None else dt
                appraiser = CLPC(
                    parameters_size,
                    window,
                    cluster,
                    sample_time or data_dt,
                    nk=nk,
                    data_sample_time=data_dt,
                    method=method,
                    gate=gate,
                )
            n_raw += values.shape[0]
            part = appraiser.push(values[:, :n_in], values[:, n_in : n_in + n_out])
            if len(part):
                part = dataclasses.replace(
                    part,
                    input_names=tuple(names[:n_in]),
                    output_names=tuple(names[n_in : n_in + n_out]),
                )
                writer.write(part)
                kept.add(part)
    assert appraiser is not None  # iter_table_chunks raises on a file without rows
    needed = window + appraiser.structure.max_lag
    if appraiser.n_samples < needed or not kept.seen:
        trace_file.unlink(missing_ok=True)
        raise DataError(
            f"the record is too short for the window: {appraiser.n_samples} sample(s) "
            f"(of {n_raw} read) but --window {window} with --parameters-size {parameters_size} "
            f"needs at least {needed}; use a smaller --window or a longer record."
        )
    trace = kept.trace()
    settings = {
        "file": file,
        "samples (after decimation)": appraiser.n_samples,
        "updates": kept.seen,
        "updates in figures and summary": f"every {kept.stride}" if kept.stride > 1 else "all",
        **appraiser.config(),
    }
    summary = trace_summary(trace)
    files = [
        trace_file,
        *write_track_report(
            out, trace, title=f"CLPC report: {file}", settings=settings, summary=summary
        ),
    ]
    model, source = steady_state(trace)
    if save and model is None:
        click.echo("no update was accepted: there is no model to save", err=True)
    elif save and model is not None:
        save_model(model, save)
        files.append(Path(save))
    _print_track(summary, source, files)


def _print_track(summary: dict[str, Any], source: str, files: list[Path]) -> None:
    conv = summary["convergence"]
    click.echo(
        f"{summary['updates']} updates: {summary['accepted']} accepted, "
        f"{summary['determined']} determined, {summary['not_enough_data']} with too few rows"
    )
    if summary["D_last"] is not None:
        d_last = ", ".join(f"{d:.6g}" for d in summary["D_last"] if d is not None)
        click.echo(f"D at the last update: {d_last}")
    if conv["converged"]:
        click.echo(
            f"converged at update {conv['update']} (sample {conv['index']}, t = {conv['time']:g} s)"
        )
    else:
        click.echo("did not converge (no quasi-constant phase)")
    for line in summary["findings"]:
        click.echo(f"  {line}")
    if summary["model"] is not None:
        click.echo(f"model ({source}):")
        click.echo(format_model_summary(summary["model"]))
    for f in files:
        click.echo(f"wrote {f}")


# ============================================================================ stream
def _parse_csv(line: str, n_in: int, n_out: int) -> tuple[list[float], list[float]]:
    fields = [f.strip() for f in line.split(",")]
    if len(fields) != n_in + n_out:
        raise ValueError(
            f"expected {n_in + n_out} comma-separated numbers ({n_in} input(s) then "
            f"{n_out} output(s)); got {len(fields)} field(s)"
        )
    values = []
    for i, f in enumerate(fields, 1):
        try:
            values.append(float(f))
        except ValueError:
            raise ValueError(f"field {i} {f!r} is not a number") from None
    _finite(values)
    return values[:n_in], values[n_in:]


def _parse_jsonl(line: str, n_in: int, n_out: int) -> tuple[list[float], list[float]]:
    try:
        obj = json.loads(line)
    except json.JSONDecodeError as exc:
        raise ValueError(f"not valid JSON ({exc.msg})") from None
    if not isinstance(obj, dict) or "u" not in obj or "y" not in obj:
        raise ValueError('expected an object {"u": ..., "y": ...}')
    out = []
    for key, n in (("u", n_in), ("y", n_out)):
        val = obj[key]
        vals = val if isinstance(val, list) else [val]
        if len(vals) != n or not all(
            isinstance(v, (int, float)) and not isinstance(v, bool) for v in vals
        ):
            want = "a number" if n == 1 else f"a list of {n} numbers"
            raise ValueError(f"{key!r} must be {want}; got {val!r}")
        out.append([float(v) for v in vals])
    _finite(out[0] + out[1])
    return out[0], out[1]


def _finite(values: list[float]) -> None:
    for i, v in enumerate(values, 1):
        if not math.isfinite(v):
            raise ValueError(f"value {i} is {v}; samples must be finite")


def _is_header(line: str) -> bool:
    fields = [f.strip() for f in line.split(",")]
    return all(f and not _is_float(f) for f in fields)


def _is_float(text: str) -> bool:
    try:
        float(text)
    except ValueError:
        return False
    return True


@cli.command()
@_APPRAISER
@_DT
@click.option(
    "--inputs",
    "n_in",
    type=click.IntRange(min=1),
    default=1,
    show_default=True,
    help="Number of inputs per sample.",
)
@click.option(
    "--outputs",
    "n_out",
    type=click.IntRange(min=1),
    default=1,
    show_default=True,
    help="Number of outputs per sample.",
)
@click.option(
    "--format",
    "fmt",
    type=click.Choice(["csv", "jsonl"]),
    default="csv",
    show_default=True,
    help='Lines "u1,...,y1,..." or {"u": ..., "y": ...}.',
)
@click.option(
    "--on-error",
    type=click.Choice(["skip", "stop"]),
    default="skip",
    show_default=True,
    help="A malformed line: report it and skip it, or exit 1.",
)
def stream(
    parameters_size: int,
    window: int,
    cluster: int,
    nk: int,
    sample_time: float | None,
    dt: float | None,
    n_in: int,
    n_out: int,
    fmt: str,
    method: str,
    gate: bool,
    on_error: str,
) -> None:
    """Run the appraiser on samples from standard input; one JSON line per cluster update.

    Each input line is one sample: csv "u,y" (or "u1,u2,y1,y2" with --inputs 2
    --outputs 2), or jsonl {"u": 0.1, "y": 2.0} (lists for several channels). Blank lines
    and lines starting with # are ignored, and a first csv line of names is a header. Each
    update is written at once (flushed) with index, time, theta, den, num, D, lambda_min,
    accepted, determined and the other statistics. A malformed line is reported on standard
    error with its line number, then skipped (--on-error skip) or ends the run with exit
    code 1 (--on-error stop).

    \b
    Examples:
      my_daq | clpc stream --window 201 --cluster 12
      tail -f log.jsonl | clpc stream --format jsonl --inputs 2 --outputs 2
    """  # noqa: D301
    appraiser = CLPC(
        parameters_size,
        window,
        cluster,
        sample_time or dt,
        nk=nk,
        data_sample_time=dt,
        method=method,
        gate=gate,
    )
    parse = _parse_csv if fmt == "csv" else _parse_jsonl
    errors = 0
    no = 0  # physical line number (1-based)
    header_possible = fmt == "csv"
    for batch in _stdin_batches():
        us: list[list[float]] = []
        ys: list[list[float]] = []
        for line in batch:
            no += 1
            text = line.strip().lstrip("\ufeff")
            if not text or text.startswith("#"):
                continue
            if header_possible and _is_header(text):
                header_possible = False
                continue
            header_possible = False
            try:
                u, y = parse(text, n_in, n_out)
            except ValueError as exc:
                errors += 1
                msg = f"line {no}: {exc}: {text[:80]!r}"
                if on_error == "stop":
                    _emit(appraiser, us, ys, n_in, n_out)  # the samples before the bad line
                    raise DataError(msg) from None
                click.echo(f"clpc stream: {msg} (skipped)", err=True)
                continue
            us.append(u)
            ys.append(y)
        _emit(appraiser, us, ys, n_in, n_out)
    if errors:
        click.echo(f"clpc stream: {errors} malformed line(s) skipped", err=True)


def _stdin_batches() -> Iterator[list[str]]:
    """Complete lines of standard input, in batches of what has arrived so far.

    ``read1`` returns what the pipe holds (at most 64 KiB) without waiting for more, so a
    slow producer gets its updates at once and a fast one is processed in vectorised batches.
    """
    raw = getattr(sys.stdin, "buffer", None)
    if raw is None or not hasattr(raw, "read1"):  # a text-only stream
        for line in iter(sys.stdin.readline, ""):
            yield [line]
        return
    rest = b""
    while block := raw.read1(1 << 16):
        lines = (rest + block).split(b"\n")
        rest = lines.pop()
        if lines:
            yield [line.decode("utf-8", errors="replace") for line in lines]
    if rest:
        yield [rest.decode("utf-8", errors="replace")]


def _emit(
    appraiser: CLPC, us: list[list[float]], ys: list[list[float]], n_in: int, n_out: int
) -> None:
    """Feed parsed samples to the appraiser; write one JSON line per update, flushed."""
    if not us:
        return
    trace = appraiser.push(np.asarray(us).reshape(-1, n_in), np.asarray(ys).reshape(-1, n_out))
    if len(trace):
        sys.stdout.write(
            "".join(json.dumps(r, allow_nan=False) + "\n" for r in update_records(trace))
        )
        sys.stdout.flush()


# ============================================================================ simulate
def _write_or_print(out: str | None, names: list[str], array: np.ndarray) -> None:
    if out:
        write_table(out, names, array)
        click.echo(f"wrote {out} ({array.shape[0]} rows)", err=True)
        return
    sys.stdout.write(",".join(names) + "\n")
    for start in range(0, array.shape[0], 10_000):
        rows = array[start : start + 10_000].tolist()
        sys.stdout.write("".join(",".join(map(repr, row)) + "\n" for row in rows))
    sys.stdout.flush()


@cli.command()
@click.argument("model_file", metavar="MODEL.json", type=click.Path(dir_okay=False))
@click.argument("file", type=click.Path(dir_okay=False))
@click.option(
    "--input",
    "-u",
    "inputs",
    multiple=True,
    metavar="COL",
    help="Input column(s), in the model's input order (default: the model's names).",
)
@click.option(
    "--out",
    "-o",
    type=click.Path(dir_okay=False),
    default=None,
    help="Write the simulation here (csv, tsv, parquet, npy, npz); default stdout.",
)
def simulate(model_file: str, file: str, inputs: tuple[str, ...], out: str | None) -> None:
    """Simulate a saved model on the input columns of FILE (free run, zero initial state).

    Writes the input columns and one simulated column per output (named OUTPUT_sim).

    \b
    Examples:
      clpc simulate model.json new_inputs.csv --input u --out sim.csv
      clpc simulate model.json new_inputs.csv > sim.csv
    """  # noqa: D301
    model = load_model(model_file)
    cols = _model_columns(model, inputs, "input", "--input")
    table = read_table(file, columns=_keys(cols))
    y_sim = np.asarray(model.simulate(table.data)).reshape(table.n_rows, -1)
    names = [*table.names, *(f"{n}_sim" for n in model.output_names)]
    _write_or_print(out, names, np.hstack([table.data, y_sim]))


# ============================================================================ compare
@cli.command()
@click.argument("model_file", metavar="MODEL.json", type=click.Path(dir_okay=False))
@click.argument("file", type=click.Path(dir_okay=False))
@click.option(
    "--input",
    "-u",
    "inputs",
    multiple=True,
    metavar="COL",
    help="Input column(s) (default: the model's input names).",
)
@click.option(
    "--output",
    "-y",
    "outputs",
    multiple=True,
    metavar="COL",
    help="Measured output column(s) (default: the model's output names).",
)
@click.option(
    "--k",
    "k",
    type=click.IntRange(min=1),
    default=None,
    help="Compare k-step-ahead predictions (default: free-run simulation).",
)
@_SAMPLING
@click.option(
    "--plot",
    type=click.Path(dir_okay=False),
    default=None,
    metavar="PNG",
    help="Also plot measured vs model to this PNG file.",
)
@_JSON
def compare(
    model_file: str,
    file: str,
    inputs: tuple[str, ...],
    outputs: tuple[str, ...],
    k: int | None,
    dt: float | None,
    time_col: str | None,
    plot: str | None,
    as_json: bool,
) -> None:
    """Compare a saved model with measured data: fit % of simulation or k-step prediction.

    The first max-lag samples give the initial conditions; the fit % (100 = perfect,
    0 = as good as the mean) is computed over the rest.

    \b
    Examples:
      clpc compare model.json validation.csv --input uVal --output yVal
      clpc compare model.json validation.csv -u uVal -y yVal --k 10 --plot cmp.png
    """  # noqa: D301
    model = load_model(model_file)
    ins = _model_columns(model, inputs, "input", "--input")
    outs = _model_columns(model, outputs, "output", "--output")
    data = _load(file, ins, outs, dt, time_col)
    y_hat, start, fit = model_response(model, data.u, data.y, k)
    what = "simulation" if k is None else f"{k}-step prediction"
    result = {
        "file": file,
        "compared": what,
        "first_sample": start,
        "n_samples": data.n_samples,
        "fit": dict(zip(outs, jsonable(fit), strict=True)),
    }
    if plot:
        from clpc.plotting import plot_compare

        plot_compare(data.time, data.y, y_hat, fit, plot, names=outs, label=what)
        result["plot"] = plot
    if as_json:
        _echo_json(result)
        return
    for name, f in result["fit"].items():
        click.echo(
            f"fit of {what}, {name}: {format_fit(f)}  (samples {start}..{data.n_samples - 1})"
        )
    if plot:
        click.echo(f"wrote {plot}")


# ============================================================================ datasets
@cli.command("datasets")
@_JSON
def datasets_cmd(as_json: bool) -> None:
    """List the real measured records shipped with clpc, with their columns and paths.

    \b
    Example:
      clpc identify "$(python -c 'import clpc.datasets as d; print(d.path("dryer"))')" \\
          --input u --output y --dt 0.08
    """  # noqa: D301
    rows = []
    for name, spec in _datasets.DATASETS.items():
        row = {
            "name": name,
            "inputs": list(spec.inputs),
            "outputs": list(spec.outputs),
            "dt": spec.dt,
            "description": spec.description,
            "path": str(_datasets.path(name)),
        }
        if spec.validation is not None:
            row["validation_inputs"] = list(spec.validation[0])
            row["validation_outputs"] = list(spec.validation[1])
        rows.append(row)
    if as_json:
        _echo_json({"datasets": rows})
        return
    for row in rows:
        dt = "dt not given" if row["dt"] is None else f"dt={row['dt']:g} s"
        ins, outs = ",".join(row["inputs"]), ",".join(row["outputs"])
        extra = ""
        if "validation_inputs" in row:
            extra = (
                f"; validation {','.join(row['validation_inputs'])} -> "
                f"{','.join(row['validation_outputs'])}"
            )
        click.echo(f"{row['name']}: {row['description']} ({ins} -> {outs}{extra}; {dt})")
        click.echo(f"    {row['path']}")


# ============================================================================ demo
@cli.command()
@click.option(
    "--out",
    "out_dir",
    type=click.Path(file_okay=False),
    required=True,
    help="Folder for the experiment's figures, tables and report.",
)
@click.option("--quick", is_flag=True, help="A short run (seconds) for a first look.")
@click.option(
    "--duration",
    type=click.FloatRange(min=0, min_open=True),
    default=None,
    help="Simulated time [s] (default: the paper's).",
)
@click.option("--seed", type=int, default=0, show_default=True, help="Random seed.")
@click.option(
    "--method", type=click.Choice(["robust", "paper"]), default="robust", show_default=True
)
@click.option("--json", "as_json", is_flag=True, help="Print the whole summary as JSON.")
def demo(
    out_dir: str, quick: bool, duration: float | None, seed: int, method: str, as_json: bool
) -> None:
    """Run the paper's brushless-servo experiment (simulated) and write its results.

    \b
    Example:
      clpc demo --out demo/ --quick
    """  # noqa: D301
    try:
        from clpc.experiment.run import run_experiment
    except ImportError as exc:
        raise click.ClickException(
            f"the demo needs clpc.experiment, which is not available here ({exc})."
        ) from None
    result = run_experiment(out_dir, duration=duration, quick=quick, seed=seed, method=method)
    if as_json:
        click.echo(json.dumps(jsonable(result), default=str, allow_nan=False))
        return
    runtime = result.get("runtime_s")
    took = f" in {runtime:.1f} s" if isinstance(runtime, (int, float)) else ""
    click.echo(f"motor experiment finished{took}; results in {out_dir}")
    for claim in result.get("claims") or []:
        click.echo(f"  {_claim_text(claim)}")
    figures = result.get("figures") or {}
    written = sorted(p.name for p in Path(out_dir).iterdir() if p.is_file())
    click.echo(f"wrote {len(written)} file(s) ({len(figures)} figure(s)): {', '.join(written)}")


def _claim_text(claim: Any) -> str:
    """One line for a claim of the experiment's summary.

    A claim is a string, or a dict with the paper's statement (``paper``, ``claim`` or
    ``text``) and per-record results ``{"verdict": ...}`` (e.g. ``ramp``, ``rich``).
    """
    if not isinstance(claim, dict):
        return str(claim)
    text = next(
        (str(claim[k]) for k in ("paper", "claim", "text", "statement") if k in claim),
        str(claim.get("id", "")),
    )
    verdicts = [
        f"{k}: {v['verdict']}" for k, v in claim.items() if isinstance(v, dict) and "verdict" in v
    ]
    if isinstance(claim.get("verdict"), (str, bool)):
        verdicts.append(str(claim["verdict"]))
    return f"{text} [{'; '.join(verdicts)}]" if verdicts else text


# ============================================================================ entry point
def main(argv: Sequence[str] | None = None) -> None:
    """Console entry point (``clpc``); ``argv`` defaults to ``sys.argv[1:]``."""
    cli.main(args=list(argv) if argv is not None else None, prog_name="clpc")


if __name__ == "__main__":  # pragma: no cover
    main()
