"""Record readers: each InputError case names file, column and row; good files load
with canonical names and a format-independent hash."""

import numpy as np
import pandas as pd
import pytest

from inertialab import InputError
from inertialab.io import read_record, validate_frame, write_record


def _gyro(tmp_path, text, name="g.csv"):
    p = tmp_path / name
    p.write_text(text, encoding="utf-8")
    return p


def test_gyro_log_round_trip_and_hash_is_format_independent(tmp_path):
    rng = np.random.default_rng(1)
    df = pd.DataFrame({"t_s": np.arange(100) * 0.01, "rate_dph": rng.normal(size=100)})
    csv = write_record(df, tmp_path / "run.csv", {"fs_hz": 100.0, "source": "virtual_lab"})
    pq = tmp_path / "run.parquet"
    df.to_parquet(pq)
    a = read_record(csv, "gyro_log")
    b = read_record(pq, "gyro_log")
    assert a.units == {"rate_dph": "dph"}
    assert a.meta["fs_hz"] == 100.0 and a.meta["schema_version"] == 1
    np.testing.assert_array_equal(a.column("rate_dph"), df["rate_dph"].to_numpy())
    assert a.sha256 == b.sha256
    assert (tmp_path / "run.meta.json").exists()


def test_spec_spellings_are_aliases(tmp_path):
    p = _gyro(tmp_path, "temp_set_C,temp_meas_C,pos_index,output_mV\n"
              + "".join(f"25,25.1,{i},{i * 0.5}\n" for i in range(24)))
    rec = read_record(p, "thermal_tumble")
    assert list(rec.data.columns) == ["temp_set_c", "temp_meas_c", "pos_index", "output_mv"]
    assert rec.data["pos_index"].dtype == np.int64


def test_header_units_give_bare_columns_a_unit(tmp_path):
    p = _gyro(tmp_path, "# units=lsb\n# lsb_per_g=16384\npos_id,ax,ay,az\n1,1,2,16384\n")
    rec = read_record(p, "triaxial_static")
    assert rec.meta == {"units": "lsb", "lsb_per_g": 16384}
    assert rec.units == {"ax_lsb": "lsb", "ay_lsb": "lsb", "az_lsb": "lsb"}


def test_unit_option_overrides_suffix_and_sidecar(tmp_path):
    p = _gyro(tmp_path, "pos_id,ax,ay,az\n1,0,0,9.8\n")
    rec = read_record(p, "triaxial_static", unit="mps2")
    assert "az_mps2" in rec.data.columns


def test_npy_is_memory_mapped_and_needs_rate_and_unit(tmp_path):
    x = np.random.default_rng(0).normal(size=1000)
    p = tmp_path / "long.npy"
    np.save(p, x)
    with pytest.raises(InputError, match="argument .unit."):
        read_record(p, "gyro_log")
    rec = read_record(p, "gyro_log", unit="dph", rate_hz=200.0)
    arr = rec.column("rate_dph")
    assert isinstance(arr, np.memmap)
    np.testing.assert_array_equal(arr, x)
    assert rec.meta["fs_hz"] == 200.0


@pytest.mark.parametrize(
    "text, kind, pattern",
    [
        (None, "gyro_log", r"no such file"),
        ("", "gyro_log", r"empty file"),
        ("t_s,rate_dph\n", "gyro_log", r"no data rows"),
        ("t_s,temp_c\n0,1\n1,2\n", "gyro_log", r"needs at least one of the columns"),
        ("t_s,rate_dph\n0,1\n0.1,abc\n", "gyro_log", r"column 'rate_dph', row 2: non-numeric value 'abc'"),
        ("t_s,rate_dph\n0,1\n0.1,nan\n", "gyro_log", r"column 'rate_dph', row 2: empty cell or NaN"),
        ("t_s,rate_dph\n0,1\n0.1,inf\n", "gyro_log", r"column 'rate_dph', row 2: infinite value"),
        ("t_s,rate_dph\n0,1\n0.1,\n", "gyro_log", r"column 'rate_dph', row 2: empty cell"),
        ("t_s,rate_dph\n0,1\n0.2,2\n0.1,3\n", "gyro_log", r"column 't_s', row 3: time stamps decrease"),
        ("t_s,rate_dph\n0,1\n0,2\n", "gyro_log", r"column 't_s', row 2: time stamps repeat"),
        ("t_s,rate_dph\n0,1\n", "gyro_log", r"too few samples: 1 rows"),
        ("t_s,rate_furlong\n0,1\n1,2\n", "gyro_log", r"column 'rate_furlong': unknown unit suffix 'furlong'"),
        ("t_s,rate_mps2\n0,1\n1,2\n", "gyro_log", r"column 'rate_mps2': unit 'mps2' is a acceleration"),
        ("pos_id,ax_mps2,ay_mps2\n1,2,3\n", "triaxial_static", r"column 'az': missing required column"),
        ("pos_id,ax,ay,az\n1,2,3,4\n", "triaxial_static", r"column 'ax': no unit"),
        ("t_s,rate_dph,RATE_DPH\n0,1,1\n1,2,2\n", "gyro_log", r"duplicated column"),
    ],
)
def test_bad_input_names_file_column_and_row(tmp_path, text, kind, pattern):
    p = tmp_path / "bad.csv"
    if text is not None:
        p.write_text(text, encoding="utf-8")
    with pytest.raises(InputError, match=pattern) as exc:
        read_record(p, kind)
    assert str(p) in str(exc.value)
    assert "\n" not in str(exc.value)
    assert isinstance(exc.value, ValueError)


def test_non_utf8_and_binary_garbage(tmp_path):
    p = tmp_path / "latin.csv"
    p.write_bytes("t_s,rate_dph\n0,1\n1,\xe9\n".encode("latin-1"))
    with pytest.raises(InputError, match="not UTF-8"):
        read_record(p, "gyro_log")
    q = tmp_path / "garbage.parquet"
    q.write_bytes(bytes(range(256)) * 4)
    with pytest.raises(InputError, match="Parquet"):
        read_record(q, "gyro_log")


def test_per_test_tables_are_sorted_with_a_warning():
    df = pd.DataFrame({"unit_id": ["A", "A"], "date": ["2024-01-02", "2024-01-01"],
                       "bias_mg": [1.0, 2.0]})
    with pytest.warns(UserWarning, match="sorted"):
        rec = validate_frame(df, "storage_drift")
    assert rec.data["bias_mg"].tolist() == [2.0, 1.0]


def test_a_cell_beyond_1e100_is_refused_naming_file_column_and_row(tmp_path):
    # one 1e308 cell used to reach the arithmetic and come out as
    # inf/NaN outputs with exit 0 (vibration apply) or an internal error (allan)
    t = np.arange(50) / 10.0
    rate = np.random.default_rng(1).normal(0.0, 1.0, 50)
    rate[17] = -1e308
    p = tmp_path / "big.csv"
    pd.DataFrame({"t_s": t, "rate_dph": rate}).to_csv(p, index=False)
    with pytest.raises(InputError, match=r"big\.csv: column 'rate_dph', row 18: value -1e\+308"):
        read_record(p, "gyro_log")
    rate[17] = 1e99  # large but harmless: accepted
    pd.DataFrame({"t_s": t, "rate_dph": rate}).to_csv(p, index=False)
    assert read_record(p, "gyro_log").column("rate_dph")[17] == 1e99


def test_naming_puts_the_file_on_errors_that_name_none():
    from inertialab.calib.triaxial_checks import ImplausibleCalibrationError
    from inertialab.io.record import naming

    with pytest.raises(InputError, match=r"^rig/log.csv: no initial rest"):
        with naming("rig/log.csv"):
            raise InputError("no initial rest")
    with pytest.raises(ImplausibleCalibrationError, match=r"^rig/log.csv: implausible"):
        with naming("rig/log.csv"):
            raise ImplausibleCalibrationError("implausible")
    with pytest.raises(InputError, match=r"^other.csv: x"):  # a named file is kept
        with naming("rig/log.csv"):
            raise InputError("x", path="other.csv")


def test_a_table_of_ids_dates_and_flags_keeps_its_header(tmp_path):
    # one number in four cells (unit id, ISO date, the value, a true/false flag): the data
    # rows are still data and the first line the header (they were taken for header rows
    # and the last line became the names)
    p = tmp_path / "drift.csv"
    p.write_text("unit_id,date,bias_mg,valid\n"
                 "A,2024-03-01,0.15,true\nA,2024-03-02,0.16,True\nB,2024-03-01,-0.08,false\n")
    rec = read_record(p, "storage_drift")
    assert list(rec.data["unit_id"]) == ["A", "A", "B"]
    np.testing.assert_allclose(rec.data["bias_mg"], [0.15, 0.16, -0.08])
    # a line of names only stays a header: names are not dates or booleans
    from inertialab.io.formats.text import _is_data_row

    assert not _is_data_row(["unit_id", "date", "bias_mg", "valid"], ".")
    assert _is_data_row(["A", "2025-01-01T08:00:00Z", "1.0"], ".")
    assert not _is_data_row(["true", "false", "2024-03-01"], ".")  # no number: not data
