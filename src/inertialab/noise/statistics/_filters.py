"""Filters of the Allan family and the generalized autocovariance of power-law noise,
shared by :mod:`inertialab.noise.statistics.edf` (the Gaussian EDF) and
:mod:`inertialab.noise.statistics.identify` (the R(n) theory); kept apart so that neither imports
the other."""

from __future__ import annotations

import numpy as np

from inertialab.errors import InputError

#: Above this averaging factor the "gaussian" EDF uses the continuous-time limit.
M_CAP = 64

_ALPHA_RANGE = {"adev": (-2, 2), "oadev": (-2, 2), "mdev": (-2, 2), "tdev": (-2, 2),
                "totdev": (-2, 2), "hdev": (-4, 2), "ohdev": (-4, 2)}


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
