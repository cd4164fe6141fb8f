"""Smoke tests of the figures (Agg) and checks of the report helpers."""

from __future__ import annotations

import json

import numpy as np
import pytest

import clpc
import clpc.datasets as ds
from clpc import plotting, report

pytest.importorskip("matplotlib")

PNG = b"\x89PNG\r\n\x1a\n"


def _is_png(path) -> bool:
    data = path.read_bytes()
    return len(data) > 1000 and data[:8] == PNG


def _wrote(fig, path) -> bool:
    """A plot function returned its figure and wrote it as PNG to ``path``."""
    from matplotlib.figure import Figure

    return isinstance(fig, Figure) and _is_png(path)


@pytest.fixture(scope="module")
def dryer():
    return ds.load("dryer")


@pytest.fixture(scope="module")
def trace(dryer):
    # cluster 5 < min_rows (12): the first updates are flagged not_enough_data / not accepted
    return clpc.CLPC(order=2, window_size=201, cluster_size=5, dt=dryer.dt).run(dryer)


@pytest.fixture(scope="module")
def model(dryer):
    return clpc.LPC(order=2).fit(dryer)


@pytest.fixture(scope="module")
def mimo():
    data = ds.load("cd_player_arm")[:600]
    return data, clpc.LPC(order=2).fit(data)


def test_plot_trace_marks_flagged_updates(trace, tmp_path):
    assert (~trace.accepted).any() and trace.not_enough_data.any()
    out = tmp_path / "sub" / "trace.png"
    fig = plotting.plot_trace(trace, out, title="dryer")
    assert _wrote(fig, out)
    (ax_d,) = [a for a in fig.axes if a.get_ylabel().startswith("D (")]
    labels = [t.get_text() for t in ax_d.get_legend().get_texts()]
    n_bad = int((~trace.accepted).sum())
    assert f"not accepted ({n_bad})" in labels


def test_plot_trace_mimo(mimo, tmp_path):
    data, _ = mimo
    tr = clpc.CLPC(order=2, window_size=101, cluster_size=12).run(data)
    fig = plotting.plot_trace(tr, tmp_path / "t.png")
    assert _wrote(fig, tmp_path / "t.png")
    assert len([a for a in fig.axes if a.get_visible()]) == 2 * (1 + len(tr.labels()))


def test_plot_compare_siso_and_mimo(dryer, model, mimo, tmp_path):
    y_hat = model.simulate(dryer.u[:, 0])
    fig = plotting.plot_compare(dryer.time, dryer.y[:, 0], y_hat, 12.5, tmp_path / "c.png")
    assert _wrote(fig, tmp_path / "c.png")
    data, m2 = mimo
    y2, _, fit = report.model_response(m2, data.u, data.y, k=1)
    fig = plotting.plot_compare(
        data.time,
        data.y,
        y2,
        fit,
        tmp_path / "c2.png",
        names=["y1", "y2"],
        label="1-step prediction",
    )
    assert _wrote(fig, tmp_path / "c2.png")
    assert fig.axes[0].get_xlabel() == "time [samples]"  # the record has no sample time
    assert _wrote(
        plotting.plot_compare(data.time, data.y, y2, None, tmp_path / "c3.png"),
        tmp_path / "c3.png",
    )


def test_plot_compare_rejects_mismatched_shapes(tmp_path):
    with pytest.raises(ValueError, match="same samples"):
        plotting.plot_compare(np.arange(5), np.zeros(5), np.zeros(4), 0.0, tmp_path / "x.png")


def test_plot_pz_and_bode(model, mimo, tmp_path):
    assert _wrote(plotting.plot_pz(model, tmp_path / "pz.png"), tmp_path / "pz.png")
    assert _wrote(plotting.plot_bode(model, tmp_path / "bode.png"), tmp_path / "bode.png")
    data, m2 = mimo
    assert _wrote(plotting.plot_pz(m2, tmp_path / "pz2.png"), tmp_path / "pz2.png")
    paired = clpc.LPC(order=2, mimo="paired").fit(data)  # zero off-diagonal channels
    fig = plotting.plot_bode(paired, tmp_path / "bode2.png")
    assert _wrote(fig, tmp_path / "bode2.png")
    assert len(fig.axes[0].get_legend().get_texts()) == 2  # the two diagonal channels


def test_html_report_embeds_or_links_images(model, tmp_path):
    png = tmp_path / "fig" / "pz.png"
    plotting.plot_pz(model, png)
    sections = [
        report.Section("Numbers <b>", text="a & b\n\nsecond", table={"x": 1.5, "y": "<z>"}),
        {
            "heading": "Rows",
            "table": [["a", "b"], [1, 2.0]],
            "images": [png],
            "preformatted": "G(z)",
        },
    ]
    out = report.write_html_report(tmp_path / "r.html", "Title", sections)
    html = out.read_text()
    assert "data:image/png;base64," in html
    assert "Numbers &lt;b&gt;" in html and "&lt;z&gt;" in html and "<pre>G(z)</pre>" in html
    linked = report.write_html_report(tmp_path / "r2.html", "T", sections, embed_images=False)
    assert 'src="fig/pz.png"' in linked.read_text()


def test_model_summary_numbers(dryer, model):
    s = report.model_summary(model, dryer)
    json.dumps(s, allow_nan=False)  # JSON-safe
    eq = s["equations"][0]
    np.testing.assert_allclose(eq["den"], model.den)
    np.testing.assert_allclose(eq["num"]["u"], model.num)
    assert eq["D"] == pytest.approx(model.info["D"])
    assert s["stable"] == model.is_stable
    k1 = clpc.kstep_fit(model, dryer.u[:, 0], dryer.y[:, 0], k=1)
    assert s["fit"]["prediction_1"][0] == pytest.approx(k1)
    assert s["fit"]["prediction_10"][0] == pytest.approx(
        clpc.kstep_fit(model, dryer.u[:, 0], dryer.y[:, 0], k=10)
    )
    text = report.format_model_summary(s)
    assert "poles" in text and "1-step prediction" in text and "z^-2" in text


def test_model_response_simulation_starts_from_measured_samples(dryer, model):
    y_hat, start, fit = report.model_response(model, dryer.u, dryer.y)
    assert start == 2
    np.testing.assert_array_equal(y_hat[:start], dryer.y[:start])
    ref = model.simulate(dryer.u[start:], y_init=dryer.y[:start], u_init=dryer.u[:start])
    np.testing.assert_allclose(y_hat[start:], ref)
    assert fit[0] == pytest.approx(clpc.fit_percent(dryer.y[start:], ref))


def test_update_records_and_trace_columns(trace):
    recs = report.update_records(trace)
    assert len(recs) == len(trace)
    json.dumps(recs, allow_nan=False)
    assert recs[-1]["index"] == int(trace.index[-1])
    np.testing.assert_allclose(recs[-1]["theta"], trace.theta[-1])
    assert len(recs[-1]["num"]) == 3 and len(recs[-1]["den"]) == 3
    names, table = report.trace_columns(trace)
    assert table.shape == (len(trace), len(names))
    np.testing.assert_allclose(table[:, names.index("D")], trace.D)
    np.testing.assert_allclose(table[:, names.index("b1")], trace.theta[:, 4])


def test_format_fit():
    assert report.format_fit(87.2876) == "87.29 %"
    assert report.format_fit(None) == "n/a (diverges)"
    assert report.format_fit(-5.2e34) == "-5.2e+34 %"


def test_track_report(trace, tmp_path):
    files = report.write_track_report(tmp_path, trace, title="t", settings={"a": 1})
    names = ["quantities.png", "step.png", "bode.png", "pz.png", "trace.png", "report.html"]
    assert [f.name for f in files] == names
    assert all(f.stat().st_size > 0 for f in files)


def test_figures_show_in_a_notebook_without_pyplot(model):
    # a figure returned to a notebook cell renders through its own _repr_png_ (IPython's
    # display hook for matplotlib is installed only by %matplotlib or a pyplot import)
    import io

    from matplotlib.image import imread

    fig = plotting.plot_step(model)
    png = fig._repr_png_()
    assert png[:8] == b"\x89PNG\r\n\x1a\n"
    width, height = (fig.get_size_inches() * fig.dpi).round().astype(int)
    assert imread(io.BytesIO(png)).shape[:2] == (height, width)
