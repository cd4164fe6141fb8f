"""Every public result shows itself in one screen: a short ``repr``, an HTML table that parses.

The results are real, built from small fits; the list of result types is checked against
every public dataclass, so a new result type cannot be forgotten.
"""

from __future__ import annotations

import dataclasses
import importlib
import inspect
import re
from html.parser import HTMLParser
from typing import Any, ClassVar

import numpy as np
import pytest

import clpc
import clpc.workflows as wf
from clpc import analysis, lpc, report
from clpc.core.compact import MAX_REPR, compact_repr, summarise
from clpc.io import write_table

PACKAGES = (
    "clpc",
    "clpc.analysis",
    "clpc.appraiser",
    "clpc.data",
    "clpc.datasets",
    "clpc.io",
    "clpc.lpc",
    "clpc.model",
    "clpc.multimodel",
    "clpc.report",
    "clpc.workflows",
)

#: public dataclasses that are settings or specifications written by the user, not results
#: (estimators, the dataclasses with a ``fit`` method, are settings too)
NOT_RESULTS = {
    "RobustRule",
    "Structure",
    "Dataset",
    "Section",
    "AppraiserSettings",
    "CompareSettings",
    "IdentifySettings",
    "RecordSpec",
    "StreamSettings",
    "TrackSettings",
}
#: result types not covered yet (none)
PENDING: set[str] = set()


def _public_dataclasses() -> set[str]:
    names = set()
    for package in PACKAGES:
        module = importlib.import_module(package)
        for name in module.__all__:
            obj = getattr(module, name)
            if inspect.isclass(obj) and dataclasses.is_dataclass(obj) and not hasattr(obj, "fit"):
                names.add(obj.__name__)
    return names


@pytest.fixture(scope="module")
def record():
    rng = np.random.default_rng(3)
    u = rng.standard_normal(800)
    y = clpc.simulate_arx([1, -1.5, 0.7], [0.5, 0.2, 0.1], u) + 0.05 * rng.standard_normal(800)
    return clpc.IOData(u, y, dt=0.01)


@pytest.fixture(scope="module")
def results(record, tmp_path_factory) -> dict[str, Any]:
    u, y = record.u[:, 0], record.y[:, 0]
    model = clpc.LPC(order=2).fit(record)
    trace = clpc.CLPC(order=2, window_size=201, cluster_size=12, dt=record.dt).run(record)
    found: dict[str, Any] = {
        "IOData": clpc.IOData.concat([record[:400], record[400:]]),
        "LinearModel": model,
        "Verdict": clpc.fit_verdict(model),
        "GainAssessment": clpc.assess_gain(model)[0],
        "Identifiability": clpc.model.identifiability(model),
        "DominantPole": clpc.dominant_poles(model)[0],
        "ResidualAnalysis": clpc.residual_analysis(model, u, y),
        "Identification": clpc.identify(record, order=2, nk=0),  # three rows: all shown
        "OrderSelection": clpc.select_order(record, orders=range(1, 4)),
        "DelaySelection": clpc.select_delay(record, delays=range(3)),
        "NoiseEstimate": clpc.estimate_noise_variances(record, order=2),
        "EivCheck": lpc.check_eiv(record, clpc.OE(order=2).fit(record)),
        "WhitenessResult": analysis.whiteness_test(y - model.simulate(u)),
        "Trace": trace,
        "Convergence": trace.convergence(),
        "OperatingPointReport": clpc.operating_point_diagnostics(trace, u, y),
        "Comparison": report.compare(model, record),
        "MultiModel": clpc.MultiModel(order=2, n_models=2).fit(record),
        "DatasetEntry": wf.list_datasets()[0],
    }
    folder = tmp_path_factory.mktemp("workflows")
    path, model_file = str(folder / "rec.csv"), str(folder / "m.json")
    write_table(path, ["u", "y"], np.column_stack([u, y]))
    clpc.save_model(model, model_file)
    found["SimulateResult"] = wf.simulate_file(model_file, path)
    found["CompareResult"] = wf.compare_file(wf.CompareSettings(model_file, wf.RecordSpec(path)))
    spec = wf.RecordSpec(path, ("u",), ("y",), dt=record.dt)
    found["IdentifyResult"] = wf.identify_file(wf.IdentifySettings(spec))
    lines = [f"{a},{b}" for a, b in zip(u[:300], y[:300], strict=True)]
    settings = wf.StreamSettings(wf.AppraiserSettings(window_size=60, cluster_size=10))
    found["StreamBatch"] = next(iter(wf.stream_samples([lines], settings)))
    if importlib.util.find_spec("matplotlib") is not None:
        spec = wf.RecordSpec(path, ("u",), ("y",), dt=record.dt)
        found["TrackResult"] = wf.track_file(wf.TrackSettings(spec, str(folder / "track")))
    return found


class _Balanced(HTMLParser):
    VOID: ClassVar[set[str]] = {"br", "img", "meta", "hr"}

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


def _html_text(markup: str) -> str:
    parser = _Balanced()
    parser.feed(markup)
    parser.close()
    assert parser.stack == [], f"unclosed {parser.stack}"
    return parser.text


def test_every_public_result_type_is_checked(results):
    public = _public_dataclasses()
    assert NOT_RESULTS | PENDING <= public  # no stale entry
    assert public - NOT_RESULTS - PENDING <= set(results)
    if "TrackResult" not in results:
        pytest.skip("matplotlib is not installed: TrackResult not built")


@pytest.mark.parametrize(
    "name",
    [
        "IOData",
        "LinearModel",
        "Verdict",
        "ResidualAnalysis",
        "Identification",
        "OrderSelection",
        "DelaySelection",
        "NoiseEstimate",
        "EivCheck",
        "WhitenessResult",
        "Trace",
        "Convergence",
        "OperatingPointReport",
        "Comparison",
        "MultiModel",
        "DatasetEntry",
        "SimulateResult",
        "CompareResult",
        "StreamBatch",
        "TrackResult",
    ],
)
def test_repr_fits_a_screen_and_html_parses(results, name):
    if name not in results:
        pytest.skip("needs matplotlib")
    obj = results[name]
    assert type(obj).__name__ == name
    text = repr(obj)
    assert len(text) < MAX_REPR
    assert text.startswith(name)
    # no array is dumped: numpy's own repr of an array never appears
    assert "array([[" not in text and "...," not in text
    markup = obj._repr_html_()
    assert name in _html_text(markup) or "fit of the" in _html_text(markup)


def test_arrays_are_summarised_by_shape_and_range(results):
    res = results["ResidualAnalysis"]
    text = repr(res)
    e = res.residuals
    shown = f"array(shape={e.shape}, float64, min={e.min():.4g}, max={e.max():.4g})"
    assert f"residuals={shown}" in text
    trace = results["Trace"]
    assert f"index=array(shape=({len(trace)},), int64" in repr(trace)
    # the long per-equation arrays are named, not shown
    assert "arrays=dict(" in repr(trace) and "theta_estimate" in repr(trace)


def test_nested_results_show_their_numbers_short(results):
    found = results["Identification"]
    text = repr(found)
    assert text.splitlines()[1].startswith("    model=LinearModel(na=")
    chosen = next(row for row in found.table if row["chosen"])
    assert f"free_run: {chosen['free_run']:.4g}" in text
    # the HTML holds the whole comparison table, one row per candidate
    html_text = _html_text(found._repr_html_())
    for row in found.table:
        assert f"{row['free_run']:.4g}" in html_text
    test = results["ResidualAnalysis"].whiteness[0]
    assert f"statistic={test.statistic:.4g}" in repr(results["ResidualAnalysis"])


def test_summarise_values():
    x = np.array([3.0, np.nan, -2.5, np.inf, *range(10)])
    assert summarise(x) == "array(shape=(14,), float64, min=-2.5, max=9, non-finite=2)"
    assert summarise(np.array([1.23456, 2.0])) == "array([1.235, 2])"
    assert summarise(np.array([[1, 2], [3, 4]])) == "array([[1, 2], [3, 4]])"
    assert summarise(np.zeros((0, 3))) == "array(shape=(0, 3), float64)"
    assert summarise(np.ones((20, 2), dtype=bool)) == "array(shape=(20, 2), bool, true=40)"
    assert summarise(("a",)) == "('a',)"
    long = "word " * 100
    cut = summarise(long, 50)
    assert len(cut) == 50 and cut.endswith("…")
    many = {f"k{i}": np.arange(100.0) for i in range(5)}
    assert summarise(many, 60).startswith("dict(5 keys: k0, k1")
    assert summarise(3.14159265) == "3.142" and summarise(np.float64(2.5)) == "2.5"


def test_the_decorator_keeps_a_class_s_own_html_and_leaves_out_hidden_fields():
    @compact_repr
    @dataclasses.dataclass
    class Own:
        values: np.ndarray
        secret: str = dataclasses.field(default="hidden", repr=False)

        def _repr_html_(self) -> str:
            return "<b>own</b>"

    shown = Own(np.arange(1000.0))
    assert repr(shown) == "Own(values=array(shape=(1000,), float64, min=0, max=999))"
    assert shown._repr_html_() == "<b>own</b>"
    with pytest.raises(TypeError, match="needs a dataclass"):
        compact_repr(int)


def test_a_long_repr_is_cut_at_one_screen():
    @compact_repr
    @dataclasses.dataclass
    class Wide:
        texts: tuple[str, ...]
        a: str
        b: str
        c: str
        d: str
        e: str
        f: str
        g: str
        h: str

    wide = Wide(tuple("x" * 300 for _ in range(50)), *("y" * 300 for _ in range(8)))
    text = repr(wide)
    assert len(text) <= MAX_REPR and text.endswith("…")
    assert re.search(r"… 44 more", text)
