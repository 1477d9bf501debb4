"""GMWM (issue 14 item 6): wavelet variance, latent-process fit, WIC selection, intervals."""

from __future__ import annotations

import math

import numpy as np
import pytest

from inertialab.errors import InputError
from inertialab.noise import allan as A
from inertialab.noise import gmwm as G
from inertialab.noise.terms import fit_noise_terms


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
