"""Dropouts, repeated stamps and saturation."""

import numpy as np
import pandas as pd
import pytest

from inertialab.errors import DataQualityWarning, InputError
from inertialab.io import read_record
from inertialab.io.gaps import apply_gap_policy, detect_gaps, detect_saturation, exclude_flagged


def _log(n=100, fs=100.0):
    t = np.arange(n) / fs
    rng = np.random.default_rng(3)
    return pd.DataFrame({"t_s": t, "rate_dph": rng.standard_normal(n)})


def test_detect_gaps_rows_durations_segments():
    t = np.arange(20) * 0.01
    t = np.delete(t, [5, 6, 7])           # 3 samples lost after index 4 -> step 0.04 s
    t = np.insert(t, 10, t[9])            # repeated stamp: new row 10 (0-based) repeats row 9
    t[14:] -= 0.5                         # backward jump at 0-based index 14
    rep = detect_gaps(t)
    kinds = [(i.kind, i.row) for i in rep.issues]
    # 1-based data rows of the sample after each jump: 0-based index + 1
    assert kinds == [("gap", 6), ("repeat", 11), ("backward", 15)]
    gap = rep.issues[0]
    assert gap.missing == 3 and gap.duration_s == pytest.approx(0.03, abs=1e-12)
    assert rep.issues[2].duration_s == pytest.approx(-0.49, abs=1e-12)
    assert rep.segments == ((0, 5), (5, 10), (10, 14), (14, 18))
    assert rep.nominal_dt_s == pytest.approx(0.01, abs=1e-15)
    assert rep.lost_s == pytest.approx(0.03, abs=1e-12)


def test_jitter_below_factor_is_not_a_gap():
    rng = np.random.default_rng(1)
    t = np.cumsum(0.01 * (1 + 0.2 * rng.uniform(-1, 1, 1000)))  # +-20 % clock jitter
    assert detect_gaps(t).ok


def test_gap_policy_error_names_rows_and_split_segments():
    df = _log()
    df.loc[50:, "t_s"] += 0.25            # dropout of 25 samples before row 51
    with pytest.raises(InputError, match=r"gap of 0\.25 s \(~25 samples\) before row 51"):
        apply_gap_policy(df, "error", path="run.csv")
    out, rep = apply_gap_policy(df, "split")
    assert out["segment"].tolist() == [0] * 50 + [1] * 50 and len(rep.issues) == 1
    with pytest.raises(InputError, match="error' or 'split"):
        apply_gap_policy(df, "ignore")


def test_read_record_gaps_split_and_error(tmp_path):
    df = _log()
    df.loc[30, "t_s"] = df.loc[29, "t_s"]     # repeated stamp at data row 31
    p = tmp_path / "log.csv"
    df.to_csv(p, index=False)
    with pytest.raises(InputError, match="repeated stamp .* at row 31"):
        read_record(p, "gyro_log", gaps="error")
    rec = read_record(p, "gyro_log", gaps="split")
    # overwriting stamp 31 with stamp 30 repeats it and leaves a 2-step gap before row 32
    issues = [(i["kind"], i["row"]) for i in rec.meta["gaps"]["issues"]]
    assert issues == [("repeat", 31), ("gap", 32)] and rec.data["segment"].max() == 2
    # the derived column does not change the data hash
    assert rec.sha256 == read_record(p, "gyro_log", gaps="split").sha256
    # without a policy the lead's strict order check still applies
    with pytest.raises(InputError, match="repeat"):
        read_record(p, "gyro_log")


def test_saturation_given_and_auto():
    x = np.array([0.1, 5.0, 5.0, 5.0, 0.2, -5.0, 0.3, 4.99, 5.0, 0.0])
    df = pd.DataFrame({"ax_g": x, "ay_g": np.zeros(10) + np.arange(10) * 0.01})
    given = detect_saturation(df, ["ax_g", "ay_g"], {"ax_g": 5.0})
    assert np.flatnonzero(given.mask).tolist() == [1, 2, 3, 5, 8]
    assert given.counts == {"ax_g": 5} and given.rows == (2, 3, 4, 6, 9)
    auto = detect_saturation(df, ["ax_g", "ay_g"])
    # auto: only the flat run of >= 3 samples at the maximum counts as clipping
    assert np.flatnonzero(auto.mask).tolist() == [1, 2, 3] and auto.method == "auto"


def test_read_record_flags_full_scale_with_warning(tmp_path):
    df = _log()
    df.loc[10:12, "rate_dph"] = 400.0
    p = tmp_path / "sat.csv"
    df.to_csv(p, index=False)
    with pytest.warns(DataQualityWarning, match="3 samples at full scale"):
        rec = read_record(p, "gyro_log", full_scale={"rate_dph": 400.0})
    assert np.flatnonzero(rec.data["saturated"]).tolist() == [10, 11, 12]
    assert rec.sha256 == read_record(p, "gyro_log").sha256


def test_exclude_flagged_cuts_static_intervals():
    mask = np.zeros(30, dtype=bool)
    mask[[5, 6, 20]] = True
    s, e = exclude_flagged([0, 15], [10, 30], mask)
    # [0,10) minus {5,6} -> [0,5), [7,10); [15,30) minus {20} -> [15,20), [21,30)
    assert s.tolist() == [0, 7, 15, 21] and e.tolist() == [5, 10, 20, 30]
    s, e = exclude_flagged([0], [10], mask, min_length=4)
    assert s.tolist() == [0] and e.tolist() == [5]
