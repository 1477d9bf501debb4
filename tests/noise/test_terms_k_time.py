"""The K term's Gauss–Markov correlation time and the short-end cut of the noise-term
fit (:mod:`inertialab.noise.terms.least_squares`): analytic shape, recovery on simulated records,
and nothing changed where the five-term model holds."""

from __future__ import annotations

import math

import numpy as np
import pytest

from inertialab.noise.statistics import allan as A
from inertialab.noise.terms.band import rw_gm_shape
from inertialab.noise.terms.fit import NoiseTerms, fit_noise_terms

RATE = 100.0


def _gm(n, s2, tc, rng):
    """Exact discrete first-order Gauss–Markov samples (variance ``s2``, time ``tc`` s)."""
    from scipy.signal import lfilter

    a = math.exp(-1.0 / (RATE * tc))
    e = rng.standard_normal(n) * math.sqrt(s2 * (1 - a * a))
    x = lfilter([1.0], [1.0, -a], e)
    return x + math.sqrt(s2) * rng.standard_normal() * a ** np.arange(1, n + 1)


def test_rw_gm_shape_is_the_gauss_markov_avar_and_a_random_walk_below_tc():
    # the Allan variance of a Gauss–Markov process of driving density q (El-Sheimy et al.
    # 2008, eq. for the exponentially correlated term), written independently:
    # q^2 T^2 / tau (1 - T/(2 tau) (3 - 4 e^-tau/T + e^-2tau/T)), and c_1 = q^2 / 3
    tc = 250.0
    tau = np.geomspace(0.01, 1e5, 60)
    ref = (3.0 * tc**2 / tau) * (1 - tc / (2 * tau) * (3 - 4 * np.exp(-tau / tc)
                                                       + np.exp(-2 * tau / tc)))
    ok = tau > 25.0  # the closed form cancels below; the series takes over there
    np.testing.assert_allclose(rw_gm_shape(tau, tc)[ok], ref[ok], rtol=1e-7)
    np.testing.assert_allclose(rw_gm_shape(tau[:10], tc), tau[:10], rtol=2e-3)
    np.testing.assert_allclose(rw_gm_shape(tau, math.inf), tau)


@pytest.mark.parametrize("seed", [0, 1])
def test_k_time_found_on_a_random_walk_that_turns_over(seed):
    # white noise + a Gauss–Markov wander (T = 300 s) over 3 h at 100 Hz: the curve rises
    # like a random walk from ~20 s and turns over near 570 s
    rng = np.random.default_rng(seed)
    n, sig_w, tc, q = 1_080_000, 0.02, 300.0, 0.002
    s2 = q * q * tc / 2.0
    y = sig_w * rng.standard_normal(n) + _gm(n, s2, tc, rng)
    t = fit_noise_terms(A.oadev(y, rate_hz=RATE, taus="octave"), unit="mps2", kind="accel",
                        n_boot=50, seed=seed)
    assert t.k_gm is not None and "gauss_markov" in t.K.flags
    assert 300.0 / 2.5 <= t.k_gm["t_s"] <= 300.0 * 2.5
    # K in m/s^2/sqrt(h) is the driving density q (m/s^2/sqrt(s)) x 60
    assert t.K.value == pytest.approx(q * 60.0, rel=0.35)
    assert t.N.value == pytest.approx(sig_w / math.sqrt(RATE) * 60.0, rel=0.03)
    d = t.to_dict()
    assert d["k_gm"] == t.k_gm and NoiseTerms.from_dict(d).to_dict() == d
    # the model curve turns over with the data: inside 2 sigma at the longest fitted tau
    r = A.oadev(y, rate_hz=RATE, taus="octave")
    i = int(np.argmin(abs(np.asarray(r.taus_s) - t.tau_range_s[1])))
    assert abs(math.log(t.model_dev(r.taus_s[i]) / r.dev[i])) < 2 * math.sqrt(2 / r.edf[i])


def test_pure_random_walk_keeps_an_infinite_time_and_the_first_tau():
    # white + random walk: no K time, and the fit keeps every tau (nothing to cut)
    rng = np.random.default_rng(3)
    n = 1_080_000
    y = 0.02 * rng.standard_normal(n) + np.cumsum(rng.standard_normal(n)) * 0.002 / math.sqrt(RATE)
    r = A.oadev(y, rate_hz=RATE, taus="octave")
    t = fit_noise_terms(r, unit="mps2", kind="accel", n_boot=0)
    assert t.k_gm is None
    assert t.tau_range_s[0] == pytest.approx(r.taus_s[0])
    assert t.K.value == pytest.approx(0.002 * 60.0, rel=0.35)


def test_short_taus_the_model_cannot_hold_are_cut():
    # white noise + a fast Gauss–Markov component (T = 2 samples) that bends the first
    # octaves by ~1-3 % where their EDFs give +-0.3 %: those taus are left out, and N is
    # read where the curve is white (white + the fast process's white equivalent 2 s2 T)
    rng = np.random.default_rng(5)
    n, sig_w, s2, tc = 1_080_000, 0.02, 0.01**2, 0.02
    y = sig_w * rng.standard_normal(n) + _gm(n, s2, tc, rng)
    r = A.oadev(y, rate_hz=RATE, taus="octave")
    t = fit_noise_terms(r, unit="mps2", kind="accel", n_boot=0)
    assert t.tau_range_s[0] >= 0.04
    n_eq = math.sqrt(sig_w**2 / RATE + 2 * s2 * tc) * 60.0
    assert t.N.value == pytest.approx(n_eq, rel=0.02)


def test_a_shared_rise_is_named_by_one_term():
    # industrial-400hz seed 4 (10 h): the curve rises significantly after its minimum;
    # fitted together, K and R share the rise and neither is significant. The one-term
    # models are compared and K (the truth: a random walk of 2.0 deg/h/sqrt(h), no ramp
    # beyond the temperature's) is named, with an interval that holds the truth
    from inertialab.sim import mems_presets as MP

    run = MP.simulate("industrial-400hz", hours=10.0, seed=4)
    r = A.oadev(run.y, rate_hz=run.rate_hz, taus="octave", confidence=0.95)
    t = fit_noise_terms(r, unit=run.unit, kind=None, seed=0)
    truth = run.truth["K"]["value"]
    assert "upper_bound" not in t.K.flags and t.K.ci[0] > 0
    assert t.K.ci[0] <= truth <= t.K.ci[1]
    assert t.R.value == 0 and "not_selected" in t.R.flags and t.R.upper_bound > 0
