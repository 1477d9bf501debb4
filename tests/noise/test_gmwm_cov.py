"""Covariance of the Haar wavelet variance across scales: the spectral
integrals against the exact discrete Allan variances, Greenhall's EDF and a simulation."""

from __future__ import annotations

import math

import numpy as np
import pytest

from inertialab.noise.gmwm import fit as G
from inertialab.noise.gmwm.covariance import log_weights, wv_covariance
from inertialab.noise.statistics import allan as A
from inertialab.noise.statistics.edf import edf_greenhall


@pytest.mark.parametrize("proc, alpha", [
    (G.Process("WN", {"sigma2": 2.0}), 0),
    (G.Process("RW", {"gamma2": 0.5}), -2),
    (G.Process("QN", {"q2": 0.3}), 2),
    (G.Process("GM", {"s2": 1.5, "tc_s": 40.0}), None),
])
def test_wavelet_variance_and_edf_from_the_spectrum(proc, alpha):
    n, m = 2**20, 2.0 ** np.arange(0, 17)
    nu2, cov = wv_covariance([proc], m, n, 1.0)
    exact = proc.avar(m, 1.0) / 2.0  # independent closed forms (time domain)
    np.testing.assert_allclose(nu2, exact, rtol=2e-3)
    if alpha is None:
        return
    # equivalent degrees of freedom 2 nu^4/Var against Greenhall's EDF where both are
    # asymptotic (m from 64 to N/256; Greenhall averages the phase over tau0, which
    # raises the white-noise EDF by up to 17 % at m = 1 and 3 % at m = 32)
    edf = 2.0 * nu2**2 / np.diag(cov)
    gh = np.array([edf_greenhall("oadev", n + 1, int(k), alpha) for k in m])
    sel = (m >= 64) & (m <= n / 256)
    np.testing.assert_allclose(edf[sel], gh[sel], rtol=0.02)


def test_cross_scale_covariance_matches_simulation():
    """White + random walk (mixed at the middle scales): the analytic covariance of the
    WV estimators against 400 simulated records of 2^13 samples."""
    n, reps = 2**13, 400
    procs = [G.Process("WN", {"sigma2": 1.0}), G.Process("RW", {"gamma2": 1e-3})]
    m = 2.0 ** np.arange(0, 9)
    rng = np.random.default_rng(11)
    wv = np.empty((reps, m.size))
    for i in range(reps):
        y = rng.standard_normal(n) + np.cumsum(rng.standard_normal(n)) * math.sqrt(1e-3)
        r = A.oadev(y, rate_hz=1.0, taus=[int(k) for k in m], alpha=0)
        wv[i] = r.dev**2 / 2.0
    nu2, cov = wv_covariance(procs, m, n, 1.0)
    np.testing.assert_allclose(wv.mean(0), nu2, rtol=0.1)
    sim_cov = np.cov(wv.T)
    # standard deviations within 15 % (400 records: sampling error ~ 4-10 %)
    np.testing.assert_allclose(np.sqrt(np.diag(sim_cov)), np.sqrt(np.diag(cov)), rtol=0.15)
    c_sim = sim_cov / np.sqrt(np.outer(np.diag(sim_cov), np.diag(sim_cov)))
    c_an = cov / np.sqrt(np.outer(np.diag(cov), np.diag(cov)))
    assert np.max(np.abs(np.diag(c_sim, 1) - np.diag(c_an, 1))) < 0.12
    assert np.max(np.abs(np.diag(c_sim, 2) - np.diag(c_an, 2))) < 0.12
    # random walk: adjacent octaves strongly correlated (~0.88), white ~0.5
    assert np.diag(c_an, 1)[-1] > 0.8 and 0.4 < np.diag(c_an, 1)[1] < 0.6


def test_log_weights_whiten_the_log_moments():
    procs = [G.Process("WN", {"sigma2": 1.0}), G.Process("RW", {"gamma2": 1e-6})]
    m = 2.0 ** np.arange(0, 14)
    bias, linv, eta, corr = log_weights(procs, m, 2**18, 1.0)
    from scipy.special import polygamma

    sd = np.sqrt(polygamma(1, eta / 2))
    S = corr * np.outer(sd, sd)
    np.testing.assert_allclose(linv @ S @ linv.T, np.eye(m.size), atol=1e-6)
    # E ln(chi2(eta)/eta) ~ -1/eta for large eta
    np.testing.assert_allclose(bias[eta > 50], -1.0 / eta[eta > 50], rtol=0.05)


def test_full_weighting_recovers_white_plus_random_walk():
    # weighting="full" (Guerrier's Omega = inverse full covariance of the log moments)
    # on white + random walk, 2^18 samples: sigma2 within 2 %, K within 25 %
    n, gamma = 2**18, 3e-3
    rng = np.random.default_rng(5)
    y = rng.standard_normal(n) + np.cumsum(rng.standard_normal(n)) * gamma
    fit = G.fit_gmwm(y, 1.0, n_boot=0, max_gm=1, auto_range=False, weighting="full")
    wn = next(p for p in fit.processes if p.kind == "WN")
    assert wn.params["sigma2"] == pytest.approx(1.0, rel=0.02)
    assert G.k_of(fit.processes, 1.0, fit.tau_range_s) == pytest.approx(gamma, rel=0.25)
    from inertialab.errors import InputError

    with pytest.raises(InputError, match="weighting"):
        G.fit_gmwm(y, 1.0, n_boot=0, weighting="diag")


@pytest.mark.parametrize("t_lo, t_hi", [(4.0, 4000.0), (2.0, 20.0), (30.0, 3e5)])
def test_band_limited_process_spectrum_matches_its_wavelet_variance(t_lo, t_hi):
    # the BL process's spectrum (a sum of sampled AR(1)s at log-midpoints) integrated to a
    # WV against its own closed-form WV (band_shape, the continuous mixture); measured
    # within 0.7 % from 4 t_lo up, 1.5x at one sample below the corner
    p = G.Process("BL", {"c0": 2.0, "t_lo_s": t_lo, "t_hi_s": t_hi})
    m = 2.0 ** np.arange(0, 19)
    nu2, _ = wv_covariance([p], m, 2**20, 1.0)
    exact = p.avar(m, 1.0) / 2.0
    sel = m >= 4 * t_lo
    np.testing.assert_allclose(nu2[sel], exact[sel], rtol=0.02)
    assert np.all(nu2[~sel] >= exact[~sel] * (1 - 1e-3))
