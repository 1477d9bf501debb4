"""Model files of format version 1 (tests/data/models, written before the commands' Configs
became the estimators' settings) load and apply through today's workflows with the output
the code of that time gave: the compensated numbers below were computed with it on the
same seeded virtual-lab records (tests/data/README.md)."""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np
import pytest

from inertialab.calib.model_types import load_model
from inertialab.errors import ExtrapolationWarning
from inertialab.io import read_record, write_record

MODELS = Path(__file__).parents[1] / "data" / "models"


def test_thermal_v1_model_applies_as_written(tmp_path):
    from inertialab.sim.thermal_tumble import simulate
    from inertialab.workflows import thermal

    run = simulate("paper", 0, 1, seed=5)
    write_record(run.frame, tmp_path / "t.csv")
    model = load_model(MODELS / "thermal-compensation-v1.json",
                       expected_type="thermal-compensation")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ExtrapolationWarning)
        res = thermal.run_apply(model, read_record(tmp_path / "t.csv", "thermal_tumble"),
                                thermal.ApplyConfig(), out=tmp_path / "o.csv")
    f = res.res.frame
    np.testing.assert_allclose(f["comp_output_mv"].to_numpy()[[0, 100, 500, -1]],
                               [-1.987160637066836, 894.7341502324125, -898.698407969119,
                                -269.9760590610746], rtol=1e-9)
    assert np.bincount(f["status"].to_numpy()).tolist() == [529, 22, 0, 1]
    d = res.to_json()["drift"]
    assert d["raw_max_drift_ug"] == pytest.approx(5250.781462008965, rel=1e-9)
    assert d["comp_max_drift_ug"] == pytest.approx(35.27183844564963, rel=1e-9)


def test_drift_v1_model_applies_as_written(tmp_path):
    from inertialab.sim.drift import simulate_storage_batch
    from inertialab.workflows import drift

    b = simulate_storage_batch(1, 70, "paper", rng=np.random.SeedSequence(11))
    write_record(b.frame, tmp_path / "d.csv", b.meta)
    model = load_model(MODELS / "storage-drift-v1.json", expected_type="storage-drift")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        res = drift.run_apply(model, read_record(tmp_path / "d.csv", "storage_drift"))
    s = res.summary["QA001"]["bias"]
    assert s["n"] == 10 and s["unit"] == "ug"
    assert s["rmse_compensated"] == pytest.approx(251.43573468335538, rel=1e-9)
    assert s["rmse_uncompensated"] == pytest.approx(252.60438518525385, rel=1e-9)
    last = res.frame.iloc[-1]
    assert (int(last["day"]), int(last["forecast_step"])) == (69, 10)
    assert last["bias_hat_ug"] == pytest.approx(-138.96430880223107, rel=1e-9)
    assert last["bias_residual_ug"] == pytest.approx(307.5754641403037, rel=1e-9)


def test_vibration_v1_model_applies_as_written(tmp_path):
    from inertialab.sim.fog_vibration import simulate
    from inertialab.workflows import vibration

    s = simulate("fixed", 2, p1_s=60.0, p3_s=60.0, p2_fixed_s=60.0)
    write_record(s.record, tmp_path / "v.csv", s.meta)
    model = load_model(MODELS / "vibration-compensation-v1.json",
                       expected_type="vibration-compensation")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ExtrapolationWarning)  # the 500-Hz run, fitted to 496
        res = vibration.run_apply(model, read_record(tmp_path / "v.csv", "gyro_log"),
                                  vibration.ApplyConfig(), out=tmp_path / "vo.csv")
    r = res.to_json()["residual"]
    assert r["delta_b"] == pytest.approx(-0.4442502329891971, rel=1e-9)
    assert r["mean"]["P2"] == pytest.approx(-0.2801967232107106, rel=1e-9)
    assert r["edge_off"] == pytest.approx(11.38916589001579, rel=1e-9)
    np.testing.assert_allclose(res.res.data["rate_comp_dph"].to_numpy()[[0, 1000, -1]],
                               [-0.6852880398552, 1.9287325210433495, -0.06054043254033178],
                               rtol=1e-9)
