"""Tests of inertialab.noise.spectral.spectra (spec 001 §3.5)."""

import numpy as np
import pytest

from inertialab.errors import InputError
from inertialab.noise.spectral.spectra import alias_frequency, cwt_scalogram, welch_asd


def test_welch_floor_of_white_rate_noise_is_sqrt2_N():
    # two-sided PSD N^2 (native units) -> one-sided ASD sqrt(2) N (spec §3.3/§3.5);
    # white rate samples have variance N^2 fs. 2^18 samples, 2^14 segments -> ~31
    # segments x 8193 bins: the median over bins is within 2 % of the truth
    fs, N = 200.0, 0.6  # (deg/h) sqrt(s)
    x = np.random.default_rng(0).normal(0, N * np.sqrt(fs), 2**18)
    sp = welch_asd(x, fs)
    assert sp.nperseg == 2**14 and sp.freq_hz[-1] == fs / 2
    floor = np.median(sp.asd[1:-1])
    assert abs(floor / (np.sqrt(2) * N) - 1) < 0.02


def test_welch_sine_peak_location():
    fs = 200.0
    t = np.arange(2**15) / fs
    x = 3.0 * np.sin(2 * np.pi * 37.0 * t)
    sp = welch_asd(x, fs, nperseg=2**12)
    assert abs(sp.freq_hz[np.argmax(sp.asd)] - 37.0) <= fs / 2**12


def test_alias_frequency():
    # 500 Hz at fs = 200 lands on 100 Hz (spec §6.3); 450 -> 50; exact multiples of fs -> 0
    a = alias_frequency([500.0, 450.0, 400.0, 30.0], 200.0)
    np.testing.assert_allclose(a[0], [100.0, 50.0, 0.0, 30.0])
    np.testing.assert_allclose(a[1], [0.0, 100.0, 0.0, 60.0])
    np.testing.assert_allclose(a[2], [100.0, 50.0, 0.0, 90.0])


def test_scalogram_localises_a_burst_in_time_and_frequency():
    # 20 Hz burst in the middle third of a white-noise record: the power at the scale
    # nearest 20 Hz is >= 20x higher inside the burst than outside (amplitude 5 vs
    # noise std 0.5 -> SNR in that band is far above 20), and the peak scale is within
    # one scale step (96 log scales over 12 octaves = 8 per octave, 9 %) of 20 Hz
    fs = 200.0
    n = 3 * 2**14
    rng = np.random.default_rng(1)
    x = 0.5 * rng.normal(size=n)
    t = np.arange(n) / fs
    mid = (t >= t[n // 3]) & (t < t[2 * n // 3])
    x[mid] += 5.0 * np.sin(2 * np.pi * 20.0 * t[mid])
    sc = cwt_scalogram(x, fs, block=2**14, max_columns=300)
    assert sc.power.shape == (96, 300)
    assert sc.freq_hz[0] == pytest.approx(100.0) and sc.freq_hz[-1] == pytest.approx(fs / 2**12)
    i = int(np.argmin(np.abs(sc.freq_hz - 20.0)))
    cols_in = (sc.time_s > t[n // 3] + 5) & (sc.time_s < t[2 * n // 3] - 5)
    cols_out = (sc.time_s < t[n // 3] - 5) | (sc.time_s > t[2 * n // 3] + 5)
    assert sc.power[i, cols_in].mean() > 20 * sc.power[i, cols_out].mean()
    peak = sc.freq_hz[np.argmax(sc.power[:, cols_in].mean(axis=1))]
    assert abs(np.log2(peak / 20.0)) < 1 / 8 + 1e-9
    assert np.all(np.isfinite(sc.power_db))


def test_scalogram_blocks_equal_single_transform_away_from_edges():
    # block processing with discarded overlaps reproduces one transform of the whole
    # signal where the block edges are >= 10 % of a block from any kept sample; the
    # widest wavelet (f_min) is limited here so that its support fits in the overlap
    fs = 200.0
    x = np.random.default_rng(2).normal(size=40_000)
    kw = dict(f_min_hz=5.0, max_columns=40_000, n_scales=12)
    whole = cwt_scalogram(x, fs, block=2**17, **kw)
    blocks = cwt_scalogram(x, fs, block=2**13, **kw)
    np.testing.assert_allclose(blocks.power[:, 3000:-3000], whole.power[:, 3000:-3000],
                               rtol=1e-6, atol=1e-9)


def test_bad_input():
    with pytest.raises(InputError):
        welch_asd([1.0], 100.0)
    with pytest.raises(InputError):
        cwt_scalogram(np.ones(100), 0.0)
