"""Model files: round trip, atomic write, refusal of tampered tags and newer formats."""

import json

import numpy as np
import pytest

from inertialab import InputError
from inertialab.io import load_model, read_envelope, save_model
from inertialab.io.modelfile import FORMAT_VERSION
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
    with pytest.raises(InputError, match="payload is invalid"):
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
