"""Every model class checks its own payload in ``from_dict`` (the schemas of
io/model_schemas.py, applied by the class, not only by the loader): each v1 model file
under tests/data/models still loads, and the same payload with one field corrupted is
refused, by ``from_dict`` in memory and by ``load_model`` from a file, with one line
naming the model and the field."""

import copy
import json
from pathlib import Path

import numpy as np
import pytest

from inertialab.calib.model_types import TYPES, load_model
from inertialab.errors import InputError
from inertialab.io.model_schemas import model_name

MODELS = Path(__file__).resolve().parents[1] / "data" / "models"

#: v1 file -> (key path in the payload, a corrupted value, what the message says).
CORRUPT = {
    "polynomial-v1.json": (("coef", 0), "x", "payload.coef[0]: must be a number, got str"),
    "rbf-v1.json": (("spread",), -1.0, "payload.spread: must be > 0, got -1.0"),
    "anfis-v1.json": (("x_span", 1), 0.0, "payload.x_span[1]: must be > 0, got 0.0"),
    "noise-terms-v1.json": (("rate_hz",), -100.0, "payload.rate_hz: must be > 0, got -100.0"),
    "vibration-compensation-v1.json": (("rbf", "weights"), "w",
                                       "payload.rbf.weights: must be a list, got str"),
    "thermal-compensation-v1.json": (("ref", "k1"), "one",
                                     "payload.ref.k1: must be a number, got str"),
    "thermal-imu-v1.json": (("sensors", 0, "axes", 0, "tau_s"), -5.0,
                            "payload.sensors[0].axes[0].tau_s: must be in [0, 3600], got -5.0"),
    "triaxial-calibration-v1.json": (("correction_matrix", 2), [1.0, 0.0],
                                     "payload.correction_matrix[2]: must have 3 entries, got 2"),
    "triaxial-calibration-ferraris-v1.json": (("offset",), [0.0, 0.0],
                                              "payload.offset: must have 3 entries, got 2"),
    "ferraris-calibration-v1.json": (("gyro", "g_sensitivity", 0, 0), None,
                                     "payload.gyro.g_sensitivity[0][0]: must be a number, "
                                     "got NoneType"),
    "dual-calibration-v1.json": (("s_a",), 5, "payload.s_a: must be in [-1, 1], got 5"),
    "storage-drift-v1.json": (("entries", "QA001", "bias", "nar", "order"), 0,
                              "payload.entries.QA001.bias.nar.order: must be in [1, 10000], "
                              "got 0"),
}


def _set(d, keys, value):
    for k in keys[:-1]:
        d = d[k]
    d[keys[-1]] = value


def test_every_v1_model_file_is_listed_and_loads():
    files = sorted(p.name for p in MODELS.glob("*-v1.json"))
    assert files == sorted(CORRUPT)
    for name in files:
        assert load_model(MODELS / name) is not None


@pytest.mark.parametrize("name", sorted(CORRUPT))
def test_a_corrupted_payload_is_refused_by_the_class_naming_the_field(name, tmp_path):
    env = json.loads((MODELS / name).read_text())
    keys, bad, message = CORRUPT[name]
    payload = copy.deepcopy(env["payload"])
    _set(payload, keys, bad)
    cls = TYPES[env["type"]]
    with pytest.raises(InputError) as caught:
        cls.from_dict(payload)
    text = str(caught.value)
    assert "\n" not in text and text == f"{model_name(env['type'])} {message}", text
    path = tmp_path / name
    path.write_text(json.dumps({**env, "payload": payload}))
    with pytest.raises(InputError) as from_file:
        load_model(path)
    assert str(from_file.value).count("\n") == 0 and message in str(from_file.value)
    assert from_file.value.path is not None and Path(from_file.value.path).name == name


def test_an_in_memory_payload_is_checked_as_a_file_would_hold_it():
    """``from_dict(to_dict())`` takes numpy arrays; a NaN where a number must be is named
    as not finite (a file would hold null there)."""
    from inertialab.learn.poly import PolynomialRegressor

    x = np.c_[np.arange(6.0)]
    d = PolynomialRegressor(degree=2).fit(x, x[:, 0] ** 2).to_dict()
    back = PolynomialRegressor.from_dict({k: np.asarray(v) if isinstance(v, list) else v
                                          for k, v in d.items()})
    assert np.allclose(back.predict(np.c_[[3.0]]), 9.0)
    d["x_span"] = np.array([np.nan])
    with pytest.raises(InputError, match=r"^polynomial model payload\.x_span\[0\]: must be "
                                         r"finite, got NaN or infinity$"):
        PolynomialRegressor.from_dict(d)


def test_the_nested_learners_check_their_own_payloads():
    """NAR (inside a drift model) and MLP-LM (inside a thermal model) refuse a corrupted
    payload themselves."""
    from inertialab.learn.mlp_lm import MLPRegressorLM
    from inertialab.learn.nar import NARForecaster

    drift = json.loads((MODELS / "storage-drift-v1.json").read_text())["payload"]
    nar = copy.deepcopy(drift["entries"]["QA001"]["bias"]["nar"])
    assert NARForecaster.from_dict(nar).order_ == nar["order"]
    nar["tail"] = "x"
    with pytest.raises(InputError, match=r"^nar model payload\.tail: must be a list, got str$"):
        NARForecaster.from_dict(nar)
    x = np.linspace(0.0, 1.0, 12)[:, None]
    d = MLPRegressorLM(hidden=2, max_epochs=20, rng=0).fit(x, x[:, 0] ** 2).to_dict()
    d["theta"] = []
    with pytest.raises(InputError, match=r"^mlp-lm model payload\.theta: must have at least 1 "):
        MLPRegressorLM.from_dict(d)
