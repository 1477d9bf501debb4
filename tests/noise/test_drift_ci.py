"""The drift RMS's interval (predicted_rms_ci) against analytic truth: a white-noise
model's interval is its N interval scaled; an upper-bound K widens the high side only;
measured non-stationarity and the observed RMS's window sampling add in the log of the
variance. Its coverage over seeds is measured by benchmarks/drift_check.py."""

import math
from types import SimpleNamespace

import numpy as np
import pytest
from scipy.special import exp1, polygamma

from inertialab.noise.terms.drift_prediction import (
    Component,
    component_variance,
    effective_windows,
    misfit_log_var,
    model_effective_windows,
    predict,
    predicted_rms_ci,
    window_covariances,
)

H = (1.0, 10.0, 60.0)


def _term(value, lo, hi, flags=(), ub=float("nan")):
    return SimpleNamespace(value=value, ci=(lo, hi), flags=flags, upper_bound=ub)


def _terms(**kw):
    nan = _term(0.0, 0.0, 0.0, ("not_observable",))
    return SimpleNamespace(**{k: kw.get(k, nan) for k in "QNBKR"})


def test_a_white_model_interval_is_its_n_interval_scaled():
    n = 0.2
    pred = predict([Component("white", "N", n * n)], H, 10.0, 100.0)
    terms = _terms(N=_term(n, n / 1.1, n * 1.1))
    ci = predicted_rms_ci(pred, terms)
    np.testing.assert_allclose(ci["low"], pred.rms / 1.1, rtol=1e-12)
    np.testing.assert_allclose(ci["high"], pred.rms * 1.1, rtol=1e-12)


def test_an_upper_bound_k_widens_only_the_high_side():
    n, k, ub = 0.2, 0.01, 0.03
    comps = [Component("white", "N", n * n), Component("rw", "K", k * k)]
    pred = predict(comps, H, 10.0, 100.0)
    terms = _terms(N=_term(n, n, n), K=_term(k, 0.0, ub, ("upper_bound",), ub))
    ci = predicted_rms_ci(pred, terms)
    v_k = pred.by_term["K"]
    np.testing.assert_allclose(ci["low"] ** 2, pred.rms ** 2 - v_k, rtol=1e-12)
    np.testing.assert_allclose(ci["high"] ** 2, pred.rms ** 2 + v_k * ((ub / k) ** 2 - 1),
                               rtol=1e-12)


def test_extra_spread_and_window_sampling_add_in_the_log_variance():
    n = 0.2
    pred = predict([Component("white", "N", n * n)], H, 10.0, 100.0)
    terms = _terms(N=_term(n, n, n))
    extra = np.array([0.0, 0.01, 0.04])
    nw = np.array([1000, 100, 20])
    ci = predicted_rms_ci(pred, terms, extra_log_var=extra, n_windows=nw)
    s = np.sqrt(extra + polygamma(1, nw / 2.0))
    np.testing.assert_allclose(ci["high"], pred.rms * np.exp(1.959963984540054 * s / 2),
                               rtol=1e-9)
    np.testing.assert_allclose(ci["low"] * ci["high"], pred.rms ** 2, rtol=1e-9)


def test_independent_windows_count_whole_and_shared_slow_noise_counts_less():
    rng = np.random.default_rng(0)
    e = rng.standard_normal(4000)
    assert effective_windows(e) > 0.7 * 4000
    slow = np.repeat(rng.standard_normal(40), 100) * 3.0  # 100 windows share one level
    assert effective_windows(e + slow) < 1000


def test_misfit_is_the_local_log_gap_between_model_and_curve():
    taus = np.array([1.0, 2.0, 4.0, 8.0, 16.0])
    res = SimpleNamespace(taus_s=taus, dev=np.array([1.0, 1.0, 1.2, 1.0, 1.0]),
                          edf=np.full(5, np.inf))
    terms = SimpleNamespace(model_dev=lambda t: np.ones_like(t), tau_range_s=(1.0, 16.0))
    v = misfit_log_var(res, terms, [1.0, 4.0])
    assert v[0] == pytest.approx((2 * math.log(1.0)) ** 2 / 2 + 0.0)
    # [2, 8]: 2, 4, 8 -> (2 ln 1.2)^2 / 3
    assert v[1] == pytest.approx((2 * math.log(1.2)) ** 2 / 3)
    # the curve's own sampling is not a misfit: with edf 50 the gap is less psi'(25)
    res.edf = np.full(5, 50.0)
    v = misfit_log_var(res, terms, [4.0])
    assert v[0] == pytest.approx(max((2 * math.log(1.2)) ** 2 - polygamma(1, 25.0), 0) / 3)


def _discrete_cross(cov_fn, t, w, fs, lag):
    """Cov(e_0, e_lag) of the sampled windows of observed_error, from the rate's
    autocovariance ``cov_fn(seconds)`` by the weight vectors (independent of the
    frequency-free closed form under test)."""
    nw, nt = int(round(w * fs)), int(round(t * fs))
    h = np.r_[np.full(nw, -nt / nw), np.ones(nt)] / fs
    i = np.arange(nw + nt)
    lag_s = (i[None, :] + lag * (nw + nt) - i[:, None]) / fs
    return float(h @ cov_fn(lag_s) @ h)


def test_gauss_markov_window_covariances_match_the_sampled_windows():
    t, w, tc, s2 = 20.0, 10.0, 30.0, 2.0
    c = window_covariances([Component("gm", "B", s2, tc)], t, w, 3)
    for k in (1, 2, 3):
        ref = _discrete_cross(lambda s: s2 * np.exp(-np.abs(s) / tc), t, w, 20.0, k)
        assert c[k - 1] == pytest.approx(ref, rel=0.01)
    assert c[0] < 0  # the bias window takes out the shared slow level: anti-correlated


def test_band_window_covariances_match_its_gauss_markov_mixture():
    t, w, q, lo, hi = 60.0, 10.0, 0.5, 5.0, 400.0

    def mix(s):  # q int_lo^hi exp(-s/T) dlnT = q (E1(s/hi) - E1(s/lo))
        s = np.maximum(np.abs(s), 1e-12)
        return q * (exp1(s / hi) - exp1(s / lo))

    c = window_covariances([Component("band", "B", q, lo, hi)], t, w, 2)
    for k in (1, 2):
        assert c[k - 1] == pytest.approx(_discrete_cross(mix, t, w, 5.0, k), rel=0.02)


def test_model_windows_white_and_random_walk_are_independent_and_a_line_is_one():
    comps = [Component("white", "N", 0.04), Component("rw", "K", 1e-4)]
    pred = predict(comps, H, 10.0, 100.0)
    np.testing.assert_allclose(model_effective_windows(pred, [500, 80, 20]),
                               [500, 80, 20], rtol=1e-12)
    # a line of period 2 (t + W): every window sees the same a^2 cos^2(phase), so the
    # mean square does not average over windows: Var(cos^2)/E(cos^2)^2 = 1/2, n_eff = 4
    f0 = 1.0 / (2 * (60.0 + 10.0))
    pred = predict([Component("line", "S", 1.0, f0)], [60.0], 10.0, 100.0)
    assert model_effective_windows(pred, [40])[0] == pytest.approx(4.0, rel=1e-9)
    # the same line under white noise, at a phase step that averages: n_eff ~ n
    f0 = 0.3183 / 70.0
    comps = [Component("white", "N", 0.04), Component("line", "S", 0.3, f0)]
    pred = predict(comps, [60.0], 10.0, 100.0)
    assert model_effective_windows(pred, [400])[0] > 300


def test_model_windows_of_a_line_match_a_monte_carlo_of_its_phase():
    rng = np.random.default_rng(3)
    t, w, n, f0, amp, nd = 60.0, 10.0, 30, 1.07 / 70.0, 0.5, 0.04
    comps = [Component("white", "N", nd), Component("line", "S", amp, f0)]
    pred = predict(comps, [t], w, 100.0)
    a = math.sqrt(2.0 * component_variance(comps[1], t, w, 100.0))  # m2 = a^2 / 2
    k = np.arange(n)
    phi = rng.uniform(0, 2 * np.pi, (20000, 1))
    e = a * np.cos(phi + 2 * np.pi * f0 * (t + w) * k) + rng.standard_normal(
        (20000, n)) * math.sqrt(nd * (t + t * t / w))
    ms = np.mean(e * e, axis=1)
    n_mc = 2 * np.mean(ms) ** 2 / np.var(ms)
    assert model_effective_windows(pred, [n])[0] == pytest.approx(n_mc, rel=0.05)
