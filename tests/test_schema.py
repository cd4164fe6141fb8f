"""One checker for model files and appraiser states (clpc._schema): the same wording in both."""

from __future__ import annotations

import copy
import json

import numpy as np
import pytest

import clpc
from clpc._schema import Fields, LongNumber, bounded_json
from clpc.appraiser.state_schema import StateError
from clpc.io.model_files import model_from_dict
from clpc.io.model_schema import ModelFileError, model_to_dict


@pytest.fixture(scope="module")
def docs():
    rng = np.random.default_rng(4)
    u = rng.standard_normal(600)
    y = np.convolve(u, [0.0, 0.5, 0.2])[:600] + 0.01 * rng.standard_normal(600)
    appraiser = clpc.CLPC(order=2, window_size=101, cluster_size=10)
    appraiser.push(u, y)
    state = json.loads(json.dumps(appraiser.state_dict()))
    return model_to_dict(clpc.LPC(order=2).fit(u, y)), state


def test_a_string_among_numbers_reads_alike_in_a_model_file_and_a_state(docs):
    model, state = copy.deepcopy(docs[0]), copy.deepcopy(docs[1])
    model["theta"][0][0] = "1.0"
    state["last_theta"]["data"][0] = "1.0"
    with pytest.raises(ModelFileError, match=r"^model file 'm\.json': theta must be a \(nested\) "):
        model_from_dict(model, source="m.json")
    with pytest.raises(StateError, match=r"^state\['last_theta'\] must be a \(nested\) list of"):
        clpc.CLPC.from_state_dict(state)


def test_a_missing_field_names_the_field_and_what_is_incomplete(docs):
    model, state = copy.deepcopy(docs[0]), copy.deepcopy(docs[1])
    del model["dt"], state["n_seen"]
    with pytest.raises(ModelFileError, match="required field 'dt' is missing; the file is"):
        model_from_dict(model, source="m.json")
    with pytest.raises(StateError, match=r"required field state\['n_seen'\] is missing; the state"):
        clpc.CLPC.from_state_dict(state)


def test_fields_checks():
    check = Fields(ValueError, "x: ")
    assert check.integer(3, "n", 1) == 3
    for bad in (True, 0, 1.0, "3", LongNumber("1" * 50)):
        with pytest.raises(ValueError, match=r"^x: n must be an integer >= 1; got "):
            check.integer(bad, "n", 1)
    assert check.positive(0.5, "dt", "seconds") == 0.5
    with pytest.raises(ValueError, match="dt must be a positive number of seconds; got 1000"):
        check.positive(10**400, "dt", "seconds")
    np.testing.assert_array_equal(check.floats([[1, 2]], "a", (1, None)), [[1.0, 2.0]])
    with pytest.raises(ValueError, match=r"a must have shape \(2,\); got \(3,\)"):
        check.floats([1, 2, 3], "a", (2,))
    with pytest.raises(ValueError, match="a holds non-finite values"):
        check.floats([1.0, float("inf")], "a", (2,))
    with pytest.raises(ValueError, match="a must be a"):
        check.floats([[1.0], [1.0, 2.0]], "a", (2, None))  # ragged
    with pytest.raises(ValueError, match="values beyond 1e"):
        check.floats([1e200], "a", (1,), max_abs=1e150)


def test_bounded_json_keeps_or_refuses_long_numbers():
    text = '{"a": 1' + "0" * 60 + "}"
    kw = dict(max_bytes=1000, max_depth=4, error=ValueError, what="t")
    assert isinstance(bounded_json(text, **kw)["a"], LongNumber)
    with pytest.raises(ValueError, match="t holds a number of 61 characters"):
        bounded_json(text, **kw, long_numbers=False)
    with pytest.raises(ValueError, match="t is nested deeper than 4 levels"):
        bounded_json("[[[[[1]]]]]", **kw)
