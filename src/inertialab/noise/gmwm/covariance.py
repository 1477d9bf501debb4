"""Covariance of the Haar wavelet variance across scales, from a latent model's spectrum
(the weight matrix and the bootstrap law of :mod:`inertialab.noise.gmwm.fit`).

The Haar (MODWT) wavelet coefficient of a rate sequence at scale ``m`` samples is half the
difference of two adjacent ``m``-sample means, a linear filter of squared gain

    |H_m(f)|^2 = sin^4(pi f m) / (m^2 sin^2(pi f)),   f in cycles per sample,

so ``nu^2_m = int_{-1/2}^{1/2} |H_m|^2 S df`` for the two-sided spectral density ``S`` of
the sequence (white ``sigma2``; AR(1) ``s2 (1 - phi^2)/|1 - phi e^{-i2pi f}|^2``; random walk
``gamma2 / (4 sin^2 pi f)``; differenced white angle ``4 q2 sin^2(pi f)/tau0^2``). For a
Gaussian sequence the estimators ``nu_hat^2_m = mean_t W_{m,t}^2`` over ``M_m = N - 2m + 1``
overlapping coefficients have the large-sample covariance (Percival & Walden 2000, §8.3;
Serroukh, Walden & Percival 2000)

    Cov(nu_hat^2_j, nu_hat^2_k) = 2/max(M_j, M_k) int |H_j|^2 |H_k|^2 S^2 df,

the covariance that Guerrier et al. (2013) invert for the GMWM weight matrix. The
integral is taken on a log-spaced frequency grid; where ``sin^4(pi f m)`` oscillates
faster than the grid resolves (``f m >= R_OSC``) it is replaced by its period mean 3/8,
and the product of two factors of close scales (ratio <= 4, commensurate) by the exact
period mean of the product (:data:`_PAIR_MEAN`). Deterministic drift and the filter's
negative remainder have no spectrum and are left out (they only shift the means).
Checked against the simulated covariance of white, AR(1) and random-walk records in
``tests/noise/test_gmwm_cov.py``.
"""

from __future__ import annotations

import math

import numpy as np

from inertialab.noise.gmwm._avar import avar_ar1

#: sin^4(pi f m) is resolved exactly up to f m = R_OSC, averaged beyond (see docstring)
R_OSC = 8.0
#: grid points per decade of frequency (>= 12 points per oscillation of the fastest
#: exactly-resolved factor)
PER_DECADE = 1000


def _pair_means(max_d: int = 2) -> dict:
    """Period mean of sin^4(x) sin^4(2^d x) (d = 0: mean sin^8 = 35/128)."""
    x = (np.arange(1 << 16) + 0.5) * (math.pi / (1 << 16))
    return {d: float(np.mean(np.sin(x) ** 4 * np.sin(x * 2**d) ** 4))
            for d in range(max_d + 1)}


_PAIR_MEAN = _pair_means()


def spectrum(processes, f, tau0: float) -> np.ndarray:
    """Two-sided spectral density (rate unit^2 per cycle/sample) of the latent processes
    with a spectrum (WN, QN, RW, GM) at frequencies ``f`` (cycles per sample)."""
    f = np.asarray(f, dtype=float)
    s2f = np.sin(np.pi * f) ** 2
    out = np.zeros_like(f)
    for p in processes:
        q = p.params
        if p.kind == "WN":
            out += q["sigma2"]
        elif p.kind == "QN":
            out += 4.0 * q["q2"] * s2f / tau0**2
        elif p.kind == "RW":
            out += q["gamma2"] / (4.0 * s2f)
        elif p.kind == "GM":
            out += _gm_spectrum(q["s2"], q["tc_s"], s2f, tau0)
        elif p.kind == "BL":
            for s2, tc in _bl_as_gm(q["c0"], q["t_lo_s"], q["t_hi_s"], tau0):
                out += _gm_spectrum(s2, tc, s2f, tau0)
    return out


def _gm_spectrum(s2, tc, s2f, tau0):
    phi = math.exp(-tau0 / tc)
    # |1 - phi e^{-iw}|^2 = (1 - phi)^2 + 4 phi sin^2(w/2)
    return s2 * (1 - phi) * (1 + phi) / ((1 - phi) ** 2 + 4 * phi * s2f)


#: Gauss–Markov processes per decade that stand for a BL process's spectrum
BL_GM_PER_DECADE = 8


def _bl_as_gm(c0, t_lo, t_hi, tau0):
    """A BL process (log-uniform GM mixture, peak AVAR ``c0``) as a discrete sum of
    sampled AR(1) processes at the log-midpoints of :data:`BL_GM_PER_DECADE` bins per
    decade of ``[t_lo, t_hi]`` with equal variances, scaled so the sum's peak AVAR is
    ``c0``. Used for the spectrum only (the bootstrap's cross-scale correlation and the
    "full" weights); the WV itself is ``band_shape``'s continuous mixture, which the
    sampled sum's WV matches within 2 % from 4 t_lo up (test) and exceeds below (1.5x at
    one sample for t_lo = 4 samples)."""
    k = max(int(math.ceil(BL_GM_PER_DECADE * math.log10(t_hi / t_lo))), 2)
    edges = np.geomspace(t_lo, t_hi, k + 1)
    tcs = np.sqrt(edges[:-1] * edges[1:])  # log-midpoints: each stands for its bin
    m = np.geomspace(max(t_lo / tau0 / 8.0, 1.0), max(8.0 * t_hi / tau0, 2.0), 256)
    peak = float(np.max(sum(avar_ar1(m, math.exp(-tau0 / tc), 1.0) for tc in tcs)))
    return [(c0 / peak, float(tc)) for tc in tcs]


def wv_covariance(processes, m, n_samples: int, tau0: float):
    """``(nu2, cov)``: the model wavelet variance at the scales ``m`` (samples) from the
    spectrum, and the large-sample covariance of the estimators (module docstring), for
    a record of ``n_samples``."""
    m = np.asarray(m, dtype=float)
    f_lo = 1e-3 / m.max()
    lf = np.linspace(math.log(f_lo), math.log(0.5), int(PER_DECADE * math.log10(0.5 / f_lo)))
    f = np.exp(lf)
    w = np.full(f.size, lf[1] - lf[0]) * f  # trapezoid in log f: df = f dlnf
    w[0] *= 0.5
    w[-1] *= 0.5
    S = spectrum(processes, f, tau0)
    base = 1.0 / (m[:, None] ** 2 * np.sin(np.pi * f)[None, :] ** 2)
    s4 = np.sin(np.pi * f[None, :] * m[:, None]) ** 4
    fast = f[None, :] * m[:, None] >= R_OSC
    exact = base * s4
    smooth = np.where(fast, base * 0.375, exact)
    nu2 = 2.0 * (smooth @ (w * S))
    # the band [0, f_lo] (integrand ~ constant or ~f^2 there)
    nu2 += 2.0 * exact[:, 0] * S[0] * f_lo
    S2w = w * S * S
    cov = 2.0 * (smooth * S2w) @ smooth.T
    # close scales: their oscillations are commensurate, use the exact pair mean
    for i in range(m.size):
        for j in range(m.size):
            d = abs(int(round(math.log2(m[j] / m[i]))))
            if d > 2:
                continue
            lo_m = min(m[i], m[j])
            both = f * lo_m >= R_OSC
            a = np.where(both, base[i] * base[j] * _PAIR_MEAN[d],
                         exact[i] * exact[j])
            cov[i, j] = 2.0 * float(a @ S2w)
    cov += 2.0 * np.outer(exact[:, 0], exact[:, 0]) * S[0] ** 2 * f_lo
    M = np.maximum(n_samples - 2 * m + 1, 1.0)
    cov *= 2.0 / np.maximum(M[:, None], M[None, :])
    return nu2, cov





def log_weights(processes, m, n_samples: int, tau0: float):
    """The GMWM weight of the log wavelet moments from a latent model.

    Returns ``(bias, linv, eta, corr)``: ``eta_j = 2 nu_j^4 / Var(nu_hat^2_j)`` (the
    equivalent chi-square degrees of freedom), ``bias_j = E[ln(chi2(eta_j)/eta_j)] =
    psi(eta_j/2) - ln(eta_j/2)`` (subtracted from ``ln nu_hat^2_j`` so the log moments are
    unbiased), ``corr`` the correlation of the estimators across scales, and ``linv`` the
    inverse Cholesky factor of the log moments' covariance ``corr_jk sd_j sd_k``,
    ``sd_j^2 = psi'(eta_j/2)`` (the variance of ``ln chi2(eta)``): the objective is
    ``|linv (ln nu_hat - bias - ln nu(theta))|^2``, Guerrier et al.'s
    ``(nu_hat - nu)' Omega (nu_hat - nu)`` on log moments with ``Omega`` the inverse of their
    full covariance."""
    from scipy.linalg import solve_triangular
    from scipy.special import digamma, polygamma

    nu2, cov = wv_covariance(processes, m, n_samples, tau0)
    d = np.sqrt(np.diag(cov))
    eta = np.maximum(2.0 * nu2**2 / d**2, 1.0)
    corr = cov / np.outer(d, d)
    sd = np.sqrt(polygamma(1, eta / 2.0))
    bias = digamma(eta / 2.0) - np.log(eta / 2.0)
    S = corr * np.outer(sd, sd)
    L = np.linalg.cholesky(S + 1e-9 * np.diag(np.diag(S)))
    linv = solve_triangular(L, np.eye(m.size), lower=True)
    return bias, linv, eta, corr


def model_edf(procs, wv) -> np.ndarray:
    """Greenhall EDF (oadev) of each scale for the noise type the model's local log-log
    slope implies there: AVAR ~ tau^s <=> alpha = -1 - s (white rate 0, flicker -1,
    random walk -2; s <= -2 gives +2), rounded to the integer types (``wv``: a
    :class:`inertialab.noise.gmwm.fit.WaveletVariance`)."""
    from inertialab.noise.statistics.edf import edf_greenhall

    m = wv.taus_s / wv.tau0_s
    lt = np.log(wv.taus_s)
    la = np.log(np.maximum(sum(p.avar(m, wv.tau0_s) for p in procs), 1e-300))
    slope = np.gradient(la, lt) if lt.size >= 2 else np.zeros(lt.size)
    alpha = np.clip(np.rint(-1.0 - slope), -2, 2).astype(int)
    alpha[slope <= -1.5] = 2
    e = np.array([edf_greenhall("oadev", wv.n_samples + 1, int(mi), int(a))
                  for mi, a in zip(wv.m, alpha)])
    return np.where(np.isfinite(e) & (e > 0), e, wv.eta)


__all__ = ["log_weights", "model_edf", "spectrum", "wv_covariance"]
