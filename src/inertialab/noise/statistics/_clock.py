"""Shared pieces of the clock statistics (:mod:`~inertialab.noise.statistics.total`,
:mod:`~inertialab.noise.statistics.theo`, :mod:`~inertialab.noise.statistics.tie`): the phase of the input, the
averaging factors, the noise type per tau and the result with its interval.

Conventions as :mod:`inertialab.noise.statistics.allan`: ``input="rate"`` is the frequency analogue
(rate samples, or fractional frequency), integrated to phase after removing the mean
(``x_0 = 0``); ``input="angle"`` is the phase analogue (angle, or phase in s). The
noise type ``alpha`` is the power-law exponent of the rate/frequency PSD (+2 WPM,
+1 FPM, 0 WFM, -1 FFM, -2 RWFM), identified per tau as Stable32 does
(:func:`inertialab.noise.statistics.identify.identify_alpha`) unless given.
"""

from __future__ import annotations

import math

import numpy as np

from inertialab.errors import InputError
from inertialab.noise.statistics._phase import _make_source, check_input_rate


def phase_source(data, rate_hz: float, input: str):
    """``(src, x)``: the in-memory phase source of ``data`` and its phase array."""
    rate = check_input_rate(input, rate_hz)
    arr = np.asarray(data, dtype=np.float64)
    if arr.ndim != 1:
        raise InputError(f"data must be one-dimensional, got shape {arr.shape}")
    if arr.size < 3:
        raise InputError(f"too few samples ({arr.size}) for any tau")
    bad = np.flatnonzero(~np.isfinite(arr))
    if bad.size:
        raise InputError("data contains NaN or infinity at sample index "
                         f"{', '.join(str(int(b)) for b in bad[:5])} (gaps: use the "
                         "gap-resistant oadev, argument 'gaps')")
    src = _make_source(arr, rate, input, False)
    if src.constant:
        raise InputError("data are constant (zero deviation at every tau); nothing to analyse")
    return src, src.x


def grid(n_phase: int, taus, rate_hz: float, mmax: int, *, even: bool = False,
         mmin: int = 1, scale: float = 1.0) -> np.ndarray:
    """Averaging factors for ``taus`` (as :func:`inertialab.noise.statistics.allan.tau_grid`:
    "octave", "decade", "many", "all", a count or seconds) within ``[mmin, mmax]``;
    ``even`` keeps even m only (Theo1); explicit seconds are divided by ``scale`` (Theo1:
    tau = 0.75 m tau0)."""
    if mmax < mmin:
        raise InputError(f"too few samples ({n_phase} phase points) for the smallest tau")
    if isinstance(taus, str):
        kind = taus.strip().lower()
        if kind == "octave":
            m = 2 ** np.arange(int(math.floor(math.log2(mmax))) + 1, dtype=np.int64)
        elif kind == "decade":
            top = int(math.floor(math.log10(mmax))) + 1
            m = np.array([k * 10 ** e for e in range(top) for k in (1, 2, 4)], dtype=np.int64)
        elif kind == "many":
            m = many_m(mmax)
        elif kind == "all":
            m = np.arange(1, mmax + 1, dtype=np.int64)
        else:
            raise InputError(f"unknown taus '{taus}' (use octave, decade, many, all, a count "
                             "or a list of seconds)")
    elif isinstance(taus, (int, np.integer)) and not isinstance(taus, bool):
        if taus < 1:
            raise InputError(f"the number of taus must be >= 1, got {taus}")
        m = np.unique(np.round(np.logspace(math.log10(mmin), math.log10(mmax),
                                           int(taus))).astype(np.int64))
    else:
        arr = np.atleast_1d(np.asarray(taus, dtype=float))
        if arr.size == 0 or not np.all(np.isfinite(arr)) or np.any(arr <= 0):
            raise InputError("taus must be positive, finite seconds")
        m = np.unique(np.maximum(np.round(arr * rate_hz / scale), 1).astype(np.int64))
    if even:
        m = np.unique(m + (m % 2))
    m = m[(m >= mmin) & (m <= mmax)]
    if m.size == 0:
        raise InputError(f"no tau in the valid range of averaging factors [{mmin}, {mmax}]")
    return m


def many_m(mmax: int, per_decade: int = 10) -> np.ndarray:
    """About ``per_decade`` log-spaced unique averaging factors per decade, 1..mmax
    (the "many" tau set: denser than octave, far cheaper than "all")."""
    if mmax < 1:
        return np.zeros(0, dtype=np.int64)
    k = max(1, int(math.ceil(per_decade * math.log10(max(mmax, 1)))) + 1)
    return np.unique(np.round(np.logspace(0, math.log10(mmax), k)).astype(np.int64))


def noise_types(src, ms, statistic: str, alpha, *, data: str = "phase", n_terms=None):
    """``(alpha array, sources, method)``: the user's alpha or the identified one
    (``data``: "phase" or "freq", the input kind; ``n_terms``: the statistic's summands
    per m, where B1's expected values are taken)."""
    from inertialab.noise.statistics import identify as _ident

    ms = np.asarray(ms, dtype=np.int64)
    if alpha is None:
        ident = _ident.identify_alpha(src, ms, statistic=statistic, data=data,
                                      n_terms=n_terms)
        return np.asarray(ident.alpha, dtype=np.int64), tuple(ident.source), "stable32"
    a = np.broadcast_to(np.asarray(alpha, dtype=np.int64), ms.shape).copy()
    return a, ("user",) * ms.size, "user"


def interval(dev, edfs, confidence: float):
    """Chi-square interval (NaN where the EDF is not positive/finite)."""
    from inertialab.noise.statistics import edf as _edf

    if not 0.0 < float(confidence) < 1.0:
        raise InputError(f"confidence must be in (0, 1), got {confidence}")
    edfs = np.asarray(edfs, dtype=float)
    lo, hi = _edf.chi2_interval(dev, np.where(np.isfinite(edfs), edfs, 0.0), confidence)
    bad = ~(np.isfinite(edfs) & (edfs > 0))
    lo = np.where(bad, np.nan, lo)
    hi = np.where(bad, np.nan, hi)
    return lo, hi
