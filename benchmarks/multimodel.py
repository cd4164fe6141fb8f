"""Multi-models (issue 18): the crank servo over seeds, the cascaded tanks, D, and speed.

1. The crank servo (``clpc_paper.plants.crank_servo``) and its negative control (velocity
   integrator 10 /s), the demo's full-size records (60 levels of 6 s for identification;
   30 new levels and a 4-leg 30 s triangle sweep for validation), seeds 0..4: validation
   free-run fit % of global LPC, global least squares, the CLPC steady-state model and
   ``MultiModel.from_trace`` (scored from sample 203 on, from the measured state).
2. The cascaded tanks (its own estimation and validation records, N = 2): global least
   squares and LPC, the default multi-model, and local LPC only (``estimator="lpc"``,
   where the stability guard replaces unstable local models).
3. What D measures on the crank trace: Spearman correlation of D and of the scale-free
   ``lambda_min / lambda_max`` with the window's signal energy and with the global
   model's mismatch in the window.
4. Speed of the free run: the compiled loop against the same loop in plain Python (a child
   process with ``NUMBA_DISABLE_JIT=1``).

Usage::

    python benchmarks/multimodel.py
"""

from __future__ import annotations

import os
import subprocess
import sys
import tempfile
import time
import warnings
from pathlib import Path

import numpy as np
from scipy import stats

import clpc
from clpc import datasets
from clpc.analysis.operating_point import operating_point_diagnostics, window_means
from clpc_paper.plants.crank_servo import CrankParameters, crank_commands, simulate_crank_servo

START = 203


def _fit(model, rec):
    u, y = rec.command, rec.position
    sim = model.simulate(u[START:], y_init=y[START - 2 : START], u_init=u[START - 2 : START])
    return clpc.fit_percent(y[START:], sim)


def crank(seeds=range(5)) -> None:
    print("1. crank servo: validation free-run fit % (levels / sweep)")
    print(
        f"{'plant':10s} {'seed':>4s} {'LPC':>11s} {'LS':>11s} {'steady':>11s} {'multi':>11s} models"
    )
    gains = {"nonlinear": [], "control": []}
    for name, prm in (
        ("nonlinear", CrankParameters()),
        ("control", CrankParameters(velocity_integrator=10.0)),
    ):
        for seed in seeds:
            s = 100 * seed
            ident = simulate_crank_servo(crank_commands(60, seed=s), seed=s + 1, params=prm)
            recs = [
                simulate_crank_servo(crank_commands(30, seed=s + 2), seed=s + 3, params=prm),
                simulate_crank_servo(
                    crank_commands(4, hold=30.0, sweep=True, seed=s + 4), seed=s + 5, params=prm
                ),
            ]
            u, y = ident.command, ident.position
            trace = clpc.CLPC(order=2, window_size=201, cluster_size=12).run(u, y, dt=0.01)
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                steady = trace.steady_state_model(allow_unconverged=True)
            models = [
                clpc.LPC(order=2).fit(u, y, dt=0.01),
                clpc.ARX(order=2).fit(u, y, dt=0.01),
                steady,
                clpc.MultiModel.from_trace(trace, u, y),
            ]
            f = np.array([[_fit(m, r) for r in recs] for m in models])
            gains[name].append(f[3] - f[:2].max(axis=0))
            cells = " ".join(f"{a:5.1f}/{b:5.1f}" for a, b in f)
            print(
                f"{name:10s} {seed:4d} {cells} {models[3].n_models} "
                f"({models[3].diagnostics['estimator']})"
            )
    for name, g in gains.items():
        g = np.array(g)
        print(
            f"   {name}: multi-model minus best global: min {g.min():+.2f}, "
            f"mean {g.mean():+.2f}, max {g.max():+.2f} points; records above +1 point: "
            f"{int((g > 1).sum())} of {g.size}"
        )


def tanks() -> None:
    print("\n2. cascaded tanks (N = 2): validation free-run fit %")
    est, val = datasets.load("cascaded_tanks")
    u, y, vu, vy = est.u[:, 0], est.y[:, 0], val.u[:, 0], val.y[:, 0]

    def fit(m):
        return clpc.fit_percent(vy[2:], m.simulate(vu[2:], y_init=vy[:2], u_init=vu[:2]))

    ls, lpc = clpc.ARX(order=2).fit(u, y, dt=est.dt), clpc.LPC(order=2).fit(u, y, dt=est.dt)
    mm = clpc.MultiModel().fit(u, y, dt=est.dt)
    only = clpc.MultiModel(estimator="lpc").fit(u, y, dt=est.dt)
    print(f"   global LS {fit(ls):.2f}, global LPC {fit(lpc):.2f}")
    print(
        f"   multi-model (default): {fit(mm):.2f} ({mm.n_models} model(s), "
        f"{mm.diagnostics['estimator']}; centres from the {mm.diagnostics['centre_source']})"
    )
    print(
        f"   multi-model, local LPC only: {fit(only):.2f} ({only.n_models} models, "
        f"replaced by the guard: {only.diagnostics['replaced']})"
    )


def what_d_measures() -> None:
    print("\n3. what D measures (crank servo, seed 0, Table 1 windows)")
    ident = simulate_crank_servo(crank_commands(60, seed=0), seed=1)
    u, y = ident.command, ident.position
    trace = clpc.CLPC(order=2, window_size=201, cluster_size=12).run(u, y, dt=0.01)
    rep = operating_point_diagnostics(trace, u, y)
    ok = np.isfinite(rep.mismatch)
    var = (
        window_means(y**2, trace.index, trace.rows) - window_means(y, trace.index, trace.rows) ** 2
    )
    for key in ("D", "eig_ratio"):
        v = np.asarray(trace.arrays[key][:, 0])
        e = stats.spearmanr(v[ok], np.log(var[ok] + 1e-300))[0]
        m = stats.spearmanr(v[ok], rep.mismatch[ok])[0]
        print(
            f"   {key:9s}: Spearman with log window variance {e:+.2f}, with the global "
            f"model's mismatch {m:+.2f}"
        )
    print(f"   verdict: {rep.verdict}")


_UNCOMPILED = """
import sys, time, numpy as np, clpc
mm = clpc.MultiModel.load(sys.argv[1])
u = np.load(sys.argv[2])
t0 = time.perf_counter()
np.save(sys.argv[3], mm.simulate(u))
print(time.perf_counter() - t0)
"""


def speed() -> None:
    print("\n4. free-run speed (36,000 samples, 7 local models)")
    ident = simulate_crank_servo(crank_commands(60, seed=0), seed=1)
    mm = clpc.MultiModel(n_models=7).fit(ident.command, ident.position, dt=0.01)
    mm.simulate(ident.command[:100])  # compile
    t0 = time.perf_counter()
    fast = mm.simulate(ident.command)
    t_fast = time.perf_counter() - t0
    with tempfile.TemporaryDirectory() as tmp:
        paths = [str(Path(tmp) / name) for name in ("mm.json", "u.npy", "y.npy")]
        mm.save(paths[0])
        np.save(paths[1], ident.command)
        env = {**os.environ, "NUMBA_DISABLE_JIT": "1"}
        res = subprocess.run(
            [sys.executable, "-c", _UNCOMPILED, *paths],
            env=env,
            capture_output=True,
            text=True,
            check=True,
        )
        t_slow = float(res.stdout.split()[-1])
        same = np.max(np.abs(fast - np.load(paths[2])))
    print(
        f"   compiled {t_fast * 1e3:.1f} ms, plain Python (NUMBA_DISABLE_JIT=1) "
        f"{t_slow * 1e3:.0f} ms: {t_slow / t_fast:.0f}x; largest difference {same:.1e} rad"
    )


if __name__ == "__main__":
    crank()
    tanks()
    what_d_measures()
    speed()
