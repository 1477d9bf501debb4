"""Allan workflow: record preparation, analysis JSON (the demo study: tests/studies)."""

from __future__ import annotations

import math

import numpy as np
import pandas as pd
import pytest

from inertialab.errors import InputError
from inertialab.io import read_record, write_record
from inertialab.noise.statistics.allan import oadev
from inertialab.workflows import allan as W

ISSUE_KEYS = {"statistic", "tau0_s", "taus_s", "dev", "ci_low", "ci_high", "n_terms", "alpha",
              "alpha_source", "edf", "unit", "noise_terms"}


def _log(tmp_path, df, name="log.csv", meta=None):
    p = tmp_path / name
    write_record(df, p, meta or {})
    return read_record(p, "gyro_log")


def _white(n=20_000, fs=10.0, seed=0):
    y = np.random.default_rng(seed).normal(0.5, 2.0, n)
    return pd.DataFrame({"t_s": np.arange(n) / fs, "rate_dph": y}), y


def test_prepare_rate_log_from_t_s(tmp_path):
    df, y = _white()
    log = W.prepare_log(_log(tmp_path, df))
    assert log.rate_hz == pytest.approx(10.0, rel=1e-9)
    assert log.unit == "dph" and log.kind == "gyro" and log.column == "rate_dph"
    np.testing.assert_array_equal(log.values, y)


def test_jittery_and_gappy_time_stamps_on_the_sensor_grid(tmp_path):
    # a logger stamps the sensor's uniform samples with jitter and loses packets: the
    # samples go on the sensor's grid at the mean rate, the lost ones as NaN (never
    # interpolated), with one warning naming the rows; repeated stamps are refused
    from inertialab.errors import DataQualityWarning

    df, y = _white(200)
    t = df["t_s"].to_numpy().copy()
    t[50:] += 0.003  # one step of 0.103 s instead of 0.1
    df["t_s"] = t
    with pytest.warns(DataQualityWarning, match=r"column 't_s': time stamps jitter.*rows 51"):
        log = W.prepare_log(_log(tmp_path, df))
    assert log.rate_hz == pytest.approx(199 / (t[-1] - t[0]), rel=1e-12)
    np.testing.assert_array_equal(log.values, y)
    # --rate overrides the time column, without a warning
    assert W.prepare_log(_log(tmp_path, df), rate_hz=10.0).rate_hz == 10.0

    # 20 000 samples on a logger clock 0.1 % fast, stamps jittering by 20 % of a step,
    # three packets lost (2, 1 and 5 samples): every kept sample lands in its own slot
    rng = np.random.default_rng(3)
    n, fs = 20_000, 10.0
    keep = np.ones(n, bool)
    keep[[1000, 1001, 7000, 15000, 15001, 15002, 15003, 15004]] = False
    t_true = np.arange(n) / fs * 1.001 + rng.uniform(-0.02, 0.02, n)
    yy = np.random.default_rng(4).normal(0.0, 1.0, n)
    df2 = pd.DataFrame({"t_s": t_true[keep] - t_true[keep][0], "rate_dph": yy[keep]})
    with pytest.warns(DataQualityWarning, match=r"8 sample\(s\) lost"):
        log = W.prepare_log(_log(tmp_path, df2, name="gappy.csv"))
    assert log.values.size == n                     # the first sample is kept
    expect = np.where(keep, yy, np.nan)
    np.testing.assert_array_equal(log.values, expect)
    assert log.rate_hz == pytest.approx(fs / 1.001, rel=1e-4)
    with pytest.warns(Warning):
        res = W.analyze(log, fit_terms=False)
    assert res.results[0].n_missing == 8 and res.results[0].n_gaps == 3

    t3 = np.arange(200) / 10.0
    t3[120] = t3[119]
    df3 = pd.DataFrame({"t_s": t3, "rate_dph": y})
    with pytest.raises(InputError, match=r"column 't_s', row 121: time stamps repeat"):
        W.prepare_log(_log(tmp_path, df3, name="rep.csv"))


def test_dtheta_and_theta_columns(tmp_path):
    # dtheta (arcsec per sample) / tau0 = rate in arcsec/s = deg/h; theta (cumulative)
    # with input angle gives the same deviations (1e-10: rounding of the cumulative sum).
    df, y = _white(8000, fs=10.0, seed=2)
    dth = y * 0.1
    theta = np.concatenate([[0.0], np.cumsum(dth)])
    d1 = W.prepare_log(_log(tmp_path, pd.DataFrame({"t_s": df["t_s"], "dtheta_arcsec": dth}),
                            "d.csv"))
    assert d1.unit == "dph"
    np.testing.assert_allclose(d1.values, y, rtol=1e-12)
    d2 = W.prepare_log(_log(tmp_path, pd.DataFrame({"t_s": np.arange(8001) / 10.0,
                                                     "theta_arcsec": theta}), "t.csv"),
                       input="angle")
    assert d2.input == "angle" and d2.unit == "dph"
    a1 = W.analyze(d1, fit_terms=False)
    a2 = W.analyze(d2, fit_terms=False)
    np.testing.assert_allclose(a2.results[0].dev, a1.results[0].dev, rtol=1e-10)


def test_accelerometer_log(tmp_path):
    n, fs = 40_000, 100.0
    y = np.random.default_rng(3).normal(0, 0.01, n)
    rec = _log(tmp_path, pd.DataFrame({"t_s": np.arange(n) / fs, "accel_mps2": y}))
    a = W.analyze(W.prepare_log(rec))
    assert a.kind == "accel" and a.terms.N.unit == "m/s/sqrt(h)"
    # white noise of per-sample std s: N = s/sqrt(fs) m/s/sqrt(s) = 60 s/sqrt(fs) m/s/sqrt(h)
    assert a.terms.N.value == pytest.approx(60 * 0.01 / math.sqrt(fs), rel=0.02)


def test_json_keys_single_and_multi():
    _, y = _white()
    a = W.analyze(y, rate_hz=10.0, unit="dph", stats="oadev")
    j = a.to_json()
    assert set(j) == ISSUE_KEYS
    assert set(j["noise_terms"]) == set("QNBKR")
    assert {"value", "unit", "ci"} <= set(j["noise_terms"]["N"])
    m = W.analyze(y, rate_hz=10.0, unit="dph", stats="oadev,tdev").to_json()
    assert set(m) == {"results"} and [r["statistic"] for r in m["results"]] == ["oadev", "tdev"]
    assert m["results"][1]["unit"] == "arcsec"
    # the terms are fitted on OADEV even when only MDEV is asked for
    only = W.analyze(y, rate_hz=10.0, unit="dph", stats=["mdev"])
    np.testing.assert_allclose(only.oadev.dev, oadev(y, rate_hz=10.0).dev, rtol=1e-15)


def test_parse_helpers():
    assert W.parse_stats("oadev, mdev,oadev") == ("oadev", "mdev")
    assert W.parse_taus("octave") == "octave" and W.parse_taus("12") == 12
    assert W.parse_taus("0.1,1,10") == [0.1, 1.0, 10.0]
    with pytest.raises(InputError, match="unknown statistic"):
        W.parse_stats("xdev")
    with pytest.raises(InputError, match="argument 'taus'"):
        W.parse_taus("often")


def test_unknown_unit_and_bad_column(tmp_path):
    df, _ = _white(100)
    rec = _log(tmp_path, df)
    with pytest.raises(InputError, match="no such column"):
        W.prepare_log(rec, column="rate_dps")
    with pytest.raises(InputError):
        W.analyze(np.ones(10), rate_hz=1.0, unit="parsec")


def test_auto_chunked_for_large_memmaps(tmp_path, monkeypatch):
    # A memory-mapped log above CHUNKED_MIN samples takes the out-of-core path; its
    # numbers equal the in-memory path to 1e-12 (same angle values, other summation).
    from inertialab.noise.statistics import _phase as A

    monkeypatch.setattr(W, "CHUNKED_MIN", 10_000)
    monkeypatch.setattr(A, "CHUNK", 8192)
    monkeypatch.setattr(A, "CHECKPOINT", 1024)
    y = np.random.default_rng(4).normal(0, 1, 60_000)
    np.save(tmp_path / "y.npy", y)
    mm = np.load(tmp_path / "y.npy", mmap_mode="r")
    calls = []
    real = A._PhaseFromRate

    class Spy(real):
        def __init__(self, *a, **k):
            calls.append(1)
            super().__init__(*a, **k)

    monkeypatch.setattr(A, "_PhaseFromRate", Spy)
    a = W.analyze(mm, rate_hz=50.0, unit="dph", stats="oadev,mdev")
    b = W.analyze(y, rate_hz=50.0, unit="dph", stats="oadev,mdev")
    assert calls  # the chunked source was used for the memmap
    for ra, rb in zip(a.results, b.results):
        np.testing.assert_allclose(ra.dev, rb.dev, rtol=1e-12)


def test_verbs_are_the_workflow_functions():
    assert W.prepare is W.prepare_log and W.fit is W.analyze


# ------------------------------------------------------------------ clock inputs

NBS14_Y = np.array([892.0, 809.0, 823.0, 798.0, 671.0, 644.0, 883.0, 903.0, 677.0])


def test_clock_units_end_to_end():
    # fractional frequency given in ppb, in Hz around a 10 MHz nominal, or dimensionless:
    # the same deviations (dimensionless), TDEV/MTIE in s, no IMU terms, bias on
    y = NBS14_Y * 1e-9
    ref = W.analyze(W.clock_log(y, input="frequency", unit="1", rate_hz=1.0),
                    stats="oadev,tdev,mtotdev,mtie", taus=[1.0, 2.0], alpha=0)
    assert ref.terms is None and ref.settings["bias_correction"] is True
    assert [ref.dev_unit(r.statistic) for r in ref.results] == ["1", "s", "1", "s"]
    np.testing.assert_allclose(ref.result("oadev").dev, [91.22945e-9, 85.95287e-9], rtol=1e-6)
    # published NBS14 MTOTDEV with the white-FM bias correction (SP 1065 Table 30)
    np.testing.assert_allclose(ref.result("mtotdev").dev, [75.50203e-9, 75.83606e-9],
                               rtol=1e-6)
    for values, unit, nominal in ((NBS14_Y, "ppb", None),
                                  (10e6 * (1 + y), "hz", 10e6)):
        a = W.analyze(W.clock_log(values, input="frequency", unit=unit, rate_hz=1.0,
                                  nominal_hz=nominal),
                      stats="oadev,tdev,mtotdev,mtie", taus=[1.0, 2.0], alpha=0)
        for r, q in zip(a.results, ref.results):
            np.testing.assert_allclose(r.dev, q.dev, rtol=1e-6)
    with pytest.raises(InputError, match="nominal"):
        W.clock_log(NBS14_Y, input="frequency", unit="hz", rate_hz=1.0)
    with pytest.raises(InputError, match="not a time unit"):
        W.clock_log(NBS14_Y, input="phase", unit="ppm", rate_hz=1.0)
    # IMU terms are refused for a clock (its noise types are the per-tau alpha)
    with pytest.raises(InputError, match="IMU noise terms"):
        W.analyze(W.clock_log(y, input="frequency", unit="1", rate_hz=1.0), fit_terms=True)


def test_prepare_clock_any_column_and_rate(tmp_path):
    x = np.cumsum(NBS14_Y) * 1e-9
    df = pd.DataFrame({"MJD": np.arange(x.size) * 10.0, "TIC reading": x * 1e9})
    log = W.prepare_clock(df, {}, input="phase", column="tic reading", unit="ns", rate_hz=0.1)
    np.testing.assert_allclose(log.values, x, rtol=1e-15)
    assert log.unit == "1" and log.input == "angle" and log.kind == "clock"
    p = tmp_path / "clk.csv"
    pd.DataFrame({"t_s": np.arange(x.size) * 10.0, "phase_ns": x * 1e9}).to_csv(p, index=False)
    log2 = W.read_clock(p, input="phase")
    assert log2.column == "phase_ns" and log2.rate_hz == pytest.approx(0.1)
    np.testing.assert_allclose(log2.values, x, rtol=1e-12)
    with pytest.raises(InputError, match="no such column"):
        W.prepare_clock(df, {}, input="phase", column="nope", rate_hz=1.0)


def test_many_taus():
    y = np.random.default_rng(1).normal(size=5000)
    a = W.analyze(y, rate_hz=1.0, unit="dph", stats="oadev", taus=W.parse_taus("many"),
                  fit_terms=False)
    m = a.results[0].m
    assert 30 <= m.size <= 40 and m[0] == 1 and np.all(np.diff(m) > 0)


def test_clock_time_stamp_gaps_become_nan_and_are_reported(tmp_path):
    rng = np.random.default_rng(4)
    x = np.cumsum(rng.standard_normal(1200)) * 1e-9
    t = np.arange(1200) * 1.0
    keep = np.ones(1200, dtype=bool)
    keep[300:305] = False  # five samples lost: the stamps jump by 6 s
    p = tmp_path / "gap.csv"
    pd.DataFrame({"t_s": t[keep], "phase_s": x[keep]}).to_csv(p, index=False)
    log = W.read_clock(p, input="phase")
    assert log.values.size == 1200 and np.isnan(log.values[300:305]).all()
    assert log.rate_hz == pytest.approx(1.0)
    with pytest.warns(Warning, match="5 missing sample"):
        a = W.analyze(log, stats="oadev", taus="octave")
    j = a.to_json()
    assert j["n_gaps"] == 1 and j["n_missing"] == 5 and min(j["used_fraction"]) < 1.0
    with pytest.warns(Warning):
        md = W.analyze(log, stats="mdev,ohdev").to_json()["results"]
    assert [r["statistic"] for r in md] == ["mdev", "ohdev"]
    assert all(r["n_gaps"] == 1 and min(r["used_fraction"]) < 1.0 for r in md)
    with pytest.warns(Warning), pytest.raises(InputError, match="no gap-resistant form"):
        W.analyze(log, stats="totdev")
    bad = tmp_path / "off.csv"
    t2 = t.copy()
    t2[600:] += 0.4
    pd.DataFrame({"t_s": t2, "phase_s": x}).to_csv(bad, index=False)
    with pytest.raises(InputError, match="off the uniform grid"):
        W.read_clock(bad, input="phase")
