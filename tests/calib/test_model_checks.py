"""Models re-checked at their training conditions on apply (inertialab.calib.model_checks):
hand-edited files that pass the payload schema but would write garbage are refused unless
forced; every fixture and a fresh fit pass."""

import json
from pathlib import Path

import numpy as np
import pytest

from inertialab.calib import load_model
from inertialab.calib.model_checks import (
    refuse_or_flag,
    thermal_findings,
    triaxial_findings,
)
from inertialab.errors import DataQualityWarning, InputError

MODELS = Path(__file__).resolve().parents[1] / "data" / "models"


def _edited(kind: str, tmp_path, edit):
    env = json.loads((MODELS / f"{kind}-v1.json").read_text())
    edit(env["payload"])
    p = tmp_path / "m.json"
    p.write_text(json.dumps(env))
    return load_model(p)


@pytest.mark.parametrize("name", ["thermal-compensation", "triaxial-calibration",
                                  "triaxial-calibration-ferraris", "ferraris-calibration"])
def test_fixtures_pass(name):
    m = load_model(MODELS / f"{name}-v1.json")
    check = thermal_findings if name.startswith("thermal") else triaxial_findings
    assert check(m) == []


def test_thermal_output_shifted_by_7_g_is_found(tmp_path):
    m = _edited("thermal-compensation", tmp_path,
                lambda p: p["regressor"].__setitem__("y_lo", p["regressor"]["y_lo"] + 7000.0))
    found = thermal_findings(m)
    assert len(found) == 1 and "7005 mV" in found[0] and "exceed the raw drift" in found[0]


def test_thermal_limit_is_twice_the_stored_raw_maximum(tmp_path):
    m = load_model(MODELS / "thermal-compensation-v1.json")
    T, N = np.meshgrid(np.linspace(*m.t_range_c, 23), np.linspace(*m.n_range_mv, 25))
    worst = float(np.abs(m.predict_nc(T.ravel(), N.ravel()) - N.ravel()).max())
    m.raw_drift_max_mv = worst / 2 * 1.01  # the limit just above the largest correction
    assert thermal_findings(m) == []
    m.raw_drift_max_mv = worst / 2 * 0.99
    assert "twice the largest raw error" in thermal_findings(m)[0]


def test_triaxial_matrix_scaled_by_1e6_is_found(tmp_path):
    m = _edited("triaxial-calibration", tmp_path, lambda p: p.__setitem__(
        "correction_matrix", [[v * 1e6 for v in r] for r in p["correction_matrix"]]))
    assert "counts per g" in triaxial_findings(m)[0]


def test_physical_unit_matrix_scaled_is_found(tmp_path):
    m = _edited("ferraris-calibration", tmp_path, lambda p: p.__setitem__(
        "correction_matrix", [[v * 10 for v in r] for r in p["correction_matrix"]]))
    assert "factor of up to 10" in triaxial_findings(m)[0]


def test_stored_rest_poses_are_checked_against_gravity(tmp_path):
    m = load_model(MODELS / "triaxial-calibration-v1.json")
    C, o, g = m.correction_matrix, m.offset, m.g_local
    u = np.array([[0, 0, 1.0], [1.0, 0, 0], [0, -1.0, 0]])
    m.rest_raw = (np.linalg.solve(C, (g * u).T).T + o)  # calibrate to exactly g
    assert triaxial_findings(m) == []
    m.rest_raw[1] = np.linalg.solve(C, 1.03 * g * u[1]) + o  # 0.03 g off: beyond the gate
    assert "training pose 2" in triaxial_findings(m)[0]


def test_refused_unless_forced_then_flagged():
    with pytest.raises(InputError, match="force"):
        refuse_or_flag(["x"], "thermal", force=False, path="m.json")
    with pytest.warns(DataQualityWarning, match="applied anyway"):
        assert refuse_or_flag(["x"], "thermal", force=True) == ["forced: x"]
    assert refuse_or_flag([], "thermal", force=False) == []
