"""OE's objective with one measured start or several: the dryer diagnosis of issue 13 part e.

On the dryer record (first 60 % = the estimation part, its mean removed from both parts, as
in ``real_data.py``) at ``N = 4, 5``, ``nk = 0``, for each of ``clpc.identify``'s origins
(fitted on the first 1/2, 2/3 and 0.8 of the estimation part, scored on the rest of it) and
for the whole estimation part (scored on the validation part), prints the free-run fit % of
least squares and of three OE objectives: ``segments=1`` (one free run over the record, the
objective before part e), ``full_run=False`` (four segments, each run on its own: multiple
shooting, part e's branch) and the default (the whole run plus a run from each later
segment start):

* ``train``: on the fitted part, started from its measured outputs (OE's objective for
  ``segments=1``); ``held``: on the scored part, started from its measured outputs (how
  ``identify`` and ``real_data.py`` score); ``cont``: the scored part simulated on
  continuously from the start of the fitted part (the input-output map alone);
* the largest pole and OE's closest pole/zero distance.

Then the validation part's free run started 0, 25, ..., 200 samples into it (the lucky start).

``--sweep``: the objectives on the 48 rows of ``real_data.py`` (its records, split and
scoring): median validation free run, rows where OE is within 1 point of the better of LPC
and least squares or ahead, rows more than 10 points behind it, the largest shortfall, rows
below 0 % (a report).

Usage::

    python benchmarks/oe_starts.py [--sweep]
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

import clpc
from clpc import datasets
from clpc.data import IOData
from clpc.lpc.comparison import fold_fits, rolling_origin
from clpc.lpc.heldout import fit_percent

#: The OE objectives compared (OE settings).
OBJECTIVES: dict[str, dict] = {
    "OE one start": {"segments": 1},
    "OE segments": {"full_run": False},
    "OE default": {},
}
#: The sweep: the objectives and other segment counts of the default.
SWEEP: dict[str, dict] = OBJECTIVES | {
    "default, segments=2": {"segments": 2},
    "default, segments=8": {"segments": 8},
}


def parts() -> tuple[IOData, IOData]:
    d = datasets.load("dryer")
    cut = round(0.6 * d.n_samples)
    mu, my = d[:cut].u.mean(axis=0), d[:cut].y.mean(axis=0)
    return (
        IOData(d[:cut].u - mu, d[:cut].y - my, dt=d.dt),
        IOData(d[cut:].u - mu, d[cut:].y - my, dt=d.dt),
    )


def continuous(model: clpc.LinearModel, fit: IOData, rest: IOData) -> float:
    sim = np.asarray(model.simulate(np.r_[fit.u, rest.u])).ravel()
    return float(fit_percent(rest.y[:, 0], sim[fit.n_samples :]))


def closest_pair(model: clpc.LinearModel) -> float:
    poles, zeros = model.poles(0), np.roots(model.numerators[0, 0])
    return float(np.min(np.abs(poles[:, None] - zeros[None, :])))


def main() -> None:
    est, val = parts()
    kw = {"uncertainty": False, "assess": False}
    for order in (4, 5):
        print(f"\nN = {order}: free run fit % (train / held / cont), largest pole, pole-zero gap")
        folds = [*rolling_origin(est, 0.2), (est, val)]
        tags = ("1/2", "2/3", "0.8", "whole -> validation")
        for tag, (fit, rest) in zip(tags, folds, strict=True):
            models = {"ARX": clpc.ARX(order=order, **kw).fit(fit)} | {
                name: clpc.OE(order=order, **opts, **kw).fit(fit)
                for name, opts in OBJECTIVES.items()
            }
            cells = []
            for name, m in models.items():
                train, held = fold_fits(m, fit, 10)[0][0], fold_fits(m, rest, 10)[0][0]
                radius = np.max(np.abs(m.poles(0)))
                gap = f" gap {closest_pair(m):.1e}" if name != "ARX" else ""
                cells.append(
                    f"{name} {train:5.1f} / {held:6.1f} / {continuous(m, fit, rest):5.1f}"
                    f" |z| {radius:.4f}{gap}"
                )
            print(f"  {tag:20s} " + " | ".join(cells))
        offsets = range(0, 201, 25)
        print(f"  validation part started at {list(offsets)} samples:")
        fitted = {"ARX": clpc.ARX(order=order, **kw).fit(est)} | {
            name: clpc.OE(order=order, **opts, **kw).fit(est) for name, opts in OBJECTIVES.items()
        }
        for name, m in fitted.items():
            runs = [fold_fits(m, val[o:], 10)[0][0] for o in offsets]
            print(
                f"    {name:16s}"
                + " ".join(f"{v:6.1f}" for v in runs)
                + f"  median {np.median(runs):.1f}"
            )


def sweep() -> None:
    sys.path.insert(0, str(Path(__file__).parent))
    from real_data import ORDERS, mimo, records, score

    recs = records()
    kw = {"uncertainty": False, "assess": False}
    rivals = {}
    for name, ue, ye, uv, yv, _ in recs:
        for n in ORDERS:
            opts = {"order": n, "mimo": mimo(ue.shape[1], ye.shape[1])} | kw
            lpc = score(clpc.LPC(**opts).fit(ue, ye), uv, yv, n)
            arx = score(clpc.ARX(**opts).fit(ue, ye), uv, yv, n)
            rivals[name, n] = [max(a["sim"], b["sim"]) for a, b in zip(lpc, arx, strict=True)]
    print(
        "\n| OE objective | median sim % | within 1 point or ahead | > 10 points behind "
        "| largest shortfall | sim < 0 |\n|---|---|---|---|---|---|"
    )
    for label, settings in SWEEP.items():
        sims, gaps = [], []
        for name, ue, ye, uv, yv, _ in recs:
            for n in ORDERS:
                opts = {"order": n, "mimo": mimo(ue.shape[1], ye.shape[1])} | kw
                rows = score(clpc.OE(**settings, **opts).fit(ue, ye), uv, yv, n)
                for j, row in enumerate(rows):
                    sims.append(row["sim"])
                    gaps.append(rivals[name, n][j] - row["sim"])
        gap = np.array(gaps)
        print(
            f"| {label} | {np.median(sims):.1f} | {np.sum(gap <= 1.0)}/{gap.size} "
            f"| {np.sum(gap > 10.0)}/{gap.size} | {gap.max():.1f} "
            f"| {sum(v < 0 for v in sims)}/{gap.size} |"
        )


if __name__ == "__main__":
    main()
    if "--sweep" in sys.argv[1:]:
        sweep()
