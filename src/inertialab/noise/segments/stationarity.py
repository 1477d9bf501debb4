"""Is one log's noise the same throughout? Allan variances of its segments compared.

A static log is cut into ``k`` equal segments (halves and quarters). At each octave tau
every segment's overlapping Allan variance ``a_i`` is, for a stationary noise, the common
variance times ``chi2(nu)/nu`` with the Greenhall EDF ``nu`` of the segment
(:mod:`inertialab.noise.statistics.edf`), so ``ln a_i`` scatters with variance ``psi'(nu/2)``
(trigamma: the variance of the log of a chi-square over its degrees of freedom; the
segments are of one length, so the log's bias is common and cancels). The homogeneity
statistic at one tau::

    Q = sum_i (ln a_i - mean ln a)^2 / psi'(nu/2)   ~  chi2(k - 1)

is computed at every tau where each segment has ``nu >= MIN_EDF``, for halves and for
quarters. The log's p value is the least one times the number of tests (Bonferroni:
neighbouring taus are correlated, so it is conservative); the verdict is "not
stationary" below ``alpha`` (default 0.05), and ``worst_tau_s`` is where the least p
value was found.

The measured **between-segment spread** (:func:`excess_log_var`) is the part of the
segments' scatter of ``ln a`` beyond their sampling, per tau: ``max(0, s^2 - psi'(nu/2))``
with ``s^2`` the segments' sample variance. It is what a later stretch of the same
length may differ by beyond sampling, and it widens the drift interval
(:func:`inertialab.noise.terms.drift_prediction.predicted_rms_ci`).

References: IEEE Std 952-1997 Annex C (the Allan variance of a stationary record);
Greenhall & Riley (2003) for the EDF; the chi-square homogeneity of variance estimates
is the classic test of equal variances (Bartlett's, here with the Allan variance's own
degrees of freedom). Hand-written; tested on simulated stationary logs and on logs whose
second half carries more noise (tests/noise/test_stationarity.py).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

#: segmentations compared: halves and quarters
SEGMENTS = (2, 4)
#: least EDF of a segment's Allan variance for a tau to be tested
MIN_EDF = 8.0
#: longest tested tau, as a fraction of a segment (the EDF of the last octaves rests on
#: the identified noise type, which a slow Gauss-Markov process or random walk there defeats)
MAX_TAU_FRACTION = 1.0 / 16.0
#: EDF cap of the test: differences of AVAR under ~10 % (deviation ~5 %) are not called,
#: whatever the record's length (a practical near-stationarity; at short taus a 1e6-sample
#: log has EDFs of 1e5, where a 1 % change of the white noise, irrelevant to a filter or a
#: drift, would be "significant")
EDF_CAP = 200.0
#: level of the "not stationary" verdict
ALPHA = 0.05


@dataclass(frozen=True)
class Stationarity:
    """The test of one series (module docstring). ``taus_s`` and, per segmentation
    ``k``, ``log_avar[k]`` (k x taus, NaN where not tested), ``edf[k]`` (taus, the mean
    EDF of a segment), ``p[k]`` (taus)."""

    segments: tuple
    statistic: float
    p_value: float
    verdict: str
    worst_tau_s: float
    worst_segments: int
    taus_s: np.ndarray
    log_avar: dict
    edf: dict
    p: dict

    def to_dict(self) -> dict:
        def num(v):
            return float(v) if math.isfinite(v) else None

        return {"segments": list(self.segments), "statistic": num(self.statistic),
                "p_value": num(self.p_value), "verdict": self.verdict,
                "worst_tau_s": num(self.worst_tau_s),
                "worst_segments": int(self.worst_segments),
                "alpha": ALPHA, "test": "chi-square homogeneity of segment Allan variances"}

    def excess(self) -> tuple[np.ndarray, np.ndarray]:
        """``(taus_s, excess log variance)`` (:func:`excess_log_var`)."""
        return excess_log_var(self)


def _trigamma(x):
    from scipy.special import polygamma

    return polygamma(1, x)


def segment_avars(y, rate_hz: float, k: int, taus_s=None):
    """``(taus_s, log_avar (k x taus), edf (taus))`` of ``k`` equal segments of ``y``:
    octave overlapping Allan variances (:func:`inertialab.noise.statistics.allan.oadev`) on the
    taus the shortest segment has (or ``taus_s``)."""
    from inertialab.noise.statistics.allan import oadev

    y = np.asarray(y, dtype=float)
    n = y.size // k
    rows, edfs, taus = [], [], None
    for i in range(k):
        seg = y[i * n:(i + 1) * n]
        r = oadev(seg, rate_hz=rate_hz, taus="octave" if taus_s is None else taus_s)
        if taus is None:
            taus = np.asarray(r.taus_s)
        m = min(taus.size, len(r.dev))
        rows.append(np.log(np.asarray(r.dev[:m], dtype=float) ** 2))
        edfs.append(np.minimum(np.asarray(r.edf[:m], dtype=float), EDF_CAP))
        taus = taus[:m]
    m = min(len(v) for v in rows)
    la = np.array([v[:m] for v in rows])
    return taus[:m], la, np.mean([e[:m] for e in edfs], axis=0)


def check_stationarity(y, rate_hz: float, *, segments=SEGMENTS,
                      alpha: float = ALPHA) -> Stationarity:
    """The test of one series ``y`` at ``rate_hz`` Hz (module docstring)."""
    from scipy.special import chdtrc

    y = np.asarray(y, dtype=float)
    taus_all, la_d, edf_d, p_d = None, {}, {}, {}
    best = (math.inf, math.nan, math.nan, 0)
    n_tests = 0
    for k in segments:
        taus, la, edf = segment_avars(y, rate_hz, k)
        if taus_all is None or taus.size > taus_all.size:
            taus_all = taus
        seg_s = y.size // k / rate_hz
        ok = ((edf >= MIN_EDF) & np.all(np.isfinite(la), axis=0)
              & (taus <= MAX_TAU_FRACTION * seg_s))
        q = np.sum((la - la.mean(axis=0)) ** 2, axis=0) / _trigamma(edf / 2.0)
        p = np.where(ok, chdtrc(k - 1, q), np.nan)
        la_d[k], edf_d[k], p_d[k] = np.where(ok, la, np.nan), edf, p
        n_tests += int(ok.sum())
        if ok.any():
            i = int(np.nanargmin(p))
            if p[i] < best[0]:
                best = (float(p[i]), float(q[i]), float(taus[i]), k)
    p_min, q, tau, k = best
    if n_tests == 0:
        return Stationarity(tuple(segments), math.nan, math.nan, "not tested", math.nan, 0,
                            np.asarray(taus_all), la_d, edf_d, p_d)
    p_log = min(1.0, p_min * n_tests)
    verdict = "not stationary" if p_log < alpha else "stationary"
    return Stationarity(tuple(segments), q, p_log, verdict, tau, k, np.asarray(taus_all),
                        la_d, edf_d, p_d)


def excess_log_var(st: Stationarity) -> tuple[np.ndarray, np.ndarray]:
    """Between-segment variance of ``ln AVAR`` beyond sampling, per tau of ``st``: the
    largest over its segmentations of ``max(0, s^2 - psi'(nu/2))``; 0 where no
    segmentation tested that tau."""
    taus = np.asarray(st.taus_s, dtype=float)
    out = np.zeros(taus.size)
    for k, la in st.log_avar.items():
        m = la.shape[1]
        n_ok = np.sum(np.isfinite(la), axis=0)
        dev = np.where(np.isfinite(la), la - np.nanmean(np.where(n_ok > 0, la, 0.0), axis=0),
                       0.0)
        s2 = np.where(n_ok > 1, np.sum(dev * dev, axis=0) / np.maximum(n_ok - 1, 1), np.nan)
        ex = s2 - _trigamma(np.asarray(st.edf[k][:m]) / 2.0)
        ex = np.where(np.isfinite(ex), np.maximum(ex, 0.0), 0.0)
        out[:m] = np.maximum(out[:m], ex)
    return taus, out


def excess_at(st: Stationarity | None, taus_s) -> np.ndarray:
    """:func:`excess_log_var` read at ``taus_s`` (log-tau interpolation; beyond the
    tested taus the nearest tested value)."""
    t = np.atleast_1d(np.asarray(taus_s, dtype=float))
    if st is None:
        return np.zeros(t.size)
    taus, ex = excess_log_var(st)
    tested = np.zeros(taus.size, dtype=bool)
    for la in st.log_avar.values():
        tested[: la.shape[1]] |= np.any(np.isfinite(la), axis=0)
    if not tested.any():
        return np.zeros(t.size)
    return np.interp(np.log(t), np.log(taus[tested]), ex[tested])


__all__ = ["ALPHA", "EDF_CAP", "MAX_TAU_FRACTION", "MIN_EDF", "SEGMENTS", "Stationarity", "excess_at", "excess_log_var",
           "check_stationarity", "segment_avars"]
