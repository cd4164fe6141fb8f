"""The errors-in-variables check of ``clpc.identify`` on simulated records (``clpc.lpc.eiv``).

A second-order system (``A = [1, -1.5, 0.7]``, ``B = [1, 0.5, 0.2]``, ``nk = 0``) driven by a
coloured input (white noise through ``1 / (1 - 0.5 q^-1)``), 1000 samples, 20 seeds per case.
White noise of standard deviation ``level * std(y0)`` is added:

* ``output``: on the output only (exact input: OE's and the exact-input TLS's assumption);
* ``eiv``: on both channels with the same standard deviation (LPC's assumption);
* ``eiv, input 0.3``: on both, the input's 0.3 times the output's;
* ``none``: noise-free.

For each record ``check_eiv(data, OE(order=2).fit(data))``: the ratio ``||p_LPC - p_OE|| /
||p_exact - p_OE||``, LPC's relative distance to OE, and how often the check says *violated*
(``ratio >= RATIO`` and distance ``>= MIN_RELATIVE``). Also each estimator's distance to the
true monic parameters (median).

Usage::

    python benchmarks/eiv_check.py
"""

from __future__ import annotations

import time

import numpy as np
from scipy import signal

import clpc
from clpc.lpc.eiv import MIN_RELATIVE, RATIO, check_eiv, exact_input_tls

A = np.array([1.0, -1.5, 0.7])
B = np.array([1.0, 0.5, 0.2])
SEEDS = range(20)
CASES = (("output", 0.0), ("eiv", 1.0), ("eiv, input 0.3", 0.3), ("none", None))


def record(seed: int, level: float, input_share: float | None) -> clpc.IOData:
    rng = np.random.default_rng(seed)
    n = 1000
    u0 = signal.lfilter([1.0], [1.0, -0.5], rng.standard_normal(n))
    y0 = signal.lfilter(B, A, u0)
    if input_share is None:
        return clpc.as_iodata(u0, y0)
    s = level * y0.std()
    return clpc.as_iodata(
        u0 + input_share * s * rng.standard_normal(n), y0 + s * rng.standard_normal(n)
    )


def main() -> None:
    t0 = time.perf_counter()
    truth = np.r_[A, -B][1:]
    print(f"threshold: ratio >= {RATIO:g} and LPC distance >= {100 * MIN_RELATIVE:g} %\n")
    cols = ["noise", "level", "ratio median", "ratio min-max", "LPC dist. median", "flagged"]
    print("| " + " | ".join([*cols, "err OE", "err LPC", "err exact"]) + " |")
    print("|" + "---|" * 9)
    for name, share in CASES:
        for level in (0.1, 0.3) if share is not None else (0.0,):
            ratio, dist, flag, err = [], [], 0, []
            for seed in SEEDS:
                data = record(seed, level, share)
                oe = clpc.OE(order=2).fit(data)
                chk = check_eiv(data, oe)
                ratio.append(chk.ratio[0])
                dist.append(chk.lpc_distance[0])
                flag += chk.violated
                lpc = clpc.LPC(order=2, cancel=False).fit(data)
                mon = [m.theta[0, 1:] / m.theta[0, 0] for m in (oe, lpc)]
                mon.append(exact_input_tls(data, oe)[0, 1:])
                err.append([np.linalg.norm(m - truth) for m in mon])
            e = np.median(err, axis=0)
            print(
                f"| {name} | {level:g} | {np.median(ratio):.3g} "
                f"| {min(ratio):.3g}-{max(ratio):.3g} "
                f"| {100 * np.median(dist):.3g} % | {flag}/{len(SEEDS)} | {e[0]:.3g} | {e[1]:.3g} "
                f"| {e[2]:.3g} |"
            )
    print(f"\n({time.perf_counter() - t0:.1f} s)")


if __name__ == "__main__":
    main()
