"""``clpc datasets`` (the shipped records) and ``clpc demo`` (the paper's experiment).

The demo runs :mod:`clpc_paper`, the section VI experiment built on the library; only
:func:`demo` imports it, when it runs.
"""

from __future__ import annotations

import warnings
from typing import Any

import click

from clpc.cli.errors import ClpcCommand
from clpc.cli.options import json_option, method_option, out_dir_option
from clpc.cli.output import echo_json
from clpc.workflows import DatasetEntry, list_datasets

__all__ = ["datasets", "demo"]


def _dataset_lines(entry: DatasetEntry) -> list[str]:
    dt = "dt not given" if entry.dt is None else f"dt={entry.dt:g} s"
    ins, outs = ",".join(entry.inputs), ",".join(entry.outputs)
    extra = ""
    if entry.validation_inputs is not None and entry.validation_outputs is not None:
        extra = (
            f"; validation {','.join(entry.validation_inputs)} -> "
            f"{','.join(entry.validation_outputs)}"
        )
    return [
        f"{entry.name}: {entry.description} ({ins} -> {outs}{extra}; {dt})",
        f"    {entry.path}",
    ]


@click.command("datasets", cls=ClpcCommand)
@json_option()
def datasets(as_json: bool) -> None:
    """List the real measured records shipped with clpc, with their columns and paths.

    \b
    Example:
      clpc identify "$(python -c 'import clpc.datasets as d; print(d.path("dryer"))')" \\
          --input u --output y --dt 0.08
    """  # noqa: D301
    entries = list_datasets()
    if as_json:
        echo_json({"datasets": [e.to_dict() for e in entries]})
        return
    for entry in entries:
        for line in _dataset_lines(entry):
            click.echo(line)


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


@click.command(cls=ClpcCommand)
@out_dir_option("Folder for the experiment's figures, tables and report.")
@click.option("--quick", is_flag=True, help="A short run (seconds) for a first look.")
@click.option(
    "--duration",
    type=click.FloatRange(min=0, min_open=True),
    default=None,
    help="Simulated time [s] (default: the paper's).",
)
@click.option("--seed", type=int, default=0, show_default=True, help="Random seed.")
@method_option(help=None)
@json_option("Print the whole summary as JSON.")
def demo(
    out_dir: str, quick: bool, duration: float | None, seed: int, method: str, as_json: bool
) -> None:
    """Run the paper's brushless-servo experiment (simulated) and write its results.

    \b
    Example:
      clpc demo --out demo/ --quick
    """  # noqa: D301
    try:  # the experiment is an application of the library, imported only here
        from clpc_paper.demo import run_demo
    except ImportError as exc:
        raise ImportError(
            f"the demo needs clpc_paper, which is not available here ({exc})."
        ) from None
    with warnings.catch_warnings(record=True) as caught:  # one plain line each, no source
        warnings.simplefilter("always", UserWarning)
        result = run_demo(out_dir, duration=duration, quick=quick, seed=seed, method=method)
    for w in caught:
        click.echo(f"clpc demo: warning: {w.message}", err=True)
    summary = result.summary
    if as_json:
        echo_json(summary, default=str)
        return
    runtime = summary.get("runtime_s")
    took = f" in {runtime:.1f} s" if isinstance(runtime, (int, float)) else ""
    click.echo(f"motor experiment finished{took}; results in {out_dir}")
    for claim in summary.get("claims") or []:
        click.echo(f"  {_claim_text(claim)}")
    written = result.written
    figures = [name for name in written if name.endswith(".png")]
    click.echo(f"wrote {len(written)} file(s) ({len(figures)} figure(s)): {', '.join(written)}")
