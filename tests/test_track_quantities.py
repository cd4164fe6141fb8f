"""The track report's first figure: DC gain and dominant pole of every update over time."""

from __future__ import annotations

import re

import numpy as np
import pytest
from scipy import signal

import clpc
from clpc import report
from clpc.plotting.track_quantities import (
    BAND_PERCENTILES,
    BAND_WINDOWS,
    MIN_SPAN_FRACTION,
    plot_track_quantities,
    robust_limits,
    spread_band,
    track_quantities,
)

pytest.importorskip("matplotlib")

NUM, DEN = [0.0, 1.0, 0.3], [1.0, -1.5, 0.7]  # complex poles, DC gain 1.3 / 0.2 = 6.5
GAINS = (1.0, 2.0)  # the plant's gain in the first and second half of the record
DT = 0.05


@pytest.fixture(scope="module")
def switched():
    """A trace of a plant whose gain doubles at mid-record (two halves concatenated)."""
    rng = np.random.default_rng(29)
    n = 3000
    u = rng.standard_normal(n)
    scale = np.where(np.arange(n) < n // 2, GAINS[0], GAINS[1])
    y = signal.lfilter(NUM, DEN, scale * u) + 0.01 * rng.standard_normal(n)
    trace = clpc.CLPC(order=2, window_size=201, cluster_size=12, nk=1, dt=DT).run(u, y)
    return trace


def _independent_gains(trace) -> np.ndarray:
    """``-B(1)/A(1)`` of each update's unit-norm theta (paper convention ``[a; b]``)."""
    na = trace.structure.na
    theta = np.asarray(trace.theta, dtype=float)
    with np.errstate(invalid="ignore"):  # zeros before the first model
        return -theta[:, na + 1 :].sum(axis=1) / theta[:, : na + 1].sum(axis=1)


def test_plotted_gain_is_minus_b1_over_a1_of_each_accepted_theta(switched):
    fig = plot_track_quantities(switched)
    plotted = np.asarray(fig.axes[0].lines[0].get_ydata(), dtype=float)
    expected = _independent_gains(switched)
    accepted = np.asarray(switched.accepted, dtype=bool)
    assert accepted.sum() > 0.5 * len(switched)
    np.testing.assert_allclose(plotted[accepted], expected[accepted], rtol=1e-9)
    assert np.all(np.isnan(plotted[~accepted]))  # not accepted: left out
    # the figure shows the change: early and late gains near the plant's
    t = np.asarray(switched.time)
    half = t[-1] / 2
    true = 6.5 * np.asarray(GAINS)
    early = np.nanmedian(plotted[t < 0.8 * half])
    late = np.nanmedian(plotted[t > 1.4 * half])
    np.testing.assert_allclose([early, late], true, rtol=0.05)


def test_dominant_pole_matches_the_roots_of_each_update(switched):
    q = track_quantities(switched)
    acc = q["accepted"]
    den = np.asarray(switched.arrays["den"][:, 0], dtype=float)
    for k in np.flatnonzero(acc)[::7]:
        roots = np.roots(den[k])
        assert np.isclose(abs(q["pole"][k]), np.abs(roots).max(), rtol=1e-9)
        s = np.log(roots[np.argmax(roots.imag)].astype(complex)) / DT
        assert np.isclose(q["wn"][k], abs(s), rtol=1e-9)
        assert np.isclose(q["zeta"][k], -s.real / abs(s), rtol=1e-9)
    # the plant's poles do not change with its gain: 1.5 +- 0.67j in z
    true = np.roots(DEN)
    s_true = np.log(true[np.argmax(true.imag)]) / DT
    np.testing.assert_allclose(np.nanmedian(q["wn"][acc]), abs(s_true), rtol=0.02)


def test_axes_have_no_offset_and_limits_do_not_magnify_noise(switched):
    fig = plot_track_quantities(switched)
    fig.canvas.draw()
    for ax in fig.axes:
        assert ax.yaxis.get_offset_text().get_text() == ""
        assert ax.xaxis.get_offset_text().get_text() == ""
    # a steady level with tiny noise: the span is the stated fraction of the level
    rng = np.random.default_rng(0)
    level = 1000.0 + 1e-4 * rng.standard_normal(200)
    lo, hi = robust_limits(level)
    assert hi - lo >= MIN_SPAN_FRACTION * 1000.0
    assert lo < level.min() and hi > level.max()
    # one wild outlier does not stretch the axes
    spiky = np.r_[np.linspace(1.0, 2.0, 200), 1e6]
    lo, hi = robust_limits(spiky)
    assert hi < 10.0


def test_track_report_shows_the_gain_figure_first(switched, tmp_path):
    files = report.write_track_report(tmp_path, switched, title="switched gain")
    assert files[0].name == "quantities.png" and files[0].is_file()
    html = files[-1].read_text()
    alts = re.findall(r'<img alt="([^"]*)"', html)
    assert alts[0] == "DC gain and dominant pole over time", alts
    assert "shaded band" in html and "lower bound" in html


def test_band_is_the_spread_of_the_neighbouring_windows(switched):
    q = track_quantities(switched)
    t, gain = q["time"], q["gain"][:, 0]
    window = float(np.max(switched.rows)) * DT
    lo, hi = spread_band(t, gain, BAND_WINDOWS * window)
    # independent recomputation at a few updates: percentiles of the accepted values whose
    # update lies within the same count of updates on each side
    step = float(np.median(np.diff(t)))
    k = int(BAND_WINDOWS * window // step)
    for i in np.flatnonzero(np.isfinite(gain))[5::37]:
        near = gain[max(0, i - k) : i + k + 1]
        near = near[np.isfinite(near)]
        np.testing.assert_allclose(
            [lo[i], hi[i]], np.percentile(near, BAND_PERCENTILES), rtol=1e-12
        )
    # drawn as the first panel's shaded area, and wider where the gain doubles
    fig = plot_track_quantities(switched)
    assert len(fig.axes[0].collections) >= 1
    width = hi - lo
    change = np.abs(t - t[-1] / 2) < window
    steady = (t > 0.2 * t[-1]) & (t < 0.35 * t[-1])
    assert np.nanmedian(width[change]) > 3 * np.nanmedian(width[steady])
