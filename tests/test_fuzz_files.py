"""Fuzzing saved appraiser states and model files (issue 15).

A mutated state must give a clear :class:`StateError` naming a field, or a resume identical
to the untampered one; states that pass the checks are pushed through the compiled kernel in
a child process, so that a crash fails the test instead of ending the test run. States whose
digest was recomputed after the edit (a deliberate forgery) may give other results but must
never crash. A mutated model file must give a :class:`ModelFileError` naming a field, or
load as a valid model.
"""

from __future__ import annotations

import copy
import json
import subprocess
import sys
import textwrap

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import clpc
from clpc import CLPC
from clpc.appraiser.state import digest
from clpc.appraiser.state_schema import StateError
from clpc.io.model_files import ModelFileError, load_model, save_model

DEN = np.array([1.0, -1.5, 0.7])
NUM = np.array([0.2, 0.5, 0.1])
SPLIT, TOTAL = 1500, 2100


@pytest.fixture(scope="module")
def record():
    rng = np.random.default_rng(41)
    u = rng.standard_normal(TOTAL)
    y = clpc.simulate_arx(DEN, NUM, u) + 0.01 * rng.standard_normal(TOTAL)
    return u, y


@pytest.fixture(scope="module")
def base_state(record):
    u, y = record
    a = CLPC(order=2, window_size=101, cluster_size=12, decimate_to=0.02, dt=0.01)
    a.push(u[:SPLIT], y[:SPLIT])
    return json.loads(json.dumps(a.state_dict()))


def _paths(obj, prefix=()):
    """Every place in a JSON document: (path, is_leaf)."""
    out = [prefix]
    if isinstance(obj, dict):
        for k, v in obj.items():
            out += _paths(v, (*prefix, k))
    elif isinstance(obj, list):
        idx = range(len(obj)) if len(obj) <= 8 else [0, 1, len(obj) // 2, len(obj) - 1]
        for i in idx:
            out += _paths(obj[i], (*prefix, i))
    return out


HOSTILE = st.one_of(
    st.integers(-(2**70), 2**70),
    st.sampled_from([0, -1, 1, 2, 10**9, 2**31, 2**63, -(2**63), 10**400]),
    st.floats(allow_nan=True, allow_infinity=True),
    st.booleans(),
    st.none(),
    st.text(max_size=4),
    st.lists(st.integers(-3, 3), max_size=4),
    st.dictionaries(st.text(max_size=3), st.integers(-2, 2), max_size=2),
)


def _get(doc, path):
    for p in path:
        doc = doc[p]
    return doc


@st.composite
def mutations(draw, doc):
    """A copy of ``doc`` with one to three edits: a value replaced, a key or item removed."""
    doc = copy.deepcopy(doc)
    for _ in range(draw(st.integers(1, 3))):
        paths = [p for p in _paths(doc) if p]
        path = draw(st.sampled_from(paths))
        parent, key = _get(doc, path[:-1]), path[-1]
        action = draw(st.sampled_from(["replace", "replace", "near", "delete"]))
        old = parent[key]
        if action == "delete":
            del parent[key]
        elif action == "near" and isinstance(old, (int, float)) and not isinstance(old, bool):
            try:
                parent[key] = old + draw(st.sampled_from([-2, -1, 1, 2, 0.5, 1e-12]))
            except OverflowError:  # a huge int from an earlier edit plus a float
                parent[key] = old + 1
        else:
            parent[key] = draw(HOSTILE)
    return doc


FIELDS = (
    "format version config n_in n_out names buf buf_start n_seen j_done last_theta last_c "
    "has_model factor dec_zi dec_phase record_dt digest window_size"
).split()


def _names_a_field(message: str) -> bool:
    return any(f in message for f in FIELDS) or "state" in message


_CHILD = textwrap.dedent(
    """
    import json, sys
    import numpy as np
    import clpc
    states, u, y = json.load(open(sys.argv[1])), *np.load(sys.argv[2])
    for i, state in enumerate(states):
        try:
            tr = clpc.CLPC.from_state_dict(state).push(u, y)
            out = {"i": i, "theta": tr.arrays["theta"].tolist(),
                   "accepted": tr.arrays["accepted"].tolist()}
        except ValueError as exc:
            out = {"i": i, "error": type(exc).__name__, "message": str(exc)}
        print(json.dumps(out), flush=True)
    """
)


def _run_in_child(states, u, y, tmp_path):
    """Resume each state on (u, y) in a child process; one result per state."""
    (tmp_path / "states.json").write_text(json.dumps(states))
    np.save(tmp_path / "uy.npy", np.vstack([u, y]))
    proc = subprocess.run(
        [sys.executable, "-c", _CHILD, tmp_path / "states.json", tmp_path / "uy.npy"],
        capture_output=True,
        text=True,
        timeout=300,
    )
    lines = proc.stdout.splitlines()
    crashed = None if proc.returncode == 0 else (len(lines), proc.returncode)
    assert crashed is None, (
        f"the child crashed on state {crashed[0]} (exit {proc.returncode}): "
        f"{json.dumps(states[crashed[0]])[:2000]}\n{proc.stderr[-2000:]}"
    )
    return [json.loads(line) for line in lines]


def _resume(state, u, y):
    tr = CLPC.from_state_dict(copy.deepcopy(state)).push(u, y)
    return tr.arrays["theta"].tolist(), tr.arrays["accepted"].tolist()


FUZZ = settings(
    max_examples=150,
    deadline=None,
    suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large],
    database=None,
)


def test_mutated_states_are_refused_or_resume_identically(base_state, record, tmp_path):
    u, y = (x[SPLIT:] for x in record)
    want_theta, want_acc = _resume(base_state, u, y)
    survivors = []

    @FUZZ
    @given(mutations(base_state))
    def check(state):
        try:
            CLPC.from_state_dict(copy.deepcopy(state))
        except StateError as exc:
            assert _names_a_field(str(exc)), str(exc)
            return
        survivors.append(state)

    check()
    survivors.append(base_state)
    for res in _run_in_child(survivors, u, y, tmp_path):
        assert "error" not in res, res
        assert res["theta"] == want_theta and res["accepted"] == want_acc


def test_forged_states_never_crash_the_kernel(base_state, record, tmp_path):
    # the digest recomputed after the edit: only the schema stands between the edit and the
    # compiled kernel, which does not check bounds
    u, y = (x[SPLIT:] for x in record)
    survivors = []

    @FUZZ
    @given(mutations({k: v for k, v in base_state.items() if k != "digest"}))
    def check(state):
        try:
            state["digest"] = digest(state)
        except (TypeError, ValueError):  # a value json.dumps refuses: not a state at all
            return
        try:
            CLPC.from_state_dict(copy.deepcopy(state))
        except StateError as exc:
            assert _names_a_field(str(exc)), str(exc)
            return
        survivors.append(state)

    check()
    results = _run_in_child(survivors, u, y, tmp_path)
    assert len(results) == len(survivors)
    for res in results:
        if "error" in res:
            assert res["message"], (
                res
            )  # a ValueError subclass with a message (the child catches no other)


@settings(max_examples=150, deadline=None, database=None)
@given(
    cut=st.integers(0, 10**9),
    insert=st.sampled_from(["", "[", "]", "{", "1" * 50, "-", "e999", '"', "\\", "NaN", "\x00"]),
)
def test_state_text_damage_is_refused_or_harmless(tmp_path_factory, base_state, cut, insert):
    text = json.dumps(base_state)
    at = cut % (len(text) + 1)
    path = tmp_path_factory.mktemp("s") / "state.json"
    path.write_text(text[:at] + insert + text[at:])
    try:
        loaded = CLPC.load(str(path))
    except StateError:
        return
    assert loaded.state_dict() == base_state


# ---------------------------------------------------------------- model files
@pytest.fixture(scope="module")
def model_doc(record, tmp_path_factory):
    u, y = record
    model = clpc.LPC(na=2, nb=2).fit(u, y, dt=0.01)
    path = tmp_path_factory.mktemp("m") / "m.json"
    save_model(model, path)
    return model, json.loads(path.read_text())


MODEL_FIELDS = (
    "format schema_version structure na nb nk mode n_inputs n_outputs theta c dt "
    "input_names output_names info num den JSON nested number"
).split()


@pytest.mark.filterwarnings("error")
@settings(max_examples=200, deadline=None, database=None)
@given(data=st.data())
def test_mutated_model_files_are_refused_or_load_valid(model_doc, tmp_path_factory, data):
    model, doc = model_doc
    edited = data.draw(mutations(doc))
    path = tmp_path_factory.mktemp("m") / "m.json"
    try:
        path.write_text(json.dumps(edited))
    except ValueError:  # json.dumps refuses the value: nothing to read
        return
    try:
        loaded = load_model(path)
    except ModelFileError as exc:
        assert any(f in str(exc) for f in MODEL_FIELDS), str(exc)
        return
    theta = np.atleast_2d(loaded.theta)
    assert np.all(np.isfinite(theta)) and theta.shape == np.atleast_2d(model.theta).shape
    assert np.isfinite(loaded.dt) and loaded.dt > 0
    # theta cannot change without num/den (which are checked against it) changing too
    if "num" in edited and "den" in edited:
        np.testing.assert_allclose(theta, np.atleast_2d(model.theta), rtol=1e-9, atol=1e-12)


@pytest.mark.parametrize("nk", [10**9, 2**63])
@pytest.mark.parametrize("keep_num", [True, False])
def test_a_huge_delay_in_a_model_file_is_refused_before_anything_is_allocated(
    model_doc, tmp_path, nk, keep_num
):
    # found by the fuzz test above: nk is not tied to theta's length; nk = 1e9 made the
    # transfer-function check allocate 8 GB (minutes), nk = 2**63 raised numpy's ValueError
    _, doc = model_doc
    edited = copy.deepcopy(doc)
    edited["structure"]["nk"] = nk
    if not keep_num:
        del edited["num"], edited["den"]
    path = tmp_path / "m.json"
    path.write_text(json.dumps(edited))
    with pytest.raises(ModelFileError, match=r"structure\.nk = "):
        load_model(path)


@pytest.mark.parametrize(
    ("text_of", "match"),
    [
        (lambda t: t.replace('"dt": 0.01', '"dt": 1' + "0" * 400), "dt must be a positive"),
        (lambda t: t.replace('"dt": 0.01', '"dt": 1' + "0" * 5000), "dt must be a positive"),
        (
            lambda t: t.replace('"info": {', '"info": {"x": ' + "[" * 100000 + "]" * 100000 + ","),
            "nested deeper",
        ),
        (lambda t: t.replace('"info": {', '"info": {"x": ' + "[" * 30 + "]" * 30 + ","), None),
        (lambda t: t.replace('"info": {', '"info": {"x": 1' + "0" * 5000 + ","), "info"),
        (lambda t: " " * (65 * 2**20) + t, "at most"),
    ],
    ids=[
        "dt-400-digits",
        "dt-5000-digits",
        "deep-nesting",
        "moderate-nesting",
        "long-int",
        "huge-file",
    ],
)
def test_model_file_limits(model_doc, tmp_path, text_of, match):
    model, _ = model_doc
    path = tmp_path / "m.json"
    save_model(model, path)
    path.write_text(text_of(path.read_text()))
    if match is None:
        load_model(path)
        return
    with pytest.raises(ModelFileError, match=match):
        load_model(path)


def test_save_model_into_a_directory_names_the_directory(model_doc, tmp_path):
    model, _ = model_doc
    with pytest.raises(ModelFileError, match="is a directory") as info:
        save_model(model, tmp_path)
    assert ".tmp" not in str(info.value)
    assert list(tmp_path.iterdir()) == []


def test_model_dict_with_huge_dt_is_refused_without_overflow(model_doc):
    _, doc = model_doc
    d = copy.deepcopy(doc)
    d["dt"] = 10**400
    with pytest.raises(ModelFileError, match="dt must be a positive"):
        clpc.io.model_files.model_from_dict(d)
