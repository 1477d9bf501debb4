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
    (as allantools and Stable32), Greenhall's oadev EDF for totdev's phase noises.
    (Until issue 14 the default was SP 1065 Table 5 for oadev and the numeric Gaussian
    EDF elsewhere; the latter collapsed for random-walk rate at small m and cost
    2-12 ms and ~49 MB per tau.)

Noise identification (:func:`identify_alpha`) follows NIST SP 1065 §5.5.6 (Riley &
Greenhall 2004): the lag-1 autocorrelation of the decimated angle, differenced until
``delta = r1/(1+r1) < 0.25`` (at most d = 2 times, 3 for Hadamard), gives
``alpha = round(2 - 2(delta + d))``; with fewer than 30 decimated points it falls back
to the B1 ratio (standard / Allan variance of the m-averages; SP 1065 §5.5.4) and, to
split white from flicker angle noise, R(n) = MVAR/AVAR (§5.5.5; for records above
``R_N_MAX`` points whose angle is not in memory, white angle noise is assumed).

Why hand-written: no maintained library offers these for our estimator set (allantools
is LGPL and a test-only cross-check).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.stats import chi2

from inertialab.errors import InputError

#: Above this averaging factor the "gaussian" EDF uses the continuous-time limit.
M_CAP = 64

#: Largest record (angle points) whose angle is materialised for the R(n) test.
R_N_MAX = 1 << 22

_ALPHA_RANGE = {"adev": (-2, 2), "oadev": (-2, 2), "mdev": (-2, 2), "tdev": (-2, 2),
                "totdev": (-2, 2), "hdev": (-4, 2), "ohdev": (-4, 2)}


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
        e = np.where(ok, edf, 1.0)
        lo = dev * np.sqrt(e / chi2.ppf(0.5 * (1 + p), e))
        hi = dev * np.sqrt(e / chi2.ppf(0.5 * (1 - p), e))
    return np.where(ok, lo, np.nan), np.where(ok, hi, np.nan)


# ----------------------------------------------------------------------------- SP 1065


def edf_oadev_sp1065(n_phase: int, m, alpha: int) -> np.ndarray:
    """Overlapping-Allan EDF, NIST SP 1065 Table 5 (spec 001 §3.2), ``N_x = n_phase``."""
    nx = float(n_phase)
    m = np.asarray(m, dtype=float)
    if alpha == 2:
        return (nx + 1) * (nx - 2 * m) / (2 * (nx - m))
    if alpha == 1:
        return np.exp(np.sqrt(np.log((nx - 1) / (2 * m)) * np.log((2 * m + 1) * (nx - 1) / 4)))
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


def _gacv(alpha: int, t: np.ndarray) -> np.ndarray:
    """Generalized autocovariance of the angle (phase) for rate PSD ~ f^alpha (any scale)."""
    t = np.abs(np.asarray(t, dtype=float))
    with np.errstate(divide="ignore", invalid="ignore"):
        lg = np.where(t > 0, np.log(np.where(t > 0, t, 1.0)), 0.0)
    if alpha == 2:
        return (t == 0).astype(float)
    if alpha == 1:
        return np.where(t == 0, 1.0, -lg)
    if alpha == 0:
        return -t
    if alpha == -1:
        return t * t * lg
    if alpha == -2:
        return t**3
    if alpha == -3:
        return -(t**4) * lg
    if alpha == -4:
        return -(t**5)
    raise InputError(f"no noise model for alpha = {alpha}")


def _family(statistic: str) -> str:
    if statistic in ("adev", "oadev", "totdev"):
        return "allan"
    if statistic in ("hdev", "ohdev"):
        return "hadamard"
    return "mod"


def filter_autocorr(statistic: str, m: int) -> np.ndarray:
    """Autocorrelation ``a_k = sum_j w_j w_{j+k}``, k = 0..L, of the statistic's filter on
    the angle at unit spacing (second difference at lag m; third for Hadamard; the
    m-average of second differences for the modified variance)."""
    fam = _family(statistic)
    if fam == "allan":
        a = np.zeros(2 * m + 1)
        a[0], a[m], a[2 * m] = 6.0, -4.0, 1.0
        return a
    if fam == "hadamard":
        a = np.zeros(3 * m + 1)
        a[0], a[m], a[2 * m], a[3 * m] = 20.0, -15.0, 6.0, -1.0
        return a
    k = np.arange(3 * m + 1)
    a = np.zeros(3 * m + 1)
    for j, s in zip((-2, -1, 0, 1, 2), (1.0, -4.0, 6.0, -4.0, 1.0)):
        d = np.abs(k - j * m)
        a += s * np.where(d < m, m - d, 0)
    return a


def _filter_cov(a: np.ndarray, alpha: int, lags: np.ndarray) -> np.ndarray:
    """Covariance ``R(k) = sum_c a_c C(k + c)`` of filter outputs at lags ``k``."""
    lags = np.asarray(lags, dtype=float)
    if alpha == 2:
        k = np.abs(lags).astype(np.int64)
        out = np.zeros(lags.shape)
        inside = k < a.size
        out[inside] = a[k[inside]]
        return out
    c = np.concatenate([a[:0:-1], a])  # lags -L..L
    off = np.arange(-(a.size - 1), a.size, dtype=float)
    out = np.empty(lags.shape)
    step = max(1, 2_000_000 // c.size)
    for s in range(0, lags.size, step):
        kk = lags[s:s + step, None] + off[None, :]
        out[s:s + step] = np.einsum("ij,j->i", _gacv(alpha, kk), c)
    return out


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
    if alpha in (2, 0, -2, -4):
        return {2: -a, 0: a**3, -2: a**5, -4: a**7}[alpha]
    lg = np.log(np.where(a > 0, a, 1.0))
    return {1: a**2, -1: a**4, -3: a**6}[alpha] * lg


def _sw_derivs(a: np.ndarray, alpha: int):
    """Second, fourth and sixth derivatives of ``sw`` at ``|t| = a > 0``."""
    with np.errstate(divide="ignore"):
        lg = np.log(np.where(a > 0, a, 1.0))
        inv2 = np.where(a > 0, 1.0 / np.where(a > 0, a, 1.0) ** 2, 0.0)
    z = np.zeros_like(a)
    if alpha == 2:
        return z, z, z
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
        mdev, tdev, hdev, ohdev; issue 14 item 4) and SP 1065 Table 7 for ``totdev``
        (Greenhall's for oadev where Table 7 has no row: alpha = +1, +2).
    """
    m = np.atleast_1d(np.asarray(m, dtype=np.int64))
    alpha = np.broadcast_to(np.asarray(alpha, dtype=np.int64), m.shape)
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
    if method == "gaussian":
        if n_terms is None:
            n_terms = _n_terms(statistic, n_phase, m)
        n_terms = np.broadcast_to(np.asarray(n_terms, dtype=np.int64), m.shape)
    for i in range(m.size):
        a, mm = int(alpha[i]), int(m[i])
        if method == "sp1065":
            a = max(min(a, 2), -2)
            if statistic == "totdev":
                out[i] = (float(edf_totdev_sp1065(n_phase, mm, a)) if a <= 0
                          else edf_greenhall("oadev", n_phase, mm, a))
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
    nx = n_phase
    if statistic == "oadev":
        return nx - 2 * m
    if statistic == "adev":
        return (nx - 1) // m - 1
    if statistic == "ohdev":
        return nx - 3 * m
    if statistic == "hdev":
        return (nx - 1) // m - 2
    if statistic in ("mdev", "tdev"):
        return nx - 3 * m + 1
    return np.full(m.shape, nx - 2)


# ----------------------------------------------------------------------------- identification


@dataclass(frozen=True)
class NoiseIdentification:
    """Noise type per tau: ``alpha`` (int) and ``source`` ("lag1" or "b1")."""

    m: np.ndarray
    alpha: np.ndarray
    source: tuple


def lag1_alpha(z: np.ndarray, *, dmax: int = 2, data_type: str = "phase") -> float:
    """Lag-1 ACF noise estimate (SP 1065 §5.5.6), unrounded ``alpha`` of the rate.

    ``z`` is decimated angle (``data_type="phase"``) or averaged rate ("freq").
    """
    z = np.asarray(z, dtype=float)
    theta = 1 if data_type == "phase" else 0
    d = 0
    while True:
        zc = z - z.mean()
        den = float(np.einsum("i,i->", zc, zc))
        r1 = float(np.einsum("i,i->", zc[:-1], zc[1:]) / den) if den > 0 else 0.0
        delta = r1 / (1.0 + r1)
        if delta < 0.25 or d >= dmax or z.size < 4:
            return -2.0 * (delta + d) + 2.0 * theta
        z = np.diff(z)
        d += 1


def b1_theory(n: int, mu: float) -> float:
    """Theoretical B1 ratio for ``n`` averages and AVAR tau-exponent ``mu`` (SP 1065 §5.5.4)."""
    if mu == 0:
        return n * math.log(n) / (2.0 * (n - 1) * math.log(2.0))
    return n * (1.0 - n**mu) / (2.0 * (n - 1) * (1.0 - 2.0**mu))


def _rn_theory(m: int, alpha: int) -> float:
    a_mod = filter_autocorr("mdev", m)
    a_al = filter_autocorr("oadev", m)
    rm = float(_filter_cov(a_mod, alpha, np.array([0.0]))[0]) / m**2
    ra = float(_filter_cov(a_al, alpha, np.array([0.0]))[0])
    return rm / ra


def identify_alpha(src, ms, *, statistic: str = "oadev", max_points: int = 1 << 16,
                   min_points: int = 30, decimated: dict | None = None) -> NoiseIdentification:
    """Noise type per averaging factor from an angle source (see module docstring).

    ``src`` offers ``n`` (angle points) and ``window(start, length, step)``. At most
    ``max_points`` decimated points (the central ones) are used per tau. ``decimated``
    maps m to those points already gathered, or to ``("lag1", alpha)`` already decided.
    """
    lo, hi = _ALPHA_RANGE.get(statistic, (-2, 2))
    dmax = 3 if _family(statistic) == "hadamard" else 2
    alphas, sources = [], []
    for m in (int(v) for v in np.atleast_1d(ms)):
        count = (src.n - 1) // m + 1
        use = min(count, max_points)
        start = ((count - use) // 2) * m
        if decimated is not None and m in decimated:
            z = decimated[m]
            if isinstance(z, tuple):  # ("lag1", unrounded alpha) computed by the caller
                alphas.append(max(lo, min(hi, int(round(z[1])))))
                sources.append("lag1")
                continue
            use = z.size
        else:
            z = np.asarray(src.window(start, use, m), dtype=float)
        if use >= min_points:
            a = int(round(lag1_alpha(z, dmax=dmax)))
            alphas.append(max(lo, min(hi, a)))
            sources.append("lag1")
            continue
        alphas.append(max(lo, min(hi, _b1_alpha(src, z, m))))
        sources.append("b1")
    return NoiseIdentification(np.asarray(list(ms), dtype=np.int64),
                               np.asarray(alphas, dtype=np.int64), tuple(sources))


def _b1_alpha(src, z: np.ndarray, m: int) -> int:
    ybar = np.diff(z)  # proportional to the m-averages of the rate
    n = ybar.size
    if n < 3:
        return 0
    avar = 0.5 * float(np.mean(np.diff(ybar) ** 2))
    if avar <= 0:
        return 0
    b1 = float(np.var(ybar, ddof=1)) / avar
    mus = (-2.0, -1.0, 0.0, 1.0)
    th = [b1_theory(n, mu) for mu in mus]
    best = 0
    for i in range(1, len(mus)):
        if b1 > math.sqrt(th[i - 1] * th[i]):
            best = i
    mu = mus[best]
    if mu > -2:
        return int(-mu - 1)
    # white vs flicker angle noise: R(n) = MVAR/AVAR at this m
    if 3 * m > src.n - 1:
        return 2
    from inertialab.noise._phase import _PhaseArray, _sum_sq_filter, _sum_sq_mod

    if not hasattr(src, "x"):
        # R(n) needs full-resolution passes; records of more than R_N_MAX points whose
        # angle is not in memory (octave fast path, chunked path) skip it and report a
        # phase-noise verdict of B1 as white angle noise
        if src.n > R_N_MAX:
            return 2
        src = _PhaseArray(np.asarray(src.window(0, src.n), dtype=np.float64))

    n_al = src.n - 2 * m
    n_mod = src.n - 3 * m + 1
    avar_o = _sum_sq_filter(src, m, (1.0, -2.0, 1.0), 1, n_al) / n_al
    mvar = _sum_sq_mod(src, m, n_mod) / n_mod / m**2
    rn = mvar / avar_o if avar_o > 0 else 1.0 / m
    # theory: white angle R(n) = 1/m exactly; flicker angle from the Gaussian model at
    # min(m, M_CAP) (it varies slowly with m)
    thr = math.sqrt((1.0 / m) * _rn_theory(min(m, M_CAP), 1))
    return 2 if rn < thr else 1


__all__ = ["GREENHALL_STATS", "J_MAX", "M_CAP", "NoiseIdentification", "b1_theory",
           "chi2_interval", "edf", "edf_gaussian", "edf_greenhall", "edf_oadev_sp1065", "edf_totdev_sp1065", "filter_autocorr",
           "identify_alpha", "lag1_alpha"]
