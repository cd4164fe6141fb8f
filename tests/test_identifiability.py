"""Identifiability first: the input's order of persistent excitation, the DC gain +- sigma,
the dominant poles, and the verdict, the command line and the report that lead with them."""

from __future__ import annotations

import json
from html.parser import HTMLParser

import numpy as np
import pytest
from click.testing import CliRunner
from scipy import signal

import clpc
from clpc.cli import cli
from clpc.io import write_table
from clpc.model import Structure
from clpc.model.excitation import EXCITATION_RTOL, excitation_ratios, needed_order
from clpc.model.identifiability import GAIN_SCALE_FRACTION, GAIN_SIGMAS, identifiability
from clpc.report import format_model_summary, model_summary

DEN = np.array([1.0, -1.5, 0.7])  # poles 0.75 +- 0.37j
NUM = np.array([0.0, 0.1, 0.1])  # nk = 1: DC gain 0.2 / 0.2 = 1
T = 2000


def lag_matrix_ratios(u: np.ndarray, n: int, experiments: list[int] | None = None) -> np.ndarray:
    """Reference: the SVD of the explicit, centered lag matrix (every lag vector a row)."""
    u = np.asarray(u, dtype=float).reshape(len(u), -1)
    parts = experiments or [len(u)]
    ends = np.cumsum(parts)
    rows = [
        np.hstack([u[e - p : e][n - 1 - i : p - i] for i in range(n)])
        for e, p in zip(ends, parts, strict=True)
    ]
    x = np.vstack(rows)
    x = x - x.mean(axis=0)
    out = []
    for k in range(1, n + 1):
        s = np.linalg.svd(x[:, : k * u.shape[1]], compute_uv=False)
        out.append(s[-1] / s[0])
    return np.array(out)


def sine_record(seed: int, w: float = 1.0, noise: float = 0.05) -> tuple[np.ndarray, np.ndarray]:
    """A single sine into the order-2 plant, white noise on the output."""
    rng = np.random.default_rng(seed)
    u = np.sin(w * np.arange(T) + 0.3)
    return u, signal.lfilter(NUM, DEN, u) + noise * rng.standard_normal(T)


def white_record(seed: int) -> tuple[np.ndarray, np.ndarray]:
    rng = np.random.default_rng(seed)
    u = rng.standard_normal(T)
    return u, signal.lfilter(NUM, DEN, u) + 0.05 * rng.standard_normal(T)


# ------------------------------------------------------------------ excitation order
@pytest.mark.parametrize("offset", [0.0, 3.0, -1e4])
@pytest.mark.parametrize("w", [0.01, 0.3, 1.0, 3.0])
def test_a_sine_is_persistently_exciting_of_order_2(w, offset):
    t = np.arange(3000)
    assert clpc.excitation_order(offset + np.sin(w * t + 0.7), 10) == 2


def test_known_signals_have_their_orders():
    t = np.arange(4000)
    rng = np.random.default_rng(0)
    two = np.sin(0.2 * t) + 0.5 * np.sin(1.3 * t + 1.0)
    three = two + 0.3 * np.cos(2.2 * t)
    assert clpc.excitation_order(two, 10) == 4
    assert clpc.excitation_order(three, 10) == 6
    assert clpc.excitation_order(rng.standard_normal(4000), 10) == 10  # white: any order
    assert clpc.excitation_order((-1.0) ** t, 10) == 1  # one real frequency, at Nyquist
    assert clpc.excitation_order(np.full(4000, 1e4), 10) == 0  # constant
    assert clpc.excitation_order(np.zeros(4000), 10) == 0
    # a sine stored in float32 is a sine: its rounding (1e-8) is not excitation
    assert clpc.excitation_order(np.sin(0.3 * t).astype(np.float32), 10) == 2
    # ... but noise well above the threshold excites every order
    assert clpc.excitation_order(np.sin(0.3 * t) + 1e-3 * rng.standard_normal(4000), 10) == 10


def test_excitation_ratios_equal_the_lag_matrix_svd():
    rng = np.random.default_rng(1)
    smooth = signal.lfilter([1.0], [1.0, -0.95], rng.standard_normal(3000))
    np.testing.assert_allclose(
        excitation_ratios(smooth, 8), lag_matrix_ratios(smooth, 8), rtol=1e-8
    )
    # two inputs, three experiments: lag vectors never cross a boundary
    u = rng.standard_normal((900, 2)) @ np.array([[1.0, 0.4], [0.0, 1.0]]) + [5.0, -2.0]
    parts = [200, 300, 400]
    got, want = excitation_ratios(u, 6, parts), lag_matrix_ratios(u, 6, parts)
    np.testing.assert_allclose(got, want, rtol=1e-8)
    assert np.all(np.diff(got) <= 1e-15)  # nested covariances: non-increasing


def test_the_joint_input_counts_its_relations():
    t = np.arange(3000)
    w = np.random.default_rng(2).standard_normal(3000)
    assert clpc.excitation_order(np.column_stack([w, w]), 5) == 0  # u1 - u2 = 0
    sines = np.column_stack([np.sin(0.4 * t), np.sin(1.1 * t)])  # 4 directions, 2 per lag
    assert clpc.excitation_order(sines, 5) == 2
    assert clpc.excitation_order(sines[:, 0], 5) == 2


def test_the_needed_order_is_that_of_the_models_a_pe_input_tells_apart():
    s = Structure(na=2, nb=2, nk=1)
    assert needed_order(s) == 5
    # two models of this structure that a sine (order 2 < 5) cannot tell apart: add to B a
    # multiple of the sine's own relation 1 - 2 cos(w) z^-1 + z^-2; their DC gains differ
    w = 1.0
    twin = np.r_[NUM, 0.0] + 0.2 * np.r_[0.0, 1.0, -2.0 * np.cos(w), 1.0]
    u, _ = sine_record(0, w)
    y1, y2 = signal.lfilter(NUM, DEN, u), signal.lfilter(twin, DEN, u)
    assert np.max(np.abs(y1 - y2)[200:]) < 1e-12  # the same data after the first transient
    gain1, gain2 = NUM.sum() / DEN.sum(), twin.sum() / DEN.sum()
    assert abs(gain1 - gain2) > 0.4
    # a white input of the same length tells them apart
    uw, _ = white_record(0)
    assert np.std(signal.lfilter(NUM, DEN, uw) - signal.lfilter(twin, DEN, uw)) > 0.1


# --------------------------------------------------------------------- the verdict
@pytest.mark.parametrize("estimator", [clpc.LPC, clpc.ARX, clpc.OE])
def test_a_sine_input_leads_the_verdict_and_leaves_the_gain_undetermined(estimator):
    u, y = sine_record(3)
    model = estimator(order=2, nk=1).fit(u, y)
    verdict = model.verdict()
    first = verdict.messages[0]
    assert first.startswith("NOT identifiable from this record")
    assert "persistently exciting of order 2 only, needs 5" in first
    assert "DC gain u -> y undetermined" in first
    assert verdict.identifiable is False
    assert (verdict.excitation_order, verdict.needed_order) == (2, 5)
    text = str(verdict)
    assert "fits" not in text
    assert not any(m.startswith("the model describes the record") for m in verdict.messages)
    assert "the data determine the parameters" not in text
    assert all(len(m) < 250 for m in verdict.messages)  # one finding per line
    ratio = model.info["excitation_ratio"]
    assert ratio < EXCITATION_RTOL and f"{ratio:.2g} < {EXCITATION_RTOL:g}" in text
    (gain,) = clpc.assess_gain(model)
    assert gain.determined is False and gain.cause == "excitation"
    assert gain.text.startswith("undetermined: ")


def test_a_white_input_says_nothing_of_the_sort():
    u, y = white_record(4)
    for estimator in (clpc.LPC, clpc.ARX, clpc.OE):
        model = estimator(order=2, nk=1).fit(u, y)
        verdict = model.verdict()
        text = str(verdict)
        assert verdict.identifiable is True and verdict.excitation_order == 5
        assert "NOT identifiable" not in text and "undetermined" not in text
        assert "persistently exciting" not in text
        (gain,) = clpc.assess_gain(model)
        assert gain.determined is True and gain.std < 0.1
        if estimator is clpc.OE:  # consistent under output noise (least squares is not)
            assert abs(gain.gain - 1.0) < 3 * gain.std
    assert clpc.LPC(order=2, nk=1).fit(u, y).verdict().messages[0] == (
        "the model describes the record"
    )


def sigma_record(seed: int) -> tuple[np.ndarray, np.ndarray]:
    """White input, a plant whose DC gain (0.05) is small beside its noise (equation noise)."""
    rng = np.random.default_rng(seed)
    u = rng.standard_normal(300)
    num = np.array([0.0, 0.5, -0.49])
    e = signal.lfilter([1.0], DEN, 0.5 * rng.standard_normal(300))
    return u, signal.lfilter(num, DEN, u) + e


def test_a_gain_within_one_sigma_of_zero_leads_the_verdict():
    # the truth (0.05) is not decided by such records: over 100 of them the least-squares
    # gain has a standard deviation 5x its size and the wrong sign in 44 %
    gains, undetermined = [], 0
    for seed in range(60):
        u, y = sigma_record(seed)
        model = clpc.ARX(order=2, nk=1, assess=False).fit(u, y)
        (g,) = clpc.assess_gain(model)
        gains.append(g.gain)
        scale = np.std(y) / np.std(u)
        want = g.std * GAIN_SIGMAS > abs(g.gain) and g.std > GAIN_SCALE_FRACTION * scale
        assert (g.determined is False) == want
        if want:
            undetermined += 1
            verdict = model.verdict()
            assert verdict.messages[0] == (
                f"NOT identifiable from this record: DC gain u -> y undetermined ({g.value})"
            )
            assert "the data do not decide its sign" in str(verdict)
            assert "fits" not in str(verdict)
    assert undetermined >= 20
    assert np.std(gains) > 3 * 0.05 and np.mean(np.array(gains) < 0) > 0.25


def test_a_gain_known_to_be_small_is_determined():
    # two inputs, the second does not act: its gain is 0 within sigma, and sigma is small
    rng = np.random.default_rng(5)
    u = rng.standard_normal((T, 2))
    y = signal.lfilter(NUM, DEN, u[:, 0]) + 0.05 * rng.standard_normal(T)
    model = clpc.LPC(order=2, nk=1, mimo="miso").fit(u, y)
    first, second = clpc.assess_gain(model)
    assert first.determined is True and abs(first.gain - 1.0) < 3 * first.std
    # within one sigma of 0 (its sign undecided), but that sigma is a small share of the
    # record's scale std(y)/std(u): the data decide that the gain is small
    scale = np.std(y) / np.std(u[:, 1])
    assert abs(second.gain) < second.std <= GAIN_SCALE_FRACTION * scale
    assert second.determined is True and second.cause == "zero"
    assert second.text.endswith("(consistent with 0)")
    assert model.verdict().identifiable is True


def test_a_two_output_summary_prints_every_pair():
    # OE on two outputs keeps one count of cancelled factors per output (it crashed the text)
    rng = np.random.default_rng(9)
    u = rng.standard_normal((600, 2))
    y = np.column_stack(
        [signal.lfilter([0, 0.5], [1, -0.8], u[:, 0]), signal.lfilter([0, 0.3], [1, -0.5], u[:, 1])]
    ) + 0.05 * rng.standard_normal((600, 2))
    model = clpc.OE(order=1, nk=1).fit(u, y)
    summary = model_summary(model)
    assert summary["cancelled"] == 0 and summary["identifiable"] is True
    text = format_model_summary(summary)
    gains = {(g.input, g.output): g for g in clpc.assess_gain(model)}
    assert len(gains) == 4 and all(g.determined for g in gains.values())
    for (inp, out), g in gains.items():
        assert f"[{out}]  DC gain {inp} -> {out}: {g.text}" in text
    for key, truth in ((("u0", "y0"), 2.5), (("u1", "y1"), 0.6), (("u1", "y0"), 0.0)):
        assert abs(gains[key].gain - truth) < 4 * gains[key].std


def test_the_delta_method_sigma_matches_monte_carlo():
    # ARX on its own noise model: the spread of the DC gain over 200 records against the
    # delta-method sigma of each fit
    gains, sigmas = [], []
    for seed in range(200):
        rng = np.random.default_rng(100 + seed)
        u = rng.standard_normal(500)
        y = signal.lfilter(NUM, DEN, u) + signal.lfilter([1.0], DEN, 0.3 * rng.standard_normal(500))
        model = clpc.ARX(order=2, nk=1, assess=False).fit(u, y)
        g, s = clpc.gain_uncertainty(model)
        gains.append(g)
        sigmas.append(s)
    ratio = np.mean(sigmas) / np.std(gains)
    assert 0.8 < ratio < 1.25, ratio
    # and the finite differences against the closed-form gradient of B(1)/A(1)
    cov = model.covariance[0]
    a1 = model.den.sum()
    grad = np.r_[np.full(2, -g / a1), np.full(model.num.size, 1.0 / a1)]
    free = np.diag(cov) > 0
    want = np.sqrt(grad[free] @ cov[np.ix_(free, free)] @ grad[free])
    assert s == pytest.approx(want, rel=1e-6)


def test_no_covariance_gives_nan_with_its_reason():
    u, y = white_record(6)
    model = clpc.LPC(order=2, nk=1, uncertainty=False).fit(u, y)
    g, s = clpc.gain_uncertainty(model)
    assert np.isfinite(g) and np.isnan(s)
    (gain,) = clpc.assess_gain(model)
    assert gain.determined is None and gain.note.startswith("no sigma:")
    assert gain.cause == "no sigma" and "no sigma" in gain.text


def test_the_excitation_travels_with_the_model_file(tmp_path):
    u, y = sine_record(7)
    model = clpc.LPC(order=2, nk=1).fit(u, y)
    clpc.save_model(model, tmp_path / "m.json")
    loaded = clpc.load_model(tmp_path / "m.json")
    assert loaded.info["excitation_order"] == 2 and loaded.info["excitation_needed"] == 5
    assert str(loaded.verdict()) == str(model.verdict())
    assert identifiability(loaded).identifiable is False


# ------------------------------------------------------------------ dominant poles
def test_dominant_poles_in_continuous_time(make_model):
    dt, wn, zeta, tau = 0.01, 30.0, 0.2, 0.5
    s = -zeta * wn + 1j * wn * np.sqrt(1 - zeta**2)
    p = np.exp(s * dt)
    den = np.real(np.poly([p, np.conj(p), np.exp(-dt / tau), 0.3]))
    model = make_model(den, np.r_[0.0, 1.0, 0.0, 0.0, 0.0], nk=1, dt=dt)
    slow = clpc.dominant_poles(model)
    assert [d.kind for d in slow] == ["real", "complex pair", "real"]  # |p|: 0.98, 0.94, 0.3
    assert slow[0].time_constant == pytest.approx(tau, rel=1e-9)
    assert slow[1].natural_frequency == pytest.approx(wn, rel=1e-9)
    assert slow[1].damping == pytest.approx(zeta, rel=1e-9)
    assert slow[1].frequency_hz == pytest.approx(wn / (2 * np.pi), rel=1e-9)
    assert slow[2].time_constant == pytest.approx(-dt / np.log(0.3), rel=1e-9)
    assert len(clpc.dominant_poles(model, count=1)) == 1
    odd = make_model(np.real(np.poly([1.0, -0.5])), np.r_[0.0, 1.0, 0.0], nk=1, dt=dt)
    assert [d.kind for d in clpc.dominant_poles(odd)] == ["integrator", "alternating"]


# ------------------------------------------------------------- command line, report
@pytest.fixture(scope="module")
def records(tmp_path_factory):
    folder = tmp_path_factory.mktemp("ident")
    out = {}
    for name, (u, y) in {"sine": sine_record(8), "white": white_record(8)}.items():
        out[name] = str(folder / f"{name}.csv")
        write_table(out[name], ["u", "y"], np.column_stack([u, y]))
    return out


#: the paper's LPC at order 2 alone (the default chooses structure and estimator)
LPC2 = ("--estimator", "lpc", "--order", "2")


def identify(*args: str):
    result = CliRunner().invoke(cli, ["identify", *map(str, args)])
    assert result.exit_code == 0, result.output
    return result.output


def test_the_command_line_prints_the_dc_gain_and_leads_with_what_is_undecided(records):
    out = identify(records["white"], "-u", "u", "-y", "y", *LPC2, "--nk", "1", "--dt", "0.01")
    model = clpc.LPC(order=2, nk=1).fit(*white_record(8), dt=0.01)
    (gain,) = clpc.assess_gain(model)
    assert f"[y]  DC gain u -> y: {gain.value}" in out and "±" in gain.value
    assert "[y]  dominant poles: " in out and "rad/s" in out and "damping" in out
    assert "NOT identifiable" not in out
    out = identify(records["sine"], "-u", "u", "-y", "y", *LPC2, "--nk", "1", "--dt", "0.01")
    assert out.startswith("NOT identifiable from this record: input persistently exciting")
    assert "[y]  DC gain u -> y: undetermined: " in out
    verdict = next(line for line in out.splitlines() if "verdict:" in line)
    assert "NOT identifiable" in verdict and len(verdict) < 200


def test_the_json_carries_the_same_numbers(records):
    summary = json.loads(
        identify(
            records["sine"], "-u", "u", "-y", "y", *LPC2, "--nk", "1", "--dt", "0.01", "--json"
        )
    )
    eq = summary["equations"][0]
    model = clpc.LPC(order=2, nk=1).fit(*sine_record(8), dt=0.01)
    (gain,) = clpc.assess_gain(model)
    assert eq["dc_gain"][0]["gain"] == pytest.approx(gain.gain, rel=1e-12)
    assert eq["dc_gain"][0]["std"] == pytest.approx(gain.std, rel=1e-9)
    assert eq["dc_gain"][0]["determined"] is False
    found = eq["identifiability"]
    assert (found["excitation_order"], found["needed_order"]) == (2, 5)
    assert found["findings"][0] == str(model.verdict()).splitlines()[0]
    assert summary["identifiable"] is False
    assert eq["dominant_poles"][0]["kind"] in ("complex pair", "real")


class _Page(HTMLParser):
    """Headings, table captions and the text of warning boxes, in document order."""

    def __init__(self) -> None:
        super().__init__()
        self.headings: list[str] = []
        self.captions: list[str] = []
        self.warnings: list[str] = []
        self.cells: list[str] = []
        self._tag: list[str] = []
        self._warn = 0

    def handle_starttag(self, tag, attrs):
        self._tag.append(tag)
        if tag == "div" and ("class", "warn") in attrs:
            self._warn = 1
        elif tag == "div" and self._warn:
            self._warn += 1

    def handle_endtag(self, tag):
        self._tag.pop()
        if tag == "div" and self._warn:
            self._warn -= 1

    def handle_data(self, data):
        where = self._tag[-1] if self._tag else ""
        if where == "h2":
            self.headings.append(data)
        elif where == "caption":
            self.captions.append(data)
        elif where == "td":
            self.cells.append(data)
        if self._warn and where == "li":
            self.warnings.append(data)


def test_the_report_opens_with_what_the_record_decides(records, tmp_path):
    out = identify(
        records["sine"], "-u", "u", "-y", "y", "--order", "2", "--nk", "1", "--dt", "0.01",
        "--report", tmp_path,
    )  # fmt: skip
    assert out.startswith("NOT identifiable")
    page = _Page()
    page.feed((tmp_path / "report.html").read_text(encoding="utf-8"))
    assert page.headings[:3] == [
        "What the record decides",
        "Estimator comparison",
        "Result: the model",
    ]
    assert page.warnings[0].startswith("NOT identifiable from this record")
    s = clpc.identify(clpc.as_iodata(*sine_record(8), dt=0.01), order=2, nk=1).structure
    needs = f"persistently exciting of order 2 only, needs {s.na + s.nb + 1}"
    assert any(needs in w for w in page.warnings), page.warnings
    assert page.captions[:2] == ["DC gains", "Dominant poles (slowest first)"]
    found = clpc.identify(clpc.as_iodata(*sine_record(8), dt=0.01), order=2, nk=1)
    for row in found.table:
        assert row["estimator"].upper() in page.cells
        assert f"na={row['na']} nb={row['nb']} nk={row['nk']}" in page.cells
        assert f"{row['free_run']:.2f} %" in page.cells
    assert "NO" in page.cells  # the gain is not determined
    html = (tmp_path / "report.html").read_text(encoding="utf-8")
    assert "Reason: " + found.reason[:40] in html.replace("&#x27;", "'")
