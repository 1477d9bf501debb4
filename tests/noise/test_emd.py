"""Tests of inertialab.noise.spectral.emd (spec 001 §3.5): optional EMD view."""

import numpy as np
import pytest

from inertialab.noise.spectral.emd import emd, hilbert_frequency, pyemd_available


def _two_tones(n=4000, fs=100.0):
    t = np.arange(n) / fs
    return t, np.sin(2 * np.pi * 10.0 * t), 0.8 * np.sin(2 * np.pi * 1.0 * t)


def test_builtin_sum_identity_and_tone_separation():
    # x = sum(IMFs) + residue exactly; two well-separated tones (10 Hz, 1 Hz): the first
    # IMF is the 10 Hz tone (rms error < 5 % of its amplitude away from the edges)
    # and its Hilbert frequency is 10 Hz within 2 %
    fs = 100.0
    t, fast, slow = _two_tones(fs=fs)
    x = fast + slow
    r = emd(x, backend="builtin")
    np.testing.assert_allclose(r.imfs.sum(0) + r.residue, x, atol=1e-12)
    assert 1 <= r.imfs.shape[0] <= 10 and all(1 <= k <= 10 for k in r.n_sifts)
    inner = slice(300, -300)
    assert np.sqrt(np.mean((r.imfs[0][inner] - fast[inner]) ** 2)) < 0.05
    f0 = hilbert_frequency(r.imfs[:1], fs)[0][inner]
    assert abs(np.median(f0) - 10.0) < 0.2


def test_builtin_respects_imf_cap():
    x = np.random.default_rng(0).normal(size=3000)
    r = emd(x, backend="builtin", max_imfs=3)
    assert r.imfs.shape[0] == 3
    np.testing.assert_allclose(r.imfs.sum(0) + r.residue, x, atol=1e-10)


def test_pyemd_backend_or_clean_skip():
    if not pyemd_available():
        with pytest.raises(ImportError, match=r"inertialab\[emd\]"):
            emd(np.ones(100), backend="pyemd")
        pytest.skip("EMD-signal (the [emd] extra) is not installed")
    t, fast, slow = _two_tones()
    r = emd(fast + slow, backend="pyemd")
    np.testing.assert_allclose(r.imfs.sum(0) + r.residue, fast + slow, atol=1e-8)
