"""Batch LPC on a file: identify a model (its order given or selected)."""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from typing import Any, Literal

import numpy as np

from clpc.core.checks import check_choice, check_int
from clpc.core.jsonable import jsonable
from clpc.io import save_model
from clpc.lpc import LPC, Identification, OrderSelection, identify, select_order
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
        Model order N (``na = nb = N``), or ``"auto"`` to choose it over 1..``max_order``.
    max_order : int
        Largest order tried by ``order="auto"``.
    criterion : {"validation", "bic", "aic", "remark1"}
        How ``order="auto"`` chooses.
    nk : int or "auto"
        Input delay in samples, or ``"auto"`` (0..4, :func:`clpc.identify`).
    method : {"robust", "paper"}
        LPC solution (without ``estimator`` only).
    mimo : {"miso", "paired"}, optional
        Multi-channel structure.
    save : str, optional
        Save the model to this JSON file.
    na, nb : int, optional
        Separate output / input orders overriding ``order`` (clpc's meaning: ``nb + 1``
        coefficients per input; MATLAB's ``arx`` nb is clpc's ``nb + 1``).
    estimator : {"auto", "lpc", "arx", "oe"}, optional
        Compare LPC, least squares and output error on held-out data (:func:`clpc.identify`)
        and keep this one (``"auto"``: the best). ``None`` (default): LPC alone, as before,
        unless ``nk="auto"`` (then ``"lpc"`` with the comparison).
    """

    record: RecordSpec
    order: int | Literal["auto"] = 2
    max_order: int = 6
    criterion: Criterion = "validation"
    nk: int | Literal["auto"] = 0
    method: Method = "robust"
    mimo: MimoMode | None = None
    save: str | None = None
    na: int | None = None
    nb: int | None = None
    estimator: str | None = None

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
        if self.order == "auto" and (self.na is not None or self.nb is not None):
            raise SettingsError("order auto chooses na = nb = N; do not also give na or nb.")
        if self.estimator is not None:
            check_choice(self.estimator, "estimator", ESTIMATORS)
        if self.compares:
            if self.na is not None or self.nb is not None:
                raise SettingsError(
                    "na/nb apply to LPC alone; the estimator comparison (estimator or "
                    "nk='auto') fits na = nb = N. Give --order instead, or drop the comparison."
                )
            if self.method != "robust":
                raise ValueError(
                    f"method={self.method!r} applies to LPC alone; the estimator comparison "
                    "(estimator or nk='auto') uses the default LPC. Drop one of the two."
                )
            if self.order == "auto" and self.criterion != "validation":
                raise ValueError(
                    f"criterion={self.criterion!r}: the estimator comparison chooses the order "
                    "on held-out data only (criterion 'validation')."
                )

    @property
    def compares(self) -> bool:
        """Whether :func:`identify_file` runs :func:`clpc.identify` (the comparison)."""
        return self.estimator is not None or self.nk == "auto"


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
    if settings.compares:
        return _compare(settings, data)
    assert settings.nk != "auto"
    estimator = LPC(
        nk=settings.nk, method=settings.method, mimo=settings.mimo, na=settings.na, nb=settings.nb
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
    if settings.save:
        save_model(model, settings.save)
        summary["saved"] = settings.save
    return IdentifyResult(model, summary, selection, settings.criterion)


def _compare(settings: IdentifySettings, data: Any) -> IdentifyResult:
    """:func:`identify_file` with the estimator comparison (:func:`clpc.identify`)."""
    found = identify(
        data,
        estimator=settings.estimator or "lpc",
        order=settings.order,
        nk=settings.nk,
        max_order=settings.max_order,
        mimo=settings.mimo,
    )
    summary = model_summary(found.model, data)
    summary["comparison"] = jsonable(
        {
            "estimators": list(found.estimators),
            "order": found.order,
            "nk": found.nk,
            "horizon": found.horizon,
            "table": found.table,
            "delays": found.delays,
            "reason": found.reason,
            "eiv_violated": None if found.eiv is None else found.eiv.violated,
        }
    )
    if settings.save:
        save_model(found.model, settings.save)
        summary["saved"] = settings.save
    return IdentifyResult(found.model, summary, None, settings.criterion, found)
