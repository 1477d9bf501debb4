"""Several logs of one sensor (or of one model) as one noise model.

* :func:`pool_curves`: the logs' overlapping Allan variances on the common tau grid of
  the reference log (the first log's octave taus; another log's curve read there by
  log-log interpolation, never extrapolated), averaged with their EDFs as weights (the
  maximum-likelihood common variance of chi-square estimates), the EDFs summed. Logs of
  another rate (another sensor filter) join only at taus >= ``QN_SPLIT_S``: the white
  noise and quantisation of the short taus follow the rate and filter, so Q and N are
  pooled only across logs of the reference's rate, and a log of another rate keeps its
  own. The pooled curve is fitted by the usual methods (WLS, GMWM).
* :func:`homogeneity`: the near-stationarity test between logs at each common tau,
  ``Q = sum_i (l_i - l_bar)^2 / psi'(nu_i/2)`` on ``l_i = ln a_i`` less its chi-square
  bias ``psi(nu_i/2) - ln(nu_i/2)``, ``l_bar`` the inverse-variance mean,
  ``Q ~ chi2(n - 1)``; the least p value times the number of taus (Bonferroni), the EDF
  capped as in :mod:`inertialab.noise.segments.stationarity`.
* :func:`between_var`: the between-group variance of a log quantity beyond each group's
  own sampling (random effects, method of moments), shrunk toward a prior with
  ``PRIOR_WEIGHT`` pseudo-groups (a log's segments: :mod:`inertialab.noise.segments.drift_spread`).
* :func:`next_log_var`: what the next log of the pool's kind may differ by from the
  pooled value: the between-log spread measured (never pulled below what the logs show;
  the logs' own segment spread its floor), times ``1 + 1/n`` (the next log, not the mean)
  and Student's ``(t_{n-1} / z)^2`` (a spread measured on ``n`` logs is known with
  ``n - 1`` degrees of freedom: the classical prediction interval for a new group). On a
  simulated population of units whose N, B and K differ by a 15 % log-sd, three units
  pooled and a fourth checked, the drift interval shrunk toward the segment spread with
  ``z`` covered 74 % of the observed RMS; this covers 95 % (benchmarks/drift_check.py
  ``--pooled-units``).
* :func:`widen_term`: a pooled term's interval carrying that between-log spread (the
  interval for the next log of the pool's kind, not for the mean).
* :func:`cv_score`: the leave-one-log-out criterion of a model fitted on the other logs:
  the mean over the left-out log's taus of ``(ln a - ln model)^2 / psi'(nu/2)``.

Anchor: the multi-signal wavelet-variance framework of Radi, Bakalli, Guerrier,
El-Sheimy, Sesay and Molinari (IEEE Trans. Instrum. Meas., 2019; the R package mgmwm of
the SMAC-Group): several replicates in one fit, a near-stationarity test between them,
and model choice by a cross-validated criterion. Hand-written from that
design on the Allan variance (no code read or copied); tested on simulated logs of one
truth and of two truths (tests/noise/test_pooled.py).
"""

from __future__ import annotations

import math

import numpy as np

from inertialab.noise.segments.stationarity import EDF_CAP, MIN_EDF

#: taus (s) from which a log of another rate than the reference joins the pooled curve
QN_SPLIT_S = 1.0
#: pseudo-segments the prior of a log's between-segment spread weighs
PRIOR_WEIGHT = 2.0
#: level of the "not near-stationary" verdict between logs
ALPHA = 0.05


def _trigamma(x):
    from scipy.special import polygamma

    return polygamma(1, x)


def curve_at(result, taus_s) -> tuple[np.ndarray, np.ndarray]:
    """``(avar, edf)`` of a curve read at ``taus_s`` (log-log interpolation; NaN outside
    its taus)."""
    t = np.asarray(result.taus_s, dtype=float)
    dev = np.asarray(result.dev, dtype=float)
    edf = np.asarray(result.edf, dtype=float)
    ok = np.isfinite(dev) & (dev > 0) & np.isfinite(edf)
    t, dev, edf = t[ok], dev[ok], edf[ok]
    x = np.log(np.asarray(taus_s, dtype=float))
    inside = (x >= math.log(t[0]) - 1e-9) & (x <= math.log(t[-1]) + 1e-9)
    la = np.interp(x, np.log(t), 2.0 * np.log(dev))
    le = np.interp(x, np.log(t), np.log(edf))
    return np.where(inside, np.exp(la), np.nan), np.where(inside, np.exp(le), np.nan)


def joins_at(rates_hz, ref_rate_hz: float, taus_s) -> np.ndarray:
    """``(logs x taus)`` mask: a log of the reference rate joins at every tau, another
    from ``QN_SPLIT_S`` on."""
    same = np.abs(np.asarray(rates_hz, dtype=float) / ref_rate_hz - 1.0) < 1e-3
    t = np.asarray(taus_s, dtype=float)
    return same[:, None] | (t[None, :] >= QN_SPLIT_S)


def pool_curves(results, rates_hz, confidence: float = 0.95):
    """The pooled curve (module docstring) as a :class:`~inertialab.noise.statistics.allan.DeviationResult`
    on the first result's taus; ``n_samples`` the logs' sum."""
    from dataclasses import replace

    from scipy.special import chdtri

    ref = results[0]
    taus = np.asarray(ref.taus_s, dtype=float)
    rows = [curve_at(r, taus) for r in results]
    a = np.array([r[0] for r in rows])
    nu = np.array([r[1] for r in rows])
    use = joins_at(rates_hz, float(rates_hz[0]), taus) & np.isfinite(a) & np.isfinite(nu)
    w = np.where(use, nu, 0.0)
    edf = w.sum(axis=0)
    avar = (np.where(use, a, 0.0) * w).sum(axis=0) / np.where(edf > 0, edf, 1.0)
    ok = edf > 0
    dev = np.sqrt(avar)
    lo_q, hi_q = (1 - confidence) / 2, (1 + confidence) / 2
    ci_low = dev * np.sqrt(edf / chdtri(edf, lo_q))
    ci_high = dev * np.sqrt(edf / chdtri(edf, hi_q))
    k = ok
    with np.errstate(invalid="ignore", divide="ignore"):
        ci_low, ci_high = ci_low, ci_high
    return replace(ref, taus_s=taus[k], m=np.asarray(ref.m)[k], dev=dev[k],
                   n_terms=np.asarray(ref.n_terms)[k], alpha=np.asarray(ref.alpha)[k],
                   edf=edf[k], ci_low=ci_low[k], ci_high=ci_high[k], confidence=confidence,
                   n_samples=int(sum(int(r.n_samples) for r in results)),
                   alpha_source=tuple(np.asarray(ref.alpha_source, dtype=object)[k])
                   if len(ref.alpha_source) == len(ref.taus_s) else ref.alpha_source)


def homogeneity(results, rates_hz, *, max_tau_s: float | None = None,
                alpha: float = ALPHA) -> dict:
    """The near-stationarity test between logs (module docstring):
    ``{"statistic", "p_value", "verdict", "worst_tau_s", "dof", "taus_tested"}``."""
    from scipy.special import chdtrc, digamma

    taus = np.asarray(results[0].taus_s, dtype=float)
    rows = [curve_at(r, taus) for r in results]
    a = np.array([r[0] for r in rows])
    nu = np.minimum(np.array([r[1] for r in rows]), EDF_CAP)
    use = joins_at(rates_hz, float(rates_hz[0]), taus) & np.isfinite(a) & (nu >= MIN_EDF)
    if max_tau_s is not None:
        use &= taus[None, :] <= max_tau_s
    best, n_tests = (math.inf, math.nan, math.nan, 0), 0
    for j in range(taus.size):
        u = use[:, j]
        if u.sum() < 2:
            continue
        v = _trigamma(nu[u, j] / 2.0)
        lj = np.log(a[u, j]) - (digamma(nu[u, j] / 2.0) - np.log(nu[u, j] / 2.0))
        lbar = np.sum(lj / v) / np.sum(1.0 / v)
        q = float(np.sum((lj - lbar) ** 2 / v))
        p = float(chdtrc(u.sum() - 1, q))
        n_tests += 1
        if p < best[0]:
            best = (p, q, float(taus[j]), int(u.sum() - 1))
    if n_tests == 0:
        return {"statistic": None, "p_value": None, "verdict": "not tested",
                "worst_tau_s": None, "dof": 0, "taus_tested": 0}
    p_log = min(1.0, best[0] * n_tests)
    return {"statistic": best[1], "p_value": p_log,
            "verdict": "near-stationary" if p_log >= alpha else "differ beyond sampling",
            "worst_tau_s": best[2], "dof": best[3], "taus_tested": n_tests,
            "test": "chi-square homogeneity of the logs' Allan variances", "alpha": alpha}


def between_var(values, sampling_var, prior: float = 0.0) -> float:
    """Between-log variance of the log quantities ``values`` (one per log) beyond their
    sampling variances, ``max(0, s^2 - mean sampling)``, shrunk toward ``prior`` with
    ``PRIOR_WEIGHT`` pseudo-logs (0 or 1 log: the prior)."""
    v = np.asarray(values, dtype=float)
    s = np.asarray(sampling_var, dtype=float)
    ok = np.isfinite(v) & np.isfinite(s)
    v, s = v[ok], s[ok]
    if v.size < 2:
        return float(prior)
    obs = max(float(np.var(v, ddof=1)) - float(np.mean(s)), 0.0)
    dof = v.size - 1
    return float((dof * obs + PRIOR_WEIGHT * prior) / (dof + PRIOR_WEIGHT))


def next_log_var(values, sampling_var, prior: float = 0.0,
                 confidence: float = 0.95) -> float:
    """Variance of the next log's log quantity about the pooled one, on the normal scale
    of ``confidence`` (module docstring): ``max(s^2 - mean sampling, prior)`` over the
    ``n`` logs' ``values``, times ``1 + 1/n`` and ``(t_{n-1} / z)^2``; with fewer than two
    usable logs nothing is measured: ``prior`` times 2.

    >>> round(next_log_var([0.0, 0.2, 0.4], [0.0, 0.0, 0.0]), 3)  # 0.04 * 4/3 * 4.82
    0.257
    >>> next_log_var([0.0], [0.01], prior=0.3)
    0.6
    """
    from scipy.special import ndtri, stdtrit

    v = np.asarray(values, dtype=float)
    s = np.asarray(sampling_var, dtype=float)
    ok = np.isfinite(v) & np.isfinite(s)
    v, s = v[ok], s[ok]
    if v.size < 2:
        return 2.0 * float(prior)
    obs = max(float(np.var(v, ddof=1)) - float(np.mean(s)), float(prior), 0.0)
    q = 0.5 + confidence / 2.0
    t_over_z = float(stdtrit(v.size - 1, q)) / float(ndtri(q))
    return obs * (1.0 + 1.0 / v.size) * t_over_z * t_over_z


def widen_term(term, between_log_var: float, z: float = 1.959963984540054):
    """The term with its interval carrying the between-log spread: each side of a
    significant term's interval, in ``ln``, widened to ``sqrt(side^2 + z^2 between)``
    (an asymmetric bootstrap interval stays asymmetric); an upper bound's upper end times
    ``exp(z sqrt(between))``."""
    from dataclasses import replace

    lo, hi = (float(v) for v in term.ci)
    val = float(term.value)
    add = z * z * max(between_log_var, 0.0)
    if not term.significant:
        ub = float(term.upper_bound) if math.isfinite(term.upper_bound) else hi
        if not math.isfinite(ub):
            return term
        ub *= math.exp(math.sqrt(add))
        return replace(term, ci=(0.0, ub), upper_bound=ub)
    if not (val > 0 and lo > 0 and math.isfinite(hi) and lo <= val <= hi):
        return term
    c = math.log(val)
    d_lo = math.sqrt((c - math.log(lo)) ** 2 + add)
    d_hi = math.sqrt((math.log(hi) - c) ** 2 + add)
    return replace(term, ci=(math.exp(c - d_lo), math.exp(c + d_hi)))


def cv_score(result, model_dev) -> float:
    """Mean over a left-out log's taus (where its EDF is at least ``MIN_EDF`` and the
    model is finite) of ``(ln a - ln model)^2 / psi'(nu/2)``, ``model_dev`` the Allan
    deviation of a model fitted on the other logs at the log's taus."""
    a = np.asarray(result.dev, dtype=float) ** 2
    m = np.asarray(model_dev, dtype=float) ** 2
    nu = np.minimum(np.asarray(result.edf, dtype=float), EDF_CAP)
    ok = np.isfinite(a) & (a > 0) & np.isfinite(m) & (m > 0) & (nu >= MIN_EDF)
    if not ok.any():
        return math.nan
    return float(np.mean(np.log(a[ok] / m[ok]) ** 2 / _trigamma(nu[ok] / 2.0)))


__all__ = ["ALPHA", "PRIOR_WEIGHT", "QN_SPLIT_S", "between_var", "curve_at", "cv_score",
           "homogeneity", "joins_at", "next_log_var", "pool_curves", "widen_term"]
