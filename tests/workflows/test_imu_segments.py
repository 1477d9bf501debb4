"""allan --imu's warm-up and stationarity hooks against simulated truth: a log whose
gyro carries a known exponential warm-up has it found, the one span cut from every axis
before fitting (and before the halves of a check on the second half); every axis gets a
stationarity verdict; a given span is cut as given."""

import math

import numpy as np
import pytest

from inertialab.sim.mems_presets import simulate
from inertialab.workflows.imu_drift import DriftOptions
from inertialab.workflows.imu_noise import analyse_imu


def _columns(warm: float = 0.0):
    cols = {}
    for j, ax in enumerate(("gx", "gy")):
        r = simulate("consumer-100hz", hours=0.5, seed=40 + j)
        y = r.y.copy()
        if ax == "gx" and warm:
            t = np.arange(y.size) / r.rate_hz
            y += warm * np.exp(-t / 200.0)
        cols[ax] = (f"{ax}_{r.unit}", y, r.unit)
    return cols, r.rate_hz


def test_a_known_warmup_is_found_cut_from_every_axis_and_reported():
    cols, fs = _columns(warm=400.0)  # deg/h on a 3-deg/h bias-instability gyro
    res = analyse_imu(cols, rate_hz=fs, terms=False)
    span = res.settings["warmup"]["span_s"]
    assert 200.0 <= span <= 1000.0 and res.settings["warmup"]["from"] == ["gx"]
    gx, gy = res.axis("gx"), res.axis("gy")
    assert gx.warmup["detected"] and gx.warmup["excluded_s"] == span
    assert not gy.warmup["detected"] and gy.warmup["excluded_s"] == span
    n_left = cols["gx"][1].size - round(span * fs)
    assert gx.deviation.n_samples == n_left and gy.deviation.n_samples == n_left
    d = gx.to_dict()
    assert d["warmup_s"] == gx.warmup["warmup_s"] and d["warmup"]["p_value"] < 0.01


def test_check_on_half_halves_what_remains_and_every_axis_has_a_verdict():
    cols, fs = _columns()
    opts = DriftOptions(horizons_s=(1.0, 10.0), check_on="half")
    res = analyse_imu(cols, rate_hz=fs, drift=opts, warmup="300")
    n_left = cols["gx"][1].size - round(300 * fs)
    for a in res.axes:
        assert a.deviation.n_samples == n_left // 2
        assert a.stationarity["verdict"] in ("stationary", "not stationary")
        ci = a.drift["predicted_rms_ci"]
        assert all(lo < p < hi for lo, p, hi in zip(ci["low"], a.drift["predicted_rms"],
                                                    ci["high"]))
        assert len(a.drift["check"]["inside_rms_ci"]) == 2
    assert res.table()[0][-1] == "stationary"


@pytest.mark.parametrize("setting", ["0", 0])
def test_warmup_zero_cuts_nothing(setting):
    cols, fs = _columns(warm=400.0)
    res = analyse_imu(cols, rate_hz=fs, terms=False, warmup=setting)
    assert res.settings["warmup"]["span_s"] == 0.0
    assert res.axis("gx").deviation.n_samples == cols["gx"][1].size
    assert math.isfinite(res.axis("gx").deviation.dev[0])
