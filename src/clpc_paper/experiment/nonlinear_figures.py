"""The crank servo's figure of validation free runs against the plant.

The multi-model's own figure is :func:`clpc.plotting.plot_multimodel`. Headless like
:mod:`clpc_paper.experiment.figures`: a :class:`matplotlib.figure.Figure` on the Agg canvas,
matplotlib imported only inside the function.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

__all__ = ["fig_fits"]


def fig_fits(
    path: Path, rec: Any, models: dict[str, Any], start: int, name: str, quick: bool
) -> str:
    """Validation free runs of the global LS model and the multi-model against the plant."""
    from matplotlib.figure import Figure

    u, y = rec.command, rec.position
    n = min(y.size - start, 3000 if not quick else 1500)
    t = np.arange(start, start + n) * rec.sample_time
    fig = Figure(figsize=(6.4, 3.6), layout="constrained")
    ax = fig.subplots()
    ax.plot(t, y[start : start + n], "k", lw=1.2, label="measured position")
    for key, style in (("global_ls", "C3"), ("multimodel", "C0")):
        m = models[key]
        sim = m.simulate(u[start:], y_init=y[start - 2 : start], u_init=u[start - 2 : start])
        ax.plot(t, sim[:n], style, lw=0.9, label=key.replace("_", " ") + " (free run)")
    ax.set_xlabel("time [s]")
    ax.set_ylabel("position [rad]")
    ax.set_title(f"Crank servo ({name}): validation levels", fontsize=10)
    ax.legend(fontsize=7)
    fig.savefig(path, dpi=110 if not quick else 80)
    return path.name
