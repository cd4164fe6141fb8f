"""Calibration of the parameter intervals, the delta method and the residual tests.

Prints, over many fixed seeds (numbers kept in docs/method.md, "Uncertainty and residual
analysis"):

1. the share of 95 % intervals (:meth:`LinearModel.confidence_interval`) that contain each
   true parameter - LPC on errors-in-variables records (white and colored input, two
   lengths), least squares on records whose noise enters the output equation, and, as the
   counter-example, least squares on records with noise on the output only (biased); OE on
   those output-noise records (one and two inputs);
2. delta-method standard deviations of a pole, the DC gain and ``|G|`` against the
   Monte-Carlo spread over the seeds;
3. for the residual tests on correct ARX models: the share of lags inside the 95 % bands
   and the share of records whose tests pass at 95 % and 99 %;
4. the time of the jackknife (scatter down-dates) against refits on the rows left.

Run: ``python benchmarks/uncertainty.py [--seeds 1000]`` (about a minute at 1000 seeds).
"""

from __future__ import annotations

import argparse
import itertools
import time

import numpy as np
from scipy import signal

import clpc
from clpc.lpc import lpc_solve, structure_blocks
from clpc.lpc.regressors import regressors
from clpc.lpc.solve import solve_scatter
from clpc.lpc.uncertainty import lpc_jackknife, monic_map

DEN = np.array([1.0, -1.5, 0.7])
NUM = np.array([0.5, 1.0, 0.5])
TRUE = np.r_[DEN[1:], NUM]
LABELS = ["a1", "a2", "b0", "b1", "b2"]


def eiv(seed: int, n: int, colored: bool) -> tuple[np.ndarray, np.ndarray]:
    rng = np.random.default_rng(seed)
    u0 = rng.standard_normal(n)
    if colored:
        u0 = signal.lfilter([1.0], [1.0, -0.7], u0)
    y0 = clpc.simulate_arx(DEN, NUM, u0)
    return u0 + 0.3 * rng.standard_normal(n), y0 + 0.3 * rng.standard_normal(n)


def equation_noise(seed: int, n: int) -> tuple[np.ndarray, np.ndarray]:
    rng = np.random.default_rng(seed)
    u = rng.standard_normal(n)
    return u, clpc.simulate_arx(DEN, NUM, u, 0.5 * rng.standard_normal(n))


def output_noise(seed: int, n: int) -> tuple[np.ndarray, np.ndarray]:
    rng = np.random.default_rng(seed)
    u = rng.standard_normal(n)
    return u, clpc.simulate_arx(DEN, NUM, u) + 0.5 * rng.standard_normal(n)


def coverage(seeds: int) -> None:
    print("1. share of 95 % intervals containing the true parameter", "  ".join(LABELS))
    cases = [
        ("LPC, EIV, white input, N=1000", clpc.LPC(order=2, assess=False), eiv, (1000, False)),
        ("LPC, EIV, white input, N=300", clpc.LPC(order=2, assess=False), eiv, (300, False)),
        ("LPC, EIV, colored input, N=2000", clpc.LPC(order=2, assess=False), eiv, (2000, True)),
        ("ARX, equation noise, N=400", clpc.ARX(order=2, assess=False), equation_noise, (400,)),
        ("ARX, equation noise, N=4000", clpc.ARX(order=2, assess=False), equation_noise, (4000,)),
        ("ARX, output noise only (biased)", clpc.ARX(order=2, assess=False), output_noise, (1000,)),
        ("OE, output noise, N=200", clpc.OE(order=2, assess=False), output_noise, (200,)),
        ("OE, output noise, N=1000", clpc.OE(order=2, assess=False), output_noise, (1000,)),
    ]
    for name, est, make, args in cases:
        hits = []
        for seed in range(seeds):
            lo, hi = est.fit(*make(seed, *args)).confidence_interval(0.95)
            hits.append((lo <= TRUE) & (TRUE <= hi))
        cover = np.mean(hits, axis=0)
        print(f"   {name:<34s}" + "  ".join(f"{c:.3f}" for c in cover))
    hits = []  # two inputs, one output: 8 parameters
    num2 = np.array([0.0, 0.3, -0.2])
    truth = np.r_[DEN[1:], NUM, num2]
    for seed in range(seeds):
        rng = np.random.default_rng(seed)
        u0 = rng.standard_normal((1500, 2))
        y0 = clpc.simulate_arx(DEN, NUM, u0[:, 0]) + clpc.simulate_arx(DEN, num2, u0[:, 1])
        u, y = u0 + 0.2 * rng.standard_normal((1500, 2)), y0 + 0.2 * rng.standard_normal(1500)
        lo, hi = clpc.LPC(order=2, assess=False).fit(u, y[:, None]).confidence_interval(0.95)
        hits.append((lo[0] <= truth) & (truth <= hi[0]))
    cover = np.mean(hits, axis=0)
    print(f"   {'LPC, EIV, 2 inputs (8 parameters)':<34s}" + "  ".join(f"{c:.3f}" for c in cover))
    hits = []  # the same system, exact inputs, white noise on the output only
    for seed in range(seeds):
        rng = np.random.default_rng(seed)
        u = rng.standard_normal((600, 2))
        y = clpc.simulate_arx(DEN, NUM, u[:, 0]) + clpc.simulate_arx(DEN, num2, u[:, 1])
        y = y + 0.5 * rng.standard_normal(600)
        lo, hi = clpc.OE(order=2, assess=False).fit(u, y[:, None]).confidence_interval(0.95)
        hits.append((lo[0] <= truth) & (truth <= hi[0]))
    cover = np.mean(hits, axis=0)
    print(f"   {'OE, output noise, 2 inputs, N=600':<34s}" + "  ".join(f"{c:.3f}" for c in cover))


def delta_vs_monte_carlo(seeds: int) -> None:
    print("2. delta-method std / Monte-Carlo std over the seeds")
    for name, est, make, args in (
        ("ARX, equation noise, N=1000", clpc.ARX(order=2, assess=False), equation_noise, (1000,)),
        ("LPC, EIV, N=1000", clpc.LPC(order=2, assess=False), eiv, (1000, False)),
    ):
        vals, stds = [], []
        for seed in range(seeds):
            m = est.fit(*make(seed, *args))
            p, sp = m.pole_std()
            i = int(np.argmax(p.imag))
            _, h, sm, sph = m.frequency_response_std(np.array([0.05, 0.2]))
            vals.append([p[i].real, p[i].imag, m.dc_gain()[0, 0], *np.abs(h), *np.angle(h)])
            stds.append([*sp[i], m.dc_gain_std()[0, 0], *sm, *sph])
        ratio = np.mean(stds, axis=0) / np.std(vals, axis=0)
        names = ["Re p", "Im p", "DC gain", "|G(.05)|", "|G(.2)|", "arg G(.05)", "arg G(.2)"]
        print(
            f"   {name:<30s}" + "  ".join(f"{n} {r:.3f}" for n, r in zip(names, ratio, strict=True))
        )


def residual_tests(seeds: int) -> None:
    print("3. residual tests of correct ARX models (colored input, white equation noise)")
    inside_a, inside_c, pass95, pass99 = [], [], [], []
    for seed in range(seeds):
        rng = np.random.default_rng(seed)
        u = signal.lfilter([1.0], [1.0, -0.5], rng.standard_normal(1000))
        y = clpc.simulate_arx(DEN, [0.0, 1.0, 0.5], u, 0.5 * rng.standard_normal(1000))
        m = clpc.ARX(order=2, assess=False).fit(u, y)
        r95 = clpc.residual_analysis(m, u, y, level=0.95)
        r99 = clpc.residual_analysis(m, u, y, level=0.99)
        inside_a.append(np.mean(np.abs(r95.autocorrelation[0, 1:]) <= r95.auto_band))
        inside_c.append(np.mean(np.abs(r95.cross_correlation[0, 0]) <= r95.cross_band[0, 0]))
        pass95.append([t.passed for t in r95.tests])
        pass99.append([t.passed for t in r99.tests])
    print(f"   lags inside the 95 % band: autocorrelation {np.mean(inside_a):.3f}, "
          f"cross-correlation {np.mean(inside_c):.3f}")  # fmt: skip
    p95, p99 = np.mean(pass95, axis=0), np.mean(pass99, axis=0)
    print(f"   records passing at 95 %: whiteness {p95[0]:.3f}, independence {p95[1]:.3f}; "
          f"at 99 %: whiteness {p99[0]:.3f}, independence {p99[1]:.3f}")  # fmt: skip


def jackknife_speed(repeats: int = 20) -> None:
    print("4. jackknife (20 segments) by scatter down-dates vs refits on the rows left")
    for n in (1000, 10000, 100000):
        u, y = eiv(0, n, False)
        data = clpc.as_iodata(u, y)
        s = clpc.Structure(2, 2, 0)
        mats, blocks, lmap = (
            regressors(data, s, "siso"),
            structure_blocks(s, 1),
            monic_map(s, 1, "siso"),
        )

        def solve(sc, mean, rows, blocks=blocks):
            return solve_scatter(sc, mean, rows, n_output_cols=3, blocks=blocks).theta

        def to_monic(theta, j, lmap=lmap):
            return (theta[:, 1:] / theta[:, :1]) @ lmap.T

        t0 = time.perf_counter()
        for _ in range(repeats):
            fast = lpc_jackknife(mats, solve, to_monic, 20)
        t_fast = (time.perf_counter() - t0) / repeats
        edges = np.arange(21) * (mats.shape[1] // 20)
        edges[-1] = mats.shape[1]
        slow_repeats = max(1, repeats * 1000 // n)
        t0 = time.perf_counter()
        for _ in range(slow_repeats):
            reps = [
                to_monic(lpc_solve(np.delete(mats, np.s_[a:b], axis=1), n_output_cols=3,
                                   blocks=blocks).theta, 0)[0]
                for a, b in itertools.pairwise(edges)
            ]  # fmt: skip
            dev = np.array(reps) - np.mean(reps, axis=0)
            slow = 19 / 20 * dev.T @ dev
        t_slow = (time.perf_counter() - t0) / slow_repeats
        err = float(np.max(np.abs(fast[0] - slow)) / np.max(np.abs(slow)))
        print(f"   T = {n:>6d}: {t_fast * 1e3:7.2f} ms vs {t_slow * 1e3:7.2f} ms refitting "
              f"({t_slow / t_fast:5.1f}x faster), max relative difference {err:.1e}")  # fmt: skip


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--seeds", type=int, default=1000)
    args = parser.parse_args()
    t0 = time.perf_counter()
    coverage(args.seeds)
    delta_vs_monte_carlo(args.seeds)
    residual_tests(args.seeds)
    jackknife_speed()
    print(f"({args.seeds} seeds, {time.perf_counter() - t0:.0f} s)")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
