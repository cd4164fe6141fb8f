"""Every estimator's coefficients against another copy of the package (before/after a change).

Fits LPC, ARX (orders 1-3, delays 0-1) and OE (orders 1-2) on the shipped records and a
synthetic second-order record, once with this package and once with the package under
``--baseline-src`` (e.g. ``git archive <commit> src | tar -x -C /tmp/base``), each in its own
process, and prints the largest coefficient difference per estimator. OE's answer is the
minimum of a simulation-error cost found by an iterative search: its coefficients are fixed
only as far as the cost is curved, so the relative difference of the cost is printed too.

Usage::

    python benchmarks/compare_coefficients.py --baseline-src /tmp/base/src
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np


def fit_all(out: str) -> None:
    """Fit every estimator on every record; save ``theta``, ``c`` (and OE's cost) to ``out``."""
    import clpc
    import clpc.datasets as ds

    rng = np.random.default_rng(0)
    u = rng.standard_normal(4000)
    y = clpc.simulate_arx([1, -1.5, 0.7], [0.5, 0.2, 0.1], u) + 0.05 * rng.standard_normal(4000)
    records = {"synthetic": clpc.IOData(u, y, dt=0.01)}
    for name in ds.names():
        loaded = ds.load(name)
        records[name] = loaded[0] if isinstance(loaded, tuple) else loaded
    found: dict[str, np.ndarray] = {}
    for name, data in records.items():
        for est in ("LPC", "ARX", "OE"):
            for order in (1, 2, 3):
                for nk in (0, 1):
                    if est == "OE" and (order > 2 or data.n_samples > 5000):
                        continue
                    key = f"{name}/{est}/N{order}/nk{nk}"
                    try:
                        model = getattr(clpc, est)(order=order, nk=nk).fit(data)
                    except (ValueError, ArithmeticError) as exc:
                        print(f"{key}: {exc}", file=sys.stderr)
                        continue
                    found[key] = np.r_[model.theta_matrix.ravel(), model.c]
                    if est == "OE":
                        found["cost:" + key] = np.atleast_1d(np.asarray(model.info["cost"]))
    np.savez(out, **found)


def run(src: str | None, out: str) -> None:
    """:func:`fit_all` in a new process, with ``src`` first on the import path."""
    env = dict(os.environ)
    if src:
        env["PYTHONPATH"] = src + os.pathsep + env.get("PYTHONPATH", "")
    code = f"import sys; sys.path.insert(0, {str(Path(__file__).parent)!r}); "
    code += f"import compare_coefficients as c; c.fit_all({out!r})"
    subprocess.run([sys.executable, "-c", code], env=env, check=True)


def main() -> None:
    """Print the largest differences per estimator."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--baseline-src", required=True, help="the other package's src folder")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        before, after = f"{tmp}/before.npz", f"{tmp}/after.npz"
        run(args.baseline_src, before)
        run(None, after)
        a, b = np.load(before), np.load(after)
        worst: dict[str, float] = {}
        cost = 0.0
        missing = sorted(set(a.files) ^ set(b.files))
        for key in sorted(set(a.files) & set(b.files)):
            if key.startswith("cost:"):
                cost = max(cost, float(np.max(np.abs(a[key] - b[key]) / np.abs(a[key]))))
                continue
            est = key.split("/")[1]
            diff = np.inf if a[key].shape != b[key].shape else np.max(np.abs(a[key] - b[key]))
            worst[est] = max(worst.get(est, 0.0), float(diff))
    print(f"{len(a.files)} entries; fitted by one copy only: {missing or 'none'}")
    for est, diff in worst.items():
        print(f"{est}: largest |coefficient difference| {diff:.3g}")
    print(f"OE: largest relative cost difference {cost:.3g}")


if __name__ == "__main__":
    main()
