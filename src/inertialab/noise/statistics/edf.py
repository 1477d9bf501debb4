"""Equivalent degrees of freedom, chi-square intervals and power-law noise identification.

EDF algorithms (``method``):

``"greenhall"``
    Greenhall & Riley (2003), "Uncertainty of stability variances based on finite
    differences" (Proc. 35th PTTI): the EDF of adev, oadev, mdev, tdev, hdev and ohdev for
    power-law noise alpha = +2..-4 from the generalised autocovariance of the phase
    (their "basic sum", eq. 10, evaluated directly for up to ``J_MAX`` = 100 lags) with
    the paper's Tables 1-3 above that and its ``m' = J_max/r`` rescaling in between.
    Written from the paper's structure (allantools' ``edf_greenhall`` read as a guide,
    not copied, and used as the independent check in the tests: agreement 1e-6 over
    alpha in {2..-2}, every statistic, m = 1..N/16). Two differences, both where the
    published code is undefined or loses digits: white phase with ``ceil(r) <= d``
    (Greenhall's closed form does not apply) uses the exact basic sum, and the second
    difference of ``sw`` is taken from its Taylor series where ``|t| F >= 64``
    (cancellation at large m). About 0.1 ms per tau, no memory beyond a few 100-element
    arrays. Greenhall models unmodified variances with the phase averaged over tau0
    (F = m); for white rate at m < ~16 that differs from point-sampled discrete white
    noise (the "gaussian" EDF below) by up to 17 % in EDF (m = 1), i.e. < 1 % in the
    interval width at such EDFs.
``"sp1065"``
    The closed-form approximations of NIST SP 1065 (Riley 2008): Table 5 (Howe, Allan
    & Barnes 1981) for the overlapping Allan variance, exactly as spec 001 §3.2 prints
    them, and Table 7 (``edf = b T/tau - c``) for the total variance (frequency noises;
    phase noises fall back to Table 5).
``"gaussian"`` (cross-check only)
    The exact EDF of the estimator under a Gaussian power-law model, computed
    numerically: ``edf = 2 E[S]^2 / Var[S]`` for the sum of squares ``S`` of the
    statistic's linear filter outputs, with the filter outputs' covariance obtained
    from the generalized autocovariance of the angle (phase) of each noise type
    (white angle: delta; white rate: ``-|t|``; flicker rate: ``t^2 ln|t|``; random-walk
    rate: ``|t|^3``; flicker angle: ``-ln|t|`` with a unit zero-lag value). This is the
    construction of Greenhall & Riley (2003, "Uncertainty of stability variances based
    on finite differences"); like Greenhall's algorithm it switches to the continuous-
    time limit for large averaging factors (here m > 64: the filter is rescaled to
    m = 64 at the same record length in units of tau). It is not Greenhall's published
    code and is cross-checked against the SP 1065 formulas and allantools'
    ``edf_greenhall`` in the tests.
``"default"``
    ``"greenhall"`` for every statistic it covers; ``"sp1065"`` Table 7 for ``totdev``
    (as allantools and Stable32), and for totdev's phase noises Table 5, the overlapping
    ADEV EDF SP 1065 points to there (Stable32's printed flicker-PM TOTDEV bounds: 1.0e-3
    with it, 1.3e-2 with Greenhall's oadev EDF used before; allantools takes its simple
    EDF there).
    (Before, the default was SP 1065 Table 5 for oadev and the numeric Gaussian
    EDF elsewhere; the latter collapsed for random-walk rate at small m and cost
    2-12 ms and ~49 MB per tau.)

Noise identification (:func:`identify_alpha`, re-exported from
:mod:`inertialab.noise.statistics.identify`, where its rules are) follows Stable32 and NIST SP 1065
§5.6: lag-1 autocorrelation, B1 ratio, R(n), and the type carried where too few points
remain.

Why hand-written: no maintained library offers these for our estimator set (allantools
is LGPL and a test-only cross-check).
"""

from __future__ import annotations

import functools
import math

import numpy as np
from scipy.special import gammaincinv

from inertialab.errors import InputError
from inertialab.noise.statistics._filters import (  # noqa: F401 - re-exported (public API)
    _ALPHA_RANGE,
    M_CAP,
    _family,
    _filter_cov,
    _gacv,
    filter_autocorr,
)
from inertialab.noise.statistics._octave import fast_kernels, n_terms

# ----------------------------------------------------------------------------- intervals


def chi2_interval(dev, edf, confidence: float = 0.683):
    """Two-sided chi-square interval of a deviation (spec 001 §3.2).

    ``[dev*sqrt(edf/chi2_{(1+p)/2}(edf)), dev*sqrt(edf/chi2_{(1-p)/2}(edf))]``;
    non-integer edf allowed. Returns ``(ci_low, ci_high)`` arrays.
    """
    dev = np.asarray(dev, dtype=float)
    edf = np.asarray(edf, dtype=float)
    p = float(confidence)
    with np.errstate(invalid="ignore", divide="ignore"):
        ok = edf > 0
        every = bool(ok.all())
        e = edf if every else np.where(ok, edf, 1.0)
        # chi2.ppf(q, e) = 2 gammaincinv(e/2, q), scipy's own formula, without the
        # ~0.1 ms argument handling of scipy.stats per call; both quantiles in one call
        q = gammaincinv(0.5 * e, np.array([[0.5 * (1 + p)], [0.5 * (1 - p)]]))
        r = np.sqrt(e / (2.0 * q))
        lo, hi = dev * r[0], dev * r[1]
    if every:
        return lo, hi
    return np.where(ok, lo, np.nan), np.where(ok, hi, np.nan)


# ----------------------------------------------------------------------------- SP 1065


def edf_oadev_sp1065(n_phase: int, m, alpha: int) -> np.ndarray:
    """Overlapping-Allan EDF, NIST SP 1065 Table 5 (spec 001 §3.2), ``N_x = n_phase``."""
    nx = float(n_phase)
    m = np.asarray(m, dtype=float)
    if alpha == 2:
        return (nx + 1) * (nx - 2 * m) / (2 * (nx - m))
    if alpha == 1:  # defined for m <= (N - 1)/2 (NaN beyond: TOTDEV's long taus)
        with np.errstate(invalid="ignore", divide="ignore"):
            v = np.log((nx - 1) / (2 * m)) * np.log((2 * m + 1) * (nx - 1) / 4)
            return np.where(v >= 0, np.exp(np.sqrt(np.maximum(v, 0.0))), np.nan)
    if alpha == 0:
        return (3 * (nx - 1) / (2 * m) - 2 * (nx - 2) / nx) * 4 * m**2 / (4 * m**2 + 5)
    if alpha == -1:
        # SP 1065 Table 5 squares (N-2) at m = 1; spec 001 §3.2 prints it without the
        # square (edf ~ 0.9 for any N, a typo); the square agrees with the exact EDF.
        return np.where(m == 1, 2 * (nx - 2) ** 2 / (2.3 * nx - 4.9),
                        5 * nx**2 / (4 * m * (nx + 3 * m)))
    if alpha == -2:
        return (nx - 2) / (m * (nx - 3) ** 2) * ((nx - 1) ** 2 - 3 * m * (nx - 1) + 4 * m**2)
    raise InputError(f"SP 1065 Table 5 has no EDF for alpha = {alpha}")


def edf_totdev_sp1065(n_phase: int, m, alpha: int) -> np.ndarray:
    """Total-variance EDF ``b (T/tau) - c`` (NIST SP 1065 Table 7); T/tau = N_x/m.
    Phase noises (alpha 1, 2) use Table 5."""
    bc = {0: (1.50, 0.0), -1: (1.17, 0.22), -2: (0.93, 0.36)}
    m = np.asarray(m, dtype=float)
    if alpha in bc:
        b, c = bc[alpha]
        return b * (n_phase / m) - c
    return edf_oadev_sp1065(n_phase, m, alpha)


# ----------------------------------------------------------------------------- Gaussian EDF


def edf_gaussian(statistic: str, n_phase: int, m: int, alpha: int, n_terms: int) -> float:
    """Exact Gaussian EDF ``2 E[S]^2 / Var[S]`` (see module docstring)."""
    overlapping = statistic in ("oadev", "ohdev", "mdev", "tdev", "totdev")
    M = int(n_terms)
    if M < 1:
        return float("nan")
    me = m
    if m > M_CAP and alpha != 2:
        # continuous-time limit: same record length in units of tau, filter at M_CAP
        f = M_CAP / m
        me = M_CAP
        M = max(1, int(round(M * f))) if overlapping else M
    stride = 1 if overlapping else me
    a = filter_autocorr(statistic, me)
    r0 = float(_filter_cov(a, alpha, np.array([0.0]))[0])
    if not r0 > 0:
        return float("nan")
    if M == 1:
        return 1.0
    # exact part of sum_{q=1}^{M-1} (M-q) R(q*stride)^2, then a log-grid tail
    q_exact = min(M - 1, max(4000, 8 * a.size // stride + 64))
    q = np.arange(1, q_exact + 1, dtype=float)
    r = _filter_cov(a, alpha, q * stride)
    tot = M * r0 * r0 + 2.0 * float(np.sum((M - q) * r * r))
    if q_exact < M - 1:
        qt = np.unique(np.geomspace(q_exact, M - 1, 400))
        rt = _filter_cov(a, alpha, qt * stride)
        g = (M - qt) * rt * rt
        tot += 2.0 * float(np.sum(0.5 * (g[1:] + g[:-1]) * np.diff(qt)))
    return float(M * M * r0 * r0 / tot)


# ----------------------------------------------------------------------------- Greenhall

#: statistic -> (d, overlapping, modified) of Greenhall & Riley (2003), Table "estimators".
GREENHALL_STATS = {"adev": (2, False, False), "oadev": (2, True, False),
                   "mdev": (2, True, True), "tdev": (2, True, True),
                   "hdev": (3, False, False), "ohdev": (3, True, False)}

#: Greenhall's J_max: the basic sum is evaluated directly up to this many lags.
J_MAX = 100

# Published constants (Greenhall & Riley 2003, Tables 1-3), rows alpha = 2..-4, columns
# d = 1, 2, 3; (a0, a1) of the large-r approximation 1/edf = (a0 - a1/r)/r. None: the
# combination is not allowed (alpha + 2d <= 1).
_TABLE1 = {  # modified variances (F = 1)
    2: ((2 / 3, 1 / 3), (7 / 9, 1 / 2), (22 / 25, 2 / 3)),
    1: ((0.840, 0.345), (0.997, 0.616), (1.141, 0.843)),
    0: ((1.079, 0.368), (1.033, 0.607), (1.184, 0.848)),
    -1: (None, (1.048, 0.534), (1.180, 0.816)),
    -2: (None, (1.302, 0.535), (1.175, 0.777)),
    -3: (None, None, (1.194, 0.703)),
    -4: (None, None, (1.489, 0.702)),
}
_TABLE2 = {  # unmodified variances (F = m)
    2: ((3 / 2, 1 / 2), (35 / 18, 1.0), (231 / 100, 3 / 2)),
    1: ((78.6, 25.2), (790.0, 410.0), (9950.0, 6520.0)),
    0: ((2 / 3, 1 / 6), (2 / 3, 1 / 3), (7 / 9, 1 / 2)),
    -1: (None, (0.852, 0.375), (0.997, 0.617)),
    -2: (None, (1.079, 0.368), (1.033, 0.607)),
    -3: (None, None, (1.053, 0.553)),
    -4: (None, None, (1.302, 0.535)),
}
_TABLE3 = ((6.0, 4.0), (15.23, 12.0), (47.8, 40.0))  # alpha = +1: (b0, b1) of sz(0) ~ b0 + b1 ln m

_DIFF = {1: (2.0, -1.0), 2: (6.0, -4.0, 1.0), 3: (20.0, -15.0, 6.0, -1.0)}


def _sw(t: np.ndarray, alpha: int) -> np.ndarray:
    """Greenhall's generalised autocovariance of the phase, ``sw(t)`` for rate PSD f^alpha
    (up to a constant factor, which cancels in the EDF)."""
    a = np.abs(t)
    if alpha == 2:
        return -a
    a2 = a * a
    if alpha in (0, -2, -4):  # |t|^3, |t|^5, |t|^7 (only the power asked for)
        p = a2 * a
        for _ in range((-alpha) // 2):
            p = p * a2
        return p
    lg = np.log(np.where(a > 0, a, 1.0))
    p = a2
    for _ in range((1 - alpha) // 2):  # |t|^2, |t|^4, |t|^6
        p = p * a2
    return p * lg


def _sw_derivs(a: np.ndarray, alpha: int):
    """Second, fourth and sixth derivatives of ``sw`` at ``|t| = a > 0``."""
    z = np.zeros_like(a)
    if alpha == 2:
        return z, z, z
    if alpha == 0:
        return 6 * a, z, z
    if alpha == -2:
        return 20 * a**3, 120 * a, z
    with np.errstate(divide="ignore"):
        lg = np.log(np.where(a > 0, a, 1.0))
        inv2 = np.where(a > 0, 1.0 / np.where(a > 0, a, 1.0) ** 2, 0.0)
    if alpha == 1:
        return 2 * lg + 3, -2 * inv2, -12 * inv2 * inv2
    if alpha == 0:
        return 6 * a, z, z
    if alpha == -1:
        return 12 * a**2 * lg + 7 * a**2, 24 * lg + 50, -24 * inv2
    if alpha == -2:
        return 20 * a**3, 120 * a, z
    if alpha == -3:
        return 30 * a**4 * lg + 11 * a**4, 360 * a**2 * lg + 342 * a**2, 720 * lg + 1764
    return 42 * a**5, 840 * a**3, 5040 * a  # alpha == -4


def _sx(t: np.ndarray, F: float, alpha: int) -> np.ndarray:
    """``sx(t) = F^2 [2 sw(t) - sw(t - 1/F) - sw(t + 1/F)]``; F = inf gives its limit
    ``-sw''(t)``. Where ``|t| F >= 64`` the second difference is taken from its Taylor
    series (exact for the polynomial ``sw``, relative error < 1e-10 for the logarithmic
    ones) instead of the cancelling direct form, which keeps large m accurate."""
    a = np.abs(t)
    if math.isinf(F):
        return -_sw_derivs(a, alpha)[0]
    h = 1.0 / F
    direct = F * F * (2.0 * _sw(t, alpha) - _sw(t - h, alpha) - _sw(t + h, alpha))
    far = a * F >= 64.0
    if not far.any():
        return direct
    g2, g4, g6 = _sw_derivs(np.where(far, a, 1.0), alpha)
    taylor = -(g2 + h * h * g4 / 12.0 + h**4 * g6 / 360.0)
    return np.where(far, taylor, direct)


def _sz(t: np.ndarray, F: float, alpha: int, d: int) -> np.ndarray:
    """``sz(t)``: the d-th order binomial difference of ``sx`` at unit spacing."""
    c = _DIFF[d]
    out = c[0] * _sx(t, F, alpha)
    for k in range(1, d + 1):
        out = out + c[k] * (_sx(t - k, F, alpha) + _sx(t + k, F, alpha))
    return out


def _inv_edf_sum(J: int, M: float, S: float, F: float, alpha: int, d: int) -> float:
    """Greenhall's basic sum (eq. 10) divided by ``sz(0)^2 M`` (= 1/edf, eq. 13)."""
    j = np.arange(0, int(J) + 1, dtype=float)
    sz = _sz(j / S, F, alpha, d)
    s2 = sz * sz
    w = 2.0 * (1.0 - j / M)
    w[0] = 1.0
    w[-1] = 1.0 - J / M
    if J == 0:
        w[0] = 1.0
    return float(np.dot(w, s2) / (s2[0] * M))


def edf_greenhall(statistic: str, n_phase: int, m: int, alpha: int) -> float:
    """EDF of Greenhall & Riley (2003) for adev, oadev, mdev, tdev, hdev, ohdev.

    ``n_phase`` angle (phase) points, averaging factor ``m``, rate PSD exponent ``alpha``.
    The published algorithm: the basic sum (their eq. 10) for up to ``J_MAX`` lags,
    Table 1/2 (and Table 3 for alpha = +1) above it, the ``m' = J_MAX/r`` rescaling in
    between; for white angle noise (alpha = 2) of an unmodified variance with
    ``ceil(r) <= d``, where the paper's closed form does not apply, the basic sum itself,
    which is exact there (the covariance of white phase has finite support).
    NaN when no summand fits (``M < 1``) or ``alpha + 2d <= 1``.
    """
    d, overlapping, modified = GREENHALL_STATS[statistic]
    alpha, m, N = int(alpha), int(m), int(n_phase)
    if alpha + 2 * d <= 1 or alpha > 2 or m < 1:
        return float("nan")
    F = 1.0 if modified else float(m)
    S = float(m) if overlapping else 1.0
    L = m / F + m * d
    M = 1.0 + math.floor(S * (N - L) / m)
    if M < 1:
        return float("nan")
    J = min(M, (d + 1) * S)
    r = M / S
    inf = float("inf")
    if modified:
        if J <= J_MAX:
            inv = _inv_edf_sum(int(J), M, S, 1.0, alpha, d)
        elif r > d + 1:
            a0, a1 = _TABLE1[alpha][d - 1]
            inv = (a0 - a1 / r) / r
        else:
            inv = _inv_edf_sum(J_MAX, J_MAX, J_MAX / r, 1.0, alpha, d)
    elif alpha <= 0:
        if J <= J_MAX:
            inv = _inv_edf_sum(int(J), M, S, float(m) if m * (d + 1) <= J_MAX else inf,
                               alpha, d)
        elif r > d + 1:
            a0, a1 = _TABLE2[alpha][d - 1]
            inv = (a0 - a1 / r) / r
        else:
            inv = _inv_edf_sum(J_MAX, J_MAX, J_MAX / r, inf, alpha, d)
    elif alpha == 1:
        b0, b1 = _TABLE3[d - 1]
        if J <= J_MAX:
            inv = _inv_edf_sum(int(J), M, S, float(m), 1, d)
        elif r > d + 1:
            a0, a1 = _TABLE2[1][d - 1]
            inv = (a0 - a1 / r) / ((b0 + b1 * math.log(m)) ** 2 * r)
        else:
            mp = J_MAX / r
            j = np.arange(0, J_MAX + 1, dtype=float)
            sz = _sz(j / mp, mp, 1, d)
            w = 2.0 * (1.0 - j / J_MAX)
            w[0], w[-1] = 1.0, 0.0
            inv = float(np.dot(w, sz * sz)) / ((b0 + b1 * math.log(m)) ** 2 * J_MAX)
    else:  # alpha == 2, unmodified
        if math.ceil(r) <= d:
            # white phase: sz(j/S) vanishes unless j is a multiple of S (finite support),
            # so the basic sum runs over those lags only
            j = np.arange(0, int(J) + 1, int(S), dtype=float)
            sz = _sz(j / S, float(m), 2, d)
            w = 2.0 * (1.0 - j / M)
            w[0] = 1.0
            if j[-1] == J:
                w[-1] = 1.0 - J / M
            inv = float(np.dot(w, sz * sz) / (sz[0] ** 2 * M))
        else:
            a0 = math.comb(4 * d, 2 * d) / math.comb(2 * d, d) ** 2
            inv = (a0 - (d / 2.0) / r) / M
    return 1.0 / inv if inv > 0 else float("nan")


def _sx_many(t: np.ndarray, F: np.ndarray, alpha: int) -> np.ndarray:
    """:func:`_sx` for a 2-D ``t`` with one ``F`` per row (``F`` shape (k, 1), inf allowed)."""
    a = np.abs(t)
    inf = np.isinf(F)
    if inf.all():
        return -_sw_derivs(a, alpha)[0]
    h = np.where(inf, 0.0, 1.0 / np.where(inf, 1.0, F))
    Fz = np.where(inf, 0.0, F)
    far = inf | (a * Fz >= 64.0)
    if alpha == 2:  # sw'' = 0: the direct form is exact wherever it applies
        direct = Fz * Fz * (2.0 * _sw(t, 2) - _sw(t - h, 2) - _sw(t + h, 2))
        return np.where(far, 0.0, direct)
    direct = Fz * Fz * (2.0 * _sw(t, alpha) - _sw(t - h, alpha) - _sw(t + h, alpha))
    if not far.any():
        return direct
    g2, g4, g6 = _sw_derivs(np.where(far, a, 1.0), alpha)
    taylor = -(g2 + h * h * g4 / 12.0 + h**4 * g6 / 360.0)
    return np.where(far, taylor, direct)


def _sz_many(t: np.ndarray, F: np.ndarray, alpha: int, d: int) -> np.ndarray:
    c = _DIFF[d]
    out = c[0] * _sx_many(t, F, alpha)
    for k in range(1, d + 1):
        out = out + c[k] * (_sx_many(t - k, F, alpha) + _sx_many(t + k, F, alpha))
    return out


def _inv_edf_sum_many(J, M, S, F, alpha: int, d: int) -> np.ndarray:
    """:func:`_inv_edf_sum` of many rows at once (arrays ``J`` int, ``M``, ``S``, ``F``)."""
    J = np.asarray(J, dtype=np.int64)
    out = np.empty(J.size)
    step = 512
    for s0 in range(0, J.size, step):
        sl = slice(s0, min(s0 + step, J.size))
        Jr, Mr = J[sl][:, None], np.asarray(M, dtype=float)[sl][:, None]
        Sr, Fr = np.asarray(S, dtype=float)[sl][:, None], np.asarray(F, dtype=float)[sl][:, None]
        j = np.arange(int(Jr.max()) + 1, dtype=float)[None, :]
        sz = _sz_many(j / Sr, Fr, alpha, d)
        s2 = sz * sz
        w = 2.0 * (1.0 - j / Mr)
        w = np.where(j <= Jr, w, 0.0)
        w[:, 0] = 1.0
        rows = np.arange(Jr.shape[0])
        w[rows, Jr[:, 0]] = 1.0 - Jr[:, 0] / Mr[:, 0]
        out[sl] = np.einsum("ij,ij->i", w, s2) / (s2[:, 0] * Mr[:, 0])
    return out


@functools.lru_cache(maxsize=1)
def _fast_tables():
    """Tables 1-3 as arrays for the compiled EDF (``[2 - alpha, d - 1, (a0, a1)]``) and
    the difference coefficients per order d."""
    t1 = np.full((7, 3, 2), np.nan)
    t2 = np.full((7, 3, 2), np.nan)
    for tab, arr in ((_TABLE1, t1), (_TABLE2, t2)):
        for a, row in tab.items():
            for j, v in enumerate(row):
                if v is not None:
                    arr[2 - a, j] = v
    return t1, t2, np.array(_TABLE3), {d: np.asarray(c) for d, c in _DIFF.items()}


def edf_greenhall_many(statistic: str, n_phase: int, m, alpha) -> np.ndarray:
    """:func:`edf_greenhall` for many averaging factors at once.

    The same algorithm and branches, evaluated as 2-D numpy arrays (one row per m, the
    basic-sum lags as columns) instead of a Python loop over m; equal to the scalar
    function up to the order of summation (tested to 1e-12). ``alpha`` is one value or one
    per m.
    """
    d, overlapping, modified = GREENHALL_STATS[statistic]
    m = np.atleast_1d(np.asarray(m, dtype=np.int64))
    N = int(n_phase)
    K = fast_kernels()
    if K is not None:  # the same branches per m, compiled
        t1, t2, t3, diffs = _fast_tables()
        al = np.asarray(alpha, dtype=np.int64)
        al = al if al.shape == m.shape else np.broadcast_to(al, m.shape).copy()
        out = np.empty(m.size)
        K.greenhall_many(float(N), m, al, d, overlapping, modified, t1, t2, t3, diffs[d],
                         J_MAX, out)
        return out
    al = np.broadcast_to(np.asarray(alpha, dtype=np.int64), m.shape)
    out = np.full(m.size, np.nan)
    for a in (int(v) for v in np.unique(al)):
        sel = np.flatnonzero((al == a) & (m >= 1))
        if a + 2 * d <= 1 or a > 2 or sel.size == 0:
            continue
        mm = m[sel].astype(float)
        F = np.ones_like(mm) if modified else mm.copy()
        S = mm.copy() if overlapping else np.ones_like(mm)
        L = mm / F + mm * d
        M = 1.0 + np.floor(S * (N - L) / mm)
        J = np.minimum(M, (d + 1) * S)
        r = M / np.where(S > 0, S, 1.0)
        inv = np.full(sel.size, np.nan)
        ok = M >= 1
        direct = ok & (J <= J_MAX)
        table = ok & ~direct & (r > d + 1)
        resc = ok & ~direct & ~table
        inf = float("inf")
        if modified or a <= 0:
            if direct.any():
                Fd = (np.ones(direct.sum()) if modified else
                      np.where(mm[direct] * (d + 1) <= J_MAX, mm[direct], inf))
                inv[direct] = _inv_edf_sum_many(J[direct], M[direct], S[direct], Fd, a, d)
            if table.any():
                a0, a1 = (_TABLE1 if modified else _TABLE2)[a][d - 1]
                inv[table] = (a0 - a1 / r[table]) / r[table]
            if resc.any():
                k = int(resc.sum())
                inv[resc] = _inv_edf_sum_many(np.full(k, J_MAX), np.full(k, float(J_MAX)),
                                              J_MAX / r[resc],
                                              np.full(k, 1.0 if modified else inf), a, d)
        elif a == 1:
            b0, b1 = _TABLE3[d - 1]
            if direct.any():
                inv[direct] = _inv_edf_sum_many(J[direct], M[direct], S[direct], mm[direct],
                                                1, d)
            if table.any():
                a0, a1 = _TABLE2[1][d - 1]
                inv[table] = (a0 - a1 / r[table]) / ((b0 + b1 * np.log(mm[table])) ** 2
                                                     * r[table])
            if resc.any():
                mp = (J_MAX / r[resc])[:, None]
                j = np.arange(0, J_MAX + 1, dtype=float)[None, :]
                sz = _sz_many(j / mp, mp, 1, d)
                w = 2.0 * (1.0 - j / J_MAX)
                w[:, 0], w[:, -1] = 1.0, 0.0
                inv[resc] = (np.einsum("ij,ij->i", np.broadcast_to(w, sz.shape), sz * sz)
                             / ((b0 + b1 * np.log(mm[resc])) ** 2 * J_MAX))
        else:  # alpha == 2, unmodified
            small = ok & (np.ceil(r) <= d)
            if small.any():
                # white phase, finite support: sz(k) = 2 F c_k at the lags j = k S, k <= d
                # (sx vanishes off zero at integer t), the same sum as the scalar branch
                Ss, Ms, Js = S[small][:, None], M[small][:, None], J[small][:, None]
                k = np.arange(d + 1, dtype=float)[None, :]
                j = k * Ss
                inside = j <= Js
                sz = 2.0 * mm[small][:, None] * np.asarray(_DIFF[d])[None, :]
                w = np.where(inside, 2.0 * (1.0 - j / Ms), 0.0)
                w[:, 0] = 1.0
                last = inside & (j == Js) & (k > 0)
                w = np.where(last, 1.0 - Js / Ms, w)
                s2 = sz * sz
                inv[small] = (np.einsum("ij,ij->i", w, s2) / (s2[:, 0] * Ms[:, 0]))
            big = ok & ~small
            a0 = math.comb(4 * d, 2 * d) / math.comb(2 * d, d) ** 2
            inv[big] = (a0 - (d / 2.0) / r[big]) / M[big]
        with np.errstate(divide="ignore", invalid="ignore"):
            out[sel] = np.where(inv > 0, 1.0 / inv, np.nan)
    return out


# ----------------------------------------------------------------------------- dispatcher


def edf(statistic: str, n_phase: int, m, alpha, *, n_terms=None, method: str = "default"):
    """EDF per tau; returns ``(edf_array, method_name)``.

    Parameters
    ----------
    statistic : str
    n_phase : int
        Number of angle (phase) points ``N_x`` (rate samples + 1).
    m, alpha : array_like of int
        Averaging factors and noise types.
    n_terms : array_like of int, optional
        Summands per tau (needed by "gaussian").
    method : {"default", "greenhall", "sp1065", "gaussian"}
        "default": Greenhall & Riley (2003) for every statistic it covers (adev, oadev,
        mdev, tdev, hdev, ohdev) and SP 1065 Table 7 for ``totdev``
        (Table 5 where Table 7 has no row: alpha = +1, +2).
    """
    m = np.atleast_1d(np.asarray(m, dtype=np.int64))
    alpha = np.asarray(alpha, dtype=np.int64)
    if alpha.shape != m.shape:
        alpha = np.broadcast_to(alpha, m.shape)
    if method not in ("default", "greenhall", "sp1065", "gaussian"):
        raise InputError(f"unknown edf method '{method}' (use default, greenhall, sp1065, "
                         "gaussian)")
    if method == "default":
        method = "sp1065" if statistic == "totdev" else "greenhall"
    if method == "sp1065" and statistic not in ("oadev", "totdev", "adev"):
        method = "greenhall"
    if method == "greenhall" and statistic not in GREENHALL_STATS:
        method = "sp1065" if statistic == "totdev" else method
    if method == "greenhall" and statistic not in GREENHALL_STATS:
        raise InputError(f"no Greenhall EDF for statistic '{statistic}'")
    out = np.empty(m.size)
    if method == "greenhall":
        lo, _ = _ALPHA_RANGE.get(statistic, (-2, 2))
        out = edf_greenhall_many(statistic, n_phase, m, np.minimum(np.maximum(alpha, lo), 2))
        out = np.where(np.isfinite(out) & (out > 0), out, np.nan)
        return out, "greenhall-2003"
    if method == "sp1065":  # vectorised per noise type (the same closed forms)
        a_all = np.clip(alpha, -2, 2)
        for a in (int(v) for v in np.unique(a_all)):
            sel = a_all == a
            if statistic == "totdev":
                out[sel] = edf_totdev_sp1065(n_phase, m[sel], a)
            else:
                out[sel] = edf_oadev_sp1065(n_phase, m[sel], a)
        out = np.where(np.isfinite(out) & (out > 0), out, np.nan)
        return out, "sp1065-table5" if statistic != "totdev" else "sp1065-table7"
    if method == "gaussian":
        if n_terms is None:
            n_terms = _n_terms(statistic, n_phase, m)
        n_terms = np.broadcast_to(np.asarray(n_terms, dtype=np.int64), m.shape)
    for i in range(m.size):
        a, mm = int(alpha[i]), int(m[i])
        if method == "sp1065":
            a = max(min(a, 2), -2)
            if statistic == "totdev":
                out[i] = float(edf_totdev_sp1065(n_phase, mm, a))
            else:
                out[i] = float(edf_oadev_sp1065(n_phase, mm, a))
        elif method == "greenhall":
            lo, _ = _ALPHA_RANGE.get(statistic, (-2, 2))
            out[i] = edf_greenhall(statistic, n_phase, mm, max(min(a, 2), lo))
        else:
            out[i] = edf_gaussian(statistic, n_phase, mm, a, int(n_terms[i]))
    out = np.where(np.isfinite(out) & (out > 0), out, np.nan)
    label = {"sp1065": "sp1065-table5" if statistic != "totdev" else "sp1065-table7",
             "gaussian": "gaussian-exact", "greenhall": "greenhall-2003"}[method]
    return out, label


def _n_terms(statistic: str, n_phase: int, m: np.ndarray) -> np.ndarray:
    """Summands per m (one count rule: :func:`inertialab.noise.statistics._octave.n_terms`)."""
    return np.broadcast_to(n_terms(statistic, n_phase, m), m.shape).copy()


# ----------------------------------------------------------------------------- identification

#: Names of :mod:`inertialab.noise.statistics.identify` still importable from here (they lived in
#: this module before).
_MOVED = ("NoiseIdentification", "R_N_MAX", "b1_theory", "identify_alpha", "lag1_alpha")


def __getattr__(name):  # PEP 562: lazy re-export (identify imports this module)
    if name in _MOVED:
        from inertialab.noise.statistics import identify

        return getattr(identify, name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


__all__ = ["GREENHALL_STATS", "J_MAX", "M_CAP", "chi2_interval", "edf", "edf_gaussian",
           "edf_greenhall", "edf_greenhall_many", "edf_oadev_sp1065", "edf_totdev_sp1065",
           "filter_autocorr"]
