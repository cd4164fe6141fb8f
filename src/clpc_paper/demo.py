"""``clpc demo``: the paper's brushless-servo experiment, run and written to a folder.

The command line's ``clpc demo`` imports this module when it runs (the library never does).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

from clpc_paper.experiment.run import run_experiment

__all__ = ["DemoResult", "run_demo"]


@dataclass(frozen=True)
class DemoResult:
    """The outcome of :func:`run_demo`.

    Attributes
    ----------
    summary : dict
        The experiment's summary (see :func:`clpc_paper.experiment.run_experiment`).
    written : list of str
        Names of the files in the output folder, sorted.
    """

    summary: dict[str, Any]
    written: list[str]


def run_demo(
    out_dir: str,
    *,
    quick: bool = False,
    duration: float | None = None,
    seed: int = 0,
    method: str = "robust",
) -> DemoResult:
    """Run the paper's brushless-servo experiment (simulated) and write its results.

    Parameters
    ----------
    out_dir : str
        Folder for the figures, tables and report.
    quick : bool
        A short run (seconds) for a first look.
    duration : float, optional
        Simulated time [s] (default: the paper's).
    seed : int
        Random seed.
    method : {"robust", "paper"}
        LPC solution.

    Returns
    -------
    DemoResult
        Summary and the files written.
    """
    summary = run_experiment(out_dir, duration=duration, quick=quick, seed=seed, method=method)
    written = sorted(p.name for p in Path(out_dir).iterdir() if p.is_file())
    return DemoResult(summary, written)
