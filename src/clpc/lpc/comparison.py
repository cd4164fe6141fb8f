"""Candidates of :func:`clpc.identify` fitted and scored at rolling origins; the final refit.

See :mod:`clpc.lpc.selection` for the rules and :mod:`clpc.lpc.choice` for the choice.
"""

from __future__ import annotations

import math
from dataclasses import replace
from typing import Any

import numpy as np

from clpc.data import DataError, IOData
from clpc.lpc import assessment, heldout
from clpc.lpc.arx import ARX
from clpc.lpc.choice import ranked
from clpc.lpc.estimator import LPC
from clpc.lpc.oe import OE
from clpc.lpc.subspace import Subspace
from clpc.lpc.uncertainty import with_covariance, without_covariance
from clpc.model import LinearModel, ModelError
from clpc.model.structure import Structure

__all__ = [
    "CANDIDATE_NFEV",
    "MAKERS",
    "ORIGINS",
    "SEARCH_SAMPLES",
    "candidate",
    "final_model",
    "fold_fits",
    "key",
    "make",
    "rolling_origin",
    "stable_refits",
    "subspace_structure",
]

#: The first two rolling origins, as shares of the record (the last: ``1 - f``).
ORIGINS = (1.0 / 2.0, 2.0 / 3.0)
MAKERS: dict[str, Any] = {"lpc": LPC, "arx": ARX, "oe": OE, "subspace": Subspace}
#: OE's evaluations per start in a candidate fit (scored, not kept; the final fit runs to
#: its tolerance). Its Levenberg-Marquardt search creeps along a curved valley for the last
#: few % of the cost (a 3,000-sample 4th-order record: 110 evaluations from the closed-form
#: start; the cost 6 % above the optimum after 40, 2 % after 60, 1e-7 after 75).
CANDIDATE_NFEV = 60
#: Samples on each side of an origin that the search fits and scores on (the final model
#: is fitted on the whole record). Ranking structures and estimators needs the differences
#: between them to stand out of the noise, not the whole of a long log: 50,000 samples are
#: 12x the longest shipped record, and they bound the search on any record (on 1e6 samples
#: the search costs what it costs on about 1.5e5; the final fit is linear in the record).
SEARCH_SAMPLES = 50_000
#: The estimator families :func:`clpc.identify` compares, in the order it fits them.
FAMILIES = ("arx", "lpc", "oe", "subspace")


def rolling_origin(data: IOData, fraction: float) -> list[tuple[IOData, IOData]]:
    """The (fitted, scored) parts at the rolling origins ``1/2, 2/3, 1 - fraction``.

    At each origin the model is fitted on the samples before it and scored on the samples
    after it, as the final model is fitted on the record and used after it: every sample,
    up to :data:`SEARCH_SAMPLES` on each side (the most recent before the origin, the first
    after it), so the search costs the same on any longer record.
    """
    n = data.n_samples
    cuts = [round(share * n) for share in ORIGINS] + [n - round(fraction * n)]
    return [(data[max(0, o - SEARCH_SAMPLES) : o], data[o : o + SEARCH_SAMPLES]) for o in cuts]


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


def key(row: dict[str, Any]) -> tuple[int, int, int]:
    """A row's structure ``(na, nb, nk)``: the rows one model can mix over its outputs."""
    return (row["na"], row["nb"], row["nk"])


def candidate(
    name: str, structure: Structure, mimo: str | None, where: tuple[list[Any], int]
) -> tuple[list[dict[str, Any]], LinearModel | None]:
    """One candidate fitted and scored in every fold: one row per output, and its last fit.

    OE starts each later origin from the previous origin's optimum (``initial``, no other
    start): the origins share most of their samples, so the optimum moves little and the
    search converges sooner (on a 3,000-sample 4th-order record: 45-49 evaluations and
    0.08 s against 110-118 and 0.4-0.7 s from the closed-form starts).
    """
    folds, k = where
    n_out = folds[0][0].n_outputs
    base = {"estimator": name, "order": structure.na}
    base |= {"na": structure.na, "nb": structure.nb, "nk": structure.nk}
    windows, kst, note = np.zeros((len(folds), n_out)), np.zeros(n_out), ""
    radius = np.zeros(n_out)
    model: LinearModel | None = None
    try:
        for w, (est, val) in enumerate(folds):
            model = make(name, structure, mimo, model).fit(est)
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
        model = None
    free = windows.mean(axis=0)
    names = folds[0][0].output_names
    rows = [
        base
        | {"output": names[j], "free_run": float(free[j]), "kstep": float(kst[j])}
        | {"windows": [float(v) for v in windows[:, j]]}
        | {"stability": _stability(float(radius[j])), "max_pole": float(radius[j])}
        | {"chosen": False, "note": note}
        for j in range(n_out)
    ]
    return rows, model


def make(
    name: str,
    structure: Structure,
    mimo: str | None,
    initial: LinearModel | None = None,
    evidence: bool = False,
) -> Any:
    """The estimator ``name`` whose models have ``structure``.

    ``evidence``: with covariance and assessment (default without; OE then stops after
    :data:`CANDIDATE_NFEV` evaluations per start). ``initial`` (OE only): start the search
    there alone. A subspace model of order ``n`` has ``na = n`` and
    ``nb = n, nk = d`` with feedthrough, ``nb = n - 1, nk = d + 1`` without
    (:class:`clpc.lpc.subspace.Subspace`): ``structure`` gives its order, delay and
    feedthrough back.
    """
    kw: dict[str, Any] = {"uncertainty": evidence, "assess": evidence, "mimo": mimo}
    if name == "subspace":
        through = structure.nb == structure.na
        nk = structure.nk - (0 if through else 1)
        return Subspace(order=structure.na, nk=nk, feedthrough=through, **kw)
    kw |= {"na": structure.na, "nb": structure.nb, "nk": structure.nk}
    if name == "oe" and initial is not None:
        kw |= {"starts": (), "initial": initial}
    if name == "oe" and not evidence:
        kw["max_nfev"] = CANDIDATE_NFEV
    return MAKERS[name](**kw)


def subspace_structure(order: int, nk: int) -> Structure:
    """The structure of a subspace model of ``order`` for a screened delay ``nk``.

    ``nk >= 1``: no feedthrough, ``u(t - nk)`` first (``Subspace(nk=nk - 1)``); ``nk = 0``:
    with feedthrough.
    """
    return Structure(order, order, 0) if nk == 0 else Structure(order, order - 1, nk)


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
    """Per output, the first ranked candidate whose refit on the whole record is stable.

    Stable here: no pole beyond the integrator tolerance
    (:data:`clpc.lpc.heldout.UNIT_CIRCLE_TOL`). A candidate stable in every window may still
    be unstable when refitted on the whole record; then the next one of the same structure
    (:func:`clpc.lpc.choice.ranked`) is taken and the row's ``note`` says why. OE is stable
    by construction and is not refitted here. When no refit is stable the pick is kept.
    """
    radius: dict[tuple[str, tuple[int, int, int]], np.ndarray] = {}
    out = []
    for j, i in enumerate(picks):
        same = [x for x, r in enumerate(rows) if key(r) == key(rows[i])]
        pool = ranked(rows, [x for x in same if rows[x]["output"] == rows[i]["output"]])
        pool = pool[pool.index(i) :]
        for x in pool:
            name, where = rows[x]["estimator"], key(rows[x])
            if name != "oe" and (name, where) not in radius:
                try:
                    m = make(name, Structure(*where), mimo).fit(data)
                    radius[name, where] = np.array(
                        [np.max(np.abs(m.poles(o))) for o in range(m.n_outputs)]
                    )
                except (ModelError, DataError, np.linalg.LinAlgError):
                    radius[name, where] = np.full(data.n_outputs, math.inf)
            if name == "oe" or radius[name, where][j] <= 1.0 + heldout.UNIT_CIRCLE_TOL:
                out.append(x)
                break
            rows[x]["note"] = (
                f"refitted on the whole record: unstable (largest pole "
                f"{radius[name, where][j]:.4g})"
            )
        else:
            out.append(i)
    return out


def final_model(
    data: IOData,
    chosen: tuple[str, ...],
    structure: Structure,
    mimo: str | None,
    evidence: bool = True,
    initial: LinearModel | None = None,
) -> LinearModel:
    """The chosen estimators refitted on the whole record (one model, one row per output).

    One estimator: its own fit, with its covariance and evidence. A mix over the outputs:
    each output's row, covariance (when every estimator stored one) and noise model
    (``info["noise_model"]`` per output) from its estimator's fit; then the held-out fit and
    residual tests of the mixed model (:func:`clpc.lpc.assessment.assess`, refitting the same
    mix). ``evidence=False``: neither covariance nor assessment (the refit). ``initial``: an
    OE fit of the same structure that starts OE's search (the last origin's optimum).
    """
    if len(set(chosen)) == 1:
        return make(chosen[0], structure, mimo, initial, evidence).fit(data)
    fits = {}
    for name in set(chosen):
        est = replace(make(name, structure, mimo, initial, evidence), assess=False)
        fits[name] = (replace(est, cancel=False) if name == "lpc" else est).fit(data)
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
        return final_model(part, chosen, structure, mimo, evidence=False)

    return assessment.assess(model, data, refit)
