"""``clpc.identify`` at its defaults beside the identification tools an engineer would use instead.

What it measures: on every real record shipped in ``clpc.datasets`` and for every output of
it (a "target"), the free-run fit on held-out data of the model each tool identifies from the
estimation data alone, with that tool's own way of choosing the structure.

Protocol (the same for every method):

* **Split.** Estimation: the first 60 % of the record; validation: the last 40 %
  (``cascaded_tanks``: its own estimation and validation records). The estimation part's
  mean (per channel) is removed from both parts, for every method.
* **Free run.** Each model is simulated from the input alone, from zero (deviation) state at
  the first sample of each experiment: the whole record (estimation then validation) for a
  split record, the validation record on its own for ``cascaded_tanks``; only the validation
  samples are scored. So no method gets its initial condition from measured outputs, and
  the estimation part serves as the warm-up of a split record's free run.
* **Scores** on the validation samples of output ``j``: fit % ``= 100 (1 - ||y - yhat|| /
  ||y - mean(y)||)`` (mean of the validation samples), RMS error ``sqrt(mean((y -
  yhat)^2))`` in the output's units. ``max |pole|``: the largest pole radius of the model of
  that output (>= 1: unstable). ``fit s``: wall time of the fit including the tool's
  structure search, not of the simulation; a model of all outputs at once (``MIMO``) shows
  the time of the whole record on each of its outputs. Every peer is imported and clpc run
  once before the first timed fit, so no fit pays for imports or compilation. The machine's
  load average is printed with the results: the seconds are as noisy as the machine.

Methods:

1. ``clpc identify``: ``clpc.identify(est).model`` with the defaults of the installed clpc,
   whatever they are; simulated by ``model.simulate(u)`` (zero initial outputs and inputs,
   its identified constant added, as by default). One model of all outputs (its default
   MIMO mode). The structure column also gives the fit of ``simulate(u,
   include_offset=False)`` (the model without its constant), for information only.
2. ``clpc identify auto``: ``clpc.identify(est, order="auto", nk="auto")``, only if it
   finishes within ``AUTO_LIMIT`` seconds on the record (else the row says it was skipped);
   left out when identify's defaults are already ``order="auto"`` and ``nk="auto"`` (the
   same call), or with ``--no-clpc-auto``.
3. SIPPY (``sippy_unipi``), ``system_identification`` with ``IC="AICc"`` (its
   information-criterion mode; AICc in every peer whose criterion we set):

   * ``SIPPY N4SID``, ``SIPPY MOESP``, ``SIPPY CVA``: one state-space model of all outputs,
     order 1..10 (``SS_orders=[1, 10]``) chosen by AICc of the estimation-part free run,
     future horizon ``SS_f=20``, ``D = 0`` (its default);
   * ``SIPPY ARX``: na 1..10, nb 1..10, delays 0..5 (the full grid, least squares);
   * ``SIPPY ARMAX``: its default iterative least squares (``ARMAX_mod="ILLS"``) over na
     1..6, nb 1..6, nc 1..2, delays 0..3 (288 fits, 82 s on ``exchanger`` at load average
     5; the full 1..10 x 0..5 grid is 6,000 fits, and nc 1..3 with delays 0..5 took over
     180 s there). A smaller grid (na, nb 1..4) cost SIPPY ARMAX 69 points on
     ``robot_arm``, which needs about six poles;
   * ``SIPPY OE``: ``OE_mod="RLLS"`` (its recursive pseudo-linear regression) over nb 1..6,
     nf 1..6, delays 0..3 (144 fits). Its default ``OE_mod="OPT"`` solves one IPOPT problem
     per candidate, 0.2-37 s each on these records (measured), too slow for a grid here.

   ``--full-grids`` runs ARMAX and OE over orders 1..10 and delays 0..5 (hours; raise
   ``--peer-limit`` with it). SIPPY's
   information criteria for ARX, ARMAX and OE are SISO only: on a multi-input record the
   library refuses (``sys.exit``) and the row shows its message; its subspace methods are
   its MIMO answer.
4. ``nfoursid N4SID``: ``NFourSID`` (PO-MOESP) with 20 block rows (2 x the largest order),
   one model of all outputs; order 1..10 chosen by the lowest AICc of the estimation-part
   free run (from zero state; SIPPY's formula and parameter count ``n (l + m) + l m``),
   i.e. on the estimation data only.
5. ``sysidentpy FROLS``: ``FROLS`` with ``Polynomial(degree=1)`` (a linear ARX chosen term by
   term), ``LeastSquares()``, ``info_criteria="aicc"`` over every model size
   (``n_info_values`` = all candidate terms), ``ylag=10``, ``xlag=10`` for each input (lags
   1..10: no direct feedthrough), one MISO model per output; free run by its own
   ``predict(X, y, steps_ahead=None)`` given ``max_lag`` zero samples first (zero state).
6. ``oracle ARX``: ``clpc.ARX(na=, nb=, nk=)`` (least squares, each output on all inputs)
   with the structure (na 1..10, nb 0..10, nk 0..5; clpc's nb counts ``nb + 1`` taps) that
   gives the best validation free-run fit, per output. It sees the validation data: it is a
   reference, not a peer, and not counted as one.

Structure column, in one convention for every tool: ``na`` poles, ``nb`` input taps, ``nk``
the lag of the first tap (0 = direct feedthrough); ARMAX adds ``nc``; state-space models
show their order ``n``; FROLS lists its chosen lags.

Each peer runs inside ``try`` with a time limit per record (``--peer-limit``, default 120 s;
a SIGALRM: it interrupts Python code, a long C call only when it returns); an exception or
the limit gives a row with the error text and the run goes on. ``clpc identify`` has no
limit (it is what is measured).

Summary: per target, identify's fit against the best peer's (the highest fit among the
peers: not identify, not identify auto, not the oracle); per method, the mean fit over the
targets with a fit below 0 counted as 0 (no better than the validation mean) and no model
as 0, the same mean over the targets where it gave a model, the median, the unstable models
and the wins; then the count of targets where identify is within 2 points of the best peer
or ahead, the worst shortfall, and whether identify's mean beats the best peer mean. The
per-target tables show the raw numbers.

Usage (the peers are not dependencies of clpc: ``pip install -e ".[peers]"`` in a venv of
its own). About 4 min on the shared 2-core machine at load average 3 with identify's
defaults automatic (no auto row); about 20 min at load average 5-6 with the auto row of
clpc before those defaults (identify auto 40-60 s per record, ``--no-clpc-auto`` to skip
it). ``identify`` limits itself to one BLAS thread; ``OPENBLAS_NUM_THREADS=1`` gives the
peers the same. The Markdown starts at heading level 3 (to sit under a section)::

    OPENBLAS_NUM_THREADS=1 python benchmarks/peers.py [--records dryer exchanger]
        [--markdown FILE] [--no-clpc-auto] [--full-grids] [--peer-limit SECONDS]
"""

from __future__ import annotations

import argparse
import contextlib
import inspect
import io
import math
import os
import platform
import signal
import subprocess
import sys
import time
import warnings
from collections.abc import Callable, Iterator
from dataclasses import dataclass, field
from datetime import datetime
from pathlib import Path

import numpy as np
from scipy.signal import lfilter, ss2tf

import clpc
from clpc import datasets

#: largest order / lag every peer searches (subspace order, ARX orders, FROLS lags)
MAX_ORDER = 10
#: largest input delay searched (SIPPY's ``delays``, the oracle's ``nk``)
MAX_DELAY = 5
#: subspace future horizon / block rows (2 x MAX_ORDER)
BLOCK_ROWS = 2 * MAX_ORDER
#: seconds clpc identify(order="auto", nk="auto") may take on one record
AUTO_LIMIT = 60.0
#: default time limit of one peer on one record [s]
PEER_LIMIT = 120.0
#: identify is "on par" when within this many points of the best peer
ON_PAR = 2.0
#: SIPPY ARMAX and OE grids: (na, nb, nc or nf, delays) ranges, reduced and full
ARMAX_GRID = {"na_ord": [1, 6], "nb_ord": [1, 6], "nc_ord": [1, 2], "delays": [0, 3]}
OE_GRID = {"nb_ord": [1, 6], "nf_ord": [1, 6], "delays": [0, 3]}
FULL_ARMAX_GRID = {"na_ord": [1, 10], "nb_ord": [1, 10], "nc_ord": [1, 10], "delays": [0, 5]}
FULL_OE_GRID = {"nb_ord": [1, 10], "nf_ord": [1, 10], "delays": [0, 5]}

CLPC = "clpc identify"
CLPC_AUTO = "clpc identify auto"
ORACLE = "oracle ARX (sees validation)"


# ====================================================================== data
@dataclass
class Record:
    """One shipped record, estimation mean removed from both parts."""

    name: str
    u_est: np.ndarray
    y_est: np.ndarray
    u_val: np.ndarray
    y_val: np.ndarray
    dt: float
    inputs: tuple[str, ...]
    outputs: tuple[str, ...]
    #: the validation part continues the estimation part (one experiment)
    continuous: bool

    @property
    def est(self) -> clpc.IOData:
        return clpc.IOData(self.u_est, self.y_est, self.dt, self.inputs, self.outputs)

    def sim_input(self) -> np.ndarray:
        """The input of the scored free run: the whole record, or the validation record."""
        return np.vstack([self.u_est, self.u_val]) if self.continuous else self.u_val

    def val_part(self, y_sim: np.ndarray) -> np.ndarray:
        """The validation samples of a free run over :meth:`sim_input`."""
        return y_sim[len(self.u_est) :] if self.continuous else y_sim

    def targets(self) -> list[str]:
        return [self.name if len(self.outputs) == 1 else f"{self.name} / {o}" for o in self.outputs]


def load(name: str) -> Record:
    loaded = datasets.load(name)
    if isinstance(loaded, tuple):
        est, val = loaded
        continuous = False
    else:
        cut = round(0.6 * loaded.n_samples)
        est, val = loaded[:cut], loaded[cut:]
        continuous = True
    mu, my = est.u.mean(axis=0), est.y.mean(axis=0)
    return Record(
        name,
        est.u - mu,
        est.y - my,
        val.u - mu,
        val.y - my,
        float(est.dt),
        tuple(est.input_names),
        tuple(est.output_names),
        continuous,
    )


# ====================================================================== results
@dataclass
class Outcome:
    """One method on one output."""

    y_val: np.ndarray | None = None  # validation part of the free run
    structure: str = ""
    pole: float = math.nan
    seconds: float = math.nan
    error: str = ""


@dataclass
class Row:
    """A method's scores on one target."""

    method: str
    fit: float
    rms: float
    structure: str
    pole: float
    seconds: float
    error: str = ""

    @property
    def ok(self) -> bool:
        return not self.error


@dataclass
class Table:
    target: str
    n_est: int
    n_val: int
    rows: list[Row] = field(default_factory=list)


def score(y: np.ndarray, yhat: np.ndarray) -> tuple[float, float]:
    """Fit % and RMS error (``-inf`` / ``inf`` for a diverged free run)."""
    with np.errstate(all="ignore"):
        err = y - yhat
        if not np.all(np.isfinite(err)):
            return -math.inf, math.inf
        fit = 100.0 * (1.0 - np.linalg.norm(err) / np.linalg.norm(y - y.mean()))
        return float(fit), float(np.sqrt(np.mean(err**2)))


class PeerTimeout(Exception):
    pass


@contextlib.contextmanager
def limit(seconds: float) -> Iterator[None]:
    """Raise :class:`PeerTimeout` after ``seconds`` (SIGALRM; main thread, POSIX)."""
    if seconds <= 0 or not hasattr(signal, "setitimer"):
        yield
        return

    def alarm(signum: int, frame: object) -> None:
        raise PeerTimeout(f"over the time limit of {seconds:.0f} s")

    old = signal.signal(signal.SIGALRM, alarm)
    signal.setitimer(signal.ITIMER_REAL, seconds)
    try:
        yield
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, old)


@contextlib.contextmanager
def quiet() -> Iterator[None]:
    """Silence the peers' prints and warnings."""
    with contextlib.redirect_stdout(io.StringIO()), warnings.catch_warnings():
        warnings.simplefilter("ignore")
        with np.errstate(all="ignore"):
            yield


def failed(rec: Record, exc: BaseException) -> list[Outcome]:
    text = " ".join(str(exc).split()) or "(no message)"
    text = f"{type(exc).__name__}: {text}"
    return [Outcome(error=text[:160]) for _ in rec.outputs]


# ====================================================================== helpers
def ranges(values: list[int] | range) -> str:
    """``[1, 2, 3, 5]`` -> ``1-3,5``."""
    vals = sorted(set(values))
    if not vals:
        return "-"
    parts, start = [], vals[0]
    for a, b in zip(vals, [*vals[1:], None], strict=True):
        if b != a + 1:
            parts.append(f"{start}" if start == a else f"{start}-{a}")
            start = b
    return ",".join(parts)


def structure_io(na: int, nb: int, nk: int, **extra: int) -> str:
    more = "".join(f" {k}={v}" for k, v in extra.items())
    return f"na={na} nb={nb} nk={nk}{more}"


def tf_simulate(num: np.ndarray, den: np.ndarray, u: np.ndarray) -> np.ndarray:
    """Zero-state response of ``num(z)/den(z)`` (descending powers of ``z``, proper)."""
    num, den = np.atleast_1d(np.asarray(num, float)), np.atleast_1d(np.asarray(den, float))
    num = np.concatenate([np.zeros(len(den) - len(num)), num])
    return lfilter(num, den, u)


def ss_simulate(a: np.ndarray, b: np.ndarray, c: np.ndarray, d: np.ndarray, u: np.ndarray):
    """Zero-state response of ``x+ = A x + B u, y = C x + D u``; ``u`` (T, m) -> (T, l).

    Through the transfer function of each input (``scipy.signal.ss2tf``, orders <= 10 here)
    and ``lfilter``: the same response as the state recursion, without a Python loop.
    """
    y = np.zeros((u.shape[0], c.shape[0]))
    with np.errstate(all="ignore"):
        for i in range(u.shape[1]):
            num, den = ss2tf(a, b, c, d, input=i)
            for j in range(c.shape[0]):
                y[:, j] += lfilter(num[j], den, u[:, i])
    return y


def max_radius(poles: np.ndarray) -> float:
    poles = np.asarray(poles)
    return float(np.max(np.abs(poles))) if poles.size else 0.0


def aicc(n_par: int, n: int, variance: float) -> float:
    """SIPPY's AICc (``functionset.information_criterion``)."""
    if n - n_par - 1 <= 0 or not variance > 0 or not math.isfinite(variance):
        return math.inf
    return n * math.log(variance) + 2 * n_par + 2 * n_par * (n_par + 1) / (n - n_par - 1)


# ====================================================================== clpc
def clpc_model(rec: Record, make: Callable[[], object], kind: str) -> list[Outcome]:
    t0 = time.perf_counter()
    ident = make()
    seconds = time.perf_counter() - t0
    model = ident.model  # type: ignore[attr-defined]
    y_sim = np.asarray(model.simulate(rec.sim_input()), float).reshape(-1, len(rec.outputs))
    s = model.structure
    chosen = getattr(ident, "estimators", None) or ("?",) * len(rec.outputs)
    # the fit the model would have without its identified constant (clpc's default adds it)
    y_dev = np.asarray(model.simulate(rec.sim_input(), include_offset=False), float)
    y_dev = rec.val_part(y_dev.reshape(-1, len(rec.outputs)))
    out = []
    for j in range(len(rec.outputs)):
        est = str(chosen[j] if j < len(chosen) else chosen[0]).upper()
        dev, _ = score(rec.y_val[:, j], y_dev[:, j])
        out.append(
            Outcome(
                rec.val_part(y_sim)[:, j],
                f"{est} {structure_io(s.na, s.nb + 1, s.nk)} ({model.mode}); "
                f"without its constant {fmt_fit(dev)}",
                max_radius(model.poles(j)),
                seconds,
            )
        )
    return out


def run_clpc(rec: Record) -> list[Outcome]:
    return clpc_model(rec, lambda: clpc.identify(rec.est), CLPC)


def run_clpc_auto(rec: Record) -> list[Outcome]:
    try:
        with limit(AUTO_LIMIT):
            return clpc_model(
                rec, lambda: clpc.identify(rec.est, order="auto", nk="auto"), CLPC_AUTO
            )
    except PeerTimeout:
        return [
            Outcome(error=f"skipped: over {AUTO_LIMIT:.0f} s on this record") for _ in rec.outputs
        ]


def run_oracle(rec: Record) -> list[Outcome]:
    """Least-squares ARX, the structure of the best validation free run per output."""
    n_out = len(rec.outputs)
    mimo = "siso" if rec.u_est.shape[1] == 1 and n_out == 1 else "miso"
    best: list[tuple[float, np.ndarray | None, str, float]] = [
        (-math.inf, None, "", math.nan)
    ] * n_out
    u_sim, est = rec.sim_input(), rec.est
    t0 = time.perf_counter()
    for na in range(1, MAX_ORDER + 1):
        for nb in range(0, MAX_ORDER + 1):
            for nk in range(0, MAX_DELAY + 1):
                try:
                    with np.errstate(all="ignore"):
                        m = clpc.ARX(
                            na=na, nb=nb, nk=nk, mimo=mimo, uncertainty=False, assess=False
                        ).fit(est)
                        y_sim = np.asarray(m.simulate(u_sim), float).reshape(-1, n_out)
                except Exception:
                    continue
                y_val = rec.val_part(y_sim)
                for j in range(n_out):
                    fit, _ = score(rec.y_val[:, j], y_val[:, j])
                    if fit > best[j][0]:
                        best[j] = (
                            fit,
                            y_val[:, j].copy(),
                            structure_io(na, nb + 1, nk),
                            max_radius(m.poles(j)),
                        )
    seconds = time.perf_counter() - t0
    return [Outcome(b[1], b[2], b[3], seconds) for b in best]


# ====================================================================== SIPPY
def sippy_ss(method: str) -> Callable[[Record], list[Outcome]]:
    def run(rec: Record) -> list[Outcome]:
        from sippy_unipi import system_identification

        t0 = time.perf_counter()
        with quiet():
            m = system_identification(
                rec.y_est,
                rec.u_est,
                method,
                IC="AICc",
                SS_orders=[1, MAX_ORDER],
                SS_f=BLOCK_ROWS,
            )
        seconds = time.perf_counter() - t0
        a, b, c, d = (np.atleast_2d(np.asarray(x, float)) for x in (m.A, m.B, m.C, m.D))
        y_sim = ss_simulate(a, b, c, d, rec.sim_input())
        pole = max_radius(np.linalg.eigvals(a))
        return [
            Outcome(rec.val_part(y_sim)[:, j], f"n={a.shape[0]} D=0 (MIMO)", pole, seconds)
            for j in range(len(rec.outputs))
        ]

    return run


def sippy_io(method: str, full: bool) -> Callable[[Record], list[Outcome]]:
    """SIPPY's ARX / ARMAX / OE with its information-criterion order search (SISO only)."""

    def run(rec: Record) -> list[Outcome]:
        import control
        from sippy_unipi import system_identification

        if method == "ARX":
            opts: dict = {
                "na_ord": [1, MAX_ORDER],
                "nb_ord": [1, MAX_ORDER],
                "delays": [0, MAX_DELAY],
            }
        elif method == "ARMAX":
            opts = dict(FULL_ARMAX_GRID if full else ARMAX_GRID)
        else:
            opts = dict(FULL_OE_GRID if full else OE_GRID, OE_mod="RLLS")
        t0 = time.perf_counter()
        try:
            with quiet():
                m = system_identification(rec.y_est, rec.u_est, method, IC="AICc", **opts)
        except SystemExit as exc:  # the library's way of refusing
            raise RuntimeError(f"sippy: {exc}") from None
        seconds = time.perf_counter() - t0
        (num,), (den,) = control.tfdata(m.G)
        num, den = np.asarray(num[0], float), np.asarray(den[0], float)
        y_sim = tf_simulate(num, den, rec.sim_input()[:, 0])
        delay = int(m.delay if method == "ARMAX" else m.theta)
        if method == "ARX":
            struct = structure_io(int(m.na), int(m.nb), delay + 1)
        elif method == "ARMAX":
            struct = structure_io(int(m.na), int(m.nb), delay + 1, nc=int(m.nc))
        else:
            # io_rls.GEN_model (OE_mod="RLLS") stores nf in its ``nc`` attribute
            nf = int(getattr(m, "nf", m.nc))
            struct = structure_io(nf, int(m.nb), delay + 1)
        return [
            Outcome(rec.val_part(y_sim[:, None])[:, 0], struct, max_radius(np.roots(den)), seconds)
        ]

    return run


# ====================================================================== nfoursid
def run_nfoursid(rec: Record) -> list[Outcome]:
    """PO-MOESP via nfoursid; order 1..10 by AICc of the estimation-part free run."""
    import pandas as pd
    from nfoursid.nfoursid import NFourSID

    l_, m_ = rec.y_est.shape[1], rec.u_est.shape[1]
    ucols = [f"u{i}" for i in range(m_)]
    ycols = [f"y{i}" for i in range(l_)]
    frame = pd.DataFrame(np.hstack([rec.u_est, rec.y_est]), columns=ucols + ycols)
    t0 = time.perf_counter()
    with quiet():
        n4 = NFourSID(frame, output_columns=ycols, input_columns=ucols, num_block_rows=BLOCK_ROWS)
        n4.subspace_identification()
        best = (math.inf, None)
        n_est = len(rec.y_est)
        for n in range(1, MAX_ORDER + 1):
            ss, _ = n4.system_identification(rank=n)
            y_fit = ss_simulate(ss.a, ss.b, ss.c, ss.d, rec.u_est)
            # SIPPY's rule: the variance of the free-run error of the unit-std outputs
            err = (rec.y_est - y_fit) / rec.y_est.std(axis=0)
            ic = aicc(n * (l_ + m_) + l_ * m_, n_est, float(np.mean(err**2)))
            if ic < best[0]:
                best = (ic, ss)
    seconds = time.perf_counter() - t0
    ss = best[1]
    if ss is None:
        raise RuntimeError("no order gave a finite free run on the estimation part")
    y_sim = ss_simulate(ss.a, ss.b, ss.c, ss.d, rec.sim_input())
    pole = max_radius(np.linalg.eigvals(ss.a))
    return [
        Outcome(rec.val_part(y_sim)[:, j], f"n={ss.a.shape[0]} with D (MIMO)", pole, seconds)
        for j in range(l_)
    ]


# ====================================================================== sysidentpy
def run_frols(rec: Record) -> list[Outcome]:
    """Linear ARX by FROLS (degree 1), AICc over all model sizes, one MISO model per output."""
    from sysidentpy.basis_function import Polynomial
    from sysidentpy.model_structure_selection import FROLS
    from sysidentpy.parameter_estimation import LeastSquares

    m_ = rec.u_est.shape[1]
    xlag = MAX_ORDER if m_ == 1 else [list(range(1, MAX_ORDER + 1))] * m_
    n_candidates = 1 + MAX_ORDER * (1 + m_)
    u_sim = rec.sim_input()
    out = []
    for j in range(len(rec.outputs)):
        try:
            t0 = time.perf_counter()
            with quiet():
                model = FROLS(
                    order_selection=True,
                    info_criteria="aicc",
                    n_info_values=n_candidates,
                    ylag=MAX_ORDER,
                    xlag=xlag,
                    estimator=LeastSquares(),
                    basis_function=Polynomial(degree=1),
                )
                model.fit(X=rec.u_est, y=rec.y_est[:, [j]])
            seconds = time.perf_counter() - t0
            lag = model.max_lag
            zeros_u = np.zeros((lag, m_))
            with quiet():
                yhat = model.predict(
                    X=np.vstack([zeros_u, u_sim]),
                    y=np.vstack([np.zeros((lag, 1)), np.zeros((len(u_sim), 1))]),
                    steps_ahead=None,
                )
            y_sim = np.asarray(yhat, float).reshape(-1)[lag:]
            codes = [int(c) for c in np.asarray(model.final_model)[:, 0]]
            theta = np.asarray(model.theta, float).reshape(-1)
            ylags = {c - 1000: th for c, th in zip(codes, theta, strict=True) if 1000 < c < 2000}
            a = np.zeros(max(ylags, default=0) + 1)
            a[0] = 1.0
            for k, th in ylags.items():
                a[k] = -th
            parts = [f"y {ranges(list(ylags))}"]
            for i in range(m_):
                lags = [c - 1000 * (i + 2) for c in codes if 1000 * (i + 2) < c < 1000 * (i + 3)]
                name = "u" if m_ == 1 else f"u{i + 1}"
                parts.append(f"{name} {ranges(lags)}")
            const = " +c" if 0 in codes else ""
            out.append(
                Outcome(
                    rec.val_part(y_sim[:, None])[:, 0],
                    f"{len(codes)} terms: {'; '.join(parts)}{const} (MISO)",
                    max_radius(np.roots(a)) if len(a) > 1 else 0.0,
                    seconds,
                )
            )
        except PeerTimeout:
            raise
        except Exception as exc:
            out.append(failed(rec, exc)[0])
    return out


# ====================================================================== the run
def defaults_are_auto() -> bool:
    """Whether ``clpc.identify`` already chooses order and delay by default."""
    params = inspect.signature(clpc.identify).parameters
    return all(p in params and params[p].default == "auto" for p in ("order", "nk"))


def methods(args: argparse.Namespace) -> list[tuple[str, Callable[[Record], list[Outcome]]]]:
    out: list[tuple[str, Callable[[Record], list[Outcome]]]] = [(CLPC, run_clpc)]
    if not args.no_clpc_auto and not defaults_are_auto():
        out.append((CLPC_AUTO, run_clpc_auto))
    out += [
        ("SIPPY N4SID", sippy_ss("N4SID")),
        ("SIPPY MOESP", sippy_ss("MOESP")),
        ("SIPPY CVA", sippy_ss("CVA")),
        ("SIPPY ARX", sippy_io("ARX", args.full_grids)),
        ("SIPPY ARMAX", sippy_io("ARMAX", args.full_grids)),
        ("SIPPY OE", sippy_io("OE", args.full_grids)),
        ("nfoursid N4SID", run_nfoursid),
        ("sysidentpy FROLS", run_frols),
        (ORACLE, run_oracle),
    ]
    return out


def is_peer(method: str) -> bool:
    return method not in (CLPC, CLPC_AUTO, ORACLE)


def run_record(rec: Record, args: argparse.Namespace) -> list[Table]:
    tables = [Table(t, len(rec.y_est), len(rec.y_val)) for t in rec.targets()]
    for name, run in methods(args):
        t0 = time.perf_counter()
        try:
            with limit(args.peer_limit if is_peer(name) else 0):
                outcomes = run(rec)
        except (Exception, SystemExit) as exc:  # SIPPY refuses with sys.exit
            outcomes = failed(rec, exc)
        print(
            f"  {rec.name}: {name} {time.perf_counter() - t0:.1f} s",
            file=sys.stderr,
            flush=True,
        )
        if len(outcomes) == 1 and len(rec.outputs) > 1:  # a SISO-only peer refused
            outcomes = outcomes * len(rec.outputs)
        for j, (table, o) in enumerate(zip(tables, outcomes, strict=True)):
            if o.error or o.y_val is None:
                table.rows.append(
                    Row(name, -math.inf, math.inf, "", math.nan, o.seconds, o.error or "no model")
                )
                continue
            fit, rms = score(rec.y_val[:, j], o.y_val)
            table.rows.append(Row(name, fit, rms, o.structure, o.pole, o.seconds))
    return tables


# ====================================================================== output
def fmt_fit(v: float) -> str:
    if not math.isfinite(v):
        return "diverges"
    return f"{v:.1f}" if abs(v) < 1e4 else f"{v:.1e}"


def fmt(v: float, digits: int = 3) -> str:
    if not math.isfinite(v):
        return "-" if math.isnan(v) else "inf"
    return f"{v:.{digits}g}"


def pole_text(v: float) -> str:
    if math.isnan(v):
        return "-"
    return f"{v:.3f}" + (" unstable" if v >= 1.0 else "")


def per_target(table: Table) -> list[str]:
    lines = [
        f"#### {table.target} ({table.n_est} estimation / {table.n_val} validation samples)",
        "",
        "| method | fit % | RMS | structure | max abs pole | fit s |",
        "|---|---|---|---|---|---|",
    ]
    for r in table.rows:
        if r.ok:
            lines.append(
                f"| {r.method} | {fmt_fit(r.fit)} | {fmt(r.rms)} | {r.structure} | "
                f"{pole_text(r.pole)} | {r.seconds:.2f} |"
            )
        else:
            err = r.error.replace("|", "/")
            lines.append(f"| {r.method} | - | - | {err} | - | - |")
    return [*lines, ""]


def floored(r: Row) -> float:
    """A row's fit for the means: no model or below 0 counts as 0 (the mean predictor)."""
    return max(r.fit, 0.0) if r.ok else 0.0


def summary(tables: list[Table]) -> list[str]:
    lines = [
        "### Summary",
        "",
        f"Best peer: the highest validation fit among the peers (not {CLPC!r}, not the oracle).",
        "",
        f"| target | {CLPC} | best peer | its fit | identify - best | oracle ARX |",
        "|---|---|---|---|---|---|",
    ]
    gaps = []
    for t in tables:
        by = {r.method: r for r in t.rows}
        ident = by[CLPC].fit if by[CLPC].ok else -math.inf
        peers = [r for r in t.rows if is_peer(r.method) and r.ok]
        best = max(peers, key=lambda r: r.fit) if peers else None
        oracle = by.get(ORACLE)
        best_fit = best.fit if best else -math.inf
        gap = ident - best_fit
        gaps.append((t.target, gap))
        lines.append(
            f"| {t.target} | {fmt_fit(ident)} | {best.method if best else '-'} | "
            f"{fmt_fit(best_fit)} | {fmt_fit(gap) if math.isfinite(gap) else '-'} | "
            f"{fmt_fit(oracle.fit) if oracle and oracle.ok else '-'} |"
        )
    names = [r.method for r in tables[0].rows]
    lines += [
        "",
        "Means of the fits, a fit below 0 counted as 0 (no better than the validation mean): "
        "over all targets (no model counts as 0) and over the targets where the method gave a "
        "model; median of the raw fits where it gave one; unstable: models with a pole on or "
        "outside the unit circle; wins: targets where the method has the highest fit of all "
        "but the oracle (ties count for each):",
        "",
        "| method | mean fit %, all | mean fit %, where it ran | median fit %, where it ran "
        "| models | unstable | wins |",
        "|---|---|---|---|---|---|---|",
    ]
    means = {}
    for name in names:
        rows = [next(r for r in t.rows if r.method == name) for t in tables]
        ran = [r for r in rows if r.ok]
        means[name] = float(np.mean([floored(r) for r in rows]))
        mean_ran = f"{np.mean([floored(r) for r in ran]):.1f}" if ran else "-"
        median = fmt_fit(float(np.median([r.fit for r in ran]))) if ran else "-"
        unstable = sum(1 for r in ran if r.pole >= 1.0)
        wins = 0
        for t, r in zip(tables, rows, strict=True):
            contenders = [x.fit for x in t.rows if x.method != ORACLE and x.ok]
            wins += bool(r.ok and name != ORACLE and contenders and r.fit >= max(contenders))
        lines.append(
            f"| {name} | {means[name]:.1f} | {mean_ran} | {median} | "
            f"{len(ran)}/{len(rows)} | {unstable} | {wins} |"
        )
    on_par = sum(1 for _, g in gaps if g >= -ON_PAR)
    worst_target, worst = min(gaps, key=lambda x: x[1])
    peer_means = {n: v for n, v in means.items() if is_peer(n)}
    best_peer = max(peer_means, key=peer_means.__getitem__)
    if worst >= 0:
        shortfall = "none (identify is never behind the best peer)"
    elif math.isfinite(worst):
        shortfall = f"{-worst:.1f} points on {worst_target}"
    else:
        shortfall = f"on {worst_target}: identify gave no usable free run"
    lines += [
        "",
        f"- identify within {ON_PAR:g} points of the best peer or ahead: {on_par}/{len(gaps)} "
        "targets",
        f"- worst shortfall: {shortfall}",
        f"- mean fit: identify {means[CLPC]:.1f} %, best peer by mean {best_peer} "
        f"{peer_means[best_peer]:.1f} %: identify's mean "
        f"{'beats' if means[CLPC] > peer_means[best_peer] else 'does not beat'} the best peer's",
        "",
    ]
    return lines


def identify_defaults() -> str:
    params = inspect.signature(clpc.identify).parameters
    keys = ("estimator", "order", "nk", "max_order", "max_delay", "mimo")
    return ", ".join(f"{k}={params[k].default!r}" for k in keys if k in params)


def git_commit() -> str:
    """The last commit that changed clpc's sources, and the checkout's HEAD."""
    root = Path(clpc.__file__).resolve().parents[2]

    def git(*cmd: str) -> str:
        out = subprocess.run(
            ["git", "-C", str(root), *cmd], capture_output=True, text=True, check=True
        )
        return out.stdout.strip()

    try:
        src, head = (
            git("log", "-1", "--format=%h", "--", "src"),
            git("rev-parse", "--short", "HEAD"),
        )
        dirty = " + uncommitted changes in src" if git("status", "--porcelain", "--", "src") else ""
        return f"{src}{dirty} (sources; checkout at {head})"
    except (OSError, subprocess.CalledProcessError):
        return "unknown"


def versions() -> str:
    from importlib.metadata import PackageNotFoundError, version

    parts = []
    for pkg in ("clpc", "numpy", "scipy", "sippy_unipi", "nfoursid", "sysidentpy"):
        try:
            parts.append(f"{pkg} {version(pkg)}")
        except PackageNotFoundError:
            parts.append(f"{pkg} ?")
    return ", ".join(parts)


def warm_up() -> None:
    """Import every peer and run clpc once, so that no timed fit pays for imports."""
    import control  # noqa: F401  (SIPPY's transfer functions)
    import pandas  # noqa: F401
    import sippy_unipi
    import sippy_unipi.armax
    import sippy_unipi.arx
    import sippy_unipi.io_rls
    import sippy_unipi.OLSims_methods  # noqa: F401
    from nfoursid.nfoursid import NFourSID  # noqa: F401
    from sysidentpy.model_structure_selection import FROLS  # noqa: F401

    rng = np.random.default_rng(0)
    u = rng.standard_normal(400)
    y = lfilter([0.0, 0.5], [1.0, -0.7], u) + 0.05 * rng.standard_normal(400)
    with quiet():
        clpc.identify(u, y)


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--records", nargs="+", choices=datasets.names(), metavar="NAME")
    parser.add_argument("--markdown", type=Path, help="also write the tables to this file")
    parser.add_argument("--no-clpc-auto", action="store_true", help="skip identify auto")
    parser.add_argument("--full-grids", action="store_true", help="SIPPY ARMAX/OE 1..10 x 0..5")
    parser.add_argument(
        "--peer-limit", type=float, default=PEER_LIMIT, help="seconds per peer per record"
    )
    args = parser.parse_args(argv)
    names = args.records or datasets.names()
    start, t0, load0 = datetime.now(), time.perf_counter(), os.getloadavg()
    warm_up()
    tables: list[Table] = []
    for name in names:
        tables += run_record(load(name), args)
    load1 = os.getloadavg()
    head = [
        f"<!-- peers.py, {start:%Y-%m-%d %H:%M}, {platform.machine()}, {os.cpu_count()} cores, "
        f"load average {load0[0]:.1f} at the start, {load1[0]:.1f} at the end, "
        f"{time.perf_counter() - t0:.0f} s -->",
        "",
        f"clpc at {git_commit()}; {versions()}.",
        "",
        f"{CLPC}: `clpc.identify(est)`, defaults {identify_defaults()}"
        + (
            f"; no {CLPC_AUTO!r} row: the defaults are order and delay 'auto' already."
            if defaults_are_auto()
            else "."
        ),
        "",
        f"{len(tables)} targets ({len(names)} records); 60/40 split (cascaded_tanks: its own "
        "records), estimation mean removed; free run from zero state, validation samples "
        "scored. Structure: na poles, nb input taps, nk first input lag.",
        "",
    ]
    body = [line for t in tables for line in per_target(t)]
    text = "\n".join([*head, *summary(tables), "### Per target", "", *body])
    print(text)
    if args.markdown:
        args.markdown.write_text(text + "\n", encoding="utf-8")


if __name__ == "__main__":
    main()
