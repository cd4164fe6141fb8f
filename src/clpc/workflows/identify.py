"""Identify a model from a file: structure and estimator chosen, or the paper's LPC alone."""

from __future__ import annotations

import dataclasses
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any, Literal

import numpy as np

from clpc.core.checks import check_choice, check_int
from clpc.core.compact import compact_repr
from clpc.core.jsonable import jsonable
from clpc.io import save_model
from clpc.lpc import LPC, Identification, OrderSelection, identify, select_delay, select_order
from clpc.lpc.selection import ESTIMATORS
from clpc.model import LinearModel, MimoMode
from clpc.report import model_summary
from clpc.workflows.common import METHODS, Method, RecordSpec, SettingsError

__all__ = ["IdentifyResult", "IdentifySettings", "identify_file"]

#: how ``order="auto"`` chooses the order (see :func:`clpc.lpc.select_order`)
Criterion = Literal["validation", "bic", "aic", "remark1"]
CRITERIA: tuple[Criterion, ...] = ("validation", "bic", "aic", "remark1")


@dataclass(frozen=True)
class IdentifySettings:
    """What :func:`identify_file` fits, and where it saves the model.

    Parameters
    ----------
    record : RecordSpec
        The record and its input/output columns.
    order : int or "auto"
        Model order N (``na = nb = N``), or ``"auto"`` (default) to choose it:
        :func:`clpc.identify` screens ``na`` 1..``max_order`` and ``nb`` 0..``max_order``
        independently; LPC alone (``estimator="lpc"``) chooses N in 1..``max_order`` by
        ``criterion``.
    max_order : int
        Largest order tried by ``order="auto"``.
    criterion : {"validation", "bic", "aic", "remark1"}
        How LPC alone chooses its order (``estimator="lpc"``).
    nk : int or "auto"
        Input delay in samples, or ``"auto"`` (default: 0..``max_delay``).
    max_delay : int
        Largest delay tried by ``nk="auto"``.
    method : {"robust", "paper"}
        LPC solution (``estimator="lpc"`` only).
    mimo : {"miso", "paired"}, optional
        Multi-channel structure.
    save : str, optional
        Save the model to this JSON file.
    na, nb : int, optional
        Separate output / input orders overriding ``order`` (clpc's meaning: ``nb + 1``
        coefficients per input; MATLAB's ``arx`` nb is clpc's ``nb + 1``).
    estimator : {"auto", "arx", "oe", "lpc"}
        ``"auto"`` (default): structure and estimator chosen on held-out data among least
        squares, LPC, output error and subspace (:func:`clpc.identify`); ``"arx"`` or
        ``"oe"``: the same search, keeping that estimator; ``"lpc"``: the paper's LPC alone
        (its order by ``criterion``, its delay by :func:`clpc.lpc.select_delay`), no
        comparison.
    """

    record: RecordSpec
    order: int | Literal["auto"] = "auto"
    max_order: int = 10
    criterion: Criterion = "validation"
    nk: int | Literal["auto"] = "auto"
    method: Method = "robust"
    mimo: MimoMode | None = None
    save: str | None = None
    na: int | None = None
    nb: int | None = None
    estimator: str = "auto"
    max_delay: int = 5

    def __post_init__(self) -> None:
        if self.order != "auto":
            check_int(self.order, "order", 1)
        check_int(self.max_order, "max_order", 1)
        check_choice(self.criterion, "criterion", CRITERIA)
        if self.nk != "auto":
            check_int(self.nk, "nk", 0)
        check_choice(self.method, "method", METHODS)
        for name in ("na", "nb"):
            if getattr(self, name) is not None:
                check_int(getattr(self, name), name, 0 if name == "nb" else 1)
        check_int(self.max_delay, "max_delay", 0)
        check_choice(self.estimator, "estimator", ESTIMATORS)
        if self.compares:
            if self.method != "robust":
                raise SettingsError(
                    f"method={self.method!r} applies to LPC alone; the estimator comparison "
                    "uses the default LPC. Give estimator 'lpc' for the paper's LPC alone."
                )
            if self.criterion != "validation":
                raise SettingsError(
                    f"criterion={self.criterion!r} applies to LPC alone; the estimator "
                    "comparison chooses on held-out data. Give estimator 'lpc' for LPC alone."
                )
        elif self.order == "auto" and (self.na is not None or self.nb is not None):
            raise SettingsError("order auto chooses na = nb = N; do not also give na or nb.")

    @property
    def compares(self) -> bool:
        """Whether :func:`identify_file` runs :func:`clpc.identify` (not LPC alone)."""
        return self.estimator != "lpc"


@compact_repr
@dataclass(frozen=True)
class IdentifyResult:
    """The outcome of :func:`identify_file`.

    Attributes
    ----------
    model : LinearModel
        The fitted model.
    summary : dict
        :func:`clpc.report.model_summary` of the model on the record (JSON-safe), with
        ``order_selection`` and ``saved`` when they apply.
    selection : OrderSelection or None
        The order selection table (``order="auto"`` only).
    criterion : str
        The criterion that chose the order.
    comparison : Identification or None
        The estimator comparison (:func:`clpc.identify`), when the settings ask for it.
    """

    model: LinearModel
    summary: dict[str, Any]
    selection: OrderSelection | None
    criterion: Criterion
    comparison: Identification | None = None

    def scores(self) -> np.ndarray:
        """The criterion's value per order of :attr:`selection`.

        Returns
        -------
        ndarray
            Held-out fit % (``validation``, higher is better), else BIC, AIC or the paper's
            ``J`` (lower is better).

        Raises
        ------
        ValueError
            The order was given, not selected.
        """
        sel = self.selection
        if sel is None:
            raise ValueError("the order was given, not selected: there are no scores.")
        if self.criterion == "validation":
            return np.asarray(sel.validation_fit)
        return {"bic": sel.bic, "aic": sel.aic, "remark1": sel.J}[self.criterion]


def identify_file(
    settings: IdentifySettings, progress: Callable[[str], None] | None = None
) -> IdentifyResult:
    """Identify a linear model ``-B(z)/A(z)`` from a record (:func:`clpc.identify`, or LPC alone).

    Parameters
    ----------
    settings : IdentifySettings
        Record, order (or its selection), structure; where to save the model.
    progress : callable, optional
        Called with one line of text per stage of the comparison (:func:`clpc.identify`).

    Returns
    -------
    IdentifyResult
        Model, summary, and the estimator comparison or (LPC alone) the order selection.

    Raises
    ------
    clpc.DataError, clpc.ModelError
        Unreadable record; data that do not determine a model.
    """
    data = settings.record.load()
    if settings.compares:
        return _compare(settings, data, progress)
    nk = settings.nk
    delay = None
    if nk == "auto":
        first = 2 if settings.order == "auto" else settings.order
        delays = range(settings.max_delay + 1)
        delay = select_delay(
            data, delays=delays, estimator=LPC(order=first, method=settings.method)
        )
        nk = delay.best
    estimator = LPC(
        nk=nk, method=settings.method, mimo=settings.mimo, na=settings.na, nb=settings.nb
    )
    selection = None
    order = settings.order
    if order == "auto":
        orders = range(1, settings.max_order + 1)
        selection = select_order(
            data, orders=orders, criterion=settings.criterion, estimator=estimator
        )
        order = selection.best
    model = dataclasses.replace(estimator, order=int(order)).fit(data)
    summary = model_summary(model, data)
    if selection is not None:
        summary["order_selection"] = jsonable(
            {
                "criterion": settings.criterion,
                "orders": selection.orders,
                "bic": selection.bic,
                "validation_fit": selection.validation_fit,
                "free_run_fit": selection.free_run_fit,
                "kstep_fit": selection.kstep_fit,
                "stability": list(selection.stability),
                "horizon": selection.horizon,
                "best": selection.best,
                "reason": selection.reason,
            }
        )
    if delay is not None:
        summary["delay_selection"] = jsonable(
            {"delays": delay.delays, "validation_fit": delay.validation_fit, "best": delay.best}
        )
    if settings.save:
        save_model(model, settings.save)
        summary["saved"] = settings.save
    return IdentifyResult(model, summary, selection, settings.criterion)


def _compare(
    settings: IdentifySettings, data: Any, progress: Callable[[str], None] | None
) -> IdentifyResult:
    """:func:`identify_file` with the estimator comparison (:func:`clpc.identify`)."""
    found = identify(
        data,
        estimator=settings.estimator,
        order=settings.order,
        na=settings.na,
        nb=settings.nb,
        nk=settings.nk,
        max_order=settings.max_order,
        max_delay=settings.max_delay,
        mimo=settings.mimo,
        progress=progress,
    )
    summary = model_summary(found.model, data)
    s = found.structure
    summary["comparison"] = jsonable(
        {
            "estimators": list(found.estimators),
            "structure": {"na": s.na, "nb": s.nb, "nk": s.nk},
            "horizon": found.horizon,
            "table": found.table,
            "screened": len(found.screen),
            "reason": found.reason,
            "eiv_violated": None if found.eiv is None else found.eiv.violated,
        }
    )
    if settings.save:
        save_model(found.model, settings.save)
        summary["saved"] = settings.save
    return IdentifyResult(found.model, summary, None, settings.criterion, found)
