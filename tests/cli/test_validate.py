"""``inertialab validate`` through the shared reading options (issue 16 item 1)."""

import json

import numpy as np

from tests.helpers import run_inprocess


def test_validate_takes_every_reading_option(tmp_path, capsys):
    p = tmp_path / "vendor.txt"
    rows = "".join(f"{1000 + 5 * i} {0.1 * i:.3f} {9.8:.3f}\n" for i in range(40))
    p.write_text("Logger export v2\nStamp GyroZ AccZ\n" + rows)
    code, out, err = run_inprocess(capsys, "validate", p, "--kind", "gyro_log", "--json",
                                   "--map", "gz_dps=GyroZ:dps,az_mps2=AccZ", "--time-col", "Stamp",
                                   "--time-unit", "ms")
    assert code in (0, None), err
    obj = json.loads(out)
    assert obj["rows"] == 40 and obj["column_units"] == {"gz_dps": "dps", "az_mps2": "mps2"}
    ts = obj["timestamps"]
    assert ts["mean_rate_hz"] == 200.0 and ts["n_gaps"] == 0 and ts["n_repeated"] == 0
    assert obj["settings"]["time_column"] == "Stamp"


def test_validate_headerless_with_rate_and_unit(tmp_path, capsys):
    p = tmp_path / "h.csv"
    x = np.random.default_rng(2).normal(size=30)
    p.write_text("".join(f"{v:.6f},{-v:.6f}\n" for v in x))
    code, out, err = run_inprocess(capsys, "validate", p, "--kind", "gyro_log", "--json",
                                   "--map", "rate=col2", "--rate", "50", "--unit", "dph")
    assert code in (0, None), err
    obj = json.loads(out)
    assert obj["meta"]["fs_hz"] == 50.0 and "rate_dph" in obj["columns"]


def test_validate_missing_column_lists_columns_and_suggests_the_map(tmp_path, capsys):
    p = tmp_path / "v.csv"
    p.write_text("Time;Gyro X;Gyro Y\ns;deg/s;deg/s\n0;1,5;2\n0,01;1,25;2\n")
    code, out, err = run_inprocess(capsys, "validate", p, "--kind", "gyro_log")
    assert code == 2 and out == ""
    line = err.strip()
    assert "\n" not in line and "Gyro X [deg/s]" in line
    assert "t_s=Time,gx_rps=Gyro X:dps" in line
    assert "--map t_s=" in line or "argument 'column_map' t_s=" in line  # main.py flags it
