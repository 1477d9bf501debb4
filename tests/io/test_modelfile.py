"""Model files: round trip, atomic write, refusal of tampered tags and newer formats."""

import json
from pathlib import Path

import numpy as np
import pytest

from inertialab import InputError
from inertialab.calib.model_types import load_model
from inertialab.io import read_envelope
from inertialab.io.modelfile import FORMAT_VERSION, save_model
from inertialab.learn.poly import PolynomialRegressor


def _model():
    x = np.linspace(-1, 3, 20)
    return PolynomialRegressor(degree=3).fit(x, 1 + 2 * x - 0.5 * x**3)


def test_round_trip_predicts_identically(tmp_path):
    m = _model()
    p = save_model(m, tmp_path / "m.json", units={"x": "hz", "y": "dph"},
                   training_data_sha256="ab" * 32, settings={"degree": 3})
    env = read_envelope(p)
    assert env["format"] == "inertialab-model" and env["format_version"] == FORMAT_VERSION
    assert env["type"] == "polynomial" and env["units"] == {"x": "hz", "y": "dph"}
    assert env["training_data_sha256"] == "ab" * 32 and "numpy" in env["dependencies"]
    back = load_model(p)
    xs = np.linspace(-1, 3, 7)
    np.testing.assert_array_equal(back.predict(xs), m.predict(xs))
    assert not list(tmp_path.glob(".*.tmp"))


def test_tampered_type_tag_is_refused(tmp_path):
    p = save_model(_model(), tmp_path / "m.json")
    env = json.loads(p.read_text())
    env["type"] = "os.system"
    p.write_text(json.dumps(env))
    with pytest.raises(InputError, match="unknown model type 'os.system'"):
        load_model(p)


def test_newer_format_is_refused(tmp_path):
    p = save_model(_model(), tmp_path / "m.json")
    env = json.loads(p.read_text())
    env["format_version"] = FORMAT_VERSION + 1
    p.write_text(json.dumps(env))
    with pytest.raises(InputError, match="newer"):
        load_model(p)


def test_wrong_expected_type_and_bad_payload(tmp_path):
    p = save_model(_model(), tmp_path / "m.json")
    with pytest.raises(InputError, match="expected 'rbf'"):
        load_model(p, expected_type="rbf")
    env = json.loads(p.read_text())
    del env["payload"]["coef"]
    p.write_text(json.dumps(env))
    with pytest.raises(InputError, match="polynomial model payload: lacks 'coef'"):
        load_model(p)
    p.write_text("{not json")
    with pytest.raises(InputError, match="not valid JSON"):
        load_model(p)


def test_released_format_fixture_still_loads():
    """tests/data/models/polynomial-v1.json was written by format version 1."""
    from pathlib import Path

    fixture = Path(__file__).parent.parent / "data" / "models" / "polynomial-v1.json"
    m = load_model(fixture)
    np.testing.assert_allclose(m.predict([0.0, 1.0, 2.0]), [1.0, 2.5, 1.0], atol=1e-9)


# ------------------------------------------------------------------ hostile files

FIXTURES = sorted((Path(__file__).resolve().parents[1] / "data" / "models").glob("*.json"))


@pytest.mark.parametrize("token", ["NaN", "Infinity", "-Infinity", "1e999", "-1e400"])
def test_non_finite_numbers_are_refused(tmp_path, token):
    text = save_model(_model(), tmp_path / "m.json").read_text()
    env = json.loads(text)
    env["payload"]["coef"][0] = 12345.5
    bad = json.dumps(env).replace("12345.5", token)
    (tmp_path / "m.json").write_text(bad)
    with pytest.raises(InputError, match=r"polynomial model payload\.coef\[0\]: .* is not "
                                         "finite"):
        load_model(tmp_path / "m.json")


def test_nesting_size_and_huge_integers_are_bounded(tmp_path):
    p = tmp_path / "m.json"
    for text, msg in [("[" * 1000 + "]" * 1000, "nested"),
                      ('{"a": ' + "[" * 40 + "]" * 40 + "}", "nested more than"),
                      ('{"format": "inertialab-model", "n": ' + "9" * 5000 + "}", "digits"),
                      ("\ufeff{}".encode().decode("latin-1"), "UTF-8|not an"),
                      ]:
        p.write_text(text, encoding="latin-1" if text.startswith("\u00ef") else "utf-8")
        with pytest.raises(InputError, match=msg):
            load_model(p)
    p.write_bytes("{}".encode("utf-16"))
    with pytest.raises(InputError, match="not UTF-8"):
        load_model(p)
    with pytest.raises(InputError, match="not a regular file"):
        load_model(tmp_path)
    with pytest.raises(InputError, match="not a regular file"):
        load_model("/dev/null")


def _leaves(obj, path=()):
    if isinstance(obj, dict):
        for k, v in obj.items():
            yield from _leaves(v, (*path, k))
    elif isinstance(obj, list) and obj:
        yield from _leaves(obj[0], (*path, 0))
        yield path, obj
    else:
        yield path, obj


def _set(obj, path, value):
    for k in path[:-1]:
        obj = obj[k]
    obj[path[-1]] = value


@pytest.mark.parametrize("fixture", FIXTURES, ids=lambda p: p.stem)
def test_wrong_typed_payloads_are_one_line_input_errors(fixture, tmp_path):
    """Every leaf of every fixture's payload replaced by a value of the wrong type, a
    non-finite-looking string, an empty list and a nested object: the model loads (the
    key is optional) or the load is one InputError line; never another exception."""
    env = json.loads(fixture.read_text())
    paths = [p for p, _ in _leaves(env["payload"]) if p]
    p = tmp_path / "m.json"
    refused = 0
    for path in paths:
        for value in ("x", None, [], {"a": 1}, True, -1e308):
            e = json.loads(json.dumps(env))
            _set(e["payload"], path, value)
            p.write_text(json.dumps(e))
            try:
                load_model(p)
            except InputError as exc:
                assert "\n" not in str(exc)
                refused += 1
    assert refused >= len(paths)  # most edits are refused, one message each


def test_schemas_accept_what_fits_write(tmp_path):
    """No schema is stricter than its class's to_dict: models fitted with defaults, and
    on constant targets (spans of 0, no NAR members, no neuron limit), load back."""
    import warnings

    from inertialab.learn.anfis import ANFIS
    from inertialab.learn.mlp_lm import MLPRegressorLM
    from inertialab.learn.nar import NARForecaster
    from inertialab.learn.rbf import RBFNetwork

    x = np.linspace(0, 1, 40)
    X2 = np.c_[x, x**2]
    cases = [(RBFNetwork(), (x[:, None], np.sin(x))),
             (RBFNetwork(), (x[:, None], np.ones_like(x))),
             (ANFIS(), (X2, np.sin(x))),
             (MLPRegressorLM(hidden=3, max_epochs=5), (np.c_[x, np.ones_like(x)],
                                                        np.ones_like(x))),
             (NARForecaster(order=2, restarts=1), (np.sin(np.arange(60) / 5),)),
             (NARForecaster(order=2, restarts=1), (np.ones(60),))]
    for i, (est, args) in enumerate(cases):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            model = est.fit(*args)
        back = load_model(save_model(model, tmp_path / f"m{i}.json"))
        assert type(back) is type(model)
