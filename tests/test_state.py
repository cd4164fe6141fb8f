"""Saved appraiser states: damaged or edited ones are refused before they reach the kernel."""

from __future__ import annotations

import copy
import json
import subprocess
import sys

import numpy as np
import pytest

import clpc
from clpc import CLPC
from clpc.appraiser.state_schema import StateError

DEN = np.array([1.0, -1.5, 0.7])
NUM = np.array([0.2, 0.5, 0.1])


@pytest.fixture(scope="module")
def saved():
    rng = np.random.default_rng(31)
    u = rng.standard_normal(3000)
    y = clpc.simulate_arx(DEN, NUM, u) + 0.01 * rng.standard_normal(3000)
    a = CLPC(order=2, window_size=201, cluster_size=12)
    a.push(u[:2000], y[:2000])
    return json.loads(json.dumps(a.state_dict())), u, y


def _arr(values):
    values = np.asarray(values, dtype=float)
    return {"shape": list(values.shape), "data": values.ravel().tolist()}


def _drop_rows(state, rows):
    buf = np.asarray(state["buf"]["data"]).reshape(state["buf"]["shape"])
    state["buf"] = _arr(buf[rows:])


TAMPERED = [
    ("n_seen", lambda s: s.update(n_seen=10**9), "n_seen"),
    ("n_seen negative", lambda s: s.update(n_seen=-5), ">= 0"),
    ("last_theta shape", lambda s: s.update(last_theta=_arr([[1, 2, 3]])), "last_theta"),
    ("buf_start large", lambda s: s.update(buf_start=10**6), "buffer holds samples"),
    ("buf_start negative", lambda s: s.update(buf_start=-100), ">= 0"),
    ("truncated buffer", lambda s: _drop_rows(s, 50), "buffer holds samples"),
    ("j_done negative", lambda s: s.update(j_done=-1), ">= 0"),
    ("j_done off", lambda s: s.update(j_done=s["j_done"] + 1), "j_done"),
    ("factor 0", lambda s: s.update(factor=0), "factor"),
    ("factor 3", lambda s: s.update(factor=3), "factor"),
    ("window changed", lambda s: s["config"].update(window_size=40), "buf_start|j_done"),
    ("NaN in buffer", lambda s: s["buf"]["data"].__setitem__(5, float("nan")), "non-finite"),
    ("missing key", lambda s: s.pop("j_done"), "j_done"),
    ("wrong type", lambda s: s.update(n_seen="2000"), "n_seen"),
    ("bool counter", lambda s: s.update(j_done=True), "j_done"),
    ("has_model", lambda s: s.update(has_model=[1]), "has_model"),
    ("config", lambda s: s["config"].update(window_size=True), "config"),
    ("names", lambda s: s.update(names=[["u"], ["y", "z"]]), "names"),
]


@pytest.mark.parametrize(("what", "edit", "match"), TAMPERED, ids=[t[0] for t in TAMPERED])
def test_tampered_states_are_refused_with_the_field(saved, what, edit, match):
    state = copy.deepcopy(saved[0])
    edit(state)
    with pytest.raises(StateError, match=match):
        CLPC.from_state_dict(state)


def test_untampered_state_continues_identically(saved):
    state, u, y = saved
    whole = CLPC(order=2, window_size=201, cluster_size=12).run(u, y)
    resumed = CLPC.from_state_dict(copy.deepcopy(state)).push(u[2000:], y[2000:])
    np.testing.assert_array_equal(resumed.theta, whole.theta[-len(resumed) :])


def test_state_saved_with_an_engine_setting_still_restores(saved):
    # states written while CLPC had engine="auto"|"compiled"|"python" (now NUMBA_DISABLE_JIT)
    from clpc.appraiser.state import digest

    state, u, y = copy.deepcopy(saved[0]), saved[1], saved[2]
    state["config"]["engine"] = "compiled"
    state["digest"] = digest(state)
    resumed = CLPC.from_state_dict(state).push(u[2000:], y[2000:])
    whole = CLPC(order=2, window_size=201, cluster_size=12).run(u, y)
    np.testing.assert_array_equal(resumed.theta, whole.theta[-len(resumed) :])


def test_state_saved_with_the_former_names_is_mapped_once(saved):
    # states saved before one name per setting: parameters_size (N + 1) and gate
    from clpc.appraiser.state import digest

    state, u, y = copy.deepcopy(saved[0]), saved[1], saved[2]
    cfg = state["config"]
    cfg["parameters_size"] = cfg.pop("order") + 1
    cfg["gate"] = cfg.pop("guard")
    state["digest"] = digest(state)
    restored = CLPC.from_state_dict(state)
    assert (restored.order, restored.guard) == (2, True)
    assert "parameters_size" not in restored.state_dict()["config"]
    whole = CLPC(order=2, window_size=201, cluster_size=12).run(u, y)
    resumed = restored.push(u[2000:], y[2000:])
    np.testing.assert_array_equal(resumed.theta, whole.theta[-len(resumed) :])


def test_state_saved_with_the_ambiguous_sample_time_is_refused(saved):
    from clpc.appraiser.state import digest

    state = copy.deepcopy(saved[0])
    state["config"]["sample_time"] = state["config"].pop("decimate_to") or 1.0
    state["digest"] = digest(state)
    with pytest.raises(StateError, match="ambiguous sample_time"):
        CLPC.from_state_dict(state)


@pytest.mark.parametrize(
    "text", ["[]", "3", '"x"', "{" * 100 + "}" * 100, '{"a": 1' + "0" * 500 + "}"]
)
def test_files_that_are_not_states(tmp_path, text):
    path = tmp_path / "state.json"
    path.write_text(text)
    with pytest.raises(StateError):
        CLPC.load(str(path))


def test_the_former_crashes_end_in_a_clear_error_in_a_real_process(saved, tmp_path):
    # these edits used to crash the interpreter inside the compiled kernel (segfault,
    # heap corruption); run them in a child process so that a crash fails this test
    state = saved[0]
    for name, edit in (
        ("n_seen", lambda s: s.update(n_seen=10**9)),
        ("last_theta", lambda s: s.update(last_theta=_arr([[1, 2, 3]]))),
    ):
        tampered = copy.deepcopy(state)
        edit(tampered)
        path = tmp_path / f"{name}.json"
        path.write_text(json.dumps(tampered))
        code = (
            "import numpy as np, clpc\n"
            "from clpc.appraiser.state_schema import StateError\n"
            f"try:\n    clpc.CLPC.load({str(path)!r}).push(np.ones(500), np.ones(500))\n"
            "except StateError as e:\n    print('refused:', e)\n"
        )
        proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
        assert proc.returncode == 0, proc.stderr
        assert "refused:" in proc.stdout


def test_state_with_a_model_but_a0_zero_is_refused(saved):
    state = copy.deepcopy(saved[0])
    theta = np.asarray(state["last_theta"]["data"])
    theta[0] = 0.0
    state["last_theta"]["data"] = theta.tolist()
    with pytest.raises(StateError, match="a0 = 0"):
        CLPC.from_state_dict(state)


def test_bad_settings_in_a_state_are_state_errors(saved):
    for edit in (
        lambda s: s["config"].update(mimo="both"),
        lambda s: s.update(record_dt=-1.0),
        lambda s: s["config"]["rule"].update(separation="x"),
    ):
        state = copy.deepcopy(saved[0])
        edit(state)
        with pytest.raises(StateError):
            CLPC.from_state_dict(state)


def test_json_depth_counts_brackets_outside_strings_only():
    from clpc.appraiser.state_schema import parse_json

    assert parse_json('{"a": "\\"' + "[" * 50 + '"}') == {"a": '"' + "[" * 50}
    with pytest.raises(StateError, match="nested deeper"):
        parse_json('{"a": "\\\\"' + ", " + '"b": ' + "[" * 50 + "]" * 50 + "}")


def test_a_save_that_fails_midway_leaves_the_previous_state_whole(tmp_path, monkeypatch):
    rng = np.random.default_rng(4)
    u = rng.standard_normal(600)
    y = clpc.simulate_arx([1, -0.5], [0, 1.0], u)
    appraiser = clpc.CLPC(order=1, window_size=101, cluster_size=10)
    appraiser.push(u[:300], y[:300])
    path = tmp_path / "state.json"
    appraiser.save(str(path))
    good = path.read_bytes()
    appraiser.push(u[300:], y[300:])

    def broken(obj, fh):
        fh.write('{"format": "clpc')  # part of the file, then the process dies
        raise KeyboardInterrupt

    monkeypatch.setattr("clpc.appraiser.state_file.json.dump", broken)
    with pytest.raises(KeyboardInterrupt):
        appraiser.save(str(path))
    assert path.read_bytes() == good
    assert sorted(p.name for p in tmp_path.iterdir()) == ["state.json"]  # no temporary left
    np.testing.assert_array_equal(
        clpc.CLPC.load(str(path)).push(u[300:], y[300:]).theta, appraiser_after(u, y).theta
    )


def appraiser_after(u, y):
    fresh = clpc.CLPC(order=1, window_size=101, cluster_size=10)
    fresh.push(u[:300], y[:300])
    return fresh.push(u[300:], y[300:])
