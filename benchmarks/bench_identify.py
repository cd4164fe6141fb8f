"""How long ``identify`` takes with everything automatic (issue 25 targets: 3 s and 20 s).

A 4th-order plant with a 2-sample delay (two real poles, one complex pair), coloured input,
5 % output noise, ``dt = 10 ms``. For each record length, in one run:

* ``identify`` (API, defaults: order, delay and estimator automatic), first call in a fresh
  process (imports included) and then warm, best of ``--repeat``;
* ``clpc identify FILE -u u -y y --time t`` as a user runs it (a fresh process: interpreter,
  imports, reading the CSV, the search, printing);
* references in the same process: one cold ``OE(order=4, nk=2)`` fit and one ``ARX`` fit on
  the whole record, so the ratios say how many fits the search costs.

Run: ``python benchmarks/bench_identify.py [--sizes 3000 25000] [--repeat 3]``.
"""

from __future__ import annotations

import argparse
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

TARGETS = {3000: 3.0, 25000: 20.0}


def record(n: int, seed: int = 1) -> tuple[np.ndarray, np.ndarray]:
    """The benchmark plant's input and noisy output, ``n`` samples."""
    from scipy import signal

    rng = np.random.default_rng(seed)
    u = signal.lfilter([1.0], [1.0, -0.9], rng.standard_normal(n))
    den = np.poly([0.95, 0.7, 0.8 * np.exp(0.4j), 0.8 * np.exp(-0.4j)]).real
    y0 = signal.lfilter([0, 0, 0.02, 0.03, -0.01], den, u)
    return u, y0 + 0.05 * y0.std() * rng.standard_normal(n)


def best(fun, repeat: int) -> float:
    """Best wall time of ``repeat`` calls [s]."""
    times = []
    for _ in range(repeat):
        start = time.perf_counter()
        fun()
        times.append(time.perf_counter() - start)
    return min(times)


def cli_seconds(path: Path) -> float:
    """Wall time of ``clpc identify`` in a fresh process [s]."""
    start = time.perf_counter()
    args = [sys.executable, "-m", "clpc", "identify", str(path), "-u", "u", "-y", "y"]
    subprocess.run([*args, "--time", "t"], check=True, capture_output=True)
    return time.perf_counter() - start


def main() -> None:
    """Print one table row per measurement."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", type=int, nargs="+", default=[3000, 25000])
    parser.add_argument("--repeat", type=int, default=3)
    args = parser.parse_args()
    start = time.perf_counter()
    import clpc

    imports = time.perf_counter() - start
    print(f"import clpc: {imports:.2f} s")
    print(f"{'path':<28}{'T':>7}{'time [s]':>10}{'target':>8}{'x target':>10}{'x OE fit':>10}")
    for n in args.sizes:
        u, y = record(n)
        data = clpc.IOData(u, y, dt=0.01)
        first = time.perf_counter()
        found = clpc.identify(data)
        first = time.perf_counter() - first
        warm = best(lambda data=data: clpc.identify(data), args.repeat)
        oe = best(lambda data=data: clpc.OE(order=4, nk=2, assess=False).fit(data), 1)
        arx = best(lambda data=data: clpc.ARX(order=4, nk=2, assess=False).fit(data), 3)
        with tempfile.TemporaryDirectory() as tmp:
            path = Path(tmp) / "rec.csv"
            t = np.arange(n) * 0.01
            np.savetxt(path, np.column_stack([t, u, y]), delimiter=",", header="t,u,y", comments="")
            cli = cli_seconds(path)
        target = TARGETS.get(n, float("nan"))
        for name, sec in (
            ("identify, first call", first),
            ("identify, warm", warm),
            ("clpc identify (process)", cli),
            ("OE(order=4) fit", oe),
            ("ARX(order=4) fit", arx),
        ):
            ratio = sec / target if name.startswith(("identify", "clpc")) else float("nan")
            print(f"{name:<28}{n:>7}{sec:>10.3f}{target:>8.0f}{ratio:>10.2f}{sec / oe:>10.2f}")
        s = found.structure
        chosen = next(r for r in found.table if r["chosen"])
        print(
            f"  chose {found.estimator.upper()} na={s.na} nb={s.nb} nk={s.nk}, held-out free run "
            f"{chosen['free_run']:.1f} % (the plant: na 4, nb 2, nk 2; the fewest coefficients "
            "within 1 point win)"
        )


if __name__ == "__main__":
    main()
