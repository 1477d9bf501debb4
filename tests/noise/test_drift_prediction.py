"""Integrated error predicted from a noise model (noise.terms.drift_prediction) against its
closed form and a Monte Carlo of each process."""

import math

import numpy as np
import pytest
from scipy.signal import lfilter

from inertialab.errors import InputError
from inertialab.noise.terms.drift_prediction import (
    Component,
    check_prediction,
    component_variance,
    kalibr_reading,
    observed_error,
    predict,
)

FS, W, H = 50.0, 10.0, (1.0, 10.0, 60.0)


def _mc_ratio(y, comps):
    p = predict(comps, H, W, FS)
    obs = np.array([math.sqrt(np.mean(observed_error(y, FS, h, W) ** 2)) for h in H])
    return obs / p.rms


def test_white_closed_form_and_monte_carlo():
    # N^2 (t + t^2/W): the integral of the window weights squared
    assert component_variance(Component("white", "N", 4.0), 5.0, 10.0, FS) == 4.0 * 7.5
    rng = np.random.default_rng(0)
    y = rng.standard_normal(2_000_000) * 0.2 * math.sqrt(FS)
    np.testing.assert_allclose(_mc_ratio(y, [Component("white", "N", 0.04)]), 1, atol=0.05)


def test_random_walk_and_gauss_markov_against_monte_carlo():
    rng = np.random.default_rng(1)
    n = 2_000_000
    k = 0.01
    rw = np.cumsum(rng.standard_normal(n)) * k / math.sqrt(FS)
    np.testing.assert_allclose(_mc_ratio(rw, [Component("rw", "K", k * k)]), 1, atol=0.06)
    s2, tc = 0.04, 20.0
    a = math.exp(-1 / (tc * FS))
    gm = lfilter([math.sqrt(s2 * (1 - a * a))], [1, -a], rng.standard_normal(n))
    np.testing.assert_allclose(_mc_ratio(gm, [Component("gm", "B", s2, tc)]), 1, atol=0.06)


def test_band_is_its_gauss_markov_mixture():
    # the band's PSD is the log-uniform mixture it stands for: 40 discrete GMs
    lo, hi, q = 1.0, 300.0, 0.01
    ts = np.exp(np.linspace(math.log(lo), math.log(hi), 401))
    mids = np.sqrt(ts[1:] * ts[:-1])
    dl = np.diff(np.log(ts))
    for t in H:
        band = component_variance(Component("band", "B", q, lo, hi), t, W, FS)
        mix = sum(component_variance(Component("gm", "B", q * d, m), t, W, FS)
                  for m, d in zip(mids, dl))
        assert band == pytest.approx(mix, rel=0.01)


def test_ramp_and_check_inflation():
    t = np.arange(200_000) / FS
    y = 0.001 * t  # a pure ramp: e = R t (t+W)/2 in every window
    p = predict([Component("ramp", "R", 0.001)], H, W, FS)
    chk = check_prediction(p, y, FS)
    np.testing.assert_allclose(chk["ratio"], 1, rtol=1e-6)
    assert chk["coverage_95"] == [1.0, 1.0, 1.0]
    # a model with half the white density: the white term's inflation is ~2
    rng = np.random.default_rng(3)
    y = rng.standard_normal(1_000_000) * 0.2 * math.sqrt(FS)
    p = predict([Component("white", "N", 0.01)], H, W, FS)
    chk = check_prediction(p, y, FS)
    np.testing.assert_allclose(chk["inflation"]["N"], 2, rtol=0.06)
    np.testing.assert_allclose(chk["ratio"], 2, rtol=0.06)


def test_kalibr_reading():
    # sigma = N/sqrt(tau) + rising K sqrt(tau/3): N at 1 s, the +1/2 line at 3 s
    from inertialab.noise.statistics.allan import DeviationResult

    taus = np.geomspace(0.01, 1000, 21)
    dev = np.sqrt(0.04 / taus + 1e-4 * taus / 3)
    r = DeviationResult(statistic="oadev", tau0_s=0.01, taus_s=taus,
                        m=np.round(taus / 0.01).astype(int), dev=dev,
                        n_terms=np.ones(taus.size, int), alpha=np.zeros(taus.size, int),
                        edf=np.ones(taus.size), ci_low=dev, ci_high=dev, confidence=0.683,
                        n_samples=10**6)
    n, k = kalibr_reading(r)
    assert n == pytest.approx(math.sqrt(0.04 + 1e-4 / 3), rel=1e-9)
    assert k == pytest.approx(0.01, rel=0.02)  # the line on the rising part: K


def test_bad_arguments():
    with pytest.raises(InputError, match="horizons_s"):
        predict([], [0.0], W, FS)
    with pytest.raises(InputError, match="bias_window_s"):
        predict([], [1.0], float("nan"), FS)
