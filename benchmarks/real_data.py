"""LPC, CLPC and least squares on every real record shipped with clpc (issue "LPC that holds
up on real data", item 5).

Records: robot_arm, ballbeam, dryer, exchanger, cascaded_tanks (its own estimation and
validation records), cd_player_arm (2x2), winding (5x2), industrial_dryer (3x3); the
multi-channel records use ``mimo="miso"`` (each output on its own past and on every input).
Estimation: the first 60 % of the record, validation: the rest (cascaded_tanks: its split).

Orders: ``N = 2`` and, per record, the order BIC chooses among ``N = 1..6`` for LPC
(``clpc.select_order`` on the estimation part; when that is 2, the runner-up). Always
``na = nb = N``, ``nk = 0``.

Methods, scored on the validation part:

(a) ``LPC paper``  ``clpc.LPC(order=N, method="paper")`` fitted on the estimation part;
(b) ``LPC robust`` ``clpc.LPC(order=N)`` (default method);
(c) ``CLPC``       ``clpc.CLPC(N + 1, W, C)`` (default, robust) run over estimation +
    validation joined end to end; ``y(n)`` is predicted ``k`` steps ahead with the held
    model of the last completed cluster whose newest sample is ``<= n - k`` (``trace.index``;
    monic ``den``/``num`` and intercept ``c / a0``), so every prediction is causal. A
    time-varying model has no single free-run simulation: ``-`` in the sim column;
(d) ``LS ARX``     ``clpc.ARX(order=N)``: least squares on the estimation part;
(e) ``WLS``        windowed least squares on the same windows as CLPC (per window
    ``lstsq`` of ``y(n)`` on the rest of the centered lag vector, intercept from the window
    means), used causally in the same way as (c).

Columns: ``sim`` = fit % (NRMSE, as MATLAB ``compare``) of the free-run simulation from the
validation input, started from the measured initial conditions; ``k1``/``k10`` = fit % of the
1- and 10-step-ahead predictions. All scores are on validation samples ``max_lag ..`` end.
Flags: ``unstable`` = the model is unstable and its free run diverges (leaves 10x the
output's range); ``*`` = the model is unstable (a pole on or outside the unit circle) but the
free run stayed bounded over the validation record; for (c)/(e) ``u:x%`` = share of the
validation samples predicted with an unstable window model; ``n/a`` = no monic model
(``a0`` about 0).

Usage::

    python benchmarks/real_data.py                   # every record, W = 201, C = 12
    python benchmarks/real_data.py --records dryer --window 101
"""

from __future__ import annotations

import argparse
import os
import platform
import sys
import time
from dataclasses import dataclass

import numpy as np

import clpc
from clpc import datasets
from clpc.lpc.regressors import Structure, miso_regressor

RECORDS = (
    "robot_arm",
    "ballbeam",
    "dryer",
    "exchanger",
    "cascaded_tanks",
    "cd_player_arm",
    "winding",
    "industrial_dryer",
)
CANDIDATE_ORDERS = (1, 2, 3, 4, 5, 6)
METHODS = ("LPC paper", "LPC robust", "CLPC", "LS ARX", "WLS")
HORIZONS = (1, 10)


# ====================================================================== data
def split(name: str) -> tuple[clpc.IOData, clpc.IOData]:
    """Estimation and validation parts: the record's own split, else 60 % / 40 %."""
    loaded = datasets.load(name)
    if isinstance(loaded, tuple):
        return loaded
    cut = round(0.6 * loaded.n_samples)
    return loaded[:cut], loaded[cut:]


def second_order(est: clpc.IOData) -> tuple[int, str]:
    """The BIC choice among CANDIDATE_ORDERS (the runner-up when BIC picks 2)."""
    sel = clpc.select_order(est, orders=CANDIDATE_ORDERS, criterion="bic")
    if sel.best != 2:
        return int(sel.best), "BIC"
    ranked = [int(o) for o in sel.orders[np.argsort(sel.bic)] if o != 2]
    return ranked[0], "BIC runner-up"


# ====================================================================== scoring helpers
@dataclass
class Score:
    sim: str
    k: dict[int, str]


def _fmt(v: float) -> str:
    if not np.isfinite(v):
        return "-inf"
    return f"{v:.1f}" if abs(v) < 1e5 else f"{v:.1e}"


def _stable_poles(den: np.ndarray) -> bool:
    """``den`` monic ascending in ``z^-1``: all roots of ``z^na A(z)`` inside |z| < 1."""
    return bool(np.all(np.abs(np.roots(den)) < 1.0)) if den.size > 1 else True


def score_fixed(model: clpc.LinearModel, val: clpc.IOData) -> list[Score]:
    """Free-run and k-step fits of a time-invariant model, one Score per output."""
    s = model.structure
    start, n_lag = s.max_lag, s.nk + s.nb
    y_val = val.y[start:]
    out = [Score("", {}) for _ in range(val.n_outputs)]
    for k in HORIZONS:
        pred = model.predict(val.u, val.y, k=k).reshape(-1, val.n_outputs)[start:]
        for j in range(val.n_outputs):
            if np.all(np.isfinite(pred[:, j])):
                out[j].k[k] = _fmt(clpc.fit_percent(y_val[:, j], pred[:, j]))
            else:
                out[j].k[k] = "diverges"
    with np.errstate(all="ignore"):
        sim = model.simulate(
            val.u[start:],
            y_init=val.y[start - s.na : start],
            u_init=val.u[start - n_lag : start] if n_lag else None,
        ).reshape(-1, val.n_outputs)
    for j in range(val.n_outputs):
        stable = _stable_poles(model.denominators[j])
        yj = y_val[:, j]
        span = np.max(np.abs(yj - yj.mean()))
        diverged = (not np.all(np.isfinite(sim[:, j]))) or (
            np.max(np.abs(sim[:, j] - yj.mean())) > 10 * span
        )
        if not stable and diverged:
            out[j].sim = "unstable"
        elif diverged:  # a stable model cannot diverge; kept for completeness
            out[j].sim = "diverges"
        else:
            fit = _fmt(clpc.fit_percent(yj, sim[:, j]))
            out[j].sim = fit if stable else fit + "*"
    return out


@dataclass
class WindowModels:
    """Time-varying models: one per window, valid from sample ``index`` on."""

    index: np.ndarray  # (n,) newest sample of the window
    den: np.ndarray  # (n, E, na + 1) monic
    num: np.ndarray  # (n, E, n_in, nk + nb + 1)
    intercept: np.ndarray  # (n, E)
    ok: np.ndarray  # (n, E) a model exists


def causal_predict(
    models: WindowModels, u: np.ndarray, y: np.ndarray, s: Structure, targets: np.ndarray, k: int
) -> tuple[np.ndarray, np.ndarray]:
    """``y_hat(n | n - k)`` for sample indices ``targets`` of the joined record.

    The model used for target ``n`` is the last window with ``index <= n - k``; it
    iterates ``k`` steps from the measured outputs up to ``n - k`` and the measured inputs.
    Returns predictions (len(targets), E) and the window used per target.
    """
    last = np.searchsorted(models.index, targets - k, side="right") - 1
    if np.any(last < 0):
        raise RuntimeError("a validation sample has no completed window before it")
    den = models.den[last]  # (T, E, na+1)
    num = models.num[last]  # (T, E, n_in, L)
    icpt = models.intercept[last]  # (T, E)
    n_out = den.shape[1]
    # z[step] = prediction of y(n - k + step), step = 1..k, for every target n
    z: list[np.ndarray] = []
    for step in range(1, k + 1):
        t = targets - k + step  # sample being predicted at this step
        acc = icpt.copy()
        for lag in range(num.shape[3]):
            acc += np.einsum("tei,ti->te", num[:, :, :, lag], u[t - lag])
        for lag in range(1, s.na + 1):
            if step - lag >= 1:
                past = z[step - lag - 1]
            else:
                past = y[t - lag][:, :n_out]
            acc -= den[:, :, lag] * past
        z.append(acc)
    return z[-1], last


def clpc_models(trace: clpc.Trace) -> WindowModels:
    a = trace.arrays
    theta = a["theta"]
    a0 = np.where(a["has_model"], theta[:, :, 0], 1.0)
    return WindowModels(
        index=trace.index,
        den=a["den"],
        num=a["num"],
        intercept=np.where(a["has_model"], a["c"] / a0, 0.0),
        ok=a["has_model"],
    )


def wls_models(
    u: np.ndarray, y: np.ndarray, s: Structure, window: int, cluster: int, min_rows: int
) -> WindowModels:
    """Windowed least squares on the CLPC windows (rows ``[max(0, Cj - W), Cj)``)."""
    n_in, n_out = u.shape[1], y.shape[1]
    lags = [miso_regressor(y[:, e], u, s) for e in range(n_out)]  # (rows, p) per output
    n_rows = lags[0].shape[0]
    n_up = n_rows // cluster
    L = s.nk + s.nb + 1
    den = np.zeros((n_up, n_out, s.na + 1))
    num = np.zeros((n_up, n_out, n_in, L))
    icpt = np.zeros((n_up, n_out))
    ok = np.zeros((n_up, n_out), dtype=bool)
    have = np.zeros(n_out, dtype=bool)
    for j in range(1, n_up + 1):
        m = cluster * j
        first = max(0, m - window)
        for e in range(n_out):
            if m - first >= min_rows:
                win = lags[e][first:m]
                mean = win.mean(axis=0)
                cen = win - mean
                x, *_ = np.linalg.lstsq(cen[:, 1:], -cen[:, 0], rcond=None)
                theta = np.concatenate([[1.0], x])  # monic: a0 = 1
                d = theta[: s.na + 1]
                b = theta[s.na + 1 :].reshape(n_in, s.nb + 1)
                den[j - 1, e] = d
                num[j - 1, e, :, s.nk :] = -b
                icpt[j - 1, e] = mean @ theta
                have[e] = True
            elif have[e]:  # hold (never reached once windows are full)
                den[j - 1, e], num[j - 1, e], icpt[j - 1, e] = (
                    den[j - 2, e],
                    num[j - 2, e],
                    icpt[j - 2, e],
                )
            else:
                den[j - 1, e, 0] = 1.0
            ok[j - 1, e] = have[e]
    index = s.max_lag + cluster * np.arange(1, n_up + 1) - 1
    return WindowModels(index, den, num, icpt, ok)


def score_varying(
    models: WindowModels, u: np.ndarray, y: np.ndarray, s: Structure, n_est: int
) -> list[Score]:
    """k-step fits over the validation samples of the joined record (no free run)."""
    n_out = y.shape[1]
    targets = np.arange(n_est + s.max_lag, y.shape[0])
    out = [Score("-", {}) for _ in range(n_out)]
    unstable_share = np.zeros(n_out)
    for k in HORIZONS:
        pred, used = causal_predict(models, u, y, s, targets, k)
        if not np.all(models.ok[used]):
            raise RuntimeError("a validation sample was predicted before any model existed")
        for e in range(n_out):
            out[e].k[k] = _fmt(clpc.fit_percent(y[targets, e], pred[:, e]))
            if k == 1:
                unst = np.array([not _stable_poles(models.den[w, e]) for w in np.unique(used)])
                share = dict(zip(np.unique(used), unst, strict=True))
                unstable_share[e] = np.mean([share[w] for w in used])
    for e in range(n_out):
        if unstable_share[e] > 0:
            out[e].sim = f"- (u:{100 * unstable_share[e]:.0f}%)"
    return out


# ====================================================================== run
def evaluate(name: str, order: int, window: int, cluster: int) -> dict[str, list[Score]]:
    est, val = split(name)
    s = Structure.from_order(order)
    res: dict[str, list[Score]] = {}
    fixed = {
        "LPC paper": clpc.LPC(order=order, method="paper"),
        "LPC robust": clpc.LPC(order=order),
        "LS ARX": clpc.ARX(order=order),
    }
    for label, estimator in fixed.items():
        try:
            model = estimator.fit(est)
            res[label] = score_fixed(model, val)
        except clpc.ModelError:
            res[label] = [Score("n/a", dict.fromkeys(HORIZONS, "n/a"))] * val.n_outputs
    u = np.vstack([est.u, val.u])
    y = np.vstack([est.y, val.y])
    app = clpc.CLPC(order + 1, window, cluster)
    trace = app.run(u, y)
    models = clpc_models(trace)
    # the held parameters are what trace.held reports at each sample
    probe = np.array([est.n_samples, u.shape[0] - 1])
    held = trace.held(u.shape[0])[probe]
    last = np.searchsorted(trace.index, probe, side="right") - 1
    assert np.array_equal(held, trace.arrays["theta"][last])
    res["CLPC"] = score_varying(models, u, y, s, est.n_samples)
    p = s.n_params(u.shape[1])
    res["WLS"] = score_varying(wls_models(u, y, s, window, cluster, 2 * p), u, y, s, est.n_samples)
    return res


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(
        description="LPC, CLPC and least squares on every real record shipped with clpc"
    )
    ap.add_argument("--records", nargs="+", default=list(RECORDS), choices=RECORDS)
    ap.add_argument("--window", type=int, default=201, help="CLPC/WLS window W (default 201)")
    ap.add_argument("--cluster", type=int, default=12, help="CLPC/WLS cluster C (default 12)")
    ap.add_argument(
        "--orders",
        nargs="+",
        type=int,
        default=None,
        help="orders to run for every record (default: 2 and the BIC choice)",
    )
    args = ap.parse_args(argv)
    t0 = time.perf_counter()
    print(
        f"<!-- real_data.py, {time.strftime('%Y-%m-%d %H:%M')}, {platform.machine()}, "
        f"{os.cpu_count()} cores, numpy {np.__version__}, clpc {clpc.__version__} -->"
    )
    print(f"CLPC and WLS: W = {args.window}, C = {args.cluster} (every record).\n")
    head = ["record", "N"]
    for m in METHODS:
        head += [f"{m} sim", f"{m} k1", f"{m} k10"]
    lines = ["| " + " | ".join(head) + " |", "|" + "|".join("---" for _ in head) + "|"]
    notes = []
    for name in args.records:
        est, val = split(name)
        if args.orders:
            orders = list(args.orders)
        else:
            n2, why = second_order(est)
            orders = [2, n2]
            notes.append(
                f"{name}: N = {n2} ({why}); est {est.n_samples} / val {val.n_samples} samples"
            )
        for order in orders:
            res = evaluate(name, order, args.window, args.cluster)
            for j, out in enumerate(val.output_names):
                label = name if val.n_outputs == 1 else f"{name} {out}"
                cells = [label, str(order)]
                for m in METHODS:
                    sc = res[m][j]
                    cells += [sc.sim, sc.k[1], sc.k[10]]
                lines.append("| " + " | ".join(cells) + " |")
    print("\n".join(lines))
    if notes:
        print("\nSecond order per record:\n")
        print("\n".join(f"- {n}" for n in notes))
    print(f"\n({time.perf_counter() - t0:.1f} s)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
