"""Selection rules for ``clpc.identify(estimator="auto")`` measured on several splits.

For every record (the real ones in ``clpc.datasets`` and a few simulated ones), every order
and every estimator (LPC, ARX, OE) this script fits

* the **final** model on the whole estimation part, scored on the validation part (the
  truth a rule is judged against, as in ``benchmarks/real_data.py``);
* **fold** models on parts of the estimation part, scored on other parts of it (all a
  rule may look at).

A rule maps the fold scores of the three estimators to one estimator per output. A row
counts as a hit when the chosen estimator's validation free-run fit is within 1 point of
the best of the three (``-inf`` when unstable), as in ``real_data.py``. ``unstable``: the
chosen final model is unstable although one of the three is not.

Splits of each real record (estimation mean removed from both parts):

* ``bench``: first 60 % estimation, last 40 % validation (cascaded_tanks: its own records),
  the protocol of ``real_data.py``;
* ``half``: first 50 % / last 50 % (cascaded_tanks: its estimation record halved);
* ``reversed``: last 60 % estimation, first 40 % validation (cascaded_tanks: its records
  swapped);
* ``seventy``: first 70 % / last 30 % (cascaded_tanks: its estimation record split so);
* ``sim``: simulated records (two systems; white output noise, errors in variables, equation
  error; seeds 0-5; orders: true and true + 1), first 60 % / last 40 %; ``sim2``: seeds 6-11.

``--identify`` adds a row for ``clpc.identify`` of the checkout imported (per output, the
estimator it chose, scored by that estimator's final fit; a rule's row without it). The
rows ``today`` and the variants are the rules as this script states them, with the fallback
of ``identify`` (a choice whose final fit is unstable gives way to the next; ``--no-guard``
drops it).

Fold parts (fractions of the estimation part, ``fit -> scored``): ``A`` 0-2/3 -> 2/3-1,
``B`` 1/3-1 -> 0-1/3 (the two folds of ``identify`` today), ``C`` 0-1/2 -> 1/2-1,
``D`` 0-0.8 -> 0.8-1, ``E`` 0.2-1 -> 0-0.2, ``F`` 0.5-1 -> 0-0.5, ``G`` 0-0.4 -> 0.4-0.6,
``H`` 0-0.6 -> 0.6-0.8, ``I`` 0-1/3 -> 1/3-2/3.

Usage::

    python benchmarks/selection_rules.py [--splits bench,half,reversed,sim,seventy,sim2]
        [--cache DIR] [--identify] [--detail RULE]

Fits are cached per split in ``--cache`` (default ``/tmp/clpc-selection-rules/<key>``, the key
a hash of the source of ``clpc.lpc`` imported: a changed estimator gets new fits; with an
explicit ``--cache``, delete it after changing an estimator).
"""

from __future__ import annotations

import argparse
import hashlib
import math
import pickle
import sys
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np
from scipy import signal

import clpc
from clpc.lpc import heldout
from clpc.lpc.comparison import MAKERS, fold_fits

sys.path.insert(0, str(Path(__file__).parent))
from real_data import score  # the same validation scoring as the benchmark

ORDERS = (2, 3, 4, 5)
EST = ("lpc", "arx", "oe")
FOLDS = {
    "A": ((0, 2 / 3), (2 / 3, 1)),
    "B": ((1 / 3, 1), (0, 1 / 3)),
    "C": ((0, 1 / 2), (1 / 2, 1)),
    "D": ((0, 0.8), (0.8, 1)),
    "E": ((0.2, 1), (0, 0.2)),
    "F": ((0.5, 1), (0, 0.5)),
    "G": ((0, 0.4), (0.4, 0.6)),
    "H": ((0, 0.6), (0.6, 0.8)),
    "I": ((0, 1 / 3), (1 / 3, 2 / 3)),
}
POINTS = 1.0


# ====================================================================== records
def centred(est: clpc.IOData, val: clpc.IOData) -> tuple[clpc.IOData, clpc.IOData]:
    mu, my = est.u.mean(axis=0), est.y.mean(axis=0)
    mk = lambda d: clpc.IOData(d.u - mu, d.y - my, output_names=d.output_names)  # noqa: E731
    return mk(est), mk(val)


def real(split: str) -> list[tuple[str, clpc.IOData, clpc.IOData, list[int]]]:
    from clpc import datasets

    out = []
    for name in datasets.names():
        d = datasets.load(name)
        if isinstance(d, tuple):
            parts = {"bench": d, "reversed": d[::-1]}.get(split)
            if parts is None:
                cut = d[0].n_samples // 2 if split == "half" else round(0.7 * d[0].n_samples)
                parts = (d[0][:cut], d[0][cut:])
        else:
            n = d.n_samples
            cuts = {"bench": 0.6, "half": 0.5, "reversed": 0.4, "seventy": 0.7}
            cut = round(cuts[split] * n)
            parts = (d[:cut], d[cut:]) if split != "reversed" else (d[cut:], d[:cut])
        out.append((name, *centred(*parts), list(ORDERS)))
    return out


def simulated(seeds: range) -> list[tuple[str, clpc.IOData, clpc.IOData, list[int]]]:
    """Two systems x three noise kinds x ``seeds``, 1000 samples, 60/40."""
    systems = {
        "s2": (np.poly([0.9 * np.exp(0.3j), 0.9 * np.exp(-0.3j)]).real, [0.0, 0.5, 0.3]),
        "s3": (np.poly([0.95 * np.exp(0.2j), 0.95 * np.exp(-0.2j), 0.7]).real, [0, 0.2, 0.1, 0.05]),
    }
    out = []
    for sname, (a, b) in systems.items():
        n_true = len(a) - 1
        for kind in ("output", "eiv", "equation"):
            for seed in seeds:
                rng = np.random.default_rng(1000 * seed + 7)
                u0 = signal.lfilter([1.0], [1.0, -0.7], rng.standard_normal(1000))
                y0 = signal.lfilter(b, a, u0)
                e = rng.standard_normal(1000)
                if kind == "output":
                    u, y = u0, y0 + 0.3 * y0.std() * e
                elif kind == "eiv":
                    u = u0 + 0.15 * u0.std() * rng.standard_normal(1000)
                    y = y0 + 0.15 * y0.std() * e
                else:
                    y = y0 + signal.lfilter([1.0], a, 0.1 * y0.std() * e)
                    u = u0
                d = clpc.IOData(u, y)
                est, val = centred(d[:600], d[600:])
                out.append((f"{sname}/{kind}/{seed}", est, val, [n_true, n_true + 1]))
    return out


def records(split: str) -> list[tuple[str, clpc.IOData, clpc.IOData, list[int]]]:
    if split == "sim":
        return simulated(range(6))
    if split == "sim2":
        return simulated(range(6, 12))
    return real(split)


# ====================================================================== fits
def part(d: clpc.IOData, lo: float, hi: float) -> clpc.IOData:
    n = d.n_samples
    return d[round(lo * n) : round(hi * n)]


def measure(recs: list) -> list[dict]:
    """One entry per record, order and output: final and fold scores of each estimator."""
    rows = []
    for name, est, val, orders in recs:
        mode = "siso" if est.n_inputs == est.n_outputs == 1 else "miso"
        n_val = round(est.n_samples / 3)
        for order in orders:
            lean = {"order": order, "nk": 0, "mimo": mode, "uncertainty": False, "assess": False}
            k = heldout.horizon(clpc.ARX(**lean).fit(est[: est.n_samples - n_val]), n_val)
            per = {}
            for e in EST:
                try:
                    final = MAKERS[e](**lean).fit(est)
                    truth = score(final, val.u, val.y, order)
                except (clpc.ModelError, clpc.DataError):
                    truth = score("failed", val.u, val.y, order)
                folds = {}
                for key, ((a0, a1), (b0, b1)) in FOLDS.items():
                    try:
                        m = MAKERS[e](**lean).fit(part(est, a0, a1))
                        f, p = fold_fits(m, part(est, b0, b1), k)
                        rad = [float(np.max(np.abs(m.poles(j)))) for j in range(est.n_outputs)]
                    except (clpc.ModelError, clpc.DataError, np.linalg.LinAlgError):
                        f = p = np.full(est.n_outputs, -math.inf)
                        rad = [math.nan] * est.n_outputs
                    folds[key] = (f, p, rad)
                per[e] = (truth, folds)
            for j, out in enumerate(est.output_names):
                label = name if est.n_outputs == 1 else f"{name}/{out}"
                rows.append(
                    {"label": label, "N": order}
                    | {
                        e: {
                            "val": per[e][0][j]["sim"],
                            "status": per[e][0][j]["status"],
                            "free": {f: float(v[0][j]) for f, v in per[e][1].items()},
                            "kstep": {f: float(v[1][j]) for f, v in per[e][1].items()},
                            "radius": {f: v[2][j] for f, v in per[e][1].items()},
                        }
                        for e in EST
                    }
                )
    return rows


# ====================================================================== rules
#: A rule ranks the estimators for one row, best first (its pick: the first whose final
#: model is not unstable, the fallback ``identify`` applies to its refit).
Rule = Callable[[dict], list[str]]


def tiers(row: dict, folds: str) -> dict[str, int]:
    """0: every fold model strictly stable with a finite score; 1: not."""
    return {
        e: 0
        if all(row[e]["radius"][f] < 1.0 and math.isfinite(row[e]["free"][f]) for f in folds)
        else 1
        for e in EST
    }


def mean_of(row: dict, e: str, folds: str, what: str = "free") -> float:
    return float(np.mean([row[e][what][f] for f in folds]))


def ranked(row: dict, folds: str, key: Callable[[str], float]) -> list[str]:
    t = tiers(row, folds)
    return sorted(EST, key=lambda e: (t[e], -key(e)))  # stable: first of equals kept


def best_mean(folds: str, what: str = "free") -> Rule:
    def rule(row: dict) -> list[str]:
        if what == "both":
            return ranked(
                row, folds, lambda e: mean_of(row, e, folds) + mean_of(row, e, folds, "kstep")
            )
        return ranked(row, folds, lambda e: mean_of(row, e, folds, what))

    return rule


def best_min(folds: str) -> Rule:
    """Maximin: the best worst fold."""
    return lambda row: ranked(row, folds, lambda e: min(row[e]["free"][f] for f in folds))


def prefer_oe(folds: str, margin: str | float) -> Rule:
    """OE unless a rival beats it by more than ``margin`` points (or the fold spread)."""

    def rule(row: dict) -> list[str]:
        order = best_mean(folds)(row)
        top = order[0]
        if top == "oe" or tiers(row, folds)["oe"]:
            return order
        if margin == "spread":
            d = [row[top]["free"][f] - row["oe"]["free"][f] for f in folds]
            m = float(np.std(d, ddof=1)) / math.sqrt(len(d)) if len(d) > 1 else 0.0
        else:
            m = float(margin)
        if mean_of(row, top, folds) - mean_of(row, "oe", folds) <= m:
            return ["oe"] + [e for e in order if e != "oe"]
        return order

    return rule


def fixed(e: str) -> Rule:
    return lambda row: [e] + [x for x in EST if x != e and x in row]


RULES: dict[str, Rule] = {
    "today: A+B mean free run": best_mean("AB"),
    "forward A only": best_mean("A"),
    "forward D only": best_mean("D"),
    "rolling origin C+A+D": best_mean("CAD"),
    "rolling origin C+A+D free+kstep": best_mean("CAD", "both"),
    "rolling origin C+A+D maximin": best_min("CAD"),
    "rolling origin C+A+D, OE unless beaten by > SE": prefer_oe("CAD", "spread"),
    "backward rolling F+B+E": best_mean("FBE"),
    "both directions C+A+D+F+B+E": best_mean("CADFBE"),
    "rolling origin, equal windows G+H+D": best_mean("GHD"),
    "rolling origin G+H+D, OE unless beaten by > SE": prefer_oe("GHD", "spread"),
    "rolling origin, windows of 1/3: I+A": best_mean("IA"),
    "more data D+E (80/20 both ways)": best_mean("DE"),
    "all five folds": best_mean("ABCDE"),
    "all five folds, OE unless beaten by > SE": prefer_oe("ABCDE", "spread"),
    "A+B free+kstep mean": best_mean("AB", "both"),
    "A+B maximin": best_min("AB"),
    "A+B, OE unless beaten by > 1": prefer_oe("AB", 1.0),
    "A+B, OE unless beaten by > SE": prefer_oe("AB", "spread"),
    "always OE": fixed("oe"),
    "always ARX": fixed("arx"),
    "always LPC": fixed("lpc"),
}


def pick(row: dict, rule: Rule, guard: bool) -> str:
    order = rule(row)
    if guard:
        for e in (x for x in order if x in row):
            if row[e]["status"] != "unstable":
                return e
    return order[0]


def evaluate(rows: list[dict], rule: Rule, guard: bool = True) -> tuple[int, int, list[str]]:
    hits = bad = 0
    misses = []
    none = {"val": -math.inf, "status": "n/a"}  # identify failed
    for r in rows:
        e = pick(r, rule, guard)
        top = max(r[x]["val"] for x in EST)
        gap = top - r.get(e, none)["val"] if math.isfinite(top) else 0.0
        hits += gap <= POINTS
        if gap > POINTS:
            misses.append(f"{r['label']} N={r['N']} {e} ({gap:.1f})")
        stable = any(r[x]["status"] != "unstable" for x in EST)
        bad += stable and r.get(e, none)["status"] == "unstable"
    return hits, bad, misses


def identify_rows(recs: list) -> list[list[str]]:
    """The estimator ``clpc.identify`` (this checkout) chooses per row, in ``measure``'s order."""
    picks = []
    for _name, est, _val, orders in recs:
        mode = "siso" if est.n_inputs == est.n_outputs == 1 else "miso"
        for order in orders:
            try:
                picks += list(clpc.identify(est, order=order, nk=0, mimo=mode).estimators)
            except (clpc.ModelError, clpc.DataError):
                picks += ["failed"] * est.n_outputs
    return picks


def source_key() -> str:
    """A short hash of the estimators' source (``clpc/lpc/*.py`` of the clpc imported)."""
    digest = hashlib.sha256()
    for path in sorted((Path(clpc.__file__).parent / "lpc").glob("*.py")):
        digest.update(path.name.encode() + path.read_bytes())
    return digest.hexdigest()[:12]


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--splits", default="bench,half,reversed,sim,seventy,sim2")
    ap.add_argument("--cache", type=Path, default=None)
    ap.add_argument("--no-guard", action="store_true", help="no fallback from an unstable refit")
    ap.add_argument("--detail", action="append", default=[], help="print a rule's misses")
    ap.add_argument(
        "--identify", action="store_true", help="also score clpc.identify of this checkout"
    )
    args = ap.parse_args(argv)
    if args.cache is None:
        args.cache = Path("/tmp/clpc-selection-rules") / source_key()
    args.cache.mkdir(parents=True, exist_ok=True)
    data = {}
    for split in args.splits.split(","):
        path = args.cache / f"{split}.pkl"
        if path.exists():
            data[split] = pickle.loads(path.read_bytes())
            continue
        t0 = time.perf_counter()
        recs = records(split)
        data[split] = measure(recs)
        path.write_bytes(pickle.dumps(data[split]))
        print(f"({split}: {time.perf_counter() - t0:.0f} s)", file=sys.stderr)
    head = " | ".join(f"{s} ({len(v)})" for s, v in data.items())
    print(f"| rule | {head} | total |\n|---|" + "---|" * (len(data) + 1))
    for name, rule in RULES.items():
        cells = []
        for rows in data.values():
            hits, bad, _ = evaluate(rows, rule, not args.no_guard)
            cells.append(f"{hits}" + (f" ({bad} unstable)" if bad else ""))
        print(f"| {name} | " + " | ".join(cells) + f" | {sum(int(c.split()[0]) for c in cells)} |")
    if args.identify:
        cells = []
        for split, rows in data.items():
            recs = records(split)
            chosen = iter(identify_rows(recs))
            hits, bad, misses = evaluate(rows, lambda r, c=chosen: fixed(next(c))(r), False)
            cells.append(f"{hits}" + (f" ({bad} unstable)" if bad else ""))
            print(f"identify / {split} misses: " + "; ".join(misses), file=sys.stderr)
        total = sum(int(c.split()[0]) for c in cells)
        print(f"| clpc.identify ({clpc.__file__}) | " + " | ".join(cells) + f" | {total} |")
    for name in args.detail:
        for split, rows in data.items():
            print(f"\n{name} / {split} misses: " + "; ".join(evaluate(rows, RULES[name])[2]))
    return 0


if __name__ == "__main__":
    sys.exit(main())
