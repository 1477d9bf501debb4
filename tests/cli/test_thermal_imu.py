"""CLI: simulate thermal-imu, thermal fit --imu with PX4 and ArduPilot exports, thermal
apply of a thermal-imu model, and the one-line refusals."""

from __future__ import annotations

import json

import numpy as np
import pandas as pd
import pytest

from tests.helpers import run_inprocess as run


@pytest.fixture(scope="module")
def fitted(tmp_path_factory):
    pytest.importorskip("pyulog")
    from inertialab.cli.main import main

    d = tmp_path_factory.mktemp("timu")
    for args in (["simulate", "thermal-imu", "--rate", "0.25", "--out", d / "cal.csv"],
                 ["simulate", "thermal-imu", "--rate", "0.25", "--ramp", "holdout", "--seed", "9",
                  "--out", d / "hold.csv"],
                 ["thermal", "fit", d / "cal.ulg", "--imu", "--out", d / "fit", "--quiet",
                  "--export", "px4", d / "tc.params", "--export", "ardupilot", d / "t.param"]):
        with pytest.raises(SystemExit) as ex:
            main([str(a) for a in args])
        assert ex.value.code == 0, args
    return d


def test_fit_writes_model_report_figures_and_both_files(fitted):
    d = fitted
    env = json.loads((d / "fit" / "model.json").read_text())
    assert env["type"] == "thermal-imu"
    rep = pd.read_csv(d / "fit" / "report.csv")
    assert len(rep) == 12 and set(rep["sensor"]) == {"accel", "gyro"}
    for col in ("order", "tau_s", "rms_in", "rms_cv", "span_c", "samples_per_c", "hysteresis"):
        assert rep[col].notna().all(), col
    assert sorted(p.name for p in (d / "fit").glob("thermal_imu_*.png")) == [
        "thermal_imu_accel0.png", "thermal_imu_accel1.png", "thermal_imu_gyro0.png",
        "thermal_imu_gyro1.png"]
    assert "TC_G1_X3_2" in (d / "tc.params").read_text()
    assert "INS_TCAL2_GYR3_Z" in (d / "t.param").read_text()
    res = json.loads((d / "fit" / "result.json").read_text())
    assert len(res["exports"]) == 2


def test_apply_writes_the_six_columns_and_warns_when_clamping(fitted, capsys, tmp_path):
    d = fitted
    code, out, err = run(capsys, "thermal", "apply", d / "fit" / "model.json", d / "hold.csv",
                         "--out", tmp_path / "c.csv")
    assert code == 0, err
    c = pd.read_csv(tmp_path / "c.csv")
    cols = ["ax_mps2", "ay_mps2", "az_mps2", "gx_rps", "gy_rps", "gz_rps"]
    assert set(cols) <= set(c.columns)
    raw = pd.read_csv(d / "hold.csv")
    g = raw[raw["instance"] == 0]
    corr = c[c["instance"] == 0]["gx_rps"].to_numpy()
    # the corrected gyro is the rate (0) plus noise and random walk: its drift is gone
    assert np.std(corr - (g["gx_rps"] - g["true_off_gx"]).to_numpy()) < \
        0.1 * np.std(g["true_off_gx"])
    hot = raw.copy()
    hot["temp_c"] += 15.0
    hot.to_csv(tmp_path / "hot.csv", index=False)
    code, out, err = run(capsys, "thermal", "apply", d / "fit" / "model.json", tmp_path / "hot.csv",
                         "--out", tmp_path / "h.csv")
    assert code == 0 and "outside the calibrated temperature range" in err


def test_refusals_are_one_line_naming_the_instance(fitted, capsys, tmp_path):
    raw = pd.read_csv(fitted / "cal.csv")
    bad = raw.copy()
    bad.loc[bad.index[bad["instance"] == 1][3], "temp_c"] = np.nan
    bad.to_csv(tmp_path / "nan.csv", index=False)
    code, _, err = run(capsys, "thermal", "fit", tmp_path / "nan.csv", "--imu", "--out",
                       tmp_path / "o1")
    assert code == 2 and "accel 1" in err and "NaN" in err and len(err.strip().splitlines()) == 1
    narrow = raw[(raw["temp_c"] > 20) & (raw["temp_c"] < 27)]
    narrow.to_csv(tmp_path / "narrow.csv", index=False)
    code, _, err = run(capsys, "thermal", "fit", tmp_path / "narrow.csv", "--imu", "--out",
                       tmp_path / "o2")
    assert code == 2 and "accel 0" in err and "spans only" in err
    assert not (tmp_path / "o2" / "model.json").exists()
    code, _, err = run(capsys, "thermal", "fit", fitted / "cal.csv", "--imu", "--out",
                       tmp_path / "o3", "--export", "betaflight", tmp_path / "x")
    assert code == 2 and "px4, ardupilot" in err


def test_a_stray_argument_is_refused(fitted, capsys, tmp_path):
    code, _, err = run(capsys, "thermal", "fit", fitted / "cal.csv", "extra.txt", "--imu",
                       "--out", tmp_path / "o")
    assert code == 2 and "unexpected argument 'extra.txt'" in err


def test_method_names_follow_the_imu_switch(fitted, capsys, tmp_path):
    # --imu takes the drone fit's methods (poly is its default, given here explicitly);
    # the ANFIS study without --imu refuses poly, naming its own methods
    code, out, err = run(capsys, "thermal", "fit", fitted / "cal.csv", "--imu", "--method",
                         "poly", "--json")
    assert code == 0, err
    assert json.loads(out)["settings"]["method"] == "poly"
    code, _, err = run(capsys, "thermal", "fit", fitted / "cal.csv", "--method", "poly")
    assert code == 2 and "--method" in err and "iafsa-scm-anfis" in err
    code, _, err = run(capsys, "thermal", "fit", fitted / "cal.csv", "--imu", "--method",
                       "fis")
    assert code == 2 and "--method" in err and "poly" in err
