"""Time stamps as they are: rate, jitter, gaps, dropped and repeated
samples measured against stamps built with known defects; resampling only when asked."""

import math

import numpy as np
import pytest

from inertialab.io import read_record
from inertialab.io.mapping import ReadOptions
from inertialab.io.timestamps import audit, resample_uniform


def test_counts_of_each_defect_are_exact():
    fs = 200.0
    t = np.arange(2000) / fs
    keep = np.ones(t.size, bool)
    keep[[500, 501, 502]] = False          # 3 samples dropped in one gap
    keep[1500] = False                     # 1 sample dropped
    t = t[keep]
    t = np.insert(t, 800, t[799])          # one repeated stamp
    a = audit(t)
    assert (a.n_gaps, a.n_dropped, a.n_repeated, a.n_out_of_order) == (2, 4, 1, 0)
    assert a.nominal_dt_s == pytest.approx(1 / fs, rel=1e-12)
    assert [g["missing"] for g in a.gaps] == [3, 1]
    assert a.gaps[0]["duration_s"] == pytest.approx(3 / fs, rel=1e-9)
    # mean rate over the span: (n - 1) samples in (1999 / fs) s
    assert a.mean_rate_hz == pytest.approx((a.n - 1) / (1999 / fs), rel=1e-12)
    assert a.jitter_s == pytest.approx(0.0, abs=1e-12) and not a.uniform


def test_jitter_matches_its_analytic_value():
    # stamps = k/fs + e_k, e_k ~ U(-j, j): a step's std is sqrt(2) * j / sqrt(3)
    fs, j, n = 400.0, 1e-4, 200_000
    rng = np.random.default_rng(11)
    t = np.arange(n) / fs + rng.uniform(-j, j, n)
    a = audit(t)
    assert a.jitter_s == pytest.approx(math.sqrt(2.0 / 3.0) * j, rel=0.01)
    assert a.jitter_max_s <= 2 * j and a.n_gaps == 0 and a.n_out_of_order == 0
    assert a.mean_rate_hz == pytest.approx(fs, rel=1e-6)


def test_out_of_order_is_counted():
    t = np.array([0.0, 0.01, 0.03, 0.02, 0.04, 0.05])
    a = audit(t)
    assert a.n_out_of_order == 1


def test_resample_is_exact_on_a_linear_signal_and_only_when_asked(tmp_path):
    rng = np.random.default_rng(3)
    t = np.cumsum(rng.uniform(0.009, 0.011, 300))
    t -= t[0]
    grid, vals = resample_uniform(t, {"x": 2.0 * t + 1.0}, 100.0)
    np.testing.assert_allclose(vals["x"], 2.0 * grid + 1.0, rtol=0, atol=1e-12)
    assert np.allclose(np.diff(grid), 0.01)
    p = tmp_path / "j.csv"
    p.write_text("t_s,rate_dph\n" + "".join(f"{a:.9f},{2 * a + 1:.9f}\n" for a in t))
    plain = read_record(p, "gyro_log")
    assert "resampled" not in plain.meta and len(plain.data) == 300
    assert plain.meta["timestamps"]["jitter_s"] > 1e-4
    rs = read_record(p, "gyro_log", options=ReadOptions(resample_hz=100.0))
    assert rs.meta["resampled"]["rate_hz"] == 100.0 and rs.meta["fs_hz"] == 100.0
    assert rs.meta["resampled"]["n_before"] == 300
    np.testing.assert_allclose(rs.data["rate_dph"], 2 * rs.data["t_s"] + 1, atol=2e-9)
    # the audit is of the stamps as recorded, before resampling
    assert rs.meta["timestamps"]["jitter_s"] == plain.meta["timestamps"]["jitter_s"]
