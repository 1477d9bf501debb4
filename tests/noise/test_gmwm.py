"""GMWM: wavelet variance, latent-process fit, WIC selection, intervals."""

from __future__ import annotations

import math

import numpy as np
import pytest

from inertialab.errors import InputError
from inertialab.noise.gmwm import fit as G
from inertialab.noise.statistics import allan as A
from inertialab.noise.terms.fit import fit_noise_terms


def test_wavelet_variance_is_half_the_allan_variance_with_eta3_interval():
    y = np.random.default_rng(0).standard_normal(2**14)
    wv = G.wavelet_variance(y, 1.0, confidence=0.95)
    r = A.oadev(y, rate_hz=1.0, taus="octave")
    np.testing.assert_allclose(wv.wv, r.dev**2 / 2, rtol=1e-12)
    # white noise: WV(tau_j) = 1/(2m); eta3 = max((N - 2m + 1)/(2m), 1)
    assert wv.eta[0] == pytest.approx((2**14 - 1) / 2)
    assert np.all(wv.ci_low < wv.wv) and np.all(wv.wv < wv.ci_high)
    inside = (wv.ci_low <= 1 / (2 * wv.m)) & (1 / (2 * wv.m) <= wv.ci_high)
    assert inside.mean() >= 0.8


def _record(n, fs, seed, sigma=1.0, gms=((0.3, 50.0),), gamma=0.0):
    rng = np.random.default_rng(seed)
    y = sigma * rng.standard_normal(n)
    for s, tc in gms:
        phi = math.exp(-1 / (fs * tc))
        e = rng.standard_normal(n) * s * math.sqrt(1 - phi * phi)
        e[0] = rng.standard_normal() * s
        from scipy.signal import lfilter

        y += lfilter([1.0], [1.0, -phi], e)
    if gamma:
        y += np.cumsum(rng.standard_normal(n)) * gamma
    return y


def test_recovers_white_plus_gauss_markov_and_selects_it():
    fs, n = 10.0, 2**18
    y = _record(n, fs, 3, sigma=1.0, gms=((0.3, 50.0),))
    fit = G.fit_gmwm(y, fs, n_boot=10, max_gm=1)
    kinds = sorted(p.kind for p in fit.processes)
    assert kinds.count("GM") == 1 and "WN" in kinds, fit.name
    wn = next(p for p in fit.processes if p.kind == "WN")
    gm = next(p for p in fit.processes if p.kind == "GM")
    assert wn.params["sigma2"] == pytest.approx(1.0, rel=0.03)
    assert gm.params["tc_s"] == pytest.approx(50.0, rel=0.35)
    assert gm.params["s2"] == pytest.approx(0.09, rel=0.35)
    lo, hi = wn.ci["sigma2"]
    assert lo < wn.params["sigma2"] < hi
    # the WIC of the chosen model is the least of all candidates
    assert fit.wic == min(fit.candidates.values())
    d = fit.to_dict()
    assert d["model"] == fit.name and d["wv"]["m"][0] >= 1


@pytest.mark.slow
def test_gmwm_terms_through_fit_noise_terms_on_mems():
    # ~25 s (16 candidate models): slow-marked
    from inertialab.sim import mems_presets as MP

    run = MP.simulate("consumer-100hz", hours=2.0, seed=5)
    r = A.oadev(run.y, rate_hz=run.rate_hz)
    t = fit_noise_terms(r, unit=run.unit, method="gmwm", n_boot=10)
    assert t.method == "gmwm" and t.gmwm["model"].startswith("FL+")  # the filter was seen
    assert t.N.value == pytest.approx(run.truth["N"]["value"], rel=0.03)
    assert t.B.value == pytest.approx(run.truth["B"]["value"], rel=0.3)
    assert t.Q.value == 0.0 and "absent" in t.Q.flags and t.Q.reason
    w = fit_noise_terms(r, unit=run.unit, method="wls", n_boot=50)
    # agreement with the Allan fit within the intervals (N, B)
    for name in "NB":
        a, b = getattr(t, name), getattr(w, name)
        assert b.ci[0] <= a.value <= b.ci[1] or a.ci[0] <= b.value <= a.ci[1], name


def test_rejects_non_oadev_curves():
    y = np.random.default_rng(0).standard_normal(4096)
    with pytest.raises(InputError, match="overlapping Allan"):
        G.wv_from_curve(A.mdev(y, rate_hz=1.0))


def test_b_reads_only_the_flat_region_inside_the_fitted_scales():
    # B of a GM sum = max sigma_GM / 0.6643 over the fitted scales; a GM whose peak lies
    # beyond the record (it looks like random walk there) does not make B
    tau0 = 0.01
    gm_in = G.Process("GM", {"s2": 4.0, "tc_s": 10.0})
    gm_out = G.Process("GM", {"s2": 400.0, "tc_s": 1e6})
    m = np.geomspace(1, 1e8, 4000)
    peak = math.sqrt(gm_in.avar(m, tau0).max()) / G.BI_FACTOR
    assert G.b_of([gm_in], tau0, (0.1, 1e4)) == pytest.approx(peak, rel=1e-3)
    both = G.b_of([gm_in, gm_out], tau0, (0.1, 1e3))
    assert both < 1.5 * peak
    assert G.b_of([gm_in, gm_out], tau0) > 5 * peak  # unbounded: the far peak


def test_slow_gm_counts_as_random_walk_not_bias_instability():
    # a GM whose Allan peak (1.89 tc) is beyond half the fitted range behaves as a random
    # walk of density 2 s2/tc there: it goes into K (flag from_gm), not into B
    tau0, rng_s = 0.01, (0.3, 5000.0)
    fast = G.Process("GM", {"s2": 4.0, "tc_s": 20.0})
    slow = G.Process("GM", {"s2": 50.0, "tc_s": 4000.0})
    assert G.b_of([fast, slow], tau0, rng_s) == pytest.approx(G.b_of([fast], tau0, rng_s))
    assert G.k_of([fast, slow], tau0, rng_s) == pytest.approx(math.sqrt(2 * 50.0 / 4000.0))
    rw = G.Process("RW", {"gamma2": 1e-6})
    assert G.k_of([rw], tau0, rng_s) == pytest.approx(math.sqrt(1e-6 / tau0))
    # the small-tau Allan variance of the slow GM is that random walk's K^2 tau/3
    m = np.array([1000.0])
    k2 = 2 * 50.0 / 4000.0
    assert float(slow.avar(m, tau0)[0]) == pytest.approx(k2 * 10.0 / 3, rel=0.01)


def test_k_from_one_slow_gm_carries_its_correlation_time():
    # K read from one slow GM alone is a random walk held by that GM's time (the terms'
    # k_gm, as the five-term fit's): the K column's Allan shape is then the GM's own
    from inertialab.noise.gmwm.terms import _k_time
    from inertialab.noise.terms.band import rw_gm_shape

    rng_s = (0.3, 5000.0)
    fast = G.Process("GM", {"s2": 4.0, "tc_s": 20.0})
    slow = G.Process("GM", {"s2": 50.0, "tc_s": 4000.0})
    assert _k_time([fast, slow], rng_s, None) == {"t_s": 4000.0}
    assert _k_time([fast, slow, G.Process("RW", {"gamma2": 1e-6})], rng_s, None) is None
    assert _k_time([slow, G.Process("GM", {"s2": 9.0, "tc_s": 9000.0})], rng_s, None) is None
    assert _k_time([fast], rng_s, None) is None
    # K^2/3 times the held shape is the slow GM's Allan variance (1 % over 0.1-5000 s)
    tau0 = 0.01
    taus = np.geomspace(0.1, 5000.0, 30)
    k2 = 2 * 50.0 / 4000.0
    np.testing.assert_allclose(k2 / 3 * rw_gm_shape(taus, 4000.0),
                               slow.avar(taus / tau0, tau0), rtol=0.01)


def test_gm_correlation_time_capped_and_low_eta_scales_dropped():
    # white + random walk + a GM (tc 20 s) at 10 Hz, 2^19 samples
    # (14.6 h). The scales with eta3 < 3 (the last two) are not fitted, no GM correlation
    # time exceeds 1/8 of the longest fitted scale, and K comes from the random walk
    # (not traded for a long GM): within 15 % of the truth (measured seeds 0-2: +5.4 %,
    # +3.1 %, -1.7 %; one GM, tc 16-18 s).
    fs, n = 10.0, 2**19
    gamma = 0.01  # per-sample increment std: K = gamma sqrt(fs)
    for seed in range(3):
        y = _record(n, fs, seed, sigma=1.0, gms=((0.2, 20.0),), gamma=gamma)
        fit = G.fit_gmwm(y, fs, n_boot=0, max_gm=2)
        assert np.all(fit.wv.eta >= 3.0)
        full = G.wavelet_variance(y, fs)
        assert fit.wv.taus_s[-1] < full.taus_s[-1] and np.sum(full.eta < 3.0) >= 1
        for p in fit.processes:
            if p.kind == "GM":
                assert p.params["tc_s"] <= fit.tau_range_s[1] / 8 * (1 + 1e-9)
        k = G.k_of(fit.processes, 1 / fs, fit.tau_range_s)
        assert k == pytest.approx(gamma * math.sqrt(fs), rel=0.15), (seed, fit.name)


def test_drift_is_a_candidate_only_beside_a_random_walk():
    # a DR read instead of the RW on the last scales set K to 0
    specs = G._specs(3, True, True)
    assert any("DR" in s for s in specs)
    assert all("RW" in s for s in specs if "DR" in s)
    assert any("RW" in s and "DR" not in s for s in specs)


@pytest.mark.slow
def test_k_interval_covers_on_white_plus_random_walk():
    # The bootstrap draws the scales correlated (a random walk's octaves ~0.88) and the
    # fit weights them with the full covariance: over 20 seeded records of white + random
    # walk (2^18 samples at 1 Hz) the 95 % interval of K covers the truth in >= 17 and
    # the median |error| of K is below 15 % (~30 s).
    n, gamma = 2**18, 3e-3
    hits, errs = 0, []
    for seed in range(20):
        rng = np.random.default_rng(1000 + seed)
        y = rng.standard_normal(n) + np.cumsum(rng.standard_normal(n)) * gamma
        fit = G.fit_gmwm(y, 1.0, n_boot=30, max_gm=1, seed=seed, auto_range=False)
        assert "RW" in fit.name
        k = G.k_of(fit.processes, 1.0, fit.tau_range_s)
        errs.append(abs(k / gamma - 1))
        hits += fit.k_ci[0] <= gamma <= fit.k_ci[1]
    assert hits >= 17, hits
    assert np.median(errs) < 0.15


def test_absent_random_walk_reported_as_an_upper_bound():
    # for GMWM: white + one GM, no random walk. The WIC leaves the RW out;
    # K is reported absent with the interval [0, upper], the upper end of the
    # objective's profile in a random walk added, held within the curve
    fs, n = 10.0, 2**18
    y = _record(n, fs, 3, sigma=1.0, gms=((0.3, 50.0),))
    r = A.oadev(y, rate_hz=fs, taus="octave")
    t = fit_noise_terms(r, unit="dph", method="gmwm", n_boot=20, seed=1)
    assert "RW" not in t.gmwm["model"], t.gmwm["model"]
    k = t.K
    assert k.value == 0.0 and {"absent", "upper_bound"} <= set(k.flags) and not k.significant
    assert k.ci[0] == 0.0 and 0.0 < k.ci[1] == k.upper_bound and math.isfinite(k.ci[1])
    assert "upper bound" in k.reason
    # the bound (data unit, rate/sqrt(s)) is a random walk the curve allows: its AVAR
    # K^2 tau/3 at most 1.05^2 (G.K_SCATTER) times the observed AVAR at every fitted
    # scale, and reaching it at the last (where a walk would show first)
    ku = t.gmwm["k_upper"]
    taus, avar = np.array(t.gmwm["wv"]["taus_s"]), 2.0 * np.array(t.gmwm["wv"]["wv"])
    ratio = ku**2 * taus / 3.0 / avar
    assert 0.0 < ratio.max() <= G.K_SCATTER**2 * (1 + 1e-9)
    assert ratio[-1] > 0.5, ratio


def test_absent_random_walk_bound_covers_the_true_walk():
    # a faint rate random walk under white noise (2^15 samples at 10 Hz, gamma per
    # sample 1e-4 to 4e-4): where the WIC leaves the walk out, its upper bound (the
    # objective's profile in a random walk added) lies above the true K. Measured on 24
    # records (seeds 100-107): left out on 19, bound 1.1-7.0x the truth on all 19; the
    # bootstrap of the best model with a walk it replaces covered 15 of 19, one at
    # 4e-5 of the truth (gamma 2e-4, seed 106, among the cases below)
    fs = 10.0
    for gamma, seed in ((2e-4, 106), (4e-4, 104), (4e-4, 105), (4e-4, 106)):
        rng = np.random.default_rng(seed)
        y = rng.normal(0.0, 1.0, 2**15) + np.cumsum(rng.normal(0.0, gamma, 2**15))
        t = fit_noise_terms(A.oadev(y, rate_hz=fs, taus="octave"), unit="dph",
                            method="gmwm", n_boot=20, seed=1)
        assert "RW" not in t.gmwm["model"], (gamma, seed, t.gmwm["model"])
        k_true = gamma * math.sqrt(fs)  # rate unit per sqrt(s)
        assert t.gmwm["k_upper"] >= k_true, (gamma, seed, t.gmwm["k_upper"] / k_true)
            # in the report unit: deg/h per sqrt(h) = (deg/h per sqrt(s)) x sqrt(3600)
        assert t.K.upper_bound == pytest.approx(t.gmwm["k_upper"] * 60.0)


def test_absent_b_is_the_bound_from_the_curve():
    # white noise alone: GMWM selects no flicker or Gauss-Markov process, and B is the
    # curve's bound 1.05 min(ADEV)/0.664 (never a bare 0); under the six-axis rule too
    from inertialab.noise.terms._bounds import B_SCATTER, BI

    y = np.random.default_rng(2).normal(0.0, 1.0, 2**15)
    r = A.oadev(y, rate_hz=10.0, taus="octave")
    for rule in ("interval", "literal"):
        t = fit_noise_terms(r, unit="dph", method="gmwm", n_boot=20, seed=1, b_rule=rule)
        assert not any(p in t.gmwm["model"] for p in ("GM", "BL")), t.gmwm["model"]
        b = t.B
        assert "upper_bound" in b.flags and "absent" in b.flags, b.flags
        assert b.upper_bound == pytest.approx(B_SCATTER * float(np.min(r.dev)) / BI)


def test_absent_drift_reported_as_a_profile_upper_bound_that_covers():
    # for GMWM: white + random walk + a faint rate ramp the WIC leaves
    # out. R is reported absent with [0, upper], the upper end of the objective's profile
    # in the drift; the true ramp lies below the bound wherever the drift is left out
    # (measured: left out in 6 of 10 records, bound 2.5-4.6x the truth; at 2^17 samples
    # with up to 3 GMs, 11 of 12 bounds covered, the twelfth selected a GM, whose profile
    # was tighter)
    n, gamma, omega = 2**15, 3e-3, 1.7e-5  # omega: rate unit per sample at 1 Hz
    hits = absent = 0
    for seed in range(10):
        rng = np.random.default_rng(2000 + seed)
        y = (rng.standard_normal(n) + np.cumsum(rng.standard_normal(n)) * gamma
             + omega * np.arange(n))
        r = A.oadev(y, rate_hz=1.0, taus="octave")
        fit = G.fit_gmwm_curve(r, max_gm=1, n_boot=5, seed=seed)
        if "DR" not in fit.name:
            absent += 1
            hits += omega <= fit.r_upper
        if seed == 4:  # the drift is left out here by both the 1- and the 3-GM search
            t = fit_noise_terms(r, unit="dph", method="gmwm", n_boot=5, seed=seed).R
            assert "DR" not in fit.name and {"absent", "upper_bound"} <= set(t.flags)
            assert t.value == 0.0 and t.ci[0] == 0.0 and "upper bound" in t.reason
            # deg/h per sample at 1 Hz -> deg/h^2
            assert t.ci[1] == t.upper_bound == pytest.approx(fit.r_upper * 3600.0, rel=1e-9)
    assert absent >= 5, absent
    assert hits >= absent - 1, (hits, absent)


def test_band_limited_bias_instability_selected_and_recovered():
    # a bias instability spread over 2.6 decades (10 equal GMs, tc 5-2000 s; the shape of
    # real MEMS gyros and of the presets): the WIC prefers the 3-parameter BL process to
    # one or two GMs, and B (IEEE flat region) comes back within 3 % with the truth inside
    # its interval (measured over seeds 0-2 at 2^19 samples: BL selected in 3 of 3, B
    # -1.2 to +0.2 %)
    fs, n = 10.0, 2**18
    gms = [(0.15, tc) for tc in np.geomspace(5.0, 2000.0, 10)]
    truth = G.b_of([G.Process("GM", {"s2": s * s, "tc_s": tc}) for s, tc in gms], 1 / fs)
    y = _record(n, fs, 1, sigma=1.0, gms=gms)
    fit = G.fit_gmwm_curve(A.oadev(y, rate_hz=fs, taus="octave"), max_gm=2, n_boot=20, seed=1)
    assert "BL" in fit.name, fit.candidates
    bl = next(p for p in fit.processes if p.kind == "BL")
    assert bl.params["t_lo_s"] < 20.0 and bl.params["t_hi_s"] > 500.0
    b = G.b_of(fit.processes, 1 / fs, fit.tau_range_s)
    assert b == pytest.approx(truth, rel=0.03)
    assert fit.b_ci[0] <= truth <= fit.b_ci[1]
