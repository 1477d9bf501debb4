"""The one reading front door: header rows, separators, headerless
files with positional maps, missing-column errors that list what the file holds and
suggest the map, and the reading options every command shares."""

import math

import numpy as np
import pandas as pd
import pytest

from inertialab.errors import InputError
from inertialab.io import read_record
from inertialab.io.formats.text import load_text, peek_names, unit_suffix
from inertialab.io.mapping import ParseOptions, ReadOptions
from inertialab.io.suggest import canonical_guess, suggest_map

DEG = math.pi / 180


def _gyro_values(n=50, seed=3):
    rng = np.random.default_rng(seed)
    return np.arange(n) * 0.01, rng.normal(0.0, 0.5, size=(n, 3))


def _write(tmp_path, name, text):
    p = tmp_path / name
    p.write_text(text, encoding="utf-8")
    return p


def test_two_row_header_name_and_unit_joined_and_used_by_the_map(tmp_path):
    t, g = _gyro_values()
    body = "".join(f"{a:.2f},{x:.6f},{y:.6f},{z:.6f}\n" for a, (x, y, z) in zip(t, g))
    p = _write(tmp_path, "mems.csv", "Time,Gyro X,Gyro Y,Gyro Z\ns,[deg/s],[deg/s],[deg/s]\n" + body)
    tab = load_text(p)
    assert list(tab.frame.columns) == ["Time", "Gyro X", "Gyro Y", "Gyro Z"]
    assert tab.header_units == {"Time": "s", "Gyro X": "deg/s", "Gyro Y": "deg/s",
                                "Gyro Z": "deg/s"}
    # without a map: the error lists the columns as the file shows them and the map
    with pytest.raises(InputError) as exc:
        read_record(p, "gyro_log")
    msg = str(exc.value)
    assert "Gyro X [deg/s]" in msg and "Unnamed" not in msg
    assert "gx_rps=Gyro X:dps" in msg and "t_s=Time" in msg
    # the suggested map works; the header's deg/s converts without a unit in the map
    rec = read_record(p, "gyro_log", column_map="t_s=Time,gx_rps=Gyro X,gy_rps=Gyro Y,"
                                                "gz_rps=Gyro Z")
    np.testing.assert_allclose(rec.data[["gx_rps", "gy_rps", "gz_rps"]],
                               np.round(g, 6) * DEG, rtol=1e-12)
    np.testing.assert_allclose(rec.data["t_s"], t, atol=1e-12)


def test_units_row_under_a_canonical_name_becomes_its_suffix(tmp_path):
    p = _write(tmp_path, "u.csv", "t_s,rate\ns,dph\n0,1.5\n0.1,2.5\n0.2,-1\n")
    rec = read_record(p, "gyro_log")
    assert rec.units == {"rate_dph": "dph"}
    np.testing.assert_array_equal(rec.data["rate_dph"], [1.5, 2.5, -1.0])


@pytest.mark.parametrize("sep", [",", ";", "\t", " ", "   "])
def test_separators_are_sniffed(tmp_path, sep):
    t, g = _gyro_values(20)
    lines = [sep.join(["t_s", "gx_dps", "gy_dps", "gz_dps"])]
    lines += [sep.join(f"{v:.6f}" for v in (a, *row)) for a, row in zip(t, g)]
    p = _write(tmp_path, "s.txt", "\n".join(lines) + "\n")
    rec = read_record(p, "gyro_log")
    np.testing.assert_allclose(rec.data["gz_dps"], np.round(g[:, 2], 6), rtol=0, atol=1e-12)


def test_headerless_whitespace_file_with_positional_map(tmp_path):
    t, g = _gyro_values(30)
    body = "".join(f"  {a:.3f}  {x:.6f} {y:.6f}\t{z:.6f}\n" for a, (x, y, z) in zip(t, g))
    p = _write(tmp_path, "raw.txt", body)
    assert peek_names(p) == ["col1", "col2", "col3", "col4"]
    with pytest.raises(InputError) as exc:
        read_record(p, "gyro_log")
    assert "col1, col2, col3, col4" in str(exc.value) and "colN" in str(exc.value) or \
        "col1, col2, col3, col4" in str(exc.value)
    rec = read_record(p, "gyro_log", column_map="t_s=col1,gx_rps=col2:dps,gz_rps=col4:dps")
    np.testing.assert_allclose(rec.data["gz_rps"], np.round(g[:, 2], 6) * DEG, rtol=1e-12)
    assert "gy_rps" not in rec.data.columns and "col3" in rec.data.columns


def test_free_text_preamble_is_skipped_without_skip_rows(tmp_path):
    p = _write(tmp_path, "log.txt", "Logger v1 export\nsite: lab 3\nt_ms;rate_dph\n0;0,5\n"
               "10;-1,25\n20;2,0\n")
    rec = read_record(p, "gyro_log")
    np.testing.assert_allclose(rec.data["rate_dph"], [0.5, -1.25, 2.0], rtol=0)
    np.testing.assert_allclose(rec.data["t_s"], [0.0, 0.01, 0.02], rtol=1e-15)


def test_exact_duplicate_header_is_refused(tmp_path):
    p = _write(tmp_path, "d.csv", "t_s,rate_dph,rate_dph\n0,1,2\n1,2,3\n")
    with pytest.raises(InputError, match=r"duplicated column header 'rate_dph' \(columns 2 and 3"):
        read_record(p, "gyro_log")


def test_bom_does_not_hide_the_time_column(tmp_path):
    rng = np.random.default_rng(0)
    rows = "".join(f"{i * 0.01:.2f},{rng.normal():.5f},{rng.normal():.5f},{9.8:.5f}\n"
                   for i in range(20))
    p = tmp_path / "pose.raw.csv"
    p.write_bytes("\ufefft_s,ax_mps2,ay_mps2,az_mps2\n".encode() + rows.encode())
    assert peek_names(p)[0] == "t_s"
    rec = read_record(p, "triaxial_raw")
    assert rec.data.columns[0] == "t_s" and rec.meta["bom_removed"] is True
    assert len(rec.data) == 20


def test_rate_builds_the_time_column_and_units_per_dimension(tmp_path):
    p = _write(tmp_path, "imu.csv", "ax,ay,az,gx,gy,gz\n" + "".join(
        f"0.01,0.02,1.0,{i},0.5,-0.5\n" for i in range(10)))
    rec = read_record(p, "gyro_log", options=ReadOptions.from_cli(rate=200.0, unit="g,dps"))
    assert rec.meta["fs_hz"] == 200.0 and rec.meta["time_from_rate"] is True
    np.testing.assert_allclose(rec.data["t_s"], np.arange(10) / 200.0, rtol=0, atol=0)
    assert rec.units["az_g"] == "g" and rec.units["gx_dps"] == "dps"
    per_col = read_record(p, "gyro_log", options=ReadOptions.from_cli(
        rate=100.0, unit="ax=mg,ay=mg,az=g,gx=deg/s,gy=rps,gz=dph"))
    assert per_col.units["ax_mg"] == "mg" and per_col.units["gx_dps"] == "dps"
    assert per_col.units["gz_dph"] == "dph"


def test_time_column_and_unit_options(tmp_path):
    p = _write(tmp_path, "v.csv", "Stamp,RateZ\n1700000000000000000,1\n1700000000002500000,2\n"
               "1700000000005000000,3\n")
    opts = ReadOptions.from_cli("rate_dph=RateZ:dph", time_col="Stamp", time_unit="ns")
    rec = read_record(p, "gyro_log", options=opts)
    np.testing.assert_array_equal(rec.data["t_s"], [0.0, 0.0025, 0.005])
    assert rec.meta["time_origin"] == {"column": "Stamp", "unit": "ns",
                                       "value": 1700000000000000000}
    assert rec.meta["timestamps"]["mean_rate_hz"] == pytest.approx(400.0, rel=1e-12)
    with pytest.raises(InputError, match="time_unit"):
        ReadOptions.from_cli(time_unit="dps")


def test_suggestions_for_vendor_names():
    assert canonical_guess("Gyro X") == ("gx", None)
    assert canonical_guess("GyrZ") == ("gz", None)
    assert canonical_guess("linear_acceleration.y") == ("ay", None)
    assert canonical_guess("Acc_X [g]") == ("ax", "g")
    assert canonical_guess("pressure") is None
    assert suggest_map(["Acc X", "Gyro X"], {"Acc X": "g"}) == "ax_mps2=Acc X:g,gx_rps=Gyro X:<unit>"
    assert unit_suffix("[deg/s]") == "dps" and unit_suffix("m/s^2") == "mps2"
    assert unit_suffix("°/s") == "dps" and unit_suffix("furlong") is None


def test_explicit_parse_options_still_win(tmp_path):
    p = _write(tmp_path, "e.txt", "junk line\nt_s;rate_dph\n0;1.5\n1;2.5\n")
    rec = read_record(p, "gyro_log", parse=ParseOptions(skip_rows=1, sep=";", decimal="."))
    np.testing.assert_array_equal(rec.data["rate_dph"], [1.5, 2.5])


def test_parquet_and_2d_npy_through_the_same_door(tmp_path):
    t, g = _gyro_values(40)
    df = pd.DataFrame({"time": t, "wx": g[:, 0]})
    df.to_parquet(tmp_path / "a.parquet")
    rec = read_record(tmp_path / "a.parquet", "gyro_log", column_map="t_s=time,gx_rps=wx:rps")
    np.testing.assert_array_equal(rec.data["gx_rps"], g[:, 0])
    np.save(tmp_path / "b.npy", np.column_stack([t, g]))
    rec2 = read_record(tmp_path / "b.npy", "gyro_log",
                       column_map="t_s=col1,gx_rps=col2:rps,gy_rps=col3:rps,gz_rps=col4:rps")
    np.testing.assert_array_equal(rec2.data[["gx_rps", "gy_rps", "gz_rps"]], g)
    s = np.zeros(40, dtype=[("t", "f8"), ("gz", "f8")])
    s["t"], s["gz"] = t, g[:, 2]
    np.save(tmp_path / "c.npy", s)
    rec3 = read_record(tmp_path / "c.npy", "gyro_log", column_map="t_s=t,gz_dps=gz:dps")
    np.testing.assert_array_equal(rec3.data["gz_dps"], g[:, 2])
