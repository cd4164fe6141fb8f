"""Notebook and library manners: shapes, reprs, HTML, ax= and returned figures, envelopes."""

from __future__ import annotations

from dataclasses import replace
from html.parser import HTMLParser
from typing import ClassVar

import numpy as np
import pytest

import clpc
import clpc.datasets as ds
from clpc import LPC, LinearModel, plotting, report
from clpc.core.figure import COLORS, MAX_POINTS, envelope
from clpc.lpc.regressors import Structure


@pytest.fixture(scope="module")
def dryer():
    return ds.load("dryer")


@pytest.fixture(scope="module")
def siso(dryer):
    return LPC(order=2).fit(dryer)


@pytest.fixture(scope="module")
def arm():
    return ds.load("cd_player_arm")[:600]


@pytest.fixture(scope="module")
def trace(dryer):
    return clpc.CLPC(order=2, window_size=201, cluster_size=12, dt=dryer.dt).run(dryer)


class _Balanced(HTMLParser):
    VOID: ClassVar[set[str]] = {"br", "img", "meta"}

    def __init__(self) -> None:
        super().__init__()
        self.stack: list[str] = []
        self.text = ""

    def handle_starttag(self, tag, attrs):
        if tag not in self.VOID:
            self.stack.append(tag)

    def handle_endtag(self, tag):
        assert self.stack and self.stack.pop() == tag, f"unbalanced </{tag}>"

    def handle_data(self, data):
        self.text += data


def _parsed_text(markup: str) -> str:
    p = _Balanced()
    p.feed(markup)
    p.close()
    assert p.stack == []
    return p.text


# ---------------------------------------------------------------- shapes and statistics
def test_siso_theta_is_1d_and_statistics_scalar(siso):
    p = siso.structure.n_params(1)
    assert siso.theta.shape == (p,)
    assert siso.theta_matrix.shape == (1, p)
    np.testing.assert_array_equal(siso.theta_matrix[0], siso.theta)
    _ = siso.theta[1]  # raised IndexError with the old (1, p) shape
    assert isinstance(siso.info["D"], float) and isinstance(siso.info["determined"], bool)
    assert isinstance(siso.info["n_null"], int)
    assert siso.info["eigenvalues"].shape == (p,)
    # D is still lambda_max - lambda_min of the same solve
    assert siso.info["D"] == pytest.approx(siso.info["lambda_max"] - siso.info["lambda_min"])


def test_mimo_keeps_its_output_axis(arm):
    model = LPC(order=2).fit(arm)
    p = model.structure.n_params(2)
    assert model.theta.shape == (2, p) and model.theta_matrix is model.theta
    assert model.info["D"].shape == (2,) and model.info["eigenvalues"].shape == (2, p)


def test_theta_round_trips_through_replace_and_files(siso, tmp_path):
    again = replace(siso, theta=siso.theta_matrix)  # 2-D in, 1-D stored
    assert again.theta.shape == siso.theta.shape
    clpc.save_model(siso, tmp_path / "m.json")
    loaded = clpc.load_model(tmp_path / "m.json")
    np.testing.assert_array_equal(loaded.theta, siso.theta)
    assert loaded.info["D"] == siso.info["D"]


# ---------------------------------------------------------------- repr and HTML
def _coefficients(line: str) -> list[float]:
    """The signed coefficients of a printed polynomial ``1 - 1.8 z^-1 + 0.9 z^-2``."""
    text = line.split("=", 1)[1].replace(" - ", " -").replace(" + ", " ")
    return [float(t) for t in text.split() if not t.startswith("z")]


def test_repr_shows_the_coefficients(siso):
    lines = repr(siso).splitlines()
    a_line = next(line for line in lines if "den(z) =" in line)
    b_line = next(line for line in lines if "num(z) =" in line)
    np.testing.assert_allclose(_coefficients(a_line), siso.den, rtol=1e-5)  # 6 digits shown
    np.testing.assert_allclose(_coefficients(b_line), siso.num[siso.num != 0], rtol=1e-5)
    assert f"offset {siso.intercept[0]:.6g}" in repr(siso) and "(stable;" in repr(siso)


def test_one_naming_of_the_transfer_function_everywhere(siso):
    """repr, notebook table, summary() and the CLI text all say num(z)/den(z), never B(z)."""
    from clpc.model.uncertainty import parameter_labels, parameter_vector

    summary = report.model_summary(siso)
    shown = [
        repr(siso),
        _parsed_text(siso._repr_html_()),
        siso.summary(),
        report.format_model_summary(summary),
    ]
    for text in shown:
        assert "num(z)" in text and "den(z)" in text
        assert "B(z) =" not in text and "numerator" not in text and "A(z) =" not in text
    # the parameters are the coefficients of num and den, named so
    values = dict(zip(parameter_labels(siso), parameter_vector(siso)[0], strict=True))
    assert values["den1"] == siso.den[1] and values["num0[u]"] == siso.num[0]
    printed = {p["name"]: p["value"] for p in summary["equations"][0]["parameters"]}
    assert printed["den2"] == siso.den[2] and printed["num1[u]"] == siso.num[1]


def test_repr_of_a_model_without_monic_form():
    bad = LinearModel(
        theta=np.array([0.0, 1.0, 0.5]), structure=Structure(1, 0), n_inputs=1, mode="siso", c=0
    )
    assert "a0 about 0" in repr(bad) and "[[0.0, 1.0, 0.5]]" in repr(bad)


def test_model_html_parses_and_holds_the_channels(arm):
    model = LPC(order=2).fit(arm)
    text = _parsed_text(model._repr_html_())
    for j, out in enumerate(model.output_names):
        for inp in model.input_names:
            assert f"{inp} → {out}" in text
        assert f"{model.intercept[j]:.6g}" in text


def test_trace_html(trace):
    text = _parsed_text(trace._repr_html_())
    conv = trace.convergence()
    assert conv.converged
    assert f"{len(trace)}" in text and f"{conv.time:.6g}" in text
    assert "clusters determine the parameters" in text
    assert "u → y" in text  # the steady-state model's table


def test_comparison_html_and_numbers(dryer, siso):
    cmp = report.compare(siso, dryer, k=None)
    ref = clpc.fit_percent(dryer.y[cmp.start :, 0], cmp.y_hat[cmp.start :, 0])
    assert cmp.fit[0] == pytest.approx(ref)
    np.testing.assert_allclose(cmp.residuals[:, 0], dryer.y[2:, 0] - cmp.y_hat[2:, 0])
    markup = cmp._repr_html_()
    text = _parsed_text(markup)
    assert report.format_fit(ref) in text and "data:image/png;base64," in markup


# ---------------------------------------------------------------- figures
def _axes(n: int):
    from matplotlib.figure import Figure

    fig = Figure()
    return fig, list(fig.subplots(n, 1, squeeze=False)[:, 0])


def test_plot_functions_draw_on_given_axes_and_return_the_figure(dryer, siso, trace):
    from clpc.plotting.traces import trace_panels

    cases = [
        (lambda ax: plotting.plot_bode(siso, ax=ax), 2),
        (lambda ax: plotting.plot_step(siso, ax=ax[0]), 1),
        (lambda ax: plotting.plot_pz(siso, ax=ax[0]), 1),
        (lambda ax: plotting.plot_fit(siso, dryer, ax=ax), 2),
        (lambda ax: plotting.plot_compare(dryer.time, dryer.y, dryer.y, 100.0, ax=ax), 1),
        (lambda ax: plotting.plot_trace(trace, ax=ax), trace_panels(trace)),
        (lambda ax: dryer.plot(ax=ax), 2),
    ]
    for draw, n in cases:
        fig, axes = _axes(n)
        assert draw(axes) is fig
        assert all(a.lines or a.collections for a in axes)
    with pytest.raises(ValueError, match="needs 2 axes; got 1"):
        plotting.plot_bode(siso, ax=_axes(1)[1][0])


def test_plot_without_path_writes_nothing(siso, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    fig = plotting.plot_step(siso)
    assert fig.axes and not list(tmp_path.iterdir())


def test_bode_grid_is_log_spaced_up_to_nyquist(siso):
    f = plotting.bode_frequencies(siso, 200)
    nyq = 0.5 / siso.dt
    assert f[-1] == pytest.approx(nyq, rel=1e-12) and f[0] == pytest.approx(nyq / 1e3)
    np.testing.assert_allclose(np.diff(np.log(f)), np.log(f[1] / f[0]), rtol=1e-9)
    fig = plotting.plot_bode(siso, n_freqs=200)
    ax_m = fig.axes[0]
    line = ax_m.lines[0]
    np.testing.assert_allclose(line.get_xdata(), f)
    _, h = siso.frequency_response(f)
    np.testing.assert_allclose(line.get_ydata(), 20 * np.log10(np.abs(h)))
    nyquist = [ln for ln in ax_m.lines if np.all(np.asarray(ln.get_xdata()) == nyq)]
    assert nyquist and any("Nyquist" in t.get_text() for t in ax_m.texts)


def test_envelope_is_the_min_and_max_of_each_bin():
    rng = np.random.default_rng(0)
    y = rng.standard_normal(100_003)
    y[500] = np.nan
    x = np.arange(y.size) * 0.5
    xb, lo, hi = envelope(x, y, max_points=1000)
    starts = np.linspace(0, y.size, 500, endpoint=False).astype(int)
    ends = np.r_[starts[1:], y.size]
    np.testing.assert_array_equal(xb, x[starts])
    bins = list(zip(starts, ends, strict=True))
    np.testing.assert_array_equal(lo, [np.nanmin(y[a:b]) for a, b in bins])
    np.testing.assert_array_equal(hi, [np.nanmax(y[a:b]) for a, b in bins])
    short = envelope(x[:10], y[:10])
    assert short[1] is short[2] and short[1].size == 10


def test_long_trace_is_drawn_as_envelopes(trace):
    long = clpc.Trace.concat([trace] * (MAX_POINTS // len(trace) + 2))
    long = replace(long, time=np.arange(len(long)) * 0.96, index=np.arange(len(long)))
    assert len(long) > MAX_POINTS
    fig = plotting.plot_trace(long)
    for ax in fig.axes:
        for line in ax.lines:
            assert len(line.get_xdata()) <= MAX_POINTS
        for coll in ax.collections:
            for path in coll.get_paths():
                assert len(path.vertices) <= 4 * MAX_POINTS + 10
    assert "envelopes" in fig.texts[0].get_text()


def test_one_colour_per_quantity(dryer, siso):
    from matplotlib.colors import to_hex

    fit = plotting.plot_fit(siso, dryer)
    cmp = plotting.plot_compare(dryer.time, dryer.y, siso.simulate(dryer.u[:, 0]), 1.0)
    measured = {to_hex(ax.lines[0].get_color()) for ax in (fit.axes[0], cmp.axes[0])}
    modelled = {to_hex(ax.lines[1].get_color()) for ax in (fit.axes[0], cmp.axes[0])}
    assert measured == {COLORS["measured"]} and modelled == {COLORS["model"]}
    assert to_hex(fit.axes[1].lines[0].get_color()) == COLORS["residual"]
    data_fig = dryer.plot()
    assert to_hex(data_fig.axes[0].lines[0].get_color()) == COLORS["input"]
    assert to_hex(data_fig.axes[1].lines[0].get_color()) == COLORS["measured"]


def test_legends_sit_outside_the_data(dryer, siso):
    fig = plotting.plot_fit(siso, dryer)
    fig.canvas.draw()
    for ax in fig.axes:
        legend = ax.get_legend()
        box, frame = legend.get_window_extent(), ax.get_window_extent()
        assert box.y0 >= frame.y1 - 1  # above the axes: covers no curve


def test_titles_carry_no_path(tmp_path, dryer, siso):
    deep = tmp_path / "a" / "very" / "deep"
    fig = plotting.plot_bode(siso, deep / "bode.png")
    assert str(tmp_path) not in fig.texts[0].get_text()


def test_iodata_plot(dryer, tmp_path):
    fig = dryer.plot(tmp_path / "d.png", title="dryer")
    assert (tmp_path / "d.png").read_bytes()[:4] == b"\x89PNG"
    assert [a.get_ylabel().split("\n")[0] for a in fig.axes] == ["u", "y"]
    np.testing.assert_array_equal(fig.axes[1].lines[0].get_ydata(), dryer.y[:, 0])
    assert fig.axes[-1].get_xlabel() == "time [s]"
