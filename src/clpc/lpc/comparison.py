"""Candidates of :func:`clpc.identify` fitted and scored at rolling origins; the delay scan.

See :mod:`clpc.lpc.selection` for the rules and :mod:`clpc.lpc.choice` for the choice.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from clpc.data import DataError, IOData
from clpc.lpc import assessment, heldout
from clpc.lpc.arx import ARX
from clpc.lpc.choice import best_row, ranked
from clpc.lpc.estimator import LPC
from clpc.lpc.oe import OE
from clpc.lpc.uncertainty import with_covariance, without_covariance
from clpc.model import LinearModel, ModelError

__all__ = [
    "MAKERS",
    "ORIGINS",
    "candidate",
    "choose_delay",
    "final_model",
    "fold_fits",
    "grid",
    "rolling_origin",
    "stable_refits",
]

#: The first two rolling origins, as shares of the record (the last: ``1 - f``).
ORIGINS = (1.0 / 2.0, 2.0 / 3.0)
MAKERS = {"lpc": LPC, "arx": ARX, "oe": OE}


def _cheap(**kw: Any) -> dict[str, Any]:
    """Settings of a candidate fit: no covariance, no held-out assessment (scored here)."""
    return kw | {"uncertainty": False, "assess": False}


def rolling_origin(data: IOData, fraction: float) -> list[tuple[IOData, IOData]]:
    """The (fitted, scored) parts at the rolling origins ``1/2, 2/3, 1 - fraction``.

    At each origin the model is fitted on every sample before it and scored on every sample
    after it, as the final model is fitted on the record and used after it.
    """
    n = data.n_samples
    cuts = [round(share * n) for share in ORIGINS] + [n - round(fraction * n)]
    return [(data[:o], data[o:]) for o in cuts]


def fold_fits(model: LinearModel, seg: IOData, k: int) -> tuple[np.ndarray, np.ndarray]:
    """Free-run and ``k``-step fit % per output of ``model`` on ``seg``."""
    s = model.structure
    start, n_lag = s.max_lag, s.nk + s.nb
    with np.errstate(all="ignore"):
        sim = np.asarray(
            model.simulate(
                seg.u[start:],
                y_init=seg.y[start - s.na : start],
                u_init=seg.u[start - n_lag : start] if n_lag else None,
            )
        ).reshape(-1, model.n_outputs)
        pred = np.asarray(model.predict(seg.u, seg.y, k=k)).reshape(seg.y.shape)
    first = start + k - 1
    free = [heldout.fit_percent(seg.y[start:, j], sim[:, j]) for j in range(seg.n_outputs)]
    kst = [heldout.fit_percent(seg.y[first:, j], pred[first:, j]) for j in range(seg.n_outputs)]
    return np.array(free), np.array(kst)


def candidate(
    name: str, order: int, nk: int, mimo: str | None, where: tuple[list[Any], int]
) -> list[dict[str, Any]]:
    """One candidate fitted and scored in every fold: one row per output."""
    folds, k = where
    n_out = folds[0][0].n_outputs
    base = {"estimator": name, "order": order, "nk": nk}
    windows, kst, note = np.zeros((len(folds), n_out)), np.zeros(n_out), ""
    radius = np.zeros(n_out)
    try:
        for w, (est, val) in enumerate(folds):
            model = MAKERS[name](**_cheap(order=order, nk=nk, mimo=mimo)).fit(est)
            radius = np.maximum(radius, [np.max(np.abs(model.poles(j))) for j in range(n_out)])
            windows[w], p = fold_fits(model, val, k)
            kst = kst + p / len(folds)
    except (ModelError, DataError, np.linalg.LinAlgError) as exc:
        windows, kst, note = (
            np.full((len(folds), n_out), -math.inf),
            np.full(n_out, -math.inf),
            str(exc),
        )
        radius = np.full(n_out, math.nan)
    free = windows.mean(axis=0)
    names = folds[0][0].output_names
    return [
        base
        | {"output": names[j], "free_run": float(free[j]), "kstep": float(kst[j])}
        | {"windows": [float(v) for v in windows[:, j]]}
        | {"stability": _stability(float(radius[j])), "max_pole": float(radius[j])}
        | {"chosen": False, "note": note}
        for j in range(n_out)
    ]


def _stability(radius: float) -> str:
    """The words of :func:`clpc.lpc.heldout.stability` for a largest pole radius."""
    if math.isnan(radius):
        return "no model"
    if radius > 1.0 + heldout.UNIT_CIRCLE_TOL:
        return "unstable"
    return "integrating" if radius >= 1.0 - heldout.UNIT_CIRCLE_TOL else "stable"


def stable_refits(
    data: IOData, rows: list[dict[str, Any]], picks: list[int], mimo: str | None
) -> list[int]:
    """Per output, the first ranked candidate whose refit on the whole record is strictly stable.

    A candidate stable in every window may still be unstable when refitted on the whole
    record; then the next one of the same order (:func:`ranked`) is taken and the row's
    ``note`` says why. OE is stable by construction and is not refitted here. When no
    refit is strictly stable the pick is kept.
    """
    radius: dict[str, np.ndarray] = {}
    out = []
    for j, i in enumerate(picks):
        same = [x for x, r in enumerate(rows) if r["order"] == rows[i]["order"]]
        pool = ranked(rows, [x for x in same if rows[x]["output"] == rows[i]["output"]])
        pool = pool[pool.index(i) :]
        for x in pool:
            name = rows[x]["estimator"]
            if name != "oe" and name not in radius:
                settings = _cheap(order=rows[x]["order"], nk=rows[x]["nk"], mimo=mimo)
                try:
                    m = MAKERS[name](**settings).fit(data)
                    radius[name] = np.array(
                        [np.max(np.abs(m.poles(o))) for o in range(m.n_outputs)]
                    )
                except (ModelError, DataError, np.linalg.LinAlgError):
                    radius[name] = np.full(data.n_outputs, math.inf)
            if name == "oe" or radius[name][j] < 1.0:
                out.append(x)
                break
            rows[x]["note"] = (
                f"refitted on the whole record: unstable (largest pole {radius[name][j]:.4g})"
            )
        else:
            out.append(i)
    return out


def grid(
    folds: list[Any], orders: list[int], nk: int, opts: tuple[str | None, int]
) -> list[dict[str, Any]]:
    """Rows of every estimator and order at delay ``nk`` (:func:`candidate`)."""
    mimo, k = opts
    return [
        row
        for name in ("lpc", "arx", "oe")
        for n in orders
        for row in candidate(name, n, nk, mimo, (folds, k))
    ]


def choose_delay(
    folds: list[Any], orders: list[int], delays: list[int], opts: tuple[str | None, int]
) -> tuple[int, list[dict[str, Any]], list[dict[str, Any]]]:
    """The delay chosen (see :mod:`clpc.lpc.selection`), the scan and the chosen rows."""
    scan, tables = [], {}
    for nk in delays:
        rows = tables[nk] = grid(folds, orders, nk, opts)
        outs = sorted({r["output"] for r in rows})
        best = [
            best_row(rows, [i for i, r in enumerate(rows) if r["output"] == o])[0] for o in outs
        ]
        scan.append({"nk": nk, "free_run": float(np.mean([rows[i]["free_run"] for i in best]))})
    chosen = int(max(scan, key=lambda r: r["free_run"])["nk"])  # the first of equals
    return chosen, scan, tables[chosen]


def final_model(
    data: IOData,
    chosen: tuple[str, ...],
    order: int,
    nk: int,
    mimo: str | None,
    evidence: bool = True,
) -> LinearModel:
    """The chosen estimators refitted on the whole record (one model, one row per output).

    One estimator: its own fit, with its covariance and evidence. A mix over the outputs:
    each output's row, covariance (when every estimator stored one) and noise model
    (``info["noise_model"]`` per output) from its estimator's fit; then the held-out fit and
    residual tests of the mixed model (:func:`clpc.lpc.assessment.assess`, refitting the same
    mix). ``evidence=False``: neither covariance nor assessment (the refit).
    """
    flags = {"uncertainty": evidence, "assess": evidence}
    if len(set(chosen)) == 1:
        return MAKERS[chosen[0]](order=order, nk=nk, mimo=mimo, **flags).fit(data)
    fits = {}
    for name in set(chosen):
        kw: dict[str, Any] = {"order": order, "nk": nk, "mimo": mimo, **flags, "assess": False}
        fits[name] = (LPC(**kw, cancel=False) if name == "lpc" else MAKERS[name](**kw)).fit(data)
    first = fits[chosen[0]]
    model = LinearModel(
        theta=np.array([fits[name].theta_matrix[j] for j, name in enumerate(chosen)]),
        structure=first.structure,
        n_inputs=first.n_inputs,
        mode=first.mode,
        c=np.array([fits[name].c[j] for j, name in enumerate(chosen)]),
        dt=first.dt,
        input_names=first.input_names,
        output_names=first.output_names,
        info={
            "method": "identify",
            "estimators": list(chosen),
            "noise_model": [
                "output-error" if name == "oe" else "equation-error" for name in chosen
            ],
        },
    )
    if not evidence:
        return model
    notes = [
        f"{name.upper()}: {fits[name].info.get('covariance_note', 'no covariance')}"
        for name in set(chosen)
        if "covariance" not in fits[name].info
    ]
    if notes:
        model = without_covariance(model, "; ".join(sorted(notes)))
    else:  # a mix has two outputs or more: info arrays keep their output axis
        cov = np.stack([fits[name].info["covariance"][j] for j, name in enumerate(chosen)])
        dof = [fits[name].info["covariance_dof"][j] for j, name in enumerate(chosen)]
        how = ", ".join(
            f"{out}: {fits[name].info['covariance_method']}"
            for out, name in zip(first.output_names, chosen, strict=True)
        )
        model = with_covariance(model, cov, np.array(dof), f"per output ({how})")

    def refit(part: IOData) -> LinearModel:
        return final_model(part, chosen, order, nk, mimo, evidence=False)

    return assessment.assess(model, data, refit)
