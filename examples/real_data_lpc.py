"""LPC versus least squares on the real measured records shipped with clpc.

For every SISO record (robot_arm, ballbeam, dryer, exchanger, cascaded_tanks) and the 2x2
cd_player_arm (``mimo="miso"``: each output on its own past and on both inputs), fit

* LPC ``method="paper"`` (the literal smallest eigenvector of the scatter matrix),
* LPC ``method="robust"`` (the default: per-channel scaling, excitation-aware solution),
* least-squares ARX (:class:`clpc.ARX`, the same lag structure),

for orders ``N = na = nb = 2..6`` (``nk = 0``) on the first two thirds of the record
(cascaded_tanks: its estimation record) and score them on the rest (cascaded_tanks: its
validation record):

* ``sim``: fit % (MATLAB ``compare`` NRMSE) of the free-run simulation from the input alone,
  started from the measured initial conditions (the first ``max_lag`` validation samples);
  ``unstable`` when the identified model has a pole on or outside the unit circle;
* ``k10``: fit % of the 10-step-ahead prediction (:func:`clpc.kstep_fit`).

Means are not removed by hand: every model carries its own intercept ``c/a0``.

Run ``python examples/real_data_lpc.py`` (or ``--records dryer --orders 2 3``).
"""

from __future__ import annotations

import argparse
import sys
import time
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass

import numpy as np

import clpc
from clpc import datasets

RECORDS: tuple[str, ...] = (
    "robot_arm",
    "ballbeam",
    "dryer",
    "exchanger",
    "cascaded_tanks",
    "cd_player_arm",
)
ORDERS: tuple[int, ...] = (2, 3, 4, 5, 6)
HORIZON = 10

ESTIMATORS: dict[str, Callable[[int], object]] = {
    "LPC paper": lambda n: clpc.LPC(order=n, method="paper"),
    "LPC robust": lambda n: clpc.LPC(order=n),
    "LS ARX": lambda n: clpc.ARX(order=n),
}


@dataclass(frozen=True)
class Row:
    """One line of the table: a record's output at one order, scored for every estimator."""

    record: str  # the record's name, with "/output" for multi-output records
    order: int
    scores: dict[str, tuple[str, str]]  # estimator -> (sim fit, k-step fit), formatted


def fmt(fit: float) -> str:
    """A fit % for the table; fits below -999 % (diverging predictions) are clipped."""
    return "< -999" if fit < -999 else f"{fit:.1f}"


def split(name: str) -> tuple[clpc.IOData, clpc.IOData]:
    """Estimation and validation parts: the record's own split, else 2/3 and 1/3."""
    loaded = datasets.load(name)
    if isinstance(loaded, tuple):
        return loaded
    cut = (2 * loaded.n_samples) // 3
    return loaded[:cut], loaded[cut:]


def scores(model: clpc.LinearModel, val: clpc.IOData, horizon: int) -> list[tuple[str, str]]:
    """(free-run simulation fit, k-step prediction fit) per output, formatted."""
    s = model.structure
    start, n_lag = s.max_lag, s.nk + s.nb
    try:
        kfits = [fmt(k) for k in np.atleast_1d(clpc.kstep_fit(model, val.u, val.y, k=horizon))]
    except ValueError:  # the prediction overflowed to inf/NaN
        kfits = ["diverges"] * val.n_outputs
    if model.is_stable:
        sim = model.simulate(
            val.u[start:],
            y_init=val.y[start - s.na : start],
            u_init=val.u[start - n_lag : start],
        )
        sim_fit = np.atleast_1d(clpc.fit_percent(val.y[start:], sim.reshape(-1, val.n_outputs)))
        sims = [fmt(v) for v in sim_fit]
    else:
        sims = ["unstable"] * val.n_outputs
    return list(zip(sims, kfits, strict=True))


def run(
    records: Iterable[str] = RECORDS, orders: Iterable[int] = ORDERS, horizon: int = HORIZON
) -> list[Row]:
    """Fit every estimator at every order on every record; one row per output and order."""
    rows: list[Row] = []
    for name in records:
        est, val = split(name)
        for order in orders:
            per_output: list[dict[str, tuple[str, str]]] = [{} for _ in range(est.n_outputs)]
            for label, make in ESTIMATORS.items():
                try:
                    model = make(order).fit(est)  # type: ignore[attr-defined]
                    result = scores(model, val, horizon)
                except clpc.ModelError:  # a0 ~ 0: no monic model
                    result = [("n/a", "n/a")] * est.n_outputs
                for j, pair in enumerate(result):
                    per_output[j][label] = pair
            for j, out in enumerate(est.output_names):
                row_label = name if est.n_outputs == 1 else f"{name}/{out}"
                rows.append(Row(row_label, int(order), per_output[j]))
    return rows


def format_table(rows: Sequence[Row], horizon: int = HORIZON) -> str:
    """The rows as a Markdown table."""
    labels = list(ESTIMATORS)
    head = ["record", "N"]
    for label in labels:
        head += [f"{label} sim %", f"{label} k{horizon} %"]
    lines = ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    for row in rows:
        cells = [row.record, str(row.order)]
        for label in labels:
            cells += list(row.scores[label])
        lines.append("| " + " | ".join(cells) + " |")
    return "\n".join(lines)


def main(argv: Sequence[str] | None = None) -> int:
    """Command line entry: print the table (and the time it took)."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--records", nargs="+", default=list(RECORDS), choices=RECORDS)
    parser.add_argument("--orders", nargs="+", type=int, default=list(ORDERS))
    parser.add_argument("--horizon", type=int, default=HORIZON)
    args = parser.parse_args(argv)
    t0 = time.perf_counter()
    rows = run(args.records, args.orders, args.horizon)
    print(format_table(rows, args.horizon))
    print(f"\n({len(rows)} rows in {time.perf_counter() - t0:.1f} s)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
