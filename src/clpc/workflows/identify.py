"""Batch LPC on a file: identify a model (its order given or selected)."""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from typing import Any, Literal

import numpy as np

from clpc.core.checks import check_choice, check_int
from clpc.core.jsonable import jsonable
from clpc.io import save_model
from clpc.lpc import LPC, OrderSelection, select_order
from clpc.model import LinearModel, MimoMode
from clpc.report import model_summary
from clpc.report.identify import write_identify_report
from clpc.workflows.common import METHODS, Method, RecordSpec

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
        Model order N (``na = nb = N``), or ``"auto"`` to choose it over 1..``max_order``.
    max_order : int
        Largest order tried by ``order="auto"``.
    criterion : {"validation", "bic", "aic", "remark1"}
        How ``order="auto"`` chooses.
    nk : int
        Input delay in samples.
    method : {"robust", "paper"}
        LPC solution.
    mimo : {"miso", "paired"}, optional
        Multi-channel structure.
    save : str, optional
        Save the model to this JSON file.
    report : str, optional
        Write an HTML report (model, parameter uncertainty, residual analysis, Bode plot)
        to this file.
    """

    record: RecordSpec
    order: int | Literal["auto"] = 2
    max_order: int = 6
    criterion: Criterion = "validation"
    nk: int = 0
    method: Method = "robust"
    mimo: MimoMode | None = None
    save: str | None = None
    report: str | None = None

    def __post_init__(self) -> None:
        if self.order != "auto":
            check_int(self.order, "order", 1)
        check_int(self.max_order, "max_order", 1)
        check_choice(self.criterion, "criterion", CRITERIA)
        check_int(self.nk, "nk", 0)
        check_choice(self.method, "method", METHODS)


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
    """

    model: LinearModel
    summary: dict[str, Any]
    selection: OrderSelection | None
    criterion: Criterion

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


def identify_file(settings: IdentifySettings) -> IdentifyResult:
    """Identify a linear model ``-B(z)/A(z)`` from a record with batch LPC.

    Parameters
    ----------
    settings : IdentifySettings
        Record, order (or its selection), structure; where to save the model.

    Returns
    -------
    IdentifyResult
        Model, summary and order selection.

    Raises
    ------
    clpc.DataError, clpc.ModelError
        Unreadable record; data that do not determine a model.
    """
    data = settings.record.load()
    estimator = LPC(nk=settings.nk, method=settings.method, mimo=settings.mimo)
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
    if settings.save:
        save_model(model, settings.save)
        summary["saved"] = settings.save
    if settings.report:
        summary["report"] = str(write_identify_report(settings.report, model, data, summary))
    return IdentifyResult(model, summary, selection, settings.criterion)
