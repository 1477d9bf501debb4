"""Spectral lines (noise.spectral.lines) and their place in the noise-term fit."""

import math

import numpy as np
import pytest

from inertialab.noise.spectral.lines import Line, line_avar, spectral_lines
from inertialab.noise.statistics.allan import oadev
from inertialab.noise.terms.fit import NoiseTerms, fit_noise_terms


def _record(n=400_000, fs=100.0, f0=0.54, amp=0.8, seed=0):
    rng = np.random.default_rng(seed)
    t = np.arange(n) / fs
    return rng.standard_normal(n) + amp * np.sin(2 * np.pi * f0 * t + 0.3)


def test_line_frequency_and_amplitude_recovered():
    lines = spectral_lines(_record(), 100.0)
    assert len(lines) == 1
    assert lines[0].f_hz == pytest.approx(0.54, abs=0.006)  # one Welch bin
    assert lines[0].amplitude == pytest.approx(0.8, rel=0.05)


@pytest.mark.parametrize("kind", ["white", "random_walk", "flicker_like"])
def test_no_line_in_noise(kind):
    rng = np.random.default_rng(3)
    e = rng.standard_normal(400_000)
    if kind == "random_walk":
        e = np.cumsum(e) * 1e-2 + e
    elif kind == "flicker_like":  # a sum of AR(1) processes over three decades
        y = np.zeros_like(e)
        for tc in (10, 100, 1000, 10000):
            a = math.exp(-1 / tc)
            from scipy.signal import lfilter
            y += lfilter([math.sqrt(1 - a * a)], [1, -a], rng.standard_normal(e.size))
        e = e + y
    assert spectral_lines(e, 100.0) == ()


def test_line_avar_is_ieee_sinusoid():
    # sigma^2 = A^2 sin^4(pi f tau)/(pi f tau)^2, checked against the Allan variance of a
    # noise-free sinusoid at taus well below the sample rate
    fs, f0, amp = 1000.0, 0.7, 2.0
    t = np.arange(2_000_000) / fs
    y = amp * np.sin(2 * np.pi * f0 * t)
    r = oadev(y, rate_hz=fs, taus=[0.1, 0.3, 0.5, 1.0])
    ln = Line(f_hz=f0, variance=amp**2 / 2, ratio=np.inf)
    np.testing.assert_allclose(r.dev**2, line_avar(r.taus_s, [ln]), rtol=0.01)


def test_fit_with_line_keeps_n_and_models_the_bump():
    # white noise + a line: without the line the fit bends N towards the bump; with it N
    # is the white density within 1 % and the model (terms + line) follows the curve
    fs = 100.0
    y = _record(fs=fs)
    r = oadev(y, rate_hz=fs, taus="octave", confidence=0.95)
    lines = spectral_lines(y, fs)
    t = fit_noise_terms(r, unit="dps", lines=lines, n_boot=0)
    n_true = 1.0 / math.sqrt(fs)  # deg/s sqrt(s)
    assert math.sqrt(t.coefficients[1]) == pytest.approx(n_true, rel=0.01)
    sel = (r.taus_s >= t.tau_range_s[0]) & (r.taus_s <= t.tau_range_s[1])
    md = t.model_dev(r.taus_s[sel])
    short = r.taus_s[sel] < 10  # the line's region (its bump is at 0.37/f0 = 0.7 s)
    assert np.all(np.abs(md[short] / r.dev[sel][short] - 1) < 0.01)
    t0 = fit_noise_terms(r, unit="dps", n_boot=0)
    assert abs(math.sqrt(t0.coefficients[1]) / n_true - 1) > 0.02
    d = t.to_dict()
    assert d["lines"][0]["f_hz"] == pytest.approx(lines[0].f_hz)
    assert NoiseTerms.from_dict(d).to_dict() == d
