"""``inertialab validate`` through the shared reading options, and validate = analyse."""

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


# ------------------------------------------------------------ validate = analyse

def _err(capsys, *args):
    code, out, err = run_inprocess(capsys, *args)
    assert code == 2, (code, out, err)
    lines = err.strip().splitlines()
    assert len(lines) == 1, err
    return lines[0]


def test_no_time_column_same_error_from_validate_and_allan(tmp_path, capsys):
    p = tmp_path / "no_time.csv"
    p.write_text("rate_dph\n" + "".join(f"{v:.4f}\n" for v in
                                        np.random.default_rng(0).normal(size=50)))
    v = _err(capsys, "validate", p, "--kind", "gyro_log")
    a = _err(capsys, "allan", p)
    assert v == a == f"error: {p}: needs a t_s column or --rate"
    assert _err(capsys, "validate", p, "--kind", "allan") == a
    assert _err(capsys, "allan", p, "--imu") == _err(capsys, "validate", p, "--kind", "imu")
    # and the rate option makes both read it
    code, _, err = run_inprocess(capsys, "validate", p, "--kind", "allan", "--rate", "10")
    assert code in (0, None), err


def test_ferraris_session_without_time_column_names_the_real_cause(tmp_path, capsys):
    import pandas as pd

    src = tmp_path / "session.csv"
    assert run_inprocess(capsys, "simulate", "ferraris-session", "--seed", "3", "--out",
                         src)[0] in (0, None)
    df = pd.read_csv(src, comment="#")
    p = tmp_path / "no_time.csv"
    df.drop(columns=["t_s"]).to_csv(p, index=False)
    f = _err(capsys, "triaxial", "ferraris", p)
    v = _err(capsys, "validate", p, "--kind", "ferraris")
    assert f == v and "needs a t_s column or --rate" in f and "pos_id" not in f
    # without the gyro the session is refused by both, naming the gyro
    df.drop(columns=[c for c in df.columns if c.startswith("gx")]).to_csv(p, index=False)
    f = _err(capsys, "triaxial", "ferraris", p)
    assert f == _err(capsys, "validate", p, "--kind", "ferraris") and "gx_<unit>" in f


def test_vibration_kind_needs_vib_on_in_validate_and_command(tmp_path, capsys):
    p = tmp_path / "static.csv"
    rng = np.random.default_rng(1)
    p.write_text("t_s,rate_dph\n" + "".join(f"{i / 100:.2f},{v:.5f}\n"
                                            for i, v in enumerate(rng.normal(size=300))))
    v = _err(capsys, "validate", p, "--kind", "vibration")
    f = _err(capsys, "vibration", "fit", p)
    assert v == f and "vib_on" in v


def test_validate_title_keeps_the_file_name_on_one_line_and_units_shown(tmp_path, capsys):
    d = tmp_path / ("a_rather_long_folder_name_for_a_rig_" * 3)
    d.mkdir()
    p = d / "log_with_a_long_name_of_the_rig_and_the_date_2026-11-26.csv"
    p.write_text("t_s,rate_dph,temp_c\n" + "".join(f"{i / 10},{i % 3},{20 + i / 100}\n"
                                                   for i in range(20)))
    code, out, err = run_inprocess(capsys, "validate", p, "--kind", "gyro_log")
    assert code in (0, None), err
    assert f"{p}: valid gyro_log record (gyro_log), 20 rows" in out.splitlines()
    rows = {line.split("│")[1].strip(): line.split("│")[2].strip()
            for line in out.splitlines() if line.count("│") == 3}
    assert rows["t_s"] == "s" and rows["temp_c"] == "c" and rows["rate_dph"] == "dph"


def test_clock_without_time_same_error_from_validate_and_allan(tmp_path, capsys):
    p = tmp_path / "phase.csv"
    p.write_text("phase_ns\n" + "".join(f"{v:.3f}\n" for v in range(20)))
    v = _err(capsys, "validate", p, "--kind", "clock_log")
    a = _err(capsys, "allan", p, "--input", "phase")
    assert v == a == f"error: {p}: needs a t_s column or --rate"


def test_a_varying_temperature_does_not_let_constant_axes_through(tmp_path, capsys):
    # the analysed axes decide: stuck gyros beside a drifting temperature are refused by
    # validate and the analysis alike; one varying axis lets the log through
    n = 2000
    t = np.arange(n) / 100.0
    temp = 25.0 + 0.001 * np.arange(n)
    stuck = tmp_path / "stuck.csv"
    rows = ["t_s,gx_dps,gy_dps,gz_dps,temp_c"] + [f"{a},0.0125,-0.05,0.1,{b}"
                                                   for a, b in zip(t, temp)]
    stuck.write_text("\n".join(rows) + "\n")
    for cmd in (("validate", str(stuck), "--kind", "allan"),
                ("validate", str(stuck), "--kind", "imu"), ("allan", str(stuck))):
        code, _, err = run_inprocess(capsys, *cmd)
        assert code == 2 and "constant in every analysed column (gx_dps, gy_dps, gz_dps)" in err
    # the six-axis analysis reads gx..az only: a varying rate column beside them is none
    rows = ["t_s,gx_dps,gy_dps,gz_dps,rate_dph"] + [f"{a},0.0125,-0.05,0.1,{3600 * b}"
                                                     for a, b in zip(t, temp)]
    stuck.write_text("\n".join(rows) + "\n")
    for cmd in (("validate", str(stuck), "--kind", "imu"), ("allan", str(stuck), "--imu")):
        code, _, err = run_inprocess(capsys, *cmd)
        assert code == 2 and "constant in every analysed column (gx_dps, gy_dps, gz_dps)" in err
    live = tmp_path / "live.csv"
    gx = 0.0125 + 0.01 * np.random.default_rng(0).standard_normal(n)
    rows = ["t_s,gx_dps,gy_dps,gz_dps,temp_c"] + [f"{a},{g},-0.05,0.1,25.0"
                                                   for a, g in zip(t, gx)]
    live.write_text("\n".join(rows) + "\n")
    code, _, err = run_inprocess(capsys, "validate", str(live), "--kind", "allan")
    assert code in (0, None), err
