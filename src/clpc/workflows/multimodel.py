"""``clpc multimodel``: fit a :class:`clpc.MultiModel` to a record, save it, draw it."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from clpc.analysis.metrics import fit_percent
from clpc.core.jsonable import jsonable
from clpc.lpc import ARX
from clpc.multimodel import MultiModel
from clpc.plotting.multimodel import plot_multimodel
from clpc.workflows.common import RecordSpec

__all__ = ["MultiModelSettings", "multimodel_file"]


@dataclass(frozen=True)
class MultiModelSettings:
    """What ``clpc multimodel`` was asked for.

    Parameters
    ----------
    record : RecordSpec
        The data file and its columns (one output).
    order : int
        ``na = nb = order`` of every local model.
    n_models : int, optional
        Number of local models (None: chosen by held-out free run).
    max_models : int
        Largest number tried.
    schedule : str
        ``"y"``, ``"u"`` or a lag-vector column (digits).
    save, figure : str, optional
        Model JSON and figure PNG to write.
    """

    record: RecordSpec
    order: int = 2
    n_models: int | None = None
    max_models: int = 8
    schedule: str = "y"
    save: str | None = None
    figure: str | None = None


def multimodel_file(settings: MultiModelSettings) -> dict[str, Any]:
    """Fit, optionally save and draw; return a JSON-safe summary.

    The summary holds the multi-model's diagnostics, its local models (monic ``den``,
    ``num``, DC gain, poles, whether the guard replaced them) and the free-run and 10-step
    fits on the record beside one global least-squares model of the same order.
    """
    data = settings.record.load()
    sched: Any = int(settings.schedule) if settings.schedule.isdigit() else settings.schedule
    mm = MultiModel(
        order=settings.order,
        n_models=settings.n_models,
        max_models=settings.max_models,
        schedule=sched,
    ).fit(data)
    u, y = data.u, data.y[:, 0]
    na = mm.structure.max_lag
    ls = ARX(order=settings.order, uncertainty=False, assess=False).fit(data)  # fits only

    def fits(model: Any) -> dict[str, float]:
        sim = np.asarray(model.simulate(u[na:], y_init=y[:na], u_init=u[:na])).ravel()
        pred = np.asarray(model.predict(u, y, k=10)).ravel()
        return {
            "free_run": fit_percent(y[na:], sim),
            "k10": fit_percent(y[na + 10 :], pred[na + 10 :]),
        }

    summary: dict[str, Any] = {
        "file": settings.record.file,
        "n_samples": data.n_samples,
        "dt": data.dt,
        **mm.diagnostics,
        "centres": mm.centres,
        "widths": mm.widths,
        "local_models": [
            {
                "den": m.den,
                "num": m.num,
                "dc_gain": float(m.dc_gain()[0, 0]),
                "poles": m.poles(),
                "estimator": m.info["estimator"],
                "replaced": m.info["replaced"],
            }
            for m in mm.local_models
        ],
        "fit_on_record": {"multimodel": fits(mm), "global_least_squares": fits(ls)},
    }
    if settings.save:
        mm.save(settings.save)
        summary["saved"] = settings.save
    if settings.figure:
        plot_multimodel(mm, settings.figure)
        summary["figure"] = settings.figure
    return dict(jsonable(summary))
