"""Automatic order (``clpc.select_order``, default criterion) on every shipped real record.

Prints, per record output, the chosen order, the prediction horizon, each candidate's
stability and held-out score, and whether the final model is unstable. Run:
``python benchmarks/auto_order.py`` (a few seconds).
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

import clpc
from clpc.lpc.heldout import stability

sys.path.insert(0, str(Path(__file__).resolve().parent))
import real_data


def main() -> int:
    rows = unstable = all_unstable = 0
    for name, u, y_all, _, _, outs in real_data.records():
        miso = "miso" if u.ndim > 1 and u.shape[1] > 1 else None
        for j in range(y_all.shape[1] if y_all.ndim > 1 else 1):
            y = y_all[:, j] if y_all.ndim > 1 else y_all
            estimator = clpc.LPC(mimo=miso)
            sel = clpc.select_order(u, y, orders=range(1, 6), estimator=estimator)
            final = clpc.LPC(order=sel.best, mimo=miso).fit(u, y)
            kind = stability(final)
            rows += 1
            unstable += kind == "unstable"
            all_unstable += "stable" not in sel.stability and "integrating" not in sel.stability
            scores = np.round(sel.validation_fit, 1).tolist()
            print(
                f"{name}/{outs[j]}: N={sel.best} k={sel.horizon} final {kind}; "
                f"candidates {list(sel.stability)}; scores {scores}"
            )
    print(
        f"{rows} record outputs; chosen model unstable in {unstable}; every candidate "
        f"unstable in {all_unstable}"
    )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
