"""Tests of inertialab.noise.spectral.wavelet (spec 001 §3.6, check 10)."""

import warnings

import numpy as np
import pytest
import pywt

from inertialab.errors import DataQualityWarning, InputError
from inertialab.noise.spectral.wavelet import (
    approximation_band_hz,
    decompose,
    detail_band_hz,
    select_level,
)

# The db4 reconstruction low-pass printed in spec 001 §3.6 (agrees with pywt to ~5e-13).
SPEC_DB4 = [0.23037781330885523, 0.7148465705525415, 0.6308807679295904,
            -0.02798376941698385, -0.18703481171888114, 0.030841381835986965,
            0.032883011666982945, -0.010597401784997278]


def test_db4_filters_match_spec_table():
    # tolerance 1e-12: the spec's printed digits differ from pywt by up to 5e-13
    w = pywt.Wavelet("db4")
    np.testing.assert_allclose(w.rec_lo, SPEC_DB4, atol=1e-12)
    h = np.asarray(w.rec_lo)
    g = np.array([(-1) ** n * h[7 - n] for n in range(8)])
    np.testing.assert_allclose(w.rec_hi, g, atol=1e-15)
    assert abs(h.sum() - np.sqrt(2)) < 1e-12 and abs(h @ h - 1) < 1e-12


def test_perfect_reconstruction_identity():
    # x = A_L + sum_{j<=L} D_j to 1e-9 rms (check 10); rounding gives ~1e-15
    rng = np.random.default_rng(1)
    x = np.cumsum(rng.normal(size=20_001)) + rng.normal(size=20_001)
    dec = decompose(x, level=10)
    assert dec.level == 10
    rms = np.sqrt(np.mean(x**2))
    for L in (1, 6, 10):
        s = dec.approximation(L) + sum(dec.detail(j) for j in range(1, L + 1))
        assert np.sqrt(np.mean((s - x) ** 2)) <= 1e-9 * rms
        np.testing.assert_allclose(dec.details_sum(L), x - dec.approximation(L),
                                   atol=1e-9 * rms)
    np.testing.assert_allclose(dec.approximation(0), x, atol=1e-9 * rms)


def test_approximation_is_wrcoef_by_hand():
    # independent construction of MATLAB wrcoef('a', ..., 6): zero details 1..6, waverec
    rng = np.random.default_rng(2)
    x = rng.normal(size=9000)
    c = pywt.wavedec(x, "db4", mode="symmetric", level=10)
    c2 = [c[0]] + [c[i] if i <= 10 - 6 else np.zeros_like(c[i]) for i in range(1, 11)]
    ref = pywt.waverec(c2, "db4", mode="symmetric")[: x.size]
    np.testing.assert_allclose(decompose(x).approximation(6), ref, rtol=0, atol=1e-12)
    # detail 3 alone
    c3 = [np.zeros_like(a) for a in c]
    c3[10 + 1 - 3] = c[10 + 1 - 3]
    ref3 = pywt.waverec(c3, "db4", mode="symmetric")[: x.size]
    np.testing.assert_allclose(decompose(x).detail(3), ref3, atol=1e-12)


def test_approximation_passes_low_frequency_and_removes_high():
    # a 0.05 Hz sine at fs = 200 Hz lies well inside the A_6 band [0, 1.56 Hz];
    # a 60 Hz sine lies in D_1 (50-100 Hz): A_6 keeps the first (<1 %), drops the second (<1 %)
    fs = 200.0
    t = np.arange(2**16) / fs
    lo = np.sin(2 * np.pi * 0.05 * t)
    hi = np.sin(2 * np.pi * 60.0 * t)
    a6 = decompose(lo + hi).approximation(6)
    inner = slice(2000, -2000)  # away from the boundary extension
    assert np.sqrt(np.mean((a6[inner] - lo[inner]) ** 2)) < 0.01
    assert approximation_band_hz(6, fs) == (0.0, 200.0 / 128)
    assert detail_band_hz(1, fs) == (50.0, 100.0)


def test_short_signal_lowers_level_with_warning():
    # N < 7168 cannot carry 10 db4 levels (spec §3.6): J is lowered with a warning
    x = np.random.default_rng(3).normal(size=3000)
    with pytest.warns(DataQualityWarning, match="levels"):
        dec = decompose(x, level=10)
    assert dec.level == pywt.dwt_max_level(3000, 8) == 8
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert decompose(np.zeros(7168), level=10).level == 10


def test_bad_input():
    with pytest.raises(InputError):
        decompose(np.array([1.0, np.nan, 2.0] * 100))
    with pytest.raises(InputError):
        decompose(np.ones(4))
    with pytest.raises(InputError):
        decompose(np.ones(9000)).approximation(11)


def test_select_level_on_step_plus_white_noise():
    # bias step of 5 (units) in the window, white noise std 1 at fs 200: delta_j is the
    # rms of D_{j+1} on W over the retained step; for white noise the detail rms is
    # sigma / 2^((j+1)/2), so delta_j <= 0.14 first at j with 2^(-(j+1)/2)/5 <= 0.14,
    # i.e. 2^((j+1)/2) >= 1.43 -> j = 1; with noise 10 the rule needs 2^((j+1)/2) >= 14.3
    # -> j + 1 >= 7.7 -> j = 7 (computed here, not tuned)
    rng = np.random.default_rng(4)
    n = 3 * 40_000
    x = 10.0 * rng.normal(size=n)
    x[40_000:80_000] += 5.0
    W = slice(41_000, 79_000)
    P1 = slice(0, 40_000)
    sel = select_level(x, window=W, reference=P1)
    assert set(sel.delta) == set(range(3, 10))
    assert sel.level == min(j for j, d in sel.delta.items() if d <= 0.14)
    assert sel.level == 7
    # delta of white noise falls by about 2^(-1/2) per level (spec §3.6), within 15 %
    r = sel.delta[5] / sel.delta[4]
    assert 0.6 < r < 0.82
    # detail power in P1 of white noise std 10: sigma^2 / 2^j within 10 % for j <= 6
    for j in range(1, 7):
        assert abs(sel.detail_power_reference[j] / (100.0 / 2**j) - 1) < 0.1


def test_select_level_returns_upper_end_when_rule_not_met():
    rng = np.random.default_rng(5)
    x = rng.normal(size=60_000)  # no step: delta_j ~ 1 everywhere
    sel = select_level(x, window=slice(20_000, 40_000), reference=slice(0, 20_000))
    assert not sel.rule_met and sel.level == 9
