"""Column mapping, parse options and the vendor example files."""

import math
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from inertialab.errors import InputError
from inertialab.io import read_record
from inertialab.io.mapping import (
    ColumnMap,
    ParseOptions,
    ReadOptions,
    apply_map,
    load_map_file,
    normalise_time_columns,
    parse_map,
    sniff,
)

VENDORS = Path(__file__).resolve().parents[2] / "docs" / "examples" / "vendors"
G = 9.80665


def test_parse_map_round_trip_and_units():
    m = parse_map("ax_mps2=AccX:g, gx_rps=GyrX:dps ,t_s=SampleTimeFine:us,temp_c=T")
    assert [e.target for e in m.entries] == ["ax_mps2", "gx_rps", "t_s", "temp_c"]
    assert [e.unit for e in m.entries] == ["g", "dps", "us", None]
    assert parse_map(m.to_text()) == m
    scaled = parse_map("t_s=SampleTimeFine:100us")
    assert scaled.entries[0].scale == 100.0 and scaled.entries[0].unit == "us"
    assert parse_map(scaled.to_text()) == scaled


@pytest.mark.parametrize("text, needle", [
    ("ax_mps2=AccX:dps", "angular_rate"),        # unit of the wrong dimension
    ("ax_mps2=AccX:furlong", "unknown unit"),
    ("ax_mps2", "target=source"),
    ("ax_mps2=A,ax_mps2=B", "twice"),
    ("accx=A:g", "no unit suffix"),
    ("t_s=Stamp:g", "acceleration"),
])
def test_parse_map_rejects(text, needle):
    with pytest.raises(InputError, match=needle):
        parse_map(text)


def test_apply_map_converts_by_hand_factors():
    df = pd.DataFrame({"AccX": [1.0, -0.5], "GyrX": [90.0, 1.0], "Stamp": [10_000, 10_500]})
    out = apply_map(df, parse_map("ax_mps2=AccX:g,gx_rps=GyrX:dps,t_s=Stamp:us"), g_local=9.8)
    # g -> m/s^2 with the local gravity given; deg/s -> rad/s = pi/180; us relative to first
    np.testing.assert_allclose(out["ax_mps2"], [9.8, -4.9], rtol=1e-15)
    np.testing.assert_allclose(out["gx_rps"], [math.pi / 2, math.pi / 180], rtol=1e-15)
    np.testing.assert_allclose(out["t_s"], [0.0, 500e-6], rtol=1e-15, atol=0)


def test_apply_map_missing_source_names_column():
    df = pd.DataFrame({"AccX": [1.0]})
    with pytest.raises(InputError, match="'AccY'.*not in the file"):
        apply_map(df, parse_map("ay_mps2=AccY:g"), path="f.csv")


def test_integer_ns_epoch_stamps_keep_resolution():
    t0 = 1_767_225_600_123_456_789
    df = pd.DataFrame({"t_ns": np.array([t0, t0 + 1, t0 + 10_000_001], dtype=np.int64),
                       "x": [1, 2, 3]})
    meta = {}
    out = normalise_time_columns(df, meta=meta)
    # float64 of the raw stamps would lose the 1 ns step (spacing at 1.7e18 is 256 ns)
    # one rounding of the ns -> s product: 1 ulp
    np.testing.assert_allclose(out["t_s"].to_numpy(), [0.0, 1e-9, 0.010000001], rtol=2.3e-16,
                               atol=0)
    assert meta["time_origin"]["value"] == t0 and "t_ns" not in out.columns


def test_sniff_semicolon_decimal_comma_and_preamble():
    lines = ["// vendor preamble\n", "# rate=100\n", "\n", "a;b\n", "1,5;-2,25\n", "3,0;4,5\n"]
    skip, sep, dec, hashes = sniff(lines)
    assert (skip, sep, dec) == (3, ";", ",") and hashes == ["# rate=100\n"]
    assert sniff(["a,b\n", "1.5,2\n"])[1:3] == (",", ".")
    assert sniff(["x\ty\n", "1\t2\n"])[1] == "\t"
    # explicit options win over sniffing
    assert sniff(["junk\n", "a;b\n", "1;2\n"], ParseOptions(skip_rows=1, decimal="."))[:3] == (
        1, ";", ".")


def test_read_record_semicolon_decimal_comma_skip_rows(tmp_path):
    p = tmp_path / "log.txt"
    p.write_text("Logger v1 export\nsite: lab 3\nt_ms;rate_dph\n0;0,5\n10;-1,25\n20;2,0\n")
    rec = read_record(p, "gyro_log", parse=ParseOptions(skip_rows=2))
    np.testing.assert_allclose(rec.data["t_s"], [0.0, 0.01, 0.02], rtol=1e-15)
    np.testing.assert_allclose(rec.data["rate_dph"], [0.5, -1.25, 2.0], rtol=0)


def test_map_file_toml_json_and_errors(tmp_path):
    t = tmp_path / "m.toml"
    t.write_text('sep=";"\ndecimal=","\n[columns]\nax_mps2="AccX:g"\n')
    cmap, opts = load_map_file(t)
    assert cmap.to_text() == "ax_mps2=AccX:g" and (opts.sep, opts.decimal) == (";", ",")
    j = tmp_path / "m.json"
    j.write_text('{"columns": {"gx_rps": {"column": "G", "unit": "dph"}}}')
    assert load_map_file(j)[0].entries[0].unit == "dph"
    bad = tmp_path / "bad.json"
    bad.write_text('{"colums": {}}')
    with pytest.raises(InputError, match="unknown keys"):
        load_map_file(bad)
    wrong = tmp_path / "wrong.toml"
    wrong.write_text('[columns]\nax_mps2="AccX:dph"\n')
    with pytest.raises(InputError, match="angular_rate"):
        load_map_file(wrong)
    # --map entries override the file's for the same target
    ro = ReadOptions.from_cli("ax_mps2=AccX:mg", t, decimal=".")
    assert ro.column_map.to_text() == "ax_mps2=AccX:mg" and ro.parse.decimal == "."
    assert ColumnMap().merged(None) == ColumnMap()


def _truth():
    """The example generator's numbers, recomputed from its seed (independent of io)."""
    n = 200
    rng = np.random.default_rng(20260101)
    acc = np.column_stack([0.002 * rng.standard_normal(n) + 0.01,
                           0.002 * rng.standard_normal(n) - 0.02,
                           G + 0.002 * rng.standard_normal(n)])
    gyr = 0.001 * rng.standard_normal((n, 3)) + [1e-4, -2e-4, 5e-5]
    return acc, gyr


@pytest.mark.parametrize("data, mapping, gyro_digits", [
    ("xsens.txt", "xsens.map.toml", 6),            # deg/s with 6 decimals
    ("vectornav.csv", "vectornav.map.json", 7),
    ("px4_sensor_combined.csv", "px4.map.toml", 7),
    ("ros_imu.csv", "ros.map.json", 7),
])
def test_vendor_examples_load(data, mapping, gyro_digits):
    ro = ReadOptions.from_cli(map_file=VENDORS / mapping)
    rec = read_record(VENDORS / data, "gyro_log", column_map=ro.column_map, parse=ro.parse,
                      gaps="error")
    acc, gyr = _truth()
    d = rec.data
    # 100 Hz from the stamps: exact ticks, so 1e-12 s covers float rounding only
    np.testing.assert_allclose(np.diff(d["t_s"]), 0.01, atol=1e-12)
    assert d["t_s"].iloc[0] == 0.0 and len(d) == 200
    # the files hold 6 decimals of m/s^2: half a unit of the last digit
    np.testing.assert_allclose(d[["ax_mps2", "ay_mps2", "az_mps2"]], acc, atol=0.5e-6 + 1e-12)
    # gyro: rad/s with 7 decimals, or deg/s with 6 decimals converted by pi/180
    tol = 0.5e-7 if gyro_digits == 7 else 0.5e-6 * math.pi / 180
    np.testing.assert_allclose(d[["gx_rps", "gy_rps", "gz_rps"]], gyr, atol=tol + 1e-15)
    assert rec.units["gx_rps"] == "rps" and "column_map" in rec.meta
