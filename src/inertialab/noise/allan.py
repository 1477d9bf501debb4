"""The Allan family of deviations with confidence intervals (spec 001 §3.1–3.2; issue 3).

Statistics: ``adev`` (non-overlapping Allan), ``oadev`` (overlapping Allan), ``mdev``
(modified Allan), ``tdev`` (time/angle deviation, ``tau/sqrt(3) * mdev``), ``hdev``
(non-overlapping Hadamard), ``ohdev`` (overlapping Hadamard) and ``totdev`` (total
deviation, reflected extension). Input is either rate samples (``input="rate"``, the
frequency analogue; integrated to angle after removing the mean, spec 001 eq. 2) or the
cumulative angle (``input="angle"``, the phase analogue). The deviation is in the
unit of the rate (for angle input: angle unit per second); ``tdev`` in rate unit times
seconds (arcsec for deg/h).

Every function returns one frozen :class:`DeviationResult` with the averaging factors,
the deviation, the number of summands, the power-law noise type ``alpha`` used for the
interval (identified per tau by the lag-1 autocorrelation method with a B1/R(n)
fallback, see :mod:`inertialab.noise.edf`, or given by the user), the equivalent
degrees of freedom and the chi-square interval at ``confidence`` (default 0.683).

Why hand-written: allantools (LGPL, a test dependency only) computes the same numbers
but allocates several arrays of the record's size per tau and has neither IMU terms nor
complete intervals. Here every per-tau sum runs over cache-sized blocks of one float64
angle array with reused buffers (no temporary of size n), which is about one memory
pass per tau; the same kernel reads a memory-mapped record too large for memory in
chunks (:func:`oadev_chunked` and ``chunked=True``), recomputing the angle from
checkpoints so that both paths produce the same angle values bit for bit.

References
----------
NIST SP 1065 (Riley 2008), §5.2 (definitions), §12 (the 1000-point test suite);
IEEE Std 952-1997 Annex C; spec 001 §3.1–3.2.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from inertialab.errors import InputError
from inertialab.noise._phase import (  # noqa: F401 - phase_window is public API here too
    BLOCK,
    CHECKPOINT,
    CHUNK,
    _chunked_mean,
    _LazyPhase,
    _make_source,
    _PhaseArray,
    _PhaseFromRate,
    _rate_to_phase,
    _reflect,
    _sum_sq_filter,
    _sum_sq_mod,
    _sumsq,
    check_input_rate,
    phase_window,
)

#: Statistics provided, in their canonical order.
STATISTICS = ("adev", "oadev", "mdev", "tdev", "hdev", "ohdev", "totdev")


#: Block length of the lag-doubling octave OADEV (its dot products are taken in
#: BLOCK-sized pieces, below OpenBLAS's threading threshold).
OCT_BLOCK = 1 << 16




@dataclass(frozen=True)
class DeviationResult:
    """One statistic evaluated at a set of averaging times.

    Attributes
    ----------
    statistic : str
        ``"adev" | "oadev" | "mdev" | "tdev" | "hdev" | "ohdev" | "totdev"``.
    tau0_s : float
        Sample interval in s.
    taus_s : ndarray, shape (k,)
        Averaging times ``m * tau0_s`` in s.
    m : ndarray of int, shape (k,)
        Averaging factors.
    dev : ndarray, shape (k,)
        The deviation, in the unit of the rate data (``tdev``: rate unit times s).
    n_terms : ndarray of int, shape (k,)
        Number of summands per tau (CONTRACTS.md "noise").
    alpha : ndarray of int, shape (k,)
        Power-law noise type of the rate PSD, ``S(f) ~ f^alpha``: +2 white angle
        (quantization), 0 white rate (ARW), -1 flicker rate (bias instability),
        -2 random-walk rate (RRW).
    edf : ndarray, shape (k,)
        Equivalent degrees of freedom.
    ci_low, ci_high : ndarray, shape (k,)
        Chi-square confidence interval of ``dev`` at ``confidence``.
    confidence : float
        Two-sided confidence level of the interval (default 0.683).
    n_samples : int
        Number of input samples.
    input : str
        ``"rate"`` or ``"angle"``.
    alpha_method : str
        ``"lag1"`` (lag-1 ACF, B1/R(n) fallback where marked in ``alpha_source``),
        ``"user"`` or ``"model"``.
    edf_method : str
        Which EDF algorithm was used (see :mod:`inertialab.noise.edf`).
    alpha_source : tuple of str
        Per tau: ``"lag1"``, ``"b1"``, ``"user"`` or ``"model"``.
    """

    statistic: str
    tau0_s: float
    taus_s: np.ndarray
    m: np.ndarray
    dev: np.ndarray
    n_terms: np.ndarray
    alpha: np.ndarray
    edf: np.ndarray
    ci_low: np.ndarray
    ci_high: np.ndarray
    confidence: float
    n_samples: int = 0
    input: str = "rate"
    alpha_method: str = "lag1"
    edf_method: str = ""
    alpha_source: tuple = field(default_factory=tuple)

    def __len__(self) -> int:
        return len(self.taus_s)

    def to_dict(self) -> dict:
        """JSON-ready dict (lists of floats/ints; NaN stays NaN for the emitter)."""
        return {
            "statistic": self.statistic,
            "tau0_s": float(self.tau0_s),
            "taus_s": [float(v) for v in self.taus_s],
            "m": [int(v) for v in self.m],
            "dev": [float(v) for v in self.dev],
            "ci_low": [float(v) for v in self.ci_low],
            "ci_high": [float(v) for v in self.ci_high],
            "n_terms": [int(v) for v in self.n_terms],
            "alpha": [int(v) for v in self.alpha],
            "edf": [float(v) for v in self.edf],
            "confidence": float(self.confidence),
            "n_samples": int(self.n_samples),
            "input": self.input,
            "alpha_method": self.alpha_method,
            "edf_method": self.edf_method,
        }


# ----------------------------------------------------------------------------- taus


def max_m(statistic: str, n_phase: int) -> int:
    """Largest valid averaging factor of ``statistic`` for ``n_phase`` angle points.

    At least one summand must remain: Allan family ``m <= (n_phase-1)//2``,
    modified and Hadamard ``m <= (n_phase-1)//3``, total ``m <= n_phase-1``
    (the reflected extension).
    """
    _check_stat(statistic)
    if statistic in ("adev", "oadev"):
        return (n_phase - 1) // 2
    if statistic in ("mdev", "tdev", "hdev", "ohdev"):
        return (n_phase - 1) // 3
    return max(n_phase - 2, 0)  # totdev: m <= N-2 keeps the extension in range


def tau_grid(n_samples: int, taus="octave", *, rate_hz: float = 1.0, statistic: str = "oadev",
             input: str = "rate") -> np.ndarray:
    """Averaging factors ``m`` (sorted, unique, int64) for a record of ``n_samples``.

    Parameters
    ----------
    n_samples : int
        Number of input samples (rate samples, or angle points for ``input="angle"``).
    taus : {"octave", "decade", "many", "all"} or int or sequence of float, default "octave"
        ``"octave"``: m = 2^k; ``"decade"``: m = {1, 2, 4}·10^k; ``"many"``: about ten
        log-spaced m per decade; ``"all"``: every m;
        an int n: n log-spaced unique m; a sequence: taus in seconds, rounded to
        the nearest m (CONTRACTS.md "noise"). Each is clipped to the statistic's
        largest valid m (:func:`max_m`).
    rate_hz : float, default 1.0
        Sample rate (only used for explicit taus).

    Raises
    ------
    InputError
        Too few samples for the smallest tau, or an unknown tau specification.
    """
    n_phase = n_samples + 1 if input == "rate" else n_samples
    mmax = max_m(statistic, n_phase)
    if isinstance(taus, str):
        kind = taus.strip().lower()
        if mmax < 1:
            raise InputError(f"too few samples ({n_samples}) for {statistic} at the smallest "
                             f"tau (m = 1 needs at least {_min_samples(statistic, input)})")
        if kind == "octave":
            m = 2 ** np.arange(int(math.floor(math.log2(mmax))) + 1, dtype=np.int64)
        elif kind == "decade":
            top = int(math.floor(math.log10(mmax))) + 1
            m = np.array([k * 10**e for e in range(top) for k in (1, 2, 4)], dtype=np.int64)
        elif kind == "all":
            m = np.arange(1, mmax + 1, dtype=np.int64)
        elif kind == "many":
            from inertialab.noise._clock import many_m

            m = many_m(mmax)
        else:
            raise InputError(f"unknown taus '{taus}' (use octave, decade, many, all, a count "
                             "or a list of seconds)")
    elif isinstance(taus, (int, np.integer)) and not isinstance(taus, bool):
        if taus < 1:
            raise InputError(f"the number of taus must be >= 1, got {taus}")
        if mmax < 1:
            raise InputError(f"too few samples ({n_samples}) for {statistic} at m = 1")
        m = np.unique(np.round(np.logspace(0, math.log10(mmax), int(taus))).astype(np.int64))
    else:
        arr = np.atleast_1d(np.asarray(taus, dtype=float))
        if arr.size == 0 or not np.all(np.isfinite(arr)) or np.any(arr <= 0):
            raise InputError("taus must be positive, finite seconds")
        m = np.unique(np.maximum(np.round(arr * rate_hz), 1).astype(np.int64))
        if mmax < m.min():
            raise InputError(
                f"too few samples ({n_samples}) for {statistic} at the smallest tau "
                f"{m.min() / rate_hz:g} s (m = {m.min()}, largest valid m = {mmax})")
    m = m[(m >= 1) & (m <= mmax)]
    if m.size == 0:
        raise InputError(f"too few samples ({n_samples}) for {statistic}")
    return m


def _min_samples(statistic: str, input: str) -> int:
    need = {"adev": 3, "oadev": 3, "mdev": 4, "tdev": 4, "hdev": 4, "ohdev": 4, "totdev": 3}
    return need[statistic] - (1 if input == "rate" else 0)


def _check_stat(statistic: str) -> None:
    if statistic not in STATISTICS:
        raise InputError(f"unknown statistic '{statistic}' (use {', '.join(STATISTICS)})")


# ----------------------------------------------------------------------------- validation


def _validate(data, rate_hz, input, *, name="data", check_finite: bool = True) -> np.ndarray:
    check_input_rate(input, rate_hz)
    arr = data if isinstance(data, np.ndarray) else np.asarray(data, dtype=float)
    if arr.ndim != 1:
        raise InputError(f"{name} must be one-dimensional, got shape {arr.shape}")
    if not np.issubdtype(arr.dtype, np.number) or np.issubdtype(arr.dtype, np.complexfloating):
        raise InputError(f"{name} must be real numbers, got dtype {arr.dtype}")
    if arr.size < 2:
        raise InputError(f"too few samples ({arr.size}) for any tau")
    if check_finite:
        _check_finite(arr, name)
    return arr


def _check_finite(arr: np.ndarray, name: str, offset: int = 0) -> None:
    if np.issubdtype(arr.dtype, np.integer):
        return
    for s in range(0, arr.size, CHUNK):
        blk = arr[s:s + CHUNK]
        ok = np.isfinite(blk)
        if not ok.all():
            bad = np.flatnonzero(~ok)[:5] + s + offset
            raise InputError(f"{name} contains NaN or infinity at sample index "
                             f"{', '.join(str(int(b)) for b in bad)}")


def _check_not_constant(src) -> None:
    if src.constant:
        raise InputError("data are constant (zero deviation at every tau); nothing to analyse")


# ----------------------------------------------------------------------------- angle sources
















def _oadev_octaves(y: np.ndarray, tau0: float, ms: np.ndarray, *, want_decimated: bool,
                   max_points: int = 1 << 13):
    """OAVAR at m = 1, 2, 4, ... by lag doubling, without the angle array.

    ``D_i = (x_{i+m} - x_i)/tau0`` starts as ``y_i - mean`` (m = 1); the second
    difference is ``D_{i+m} - D_i`` and ``D`` at 2m is ``D_i + D_{i+m}``, updated in place
    in ascending blocks. Per tau: one fused pass over one float64 array of the input's
    size (the only extra memory). Also returns, per m, the lag-1 noise verdict on the
    central ``max_points`` decimated angle points (or the points, where fewer than 30
    remain, for the B1 fallback).
    """
    from inertialab.noise import edf as _edf

    n = y.size
    nx = n + 1
    mean = _chunked_mean(y)
    if not math.isfinite(mean):
        _check_finite(y, "data")  # names the samples
        raise InputError("data too large to sum in float64")
    # D in units of (data unit) x samples; tau0 enters once in the variance (one pass less)
    d = np.subtract(y, mean, dtype=np.float64)
    var = np.empty(ms.size)
    nt = np.empty(ms.size, dtype=np.int64)
    dec = {} if want_decimated else None
    B = OCT_BLOCK
    buf = np.empty(B)
    wlo = np.empty(B)
    whi = np.empty(B)
    wsh = np.empty(B + B // 4)

    def identify(m: int, pair: bool) -> None:
        # decimated angle at lag m (or 2m, from pairs of D(m)), central max_points points
        lag = 2 * m if pair else m
        count = (nx - 1) // lag + 1
        use = min(count, max_points)
        start = ((count - use) // 2) * lag
        z = np.empty(use)
        z[0] = 0.0
        inc = d[start:start + (use - 1) * lag:m][:(use - 1) * (2 if pair else 1)]
        if pair:
            inc = inc[0::2] + inc[1::2]
        np.cumsum(inc, out=z[1:])
        # lag-1 verdict now (keeps memory at one copy); few points: keep them for B1
        dec[lag] = ("lag1", _edf.lag1_alpha(z, dmax=2)) if use >= 30 else z

    k = 0
    while k < ms.size:
        m = int(ms[k])
        pair = k + 1 < ms.size and int(ms[k + 1]) == 2 * m
        if dec is not None:
            identify(m, False)
            if pair:
                identify(m, True)
        n1 = nx - 2 * m  # second differences at m (D(m) has n - m + 1 valid entries)
        t1 = 0.0
        if not pair:
            more = k + 1 < ms.size
            # one pass: the second difference of the block, then (while the block is in
            # cache) D(2m)_i = D(m)_i + D(m)_{i+m} in place, for the same i <= n - 2m;
            # ascending blocks read only entries not yet updated
            for s in range(0, n1, B):
                e = min(s + B, n1)
                b = buf[:e - s]
                hi = d[s + m:e + m]
                lo = d[s:e]
                np.subtract(hi, lo, out=b)
                t1 += _sumsq(b)
                if more:
                    np.add(lo, hi, out=lo)
            var[k] = t1 / (2.0 * m * m * n1)
            nt[k] = n1
            k += 1
            continue
        # two octaves per pass: D(2m) at i and i + 2m from D(m), the second differences
        # at m and 2m, and D(4m)_i = D(2m)_i + D(2m)_{i+2m} written in place (same
        # operations, hence the same numbers, as two single passes)
        more = k + 2 < ms.size
        shared = 8 * m <= B
        n2 = nx - 4 * m  # second differences at 2m = valid D(4m) entries
        t2 = 0.0
        for s in range(0, n1, B):
            e = min(s + B, n1)
            b = buf[:e - s]
            np.subtract(d[s + m:e + m], d[s:e], out=b)
            t1 += _sumsq(b)
            L2 = min(s + B, n2) - s
            if L2 > 0:
                if shared:  # D(2m) on [s, s + L2 + 2m) once; both taps are views of it
                    w = wsh[:L2 + 2 * m]
                    np.add(d[s:s + L2 + 2 * m], d[s + m:s + 3 * m + L2], out=w)
                    lo, hi = w[:L2], w[2 * m:2 * m + L2]
                else:
                    lo, hi = wlo[:L2], whi[:L2]
                    np.add(d[s:s + L2], d[s + m:s + m + L2], out=lo)
                    np.add(d[s + 2 * m:s + 2 * m + L2], d[s + 3 * m:s + 3 * m + L2], out=hi)
                b2 = buf[:L2]
                np.subtract(hi, lo, out=b2)
                t2 += _sumsq(b2)
                if more:
                    np.add(lo, hi, out=d[s:s + L2])
        var[k] = t1 / (2.0 * m * m * n1)
        nt[k] = n1
        var[k + 1] = t2 / (2.0 * (2 * m) ** 2 * n2)
        nt[k + 1] = n2
        k += 2
    return var, nt, dec




# ----------------------------------------------------------------------------- kernels








def _variances(src, statistic: str, ms: np.ndarray, tau0: float) -> tuple[np.ndarray, np.ndarray]:
    """Variance and summand count of ``statistic`` at each m."""
    nx = src.n
    var = np.empty(ms.size)
    nt = np.empty(ms.size, dtype=np.int64)
    for k, m in enumerate(int(v) for v in ms):
        tau = m * tau0
        if statistic == "oadev":
            n = nx - 2 * m
            s = _sum_sq_filter(src, m, (1.0, -2.0, 1.0), 1, n)
            var[k] = s / (2.0 * tau * tau * n)
        elif statistic == "adev":
            n = (nx - 1) // m - 1
            s = _sum_sq_filter(src, m, (1.0, -2.0, 1.0), m, n)
            var[k] = s / (2.0 * tau * tau * n)
        elif statistic == "ohdev":
            n = nx - 3 * m
            s = _sum_sq_filter(src, m, (-1.0, 3.0, -3.0, 1.0), 1, n)
            var[k] = s / (6.0 * tau * tau * n)
        elif statistic == "hdev":
            n = (nx - 1) // m - 2
            s = _sum_sq_filter(src, m, (-1.0, 3.0, -3.0, 1.0), m, n)
            var[k] = s / (6.0 * tau * tau * n)
        elif statistic in ("mdev", "tdev"):
            n = nx - 3 * m + 1
            s = _sum_sq_mod(src, m, n)
            var[k] = s / (2.0 * m * m * tau * tau * n)
            if statistic == "tdev":
                var[k] *= tau * tau / 3.0
        elif statistic == "totdev":
            n = nx - 2
            ext = _reflect(src)
            s = _sum_sq_filter(ext, m, (1.0, -2.0, 1.0), 1, n, start=(nx - 1) - m)
            var[k] = s / (2.0 * tau * tau * n)
        else:  # pragma: no cover - guarded by _check_stat
            raise InputError(f"unknown statistic '{statistic}'")
        nt[k] = n
    return var, nt




# ----------------------------------------------------------------------------- public API


def deviation(statistic: str, data, *, rate_hz: float, taus="octave", input: str = "rate",
              confidence: float = 0.683, alpha=None, edf_method: str = "default",
              chunked: bool = False) -> DeviationResult:
    """Compute one statistic of the Allan family with its confidence interval.

    Parameters
    ----------
    statistic : str
        One of :data:`STATISTICS`.
    data : array_like, shape (n,)
        Rate samples (any unit) or, with ``input="angle"``, the cumulative angle in
        (rate unit)·s. A ``numpy.memmap`` is read in chunks with ``chunked=True``.
    rate_hz : float
        Sample rate in Hz (``tau0 = 1/rate_hz``).
    taus : see :func:`tau_grid`, default "octave"
    input : {"rate", "angle"}, default "rate"
    confidence : float, default 0.683
        Two-sided confidence level of the chi-square interval (spec 001 §3.2).
    alpha : int or array_like of int or None, default None
        Power-law noise type per tau; None identifies it from the data
        (:func:`inertialab.noise.edf.identify_alpha`).
    edf_method : {"default", "sp1065", "gaussian"}, default "default"
        EDF algorithm (:func:`inertialab.noise.edf.edf`).
    chunked : bool, default False
        Compute the angle on demand from chunks of ``data`` instead of holding it in
        memory (out-of-core path; equal results). Rate input only.

    Raises
    ------
    InputError
        Unknown statistic, non-finite or constant data, too few samples, bad rate.
    """
    from inertialab.noise import edf as _edf

    _check_stat(statistic)
    # the octave OADEV fast path checks finiteness through its mean (one pass fewer)
    fast = statistic == "oadev" and input == "rate" and not chunked
    arr = _validate(data, rate_hz, input, check_finite=not fast)
    if not 0.0 < float(confidence) < 1.0:
        raise InputError(f"confidence must be in (0, 1), got {confidence}")
    if chunked and input != "rate":
        raise InputError("the chunked path takes rate samples (input='rate')")
    ms = tau_grid(arr.size, taus, rate_hz=rate_hz, statistic=statistic, input=input)
    tau0 = 1.0 / float(rate_hz)
    decimated = None
    if fast and np.array_equal(ms, 2 ** np.arange(ms.size)):
        var, nt, decimated = _oadev_octaves(arr, tau0, ms, want_decimated=alpha is None)
        # constant data <=> D constant <=> every second difference at m = 1 is zero
        if var[0] == 0.0:
            raise InputError("data are constant (zero deviation at every tau); nothing to analyse")
        src = _LazyPhase(arr, tau0)
    else:
        if fast:
            _check_finite(arr, "data")
        src = _make_source(arr, rate_hz, input, chunked)
        _check_not_constant(src)
        var, nt = _variances(src, statistic, ms, tau0)
    dev = np.sqrt(var)
    n_phase = src.n
    if alpha is None:
        ident = _edf.identify_alpha(src, ms, statistic=statistic, decimated=decimated)
        alphas, sources, amethod = ident.alpha, ident.source, "lag1"
    else:
        alphas = np.broadcast_to(np.asarray(alpha, dtype=np.int64), ms.shape).copy()
        sources, amethod = ("user",) * ms.size, "user"
    edfs, emethod = _edf.edf(statistic, n_phase, ms, alphas, n_terms=nt, method=edf_method)
    lo, hi = _edf.chi2_interval(dev, edfs, confidence)
    return DeviationResult(
        statistic=statistic, tau0_s=tau0, taus_s=ms * tau0, m=ms, dev=dev, n_terms=nt,
        alpha=alphas, edf=edfs, ci_low=lo, ci_high=hi, confidence=float(confidence),
        n_samples=int(arr.size), input=input, alpha_method=amethod, edf_method=emethod,
        alpha_source=tuple(sources))


def _doc(name: str, what: str):
    def f(data, *, rate_hz: float, taus="octave", input: str = "rate", confidence: float = 0.683,
          alpha=None, edf_method: str = "default", chunked: bool = False) -> DeviationResult:
        return deviation(name, data, rate_hz=rate_hz, taus=taus, input=input,
                         confidence=confidence, alpha=alpha, edf_method=edf_method,
                         chunked=chunked)

    f.__name__ = name
    f.__qualname__ = name
    f.__doc__ = (f"{what}\n\n    Same parameters and result as :func:`deviation` with "
                 f"``statistic='{name}'``.\n")
    return f


adev = _doc("adev", "Non-overlapping Allan deviation (NIST SP 1065 eq. 7, stride m).")
oadev = _doc("oadev", "Overlapping Allan deviation (spec 001 eq. 3; NIST SP 1065 eq. 11).")
mdev = _doc("mdev", "Modified Allan deviation (NIST SP 1065 eq. 14).")
tdev = _doc("tdev", "Time (angle) deviation ``tau/sqrt(3) * mdev`` (NIST SP 1065 eq. 15).")
hdev = _doc("hdev", "Non-overlapping Hadamard deviation (NIST SP 1065 eq. 17).")
ohdev = _doc("ohdev", "Overlapping Hadamard deviation (NIST SP 1065 eq. 18).")
totdev = _doc("totdev", "Total deviation with reflected extension (NIST SP 1065 eq. 25).")


def oadev_chunked(data, *, rate_hz: float, taus="octave", confidence: float = 0.683,
                  alpha=None, edf_method: str = "default") -> DeviationResult:
    """:func:`oadev` of a rate record read in chunks (e.g. a ``numpy.load(...,
    mmap_mode="r")`` array larger than memory). Memory: one chunk plus O(n/CHUNK)."""
    return deviation("oadev", data, rate_hz=rate_hz, taus=taus, input="rate",
                     confidence=confidence, alpha=alpha, edf_method=edf_method, chunked=True)


__all__ = ["STATISTICS", "DeviationResult", "adev", "deviation", "hdev", "mdev", "max_m",
           "oadev", "oadev_chunked", "ohdev", "tau_grid", "tdev", "totdev"]
