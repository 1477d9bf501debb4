"""The Allan family of deviations with confidence intervals (spec 001 §3.1–3.2).

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
fallback, see :mod:`inertialab.noise.statistics.edf`, or given by the user), the equivalent
degrees of freedom and the chi-square interval at ``confidence`` (default 0.683).

Why hand-written: allantools (LGPL, a test dependency only) computes the same numbers
but allocates several arrays of the record's size per tau and has neither IMU terms nor
complete intervals. Here octave taus run on lag-doubling kernels that update one working
array of first differences in place (:mod:`inertialab.noise.statistics._octave`; the only extra
memory is that copy), other taus on per-m kernels with reused buffers, and the noise
identification, EDF and intervals are evaluated for all taus at once.
A record too large for memory is read in chunks (:func:`oadev_chunked` and
``chunked=True``, :mod:`inertialab.noise.statistics._stream`): octave OADEV/OHDEV/TOTDEV on the
compiled kernels from windows of the record and the angle's checkpoints (no angle
stored), otherwise from its angle spilled to a temporary file; the results equal the
in-memory ones to ~1e-13.

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
from inertialab.limits import check_work
from inertialab.noise.statistics import _octave, _phase
from inertialab.noise.statistics._octave import is_octave
from inertialab.noise.statistics._phase import (  # noqa: F401 - phase_window is public API here too
    BLOCK,
    CHECKPOINT,
    CHUNK,
    PageReleaser,
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
        Number of summands per tau (docs/allan.md).
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
        ``"stable32"`` (identified per tau as Stable32 does, how in ``alpha_source``),
        ``"user"`` or ``"model"``.
    edf_method : str
        Which EDF algorithm was used (see :mod:`inertialab.noise.statistics.edf`).
    alpha_source : tuple of str
        Per tau, how alpha was found: ``"acf"`` (lag-1 autocorrelation), ``"b1"`` (B1
        ratio), ``"b1+rn"`` (B1, then R(n) = MVAR/AVAR), ``"carried"`` (too few points:
        the type of the nearest shorter identified tau), ``"none"`` (record too short to
        identify: white rate assumed), ``"user"`` or ``"model"``
        (:mod:`inertialab.noise.statistics.identify`).

    :meth:`to_dict` adds, per tau, ``alpha_source`` and ``bias_factor`` (1.0: no bias
    correction; see :class:`CorrectedResult`).

    Examples
    --------
    White rate noise of sigma 1 at 100 Hz: the interval at each tau holds ``1/sqrt(m)``,
    and the noise type found is white rate (``alpha = 0``):

    >>> import numpy as np
    >>> y = np.random.default_rng(0).normal(0.0, 1.0, 10_000)
    >>> r = deviation("oadev", y, rate_hz=100.0, taus=[0.01, 0.16])
    >>> r.statistic, r.tau0_s, r.m.tolist(), r.alpha.tolist()
    ('oadev', 0.01, [1, 16], [0, 0])
    >>> bool(np.all((r.ci_low < 1 / np.sqrt(r.m)) & (1 / np.sqrt(r.m) < r.ci_high)))
    True
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
    alpha_method: str = "stable32"
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
            "alpha_source": list(self.alpha_source),
            "bias_factor": [float(v) for v in getattr(self, "bias", np.ones(len(self)))],
            "edf_method": self.edf_method,
        }


@dataclass(frozen=True)
class CorrectedResult(DeviationResult):
    """A :class:`DeviationResult` with Stable32's bias correction applied (TOTDEV, MTOT,
    TTOT, HTOT, Theo1; :mod:`inertialab.noise.statistics.family`): ``bias`` per tau is the factor the
    variance was divided by (1.0 where the statistic has none for the noise type, or no
    type was identified)."""

    bias: np.ndarray = field(default_factory=lambda: np.zeros(0))

    def __post_init__(self):
        if np.size(self.bias) != np.size(self.taus_s):  # none given: 1.0 per tau
            object.__setattr__(self, "bias", np.ones(np.size(self.taus_s)))


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
        the nearest m. Each is clipped to the statistic's
        largest valid m (:func:`max_m`).
    rate_hz : float, default 1.0
        Sample rate (only used for explicit taus).

    Raises
    ------
    InputError
        Too few samples for the smallest tau, or an unknown tau specification.

    Examples
    --------
    >>> tau_grid(1000).tolist()
    [1, 2, 4, 8, 16, 32, 64, 128, 256]
    >>> tau_grid(1000, "decade").tolist()
    [1, 2, 4, 10, 20, 40, 100, 200, 400]
    >>> tau_grid(1000, [0.5, 1.0], rate_hz=10.0).tolist()
    [5, 10]
    """
    n_phase = n_samples + 1 if input == "rate" else n_samples
    mmax = max_m(statistic, n_phase)
    if isinstance(taus, str):
        kind = taus.strip().lower()
        if mmax < 1:
            raise InputError(f"too few samples ({n_samples}) for {statistic} at the smallest "
                             f"tau (m = 1 needs at least {_min_samples(statistic, input)})")
        if kind == "octave":  # (1 <= m <= mmax by construction)
            return 2 ** np.arange(int(math.floor(math.log2(mmax))) + 1, dtype=np.int64)
        elif kind == "decade":
            top = int(math.floor(math.log10(mmax))) + 1
            m = np.array([k * 10**e for e in range(top) for k in (1, 2, 4)], dtype=np.int64)
        elif kind == "all":  # every m: about n_phase steps each (more for the modified
            # total and Theo families, measured ~8x), O(N^2) in all
            heavy = 8.0 if statistic.startswith(("mtot", "htot", "ttot", "theo")) else 1.0
            check_work(heavy * mmax * n_phase, f"{statistic} at every tau of {n_samples} "
                       "samples", "ask for taus 'many' (dense, log-spaced) or a count")
            m = np.arange(1, mmax + 1, dtype=np.int64)
        elif kind == "many":
            from inertialab.noise.statistics._clock import many_m

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


def _validate(data, rate_hz, input, *, name="data", check_finite: bool = True,
              sums: list | None = None) -> np.ndarray:
    """The checked 1-D real array of ``data``; with ``sums`` (a list) the finiteness
    check appends the record's float64 sum to it (:func:`_check_finite`)."""
    check_input_rate(input, rate_hz)
    arr = data if isinstance(data, np.ndarray) else np.asarray(data, dtype=float)
    if arr.ndim != 1:
        raise InputError(f"{name} must be one-dimensional, got shape {arr.shape}")
    if arr.dtype.kind not in "iufm":  # (numpy real number kinds; not bool or complex)
        raise InputError(f"{name} must be real numbers, got dtype {arr.dtype}")
    if arr.size < 2:
        raise InputError(f"too few samples ({arr.size}) for any tau")
    if check_finite:
        total = _check_finite(arr, name)
        if sums is not None and total is not None:
            sums.append(total)
    return arr


def _check_finite(arr: np.ndarray, name: str, offset: int = 0) -> float | None:
    """Raise :class:`InputError` naming the first non-finite samples; return the
    record's sum in float64 as the sum of per-``CHUNK`` sums (the order of
    :func:`inertialab.noise.statistics._phase._chunked_mean`, so ``total / n`` is its mean bit for
    bit; None for an integer array, which is not summed)."""
    if np.issubdtype(arr.dtype, np.integer):
        return None
    release = _phase._Releaser(arr)  # a read-only memory map is not kept resident
    total = 0.0
    for s in range(0, arr.size, CHUNK):
        blk = arr[s:s + CHUNK]
        release(s)
        part = float(np.sum(blk, dtype=np.float64))
        total += part
        if math.isfinite(part):
            continue  # NaN and infinity propagate into the sum (one pass, no mask)
        ok = np.isfinite(blk)
        if not ok.all():
            bad = np.flatnonzero(~ok)[:5] + s + offset
            raise InputError(f"{name} contains NaN or infinity at sample index "
                             f"{', '.join(str(int(b)) for b in bad)}")
    return total


def _check_not_constant(src) -> None:
    if src.constant:
        raise InputError("data are constant (zero deviation at every tau); nothing to analyse")


# ----------------------------------------------------------------------------- angle sources


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


def _normalise(statistic: str, sums: np.ndarray, ms: np.ndarray, nt: np.ndarray,
               tau0: float) -> np.ndarray:
    """Variance from the sums of squared filter outputs (angle units) per m (SP 1065 §5.2)."""
    tau = ms * tau0
    n = np.maximum(nt, 1).astype(float)
    if statistic in ("adev", "oadev", "totdev"):
        return sums / (2.0 * tau * tau * n)
    if statistic in ("hdev", "ohdev"):
        return sums / (6.0 * tau * tau * n)
    var = sums / (2.0 * ms.astype(float) ** 2 * tau * tau * n)
    return var * (tau * tau / 3.0) if statistic == "tdev" else var


def _all_equal(v: np.ndarray) -> bool:
    """True when every entry equals the first (blockwise; stops at the first block that
    differs, so one small block for any non-constant record)."""
    if v.size == 0:
        return True
    v0 = v[0]
    for s in range(0, v.size, _octave.OCT_BLOCK):
        if (v[s:s + _octave.OCT_BLOCK] != v0).any():
            return False
    return True


def _angle_constant(x: np.ndarray) -> bool:
    """True when every first difference of the angle ``x`` is equal (a constant rate):
    the first 64 differences decide for almost any record, then a block, then all."""
    if x.size > 2 and x[2] - x[1] != x[1] - x[0]:  # (scalars: most records stop here)
        return False
    return (_all_equal(np.diff(x[:65])) and _all_equal(np.diff(x[:_octave.OCT_BLOCK + 1]))
            and _all_equal(np.diff(x)))


def _angle_source(x: np.ndarray) -> _PhaseArray:
    """In-memory angle source of ``x`` (float64) without re-checking constancy."""
    src = _PhaseArray.__new__(_PhaseArray)
    src.x, src.n, src.constant = x, x.size, False
    return src


# ----------------------------------------------------------------------------- public API


def deviation(statistic: str, data, *, rate_hz: float, taus="octave", input: str = "rate",
              confidence: float = 0.683, alpha=None, edf_method: str = "default",
              chunked: bool = False, progress=None) -> DeviationResult:
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
        (:func:`inertialab.noise.statistics.identify.identify_alpha`).
    edf_method : {"default", "sp1065", "gaussian"}, default "default"
        EDF algorithm (:func:`inertialab.noise.statistics.edf.edf`).
    chunked : bool, default False
        Compute the angle on demand from chunks of ``data`` instead of holding it in
        memory (out-of-core path; equal results). Rate input only.
    progress : object with ``update(done, total, note)``, optional
        Hears the out-of-core path's passes advance (:class:`inertialab.progress.Progress`;
        the command line's bar); ignored in memory.

    Raises
    ------
    InputError
        Unknown statistic, non-finite or constant data, too few samples, bad rate.

    Examples
    --------
    White rate noise of sigma 1 at 100 Hz has ``oadev = sigma / sqrt(m)``:

    >>> import numpy as np
    >>> y = np.random.default_rng(0).normal(0.0, 1.0, 10_000)
    >>> r = deviation("oadev", y, rate_hz=100.0, taus=[0.01, 0.1])
    >>> r.m.tolist()
    [1, 10]
    >>> np.round(r.dev * np.sqrt(r.m), 1).tolist()
    [1.0, 1.0]
    """
    _check_stat(statistic)
    # an angle record on the compiled kernels is checked for NaN/infinity after its sums
    # (every point enters the m = 1 sums, and non-finite values make them non-finite):
    # one pass less over the record; otherwise before anything else
    defer = input == "angle" and not chunked and _octave.fast_kernels() is not None
    total = []  # the record's sum, from the finiteness check (rate input: its mean)
    arr = _validate(data, rate_hz, input, check_finite=not defer, sums=total)
    if not 0.0 < float(confidence) < 1.0:
        raise InputError(f"confidence must be in (0, 1), got {confidence}")
    if chunked and input != "rate":
        raise InputError("the chunked path takes rate samples (input='rate')")
    ms, defer = _grid(arr, statistic, taus, rate_hz, input, defer)
    tau0 = 1.0 / float(rate_hz)
    if chunked:
        st = _chunked_variances(arr, statistic, ms, tau0, alpha is None, progress, total)
    else:
        if input == "rate" and _all_equal(arr):
            raise InputError("data are constant (zero deviation at every tau); "
                             "nothing to analyse")
        if is_octave(ms) and not (input == "angle" and statistic in _octave.E_STATS) and not (
                statistic == "totdev" and input == "angle" and _octave.fast_kernels()):
            # lag-doubling kernels on one working array of first differences
            # (non-overlapping statistics of an angle record: strided views are cheaper)
            st = _octave_variances(arr, statistic, ms, tau0, input, alpha is None, total)
        else:
            st = _dense_variances(arr, statistic, ms, tau0, rate_hz, input, alpha is None)
    if defer and not np.isfinite(st.var).all():
        _check_finite(arr, "data")  # raises where the record holds NaN or infinity
    return _with_intervals(statistic, arr, ms, tau0, np.sqrt(st.var), st, alpha, input,
                           confidence, edf_method)


@dataclass
class _Sums:
    """What a path of :func:`deviation` hands on: the variance and summand count per m,
    the angle source (for the identification), points gathered for it, lag-1 verdicts a
    kernel took in place, or the identification itself (chunked path)."""

    var: np.ndarray
    nt: np.ndarray
    src: object
    decimated: object = None
    acf: tuple | None = None
    ident: object = None


def _grid(arr, statistic, taus, rate_hz, input, defer):
    """``(ms, defer)``: the averaging factors; a deferred finiteness check is taken now
    where the grid fails (the non-finite data error takes precedence) or m = 1 is not
    in it (not every point enters the sums)."""
    if not defer:
        return tau_grid(arr.size, taus, rate_hz=rate_hz, statistic=statistic,
                        input=input), False
    try:
        ms = tau_grid(arr.size, taus, rate_hz=rate_hz, statistic=statistic, input=input)
    except InputError:
        _check_finite(arr, "data")
        raise
    if ms[0] != 1:
        _check_finite(arr, "data")
        return ms, False
    return ms, True


def _chunked_variances(arr, statistic, ms, tau0, identify, progress=None, total=None) -> _Sums:
    """Out-of-core path (:mod:`inertialab.noise.statistics._stream`): compiled octave OADEV/OHDEV/
    TOTDEV from windows of the record and the angle's checkpoints (never stored), the
    noise type from the lag-m increments those passes gather; otherwise the angle
    computed once and spilled to a temporary file, the noise type from the points
    gathered by that pass. ``total``: the record's sum from the finiteness check."""
    from inertialab.noise.statistics import _stream
    from inertialab.noise.statistics import identify as _ident

    if _stream.octave_fast(statistic, ms, arr.dtype):
        if _all_equal(arr):
            raise InputError("data are constant (zero deviation at every tau); "
                             "nothing to analyse")
        mean = total[0] / arr.size if total else _phase._chunked_mean(arr)
        if not math.isfinite(mean):
            raise InputError("data too large to sum in float64")
        src, sums, nt, dec = _stream.octave_out_of_core(
            arr, tau0, mean, statistic, ms, _ident.MAX_POINTS if identify else 0, progress)
        ident = _ident.identify_alpha(src, ms, statistic=statistic, data="freq", n_terms=nt,
                                      decimated=dec) if identify else None
        return _Sums(_normalise(statistic, sums, ms, nt, tau0), nt, src, ident=ident)
    gather = _octave.gather_indices(arr.size + 1, ms, _ident.MAX_POINTS) if identify else None
    src = _phase._PhaseFromRate(arr, tau0, spill=True, gather=gather,
                                progress=_stream.Scaled(progress, 0.0, 0.3))
    try:
        _check_not_constant(src)
        if statistic in _stream.STREAM_STATS:
            sums, nt = _stream.stream_sums(src, statistic, ms, progress=progress)
            var = _normalise(statistic, sums, ms, nt, tau0)
        else:
            var, nt = _variances(src, statistic, ms, tau0)
        ident = None
        if identify:  # points gathered by the spilling pass (x_start subtracted)
            decimated = {m: z - z[0] for m, z in src.gathered.items()}
            ident = _ident.identify_alpha(src, ms, statistic=statistic, data="freq",
                                          n_terms=nt, decimated=decimated)
    finally:
        src.close()
    return _Sums(var, nt, src, ident=ident)


def _octave_variances(arr, statistic, ms, tau0, input, identify, total) -> _Sums:
    """Octave m by the lag-doubling kernels (:func:`inertialab.noise.statistics._octave.octave_sums`)
    on one working copy of the first differences; a rate record's decimated points (or
    its lag-1 verdicts, compiled) come from the same pass; TOTDEV adds its reflected
    summands from the angle."""
    from inertialab.noise.statistics import identify as _ident

    if input == "rate":
        mean = total[0] / arr.size if total else _chunked_mean(arr)
        if not math.isfinite(mean):
            raise InputError("data too large to sum in float64")
        d = np.subtract(arr, mean, dtype=np.float64)
        scale = tau0  # angle increment per unit of d
        src = _LazyPhase(arr, tau0, mean)
    else:
        x = np.asarray(arr, dtype=np.float64)
        d = np.diff(x)
        if _all_equal(d):
            raise InputError("data are constant (zero deviation at every tau); "
                             "nothing to analyse")
        scale = 1.0
        src = _angle_source(x)
    # the lag-1 test in the octave pass (compiled): on a rate record's frequency
    # averages, or on an angle record's decimated points read at stride m
    phase = (input == "angle" and statistic in _octave.D_STATS
             and _octave.fast_kernels() is not None)
    want = _ident.MAX_POINTS if identify and (input == "rate" or phase) else 0
    sums, nt, decimated = _octave.octave_sums(
        d, statistic, ms, decimate=want, acf=_ident.acf_rules(statistic)[:2] if want else None,
        x=src.x if phase else None)
    del d  # the working copy; totdev's reflected summands read the angle
    sums = sums * (scale * scale)
    if statistic == "totdev":
        K = _octave.fast_kernels()
        xf = x if input == "angle" else _rate_to_phase(arr, tau0, mean)
        if K is not None:  # the reflected summands only (compiled)
            sums += K.dense_totdev(xf, ms, False)
        else:
            sums += [_octave.totdev_edge_sum(lambda a, n: xf[a:a + n], xf.size, int(m))
                     for m in ms]
        if input == "rate":
            src = _angle_source(xf)  # the identification reads the angle in place
        del xf
    # (an angle record's rows were tested or are read in place: none was gathered)
    return _Sums(_normalise(statistic, sums, ms, nt, tau0), nt, src,
                 None if phase else decimated, getattr(decimated, "acf", None))


def _dense_variances(arr, statistic, ms, tau0, rate_hz, input, identify) -> _Sums:
    """Any m on the in-memory angle (per-m kernels, :func:`inertialab.noise.statistics._octave.
    dense_sums`); octave ADEV/HDEV of an angle record on the compiled halving kernel,
    which takes the lag-1 test of each m in place."""
    from inertialab.noise.statistics import identify as _ident

    if input == "rate":
        src = _make_source(arr, rate_hz, input, False)
    else:
        x = np.asarray(arr, dtype=np.float64)
        if _angle_constant(x):
            raise InputError("data are constant (zero deviation at every tau); "
                             "nothing to analyse")
        src = _angle_source(x)
    K = _octave.fast_kernels()
    acf = None
    if K is not None and statistic == "totdev" and input == "angle":
        # compiled: one pass over the angle per m, the reflected summands by index
        sums = _octave.dense_sums_fast(K, src.x, statistic, ms)
        nt = _octave.n_terms_many(statistic, src.x.size, ms)
    elif K is not None and statistic in _octave.E_STATS and is_octave(ms) and ms.size > 1:
        rules = _ident.acf_rules(statistic) if identify else None
        sums, nt, got = _octave.octave_strided_sums(K, src.x, statistic, ms, rules,
                                                    _ident.MAX_POINTS)
        acf = None if got is None else (got[1] == -2, got[0])
    else:
        sums, nt = _octave.dense_sums(src.x, statistic, ms)
    return _Sums(_normalise(statistic, sums, ms, nt, tau0), nt, src, acf=acf)


def _with_intervals(statistic, arr, ms, tau0, dev, st: _Sums, alpha, input, confidence,
                    edf_method) -> DeviationResult:
    """The result: noise type per m (identified as Stable32 does, or given), EDF and the
    chi-square interval (:mod:`inertialab.noise.statistics.edf`)."""
    from inertialab.noise.statistics import edf as _edf
    from inertialab.noise.statistics import identify as _ident

    if alpha is None:
        ident = st.ident or _ident.identify_alpha(
            st.src, ms, statistic=statistic, data="freq" if input == "rate" else "phase",
            n_terms=st.nt, decimated=st.decimated, acf=st.acf)
        alphas, sources, amethod = ident.alpha, ident.source, "stable32"
    else:
        alphas = np.broadcast_to(np.asarray(alpha, dtype=np.int64), ms.shape).copy()
        sources, amethod = ("user",) * ms.size, "user"
    nt = st.nt
    edfs, emethod = _edf.edf(statistic, st.src.n, ms, alphas, n_terms=nt, method=edf_method)
    lo, hi = _edf.chi2_interval(dev, edfs, confidence)
    return DeviationResult(
        statistic=statistic, tau0_s=tau0, taus_s=ms * tau0, m=ms, dev=dev, n_terms=nt,
        alpha=alphas, edf=edfs, ci_low=lo, ci_high=hi, confidence=float(confidence),
        n_samples=int(arr.size), input=input, alpha_method=amethod, edf_method=emethod,
        alpha_source=tuple(sources))


#: The Examples section of each statistic's docstring: white rate noise of sigma 1 (say
#: deg/s) at 100 Hz, whose Allan deviation is ``sigma / sqrt(m)`` (IEEE 952 Annex C).
_EXAMPLES = {
    "adev": """
    >>> import numpy as np
    >>> y = np.random.default_rng(0).normal(0.0, 1.0, 10_000)
    >>> r = adev(y, rate_hz=100.0, taus=[0.01, 0.04, 0.16])
    >>> r.m.tolist()
    [1, 4, 16]
    >>> bool(np.allclose(r.dev * np.sqrt(r.m), 1.0, atol=0.03))
    True
""",
    "oadev": """
    >>> import numpy as np
    >>> y = np.random.default_rng(0).normal(0.0, 1.0, 10_000)
    >>> r = oadev(y, rate_hz=100.0, taus=[0.01, 0.04, 0.16])
    >>> bool(np.allclose(r.dev * np.sqrt(r.m), 1.0, atol=0.03))
    True
    >>> bool(np.all((r.ci_low < 1 / np.sqrt(r.m)) & (1 / np.sqrt(r.m) < r.ci_high)))
    True
""",
    "mdev": """
    Equal to the Allan deviation at ``m = 1``; for white rate noise ``1/sqrt(2)`` of it
    at long taus (the ratio ``Mod sigma^2 / sigma^2`` of white frequency noise):

    >>> import numpy as np
    >>> y = np.random.default_rng(0).normal(0.0, 1.0, 10_000)
    >>> ratio = (mdev(y, rate_hz=100.0, taus=[0.01, 0.64]).dev
    ...          / oadev(y, rate_hz=100.0, taus=[0.01, 0.64]).dev)
    >>> bool(abs(ratio[0] - 1) < 1e-9), bool(abs(ratio[1] - 2 ** -0.5) < 0.05)
    (True, True)
""",
    "tdev": """
    >>> import numpy as np
    >>> y = np.random.default_rng(0).normal(0.0, 1.0, 10_000)
    >>> t = tdev(y, rate_hz=100.0, taus=[0.01, 0.16])
    >>> m = mdev(y, rate_hz=100.0, taus=[0.01, 0.16])
    >>> bool(np.allclose(t.dev, t.taus_s / np.sqrt(3) * m.dev))
    True
""",
    "hdev": """
    For white rate noise the Hadamard variance equals the Allan variance, ``sigma^2/m``:

    >>> import numpy as np
    >>> y = np.random.default_rng(0).normal(0.0, 1.0, 10_000)
    >>> r = hdev(y, rate_hz=100.0, taus=[0.01, 0.04, 0.16])
    >>> bool(np.allclose(r.dev * np.sqrt(r.m), 1.0, atol=0.03))
    True
""",
    "ohdev": """
    For white rate noise the Hadamard variance equals the Allan variance, ``sigma^2/m``:

    >>> import numpy as np
    >>> y = np.random.default_rng(0).normal(0.0, 1.0, 10_000)
    >>> r = ohdev(y, rate_hz=100.0, taus=[0.01, 0.04, 0.16])
    >>> bool(np.allclose(r.dev * np.sqrt(r.m), 1.0, atol=0.03))
    True
""",
    "totdev": """
    Close to the overlapping Allan deviation where both are well estimated:

    >>> import numpy as np
    >>> y = np.random.default_rng(0).normal(0.0, 1.0, 10_000)
    >>> tot = totdev(y, rate_hz=100.0, taus=[0.01, 0.16])
    >>> bool(np.allclose(tot.dev, oadev(y, rate_hz=100.0, taus=[0.01, 0.16]).dev, rtol=0.01))
    True
""",
}


def _doc(name: str, what: str):
    def f(data, *, rate_hz: float, taus="octave", input: str = "rate", confidence: float = 0.683,
          alpha=None, edf_method: str = "default", chunked: bool = False) -> DeviationResult:
        return deviation(name, data, rate_hz=rate_hz, taus=taus, input=input,
                         confidence=confidence, alpha=alpha, edf_method=edf_method,
                         chunked=chunked)

    f.__name__ = name
    f.__qualname__ = name
    f.__doc__ = (f"{what}\n\n    Same parameters and result as :func:`deviation` with "
                 f"``statistic='{name}'``.\n\n    Examples\n    --------{_EXAMPLES[name]}")
    return f


adev = _doc("adev", "Non-overlapping Allan deviation (NIST SP 1065 eq. 7, stride m).")
oadev = _doc("oadev", "Overlapping Allan deviation (spec 001 eq. 3; NIST SP 1065 eq. 11).")
mdev = _doc("mdev", "Modified Allan deviation (NIST SP 1065 eq. 14).")
tdev = _doc("tdev", "Time (angle) deviation ``tau/sqrt(3) * mdev`` (NIST SP 1065 eq. 15).")
hdev = _doc("hdev", "Non-overlapping Hadamard deviation (NIST SP 1065 eq. 17).")
ohdev = _doc("ohdev", "Overlapping Hadamard deviation (NIST SP 1065 eq. 18).")
totdev = _doc("totdev", "Total deviation with reflected extension (NIST SP 1065 eq. 25).")


def oadev_chunked(data, *, rate_hz: float, taus="octave", confidence: float = 0.683,
                  alpha=None, edf_method: str = "default", progress=None) -> DeviationResult:
    """:func:`oadev` of a rate record read in chunks (e.g. a ``numpy.load(...,
    mmap_mode="r")`` array larger than memory). Memory: one window of
    :data:`inertialab.noise.statistics._stream.WINDOW` samples (float64), the sweep's ring of at
    most :data:`inertialab.noise.statistics._stream.RING_BYTES` and the angle's checkpoints (8
    bytes per 4096 samples); without the compiled kernels or at taus that are not
    octaves the angle is spilled to a temporary file (8 bytes per sample)."""
    return deviation("oadev", data, rate_hz=rate_hz, taus=taus, input="rate",
                     confidence=confidence, alpha=alpha, edf_method=edf_method, chunked=True,
                     progress=progress)


__all__ = ["STATISTICS", "CorrectedResult", "DeviationResult", "PageReleaser", "adev", "deviation", "hdev", "mdev", "max_m",
           "oadev", "oadev_chunked", "ohdev", "tau_grid", "tdev", "totdev"]
