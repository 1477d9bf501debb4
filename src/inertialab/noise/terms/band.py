"""Band-limited flicker: the Allan-variance shape of a log-uniform mixture of
Gauss–Markov processes, the B term of the noise-term fit and the BL process of GMWM
(split from :mod:`inertialab.noise.terms.base` so that the GMWM latent processes and
the noise-term types import it without importing each other)."""

from __future__ import annotations

import math

import numpy as np


def _gm_shape(v: np.ndarray) -> np.ndarray:
    """Allan variance of a unit-variance continuous Gauss–Markov process at ``tau = v Tc``:
    ``(2v - 3 + 4 e^-v - e^-2v) / v^2`` (series for small v, no cancellation)."""
    v = np.asarray(v, dtype=float)
    out = np.empty_like(v)
    small = v < 0.05
    vs = v[small]
    ser = np.zeros_like(vs)
    for k in range(12, 2, -1):  # sum_k>=3 (4(-1)^k - (-2)^k) v^(k-2) / k!
        ser = ser * vs + (4.0 * (-1) ** k - (-2.0) ** k) / math.factorial(k)
    out[small] = ser * vs
    vl = v[~small]
    out[~small] = (2 * vl - 3 + 4 * np.exp(-vl) - np.exp(-2 * vl)) / (vl * vl)
    return out


_LU = np.linspace(math.log(1e-9), math.log(1e11), 8001)
_h = _gm_shape(np.exp(_LU))
#: H(u) = int_0^u h(v) dv/v on the log grid _LU (H(0) = 0, H(inf) = 2 ln 2)
_HTAB = (2.0 / 3.0) * math.exp(_LU[0]) + np.concatenate(
    [[0.0], np.cumsum(0.5 * (_h[1:] + _h[:-1]) * np.diff(_LU))])
_HINF = 2.0 * math.log(2.0)


def _H(u) -> np.ndarray:
    u0 = np.asarray(u, dtype=float)
    u = np.atleast_1d(u0)
    with np.errstate(divide="ignore"):
        lu = np.log(u)
    out = np.interp(lu, _LU, _HTAB)
    lo = lu < _LU[0]
    out[lo] = (2.0 / 3.0) * u[lo]
    out[lu > _LU[-1]] = _HINF
    return out.reshape(u0.shape)


def band_shape(taus_s, t_lo: float, t_hi: float) -> np.ndarray:
    """Allan-variance shape of band-limited flicker (bias instability), peak 1.

    Flicker rate noise ``h/f`` between the corners ``1/(2 pi t_hi)`` and
    ``1/(2 pi t_lo)``, built as the log-uniform mixture of first-order Gauss–Markov
    processes with correlation times in ``[t_lo, t_hi]`` (equal variance per
    ``d ln Tc``; the sum of Gauss–Markov processes of real MEMS gyros and of the
    virtual-lab presets). Its AVAR is proportional to
    ``H(tau/t_lo) - H(tau/t_hi)``, ``H(u) = int_0^u h(v) dv/v`` with ``h`` the
    Gauss–Markov shape; it is flat (``2 ln2 h``, IEEE 952 flicker) between the corners,
    rises like random walk below ``t_lo`` and falls like white noise above ``t_hi``.
    Normalised to its maximum over all tau, so the B coefficient ``c_0`` is the peak
    AVAR of the term and ``B = sqrt(c_0)/0.6643`` is IEEE 952's flat-region value (the
    definition of the virtual-lab truth). ``t_lo = 0, t_hi = inf`` is pure flicker (1).
    """
    t = np.asarray(taus_s, dtype=float)
    lo = float(t_lo)
    hi = float(t_hi)
    if lo <= 0 and not math.isfinite(hi):
        return np.ones(t.shape)
    a = _H(t / lo) if lo > 0 else np.full(t.shape, _HINF)
    b = _H(t / hi) if math.isfinite(hi) else np.zeros(t.shape)
    return (a - b) / _band_peak(lo, hi)


def _band_peak(lo: float, hi: float) -> float:
    if lo <= 0 or not math.isfinite(hi):
        return _HINF
    x = np.exp(np.linspace(math.log(lo) - 3.0, math.log(hi) + 3.0, 400))
    p = _H(x / lo) - _H(x / hi)
    i = int(np.argmax(p))
    xf = np.exp(np.linspace(math.log(x[max(i - 1, 0)]), math.log(x[min(i + 1, x.size - 1)]), 64))
    return float(np.max(_H(xf / lo) - _H(xf / hi)))


def rw_gm_shape(taus_s, t_c: float) -> np.ndarray:
    """Allan-variance shape of a rate random walk that is a first-order Gauss–Markov
    process of correlation time ``t_c`` (s): ``1.5 t_c h(tau / t_c)``, with ``h`` the
    Gauss–Markov shape of :func:`_gm_shape`. It equals ``tau`` (the K column of the
    five-term model, IEEE 952's ``K^2 tau / 3`` per unit ``K^2/3``) for ``tau << t_c``,
    peaks near ``tau = 1.9 t_c`` and falls like white noise beyond: a random walk that is
    held to a finite variance ``1.5 t_c c_1`` (a temperature-driven wander, a bias that
    returns). ``t_c = inf`` is the random walk itself."""
    t = np.asarray(taus_s, dtype=float)
    if not math.isfinite(t_c):
        return t.copy()
    return 1.5 * t_c * _gm_shape(t / t_c)


__all__ = ["band_shape", "rw_gm_shape"]
