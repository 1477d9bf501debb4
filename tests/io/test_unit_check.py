"""Units that cannot be silently wrong: a mapped column without a unit is an error
naming it and the units it could be, unless the data decide (an accelerometer triad's
norm is gravity; a gyro's quantisation step); an accelerometer whose magnitude
contradicts its declared unit is refused with the unit it looks like."""

import json
import math

import numpy as np
import pandas as pd
import pytest
from tests.helpers import run_inprocess

from inertialab.errors import DataQualityWarning, InputError
from inertialab.io import read_record
from inertialab.io.mapping import ReadOptions
from inertialab.io.unit_check import quantisation_step


def _static_imu(n=3000, seed=0):
    """A static IMU in the ADIS16405 style: gyro codes of 0.05 deg/s, accel in g."""
    rng = np.random.default_rng(seed)
    gyro_dps = np.round((rng.normal(0.0, 0.3, (n, 3)) + [0.1, -0.2, 0.05]) / 0.05) * 0.05
    acc_g = rng.normal(0.0, 0.003, (n, 3)) + [0.01, -0.02, -1.02]
    return np.arange(n) / 100.0, gyro_dps, acc_g


def _csv(tmp_path, t, gyro, acc, name="adis.csv"):
    p = tmp_path / name
    pd.DataFrame({"Time": t, "Gyro. X": gyro[:, 0], "Gyro. Y": gyro[:, 1],
                  "Gyro. Z": gyro[:, 2], "Accel. X": acc[:, 0], "Accel. Y": acc[:, 1],
                  "Accel. Z": acc[:, 2]}).to_csv(p, index=False, float_format="%.6f")
    return p


MAP = ("t_s=Time,gx_rps=Gyro. X,gy_rps=Gyro. Y,gz_rps=Gyro. Z,"
       "ax_mps2=Accel. X,ay_mps2=Accel. Y,az_mps2=Accel. Z")


def test_gyro_step_of_two_units_asks_and_g_accel_is_inferred(tmp_path):
    t, gyro, acc = _static_imu()
    p = _csv(tmp_path, t, gyro, acc)
    # a 0.05 step is an ADIS16405's in deg/s and a fibre-optic gyro's in deg/h: the data
    # cannot tell which, so the error names both
    with pytest.raises(InputError, match=r"column 'Gyro. X': .*quantisation step 0.05 is a "
                                         r"gyro's step in deg/s and in deg/h alike"):
        read_record(p, "gyro_log", column_map=MAP)
    declared = MAP.replace("Gyro. X", "Gyro. X:dps").replace("Gyro. Y", "Gyro. Y:dps") \
        .replace("Gyro. Z", "Gyro. Z:dps")
    with pytest.warns(DataQualityWarning) as w:
        rec = read_record(p, "gyro_log", column_map=declared)
    assert "read in g" in " ".join(str(x.message) for x in w)
    # the 57x error is gone: the deg/s values arrive in rad/s
    raw = pd.read_csv(p)
    np.testing.assert_allclose(rec.data["gx_rps"], raw["Gyro. X"] * math.pi / 180, rtol=1e-12)
    np.testing.assert_allclose(rec.data["az_mps2"], raw["Accel. Z"] * 9.80665, rtol=1e-12)
    inf = rec.meta["inferred_units"]
    assert "gx_rps" not in inf and inf["ax_mps2"]["unit"] == "g"


def test_a_step_of_one_unit_alone_decides(tmp_path):
    # 3e-5 rad/s (a navigation-grade MEMS) is a step in rad/s only; 2 deg/h in deg/h only
    rng = np.random.default_rng(4)
    for q, unit in ((3e-5, "rps"), (2.0, "dph")):
        y = np.round(rng.normal(0, 40 * q, 3000) / q) * q
        p = tmp_path / f"g{unit}.csv"
        pd.DataFrame({"t_s": np.arange(3000) / 100.0, "G": y}).to_csv(p, index=False)
        with pytest.warns(DataQualityWarning, match=f"read in {unit}"):
            rec = read_record(p, "gyro_log", column_map="t_s=t_s,gx_rps=G")
        assert rec.meta["inferred_units"]["gx_rps"]["unit"] == unit


def test_undecidable_unit_is_an_error_naming_the_column_and_the_candidates(tmp_path):
    t, gyro, acc = _static_imu()
    gyro = gyro + np.random.default_rng(1).normal(0, 1e-3, gyro.shape)  # floats: no grid
    p = _csv(tmp_path, t, gyro, acc)
    p2 = tmp_path / "f.csv"
    pd.read_csv(p).to_csv(p2, index=False)  # full float precision
    with pytest.raises(InputError, match=r"f.csv: column 'Gyro. X': mapped to 'gx_rps' without "
                                         r"a unit, .*gx_rps=Gyro. X:rps\|dps\|dph"):
        read_record(p2, "gyro_log", column_map=MAP)
    # a declared unit (in the map or the unit option) is taken as declared
    rec = read_record(p2, "gyro_log", options=ReadOptions.from_cli(
        MAP.replace("Gyro. X", "Gyro. X:dps").replace("Gyro. Y", "Gyro. Y:dps")
        .replace("Gyro. Z", "Gyro. Z:dps"), unit="g"))
    assert "inferred_units" not in rec.meta


def test_accelerometer_contradicting_its_declared_unit_is_refused(tmp_path):
    t, _, acc = _static_imu()
    p = tmp_path / "lab.csv"
    pd.DataFrame({"t_s": t, "ax_mps2": acc[:, 0], "ay_mps2": acc[:, 1],
                  "az_mps2": acc[:, 2]}).to_csv(p, index=False)
    with pytest.raises(InputError, match=r"lab.csv: column 'ax_mps2, ay_mps2, az_mps2': the "
                                         r"accelerometer reads a median \|a\| of 1.02 m/s\^2, "
                                         r"which is gravity in g: the columns look like g"):
        read_record(p, "gyro_log")
    p2 = tmp_path / "lab2.csv"
    pd.DataFrame({"t_s": t, "ax_g": 9.80665 * acc[:, 0], "ay_g": 9.80665 * acc[:, 1],
                  "az_g": 9.80665 * acc[:, 2]}).to_csv(p2, index=False)
    with pytest.raises(InputError, match=r"look like mps2, not g"):
        read_record(p2, "gyro_log")


def test_quantisation_step_found_and_decimal_rounding_ignored():
    x = np.round(np.random.default_rng(0).normal(0, 1, 5000) / 0.0153) * 0.0153
    assert quantisation_step(x) == pytest.approx(0.0153, rel=1e-9)
    assert quantisation_step(np.round(np.random.default_rng(1).normal(0, 1, 5000), 6)) is None


def test_validate_json_records_the_inferred_unit(tmp_path, capsys):
    t, gyro, acc = _static_imu()
    p = _csv(tmp_path, t, gyro, acc)
    code, out, err = run_inprocess(capsys, "validate", p, "--kind", "gyro_log", "--json",
                                   "--map", MAP.replace("Gyro. X", "Gyro. X:dps")
                                   .replace("Gyro. Y", "Gyro. Y:dps")
                                   .replace("Gyro. Z", "Gyro. Z:dps"))
    assert code in (0, None), err
    obj = json.loads(out)
    assert obj["meta"]["inferred_units"]["az_mps2"]["unit"] == "g"
    assert any("read in g" in w for w in obj["warnings"])


def test_sidecar_units_declare_the_source_unit_of_a_mapped_column(tmp_path):
    from inertialab.io import write_record

    rng = np.random.default_rng(3)
    g = rng.normal(0, 1.0, 100)  # floats: the data decide nothing
    p = write_record(pd.DataFrame({"t_s": np.arange(100) / 10.0, "GyroX": g}),
                     tmp_path / "s.csv", {"units": {"gx": "dps"}})
    rec = read_record(p, "gyro_log", column_map="gx_rps=GyroX")
    np.testing.assert_allclose(rec.data["gx_rps"], pd.read_csv(p)["GyroX"] * math.pi / 180,
                               rtol=1e-12)
    assert "inferred_units" not in rec.meta


def test_an_angle_column_must_declare_its_unit(tmp_path):
    p = tmp_path / "a.csv"
    p.write_text("t,dth\n" + "".join(f"{i / 10},{0.01 * i}\n" for i in range(20)))
    with pytest.raises(InputError, match=r"'dth': mapped to 'dtheta_arcsec' without a unit, and "
                                         r"the unit of an angle cannot be told .*"
                                         r"arcsec\|deg\|rad"):
        read_record(p, "gyro_log", column_map="t_s=t,dtheta_arcsec=dth")


def test_declared_gyro_unit_contradicted_by_its_step_is_refused(tmp_path):
    # an ADIS16405's 0.05 deg/s codes declared in rad/s (57x): the step is no rad/s
    # gyro's, and the error names the column and the units it looks like
    t, gyro, acc = _static_imu()
    p = tmp_path / "adis_rps.csv"
    pd.DataFrame({"t_s": t, "gx_rps": gyro[:, 0], "ax_g": acc[:, 0], "ay_g": acc[:, 1],
                  "az_g": acc[:, 2]}).to_csv(p, index=False, float_format="%.6f")
    with pytest.raises(InputError, match=r"column 'gx_rps': its values step by 0.05 rad/s, "
                                         r"no gyro's quantisation step in rad/s .* looks like "
                                         r"deg/s or deg/h"):
        read_record(p, "gyro_log")


def test_raw_counts_declared_as_si_are_refused(tmp_path):
    # imu_tk-style unsigned counts about 33,000 declared m/s^2: |a| of 6,000 g
    rng = np.random.default_rng(2)
    n = 500
    acc = np.round(32768 + np.array([0, 0, 6000]) + rng.normal(0, 20, (n, 3)))
    p = tmp_path / "counts.csv"
    pd.DataFrame({"t_s": np.arange(n) / 100.0, "ax_mps2": acc[:, 0], "ay_mps2": acc[:, 1],
                  "az_mps2": acc[:, 2]}).to_csv(p, index=False)
    with pytest.raises(InputError, match=r"ax_mps2, ay_mps2, az_mps2.*no accelerometer reads "
                                         r"that; the values are whole numbers, like raw ADC "
                                         r"counts \(declare them lsb"):
        read_record(p, "gyro_log")
