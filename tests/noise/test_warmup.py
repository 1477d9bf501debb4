"""Warm-up detection against simulated truth: a known exponential start on a MEMS log
is found and ends where it fades into the noise; stationary logs (ramp and random walk
included) report none; one span per log is the latest end over its series."""

import math

import numpy as np
import pytest

from inertialab.errors import InputError
from inertialab.noise.segments.warmup import block_means, detect_warmup, log_warmup
from inertialab.sim.mems_presets import simulate


def _log(seed=0, hours=1.0):
    r = simulate("consumer-100hz", hours=hours, seed=seed)
    return r.y, r.rate_hz


def _block_sd(y, fs, bs):
    _, m = block_means(y, fs, bs)
    return float(np.std(np.diff(m)) / math.sqrt(2.0))


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_a_stationary_log_has_no_warmup(seed):
    y, fs = _log(seed)
    w = detect_warmup(y, fs)
    assert not w.detected and w.warmup_s == 0.0 and w.p_value >= 0.01


def test_a_known_exponential_warmup_is_found_and_ends_near_where_it_fades():
    y, fs = _log(3)
    w0 = detect_warmup(y, fs)
    sd = _block_sd(y, fs, w0.block_s)
    t = np.arange(y.size) / fs
    tc = 300.0
    w = detect_warmup(y + 30.0 * sd * np.exp(-t / tc), fs)
    assert w.detected and w.p_value < 1e-3
    assert w.offset > 0  # the first window above the next
    # it fades to one block sd at tc ln 30 = 1020 s; found between 1 and 4 time constants
    assert tc <= w.warmup_s <= 4 * tc


def test_a_linear_ramp_is_not_a_warmup():
    y, fs = _log(4)
    t = np.arange(y.size) / fs
    sd = _block_sd(y, fs, detect_warmup(y, fs).block_s)
    w = detect_warmup(y + 50.0 * sd * t / t[-1], fs)
    assert not w.detected


def test_one_span_per_log_is_the_latest_end_and_a_given_span_is_kept():
    y, fs = _log(5)
    t = np.arange(y.size) / fs
    sd = _block_sd(y, fs, detect_warmup(y, fs).block_s)
    a = y + 40.0 * sd * np.exp(-t / 200.0)
    b = y[::-1].copy()
    info = log_warmup({"gx": a, "gy": b}, fs)
    assert info["by"]["gx"]["detected"] and not info["by"]["gy"]["detected"]
    assert info["span_s"] == info["by"]["gx"]["warmup_s"] and info["from"] == ["gx"]
    assert info["n_samples"] == round(info["span_s"] * fs)
    given = log_warmup({"gx": a}, fs, setting="120")
    assert given["span_s"] == 120.0 and given["by"]["gx"]["detected"]


@pytest.mark.parametrize("bad", ["soon", "-5", "nan"])
def test_a_bad_warmup_setting_is_refused(bad):
    y, fs = _log(0, hours=0.2)
    with pytest.raises(InputError, match="argument 'warmup'"):
        log_warmup({"gx": y}, fs, setting=bad)


def test_a_warmup_over_half_the_log_is_refused():
    y, fs = _log(0, hours=0.2)
    with pytest.raises(InputError, match="less than half"):
        log_warmup({"gx": y}, fs, setting=str(0.6 * y.size / fs))
