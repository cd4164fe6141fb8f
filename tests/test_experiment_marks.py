"""Figs. 6-12 draw what the report judges: same convergence, same trusted updates, gaps.

One ramp identification (the paper's Table 1 settings on the simulated servo, a few
seconds) is shared by the module; the marks are checked against an independent
recomputation from the trace, and the drawn lines are read back from matplotlib.
"""

from __future__ import annotations

import copy

import numpy as np
import pytest
from scipy import signal

from clpc.appraiser.convergence import convergence, usable
from clpc_paper.experiment import analysis
from clpc_paper.experiment.figures import draw_parameter
from clpc_paper.experiment.identification import find_convergence, identify
from clpc_paper.experiment.marks import estimate_series, parameter_marks, window_states
from clpc_paper.experiment.results import Identification
from clpc_paper.experiment.run import commands
from clpc_paper.experiment.settings import LOG_SAMPLE_TIME, RAMP_DURATION, TOLERANCES
from clpc_paper.experiment.statistics import parameter_statistics
from clpc_paper.plants import ServoParameters, simulate_servo


@pytest.fixture(scope="module")
def ramp_ident() -> Identification:
    ramp, _ = commands(RAMP_DURATION, 8.0, 0)
    rec = simulate_servo(
        ramp(LOG_SAMPLE_TIME), sample_time=LOG_SAMPLE_TIME, params=ServoParameters(), seed=0
    )
    return identify(rec.position_command, rec.position, "robust")


def test_marker_and_steady_state_come_from_the_verdicts_trusted_updates(
    ramp_ident: Identification,
) -> None:
    ident, trace = ramp_ident, ramp_ident.trace
    marks = parameter_marks(ident)
    stats = parameter_statistics(ident)  # what the report's verdict reads
    assert ident.convergence.converged and marks.cluster is not None
    # the same convergence the verdict uses, recomputed from the trace
    conv, level = find_convergence(trace)
    assert conv == convergence(trace, *TOLERANCES[level])
    assert marks.cluster == conv.update + 1 == stats["cluster"]
    # averaged updates: accepted, trusted, from the marker on - and nothing else
    idx = np.arange(len(trace))
    expected = trace.accepted & trace.has_model & trace.trusted & (idx >= conv.update)
    np.testing.assert_array_equal(marks.used, expected)
    assert not np.all(trace.trusted)  # the ramp has untrusted windows to leave out
    mean = trace.theta[marks.used].mean(axis=0)
    np.testing.assert_allclose(marks.steady, mean / np.linalg.norm(mean), atol=1e-12)
    np.testing.assert_allclose(marks.steady, np.atleast_2d(ident.model.theta)[0], atol=1e-12)
    # the band is the range of the averaged updates; the verdict's variation is within it
    spread = np.linalg.norm(trace.theta[marks.used] - marks.steady, axis=1).max()
    assert stats["theta_variation"] == pytest.approx(spread, abs=1e-12)
    np.testing.assert_allclose(marks.low, trace.theta[marks.used].min(axis=0))
    np.testing.assert_allclose(marks.high, trace.theta[marks.used].max(axis=0))
    assert f"{TOLERANCES[level][0]:g}" in marks.rule


def test_untrusted_quiet_updates_do_not_start_convergence(ramp_ident: Identification) -> None:
    trace = ramp_ident.trace
    conv, level = find_convergence(trace)
    tol = TOLERANCES[level]
    edited = copy.deepcopy(trace)
    edited.arrays["trusted"][conv.update : conv.update + tol[2]] = False
    later = convergence(edited, *tol)
    assert not np.any(usable(edited)[conv.update : conv.update + tol[2]])
    assert not later.converged or later.update >= conv.update + tol[2]


def test_clusters_without_an_estimate_are_gaps_not_zeros(ramp_ident: Identification) -> None:
    from matplotlib.figure import Figure

    ident, trace = ramp_ident, ramp_ident.trace
    no_estimate = ~(trace.accepted & trace.has_model)
    assert no_estimate[:4].all()  # the ramp's first windows hold the motor at rest
    for index in range(6):
        ax = Figure().add_subplot()
        draw_parameter(ax, ident, index)
        (line,) = [ln for ln in ax.get_lines() if "held output" in str(ln.get_label())]
        y = np.asarray(line.get_ydata(), dtype=float)
        np.testing.assert_array_equal(np.isnan(y), no_estimate)
        np.testing.assert_array_equal(y[~no_estimate], trace.theta[~no_estimate, index])
    series = estimate_series(ident, trace.theta[:, 0])
    assert np.all(np.isnan(series[no_estimate]))


def test_windows_at_rest_are_those_with_a_constant_command(ramp_ident: Identification) -> None:
    ident, trace = ramp_ident, ramp_ident.trace
    states = window_states(ident)
    lag = trace.structure.max_lag
    for j in range(len(trace)):
        first = max(int(trace.index[j] - trace.rows[j] - lag + 1), 0)
        window = ident.u[first : int(trace.index[j]) + 1]
        assert states.at_rest[j] == (window.max() == window.min())
    assert states.at_rest[:4].all() and not states.at_rest[4:].any()
    assert not np.any(states.at_rest & states.untrusted)
    np.testing.assert_array_equal(states.untrusted, ~trace.trusted & ~states.at_rest)


# ---------------------------------------------------------------- the torque estimate's tools
def test_stable_inverse_has_no_end_transient_when_the_record_ends_settled(make_model, rng) -> None:
    den, num = np.array([1.0, -1.5, 0.7]), np.array([0.5, 1.0, 0.3])  # zero -1.63 outside
    model = make_model(den, num)
    u = np.r_[np.zeros(5), rng.standard_normal(300), np.full(200, 0.8)]
    y = signal.lfilter(num, den, u)
    u_hat = analysis.stable_inverse(model, y)
    np.testing.assert_allclose(u_hat[-100:], 0.8, atol=1e-9)  # zero state: off by O(1)
    np.testing.assert_allclose(u_hat[5:250], u[5:250], atol=1e-8)


def test_inverse_noise_is_the_linear_part_of_the_inverse(make_model, rng) -> None:
    model = make_model(np.array([1.0, -1.9, 0.9]), np.array([0.01, 0.1, 0.02]), intercept=0.003)
    y = np.cumsum(rng.standard_normal(400)) * 1e-2
    e = 1e-4 * rng.standard_normal(400)
    both = analysis.stable_inverse(model, y + e) - analysis.stable_inverse(model, y)
    np.testing.assert_allclose(both, analysis.inverse_noise(model, e), atol=1e-9)


def test_linear_bound_is_exact_for_a_linear_relation_and_low_for_noise(rng) -> None:
    y = np.cumsum(rng.standard_normal(500))
    u = 3.0 * np.roll(y, -1) - 2.0 * y + 0.5 * np.roll(y, 2) + 0.1
    assert analysis.linear_bound(u, y) == pytest.approx(100.0, abs=1e-6)
    assert analysis.linear_bound(rng.standard_normal(500), y) < 15.0
