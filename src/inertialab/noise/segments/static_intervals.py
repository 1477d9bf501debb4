"""Static-interval detection in a raw accelerometer log (spec 002 §2.4, after Tedaldi et al.).

1. A centred moving variance over a window ``window_s`` per axis; the statistic is
   ``s(t) = var_x + var_y + var_z``.
2. The threshold is ``tau = k_thr * s0`` with ``s0`` the median of ``s`` over the
   initial rest of length ``t_init_s``, or an absolute ``threshold`` in the squared
   unit of the data. The log must start at rest: more than 5 % of the initial samples
   above ``3 s0`` is an :class:`InputError` ("no initial rest").
3. Samples with ``s <= tau`` are static; runs of at least ``min_duration_s`` (before
   trimming) are kept, ``trim_s`` is cut from each end, and each run gives one static
   record (mean, standard deviation, n). A time gap larger than two sample periods
   ends a run.
   With gyro channels (``gyro``), a sample is static only when the gyro is also at
   rest (:func:`gyro_rest`): a turn about the vertical keeps the accelerometer still
   but not the gyro (the same joint rule as the Ferraris detector).
4. :func:`sweep_thresholds` tries ``k_thr`` in {2, ..., 10} and keeps the value whose
   score (e.g. a calibration residual supplied by the caller) is smallest among those
   giving the expected interval count, or at least ``min_count`` intervals when no
   count is expected. When none qualifies the error lists the count found at each
   threshold and what to change.

The moving variance and the initial-rest test live in :mod:`inertialab.io.rest`, which
``validate --kind triaxial`` runs too (pandas' rolling window, a numerically stable
online algorithm: raw counts with a 32768 offset would lose digits in a naive sum of
squares). The run logic is a few lines of numpy; no library offers this procedure.

References
----------
Spec 002 §2.4. Tedaldi, Pretto & Menegatti, "A robust and easy to implement method
for IMU calibration without external equipments", ICRA 2014.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

import numpy as np

from inertialab.errors import InputError
from inertialab.io.gaps import detect_gaps
from inertialab.io.rest import initial_rest, moving_variance
from inertialab.io.timestamps import stamps_rate_hz

__all__ = ["GyroRest", "StaticIntervals", "ThresholdSweep", "detect_static_intervals",
           "gyro_rest", "moving_variance", "sweep_thresholds"]


@dataclass(frozen=True)
class StaticIntervals:
    """Static intervals found in a log.

    Attributes
    ----------
    start, stop : ndarray (m,) int
        Sample index range ``[start, stop)`` of each interval after trimming.
    t_start, t_end : ndarray (m,)
        Times of the first and last kept sample, s.
    mean, sd : ndarray (m, 3)
        Per-axis mean and standard deviation (ddof=1) over the interval, data unit.
    n : ndarray (m,) int
        Samples per interval.
    threshold : float
        The variance threshold tau used, squared data unit.
    s0 : float
        Median of the statistic over the initial rest (nan with an absolute threshold).
    k_thr : float or None
        The multiplier used (None with an absolute threshold).
    fs : float
        Sample rate, Hz: the caller's (the record's time base) or the stamps'
        (:func:`inertialab.io.timestamps.stamps_rate_hz`).
    """

    start: np.ndarray
    stop: np.ndarray
    t_start: np.ndarray
    t_end: np.ndarray
    mean: np.ndarray
    sd: np.ndarray
    n: np.ndarray
    threshold: float
    s0: float
    k_thr: float | None
    fs: float

    @property
    def count(self) -> int:
        return int(self.start.size)

    def channel_means(self, y) -> np.ndarray:
        """Means of another channel array ``y`` (N, c) over the same intervals: (m, c)."""
        y = np.asarray(y, dtype=float)
        return np.array([y[a:b].mean(axis=0) for a, b in zip(self.start, self.stop)])


@dataclass(frozen=True)
class GyroRest:
    """What :func:`gyro_rest` decided: the gyro-at-rest mask and the quantities behind it.

    Attributes
    ----------
    rest : ndarray (N,) bool
        Gyro at rest (smoothed deviation below ``threshold``).
    bias : ndarray (3,)
        Rest value of the gyro (median over the still samples, refined), gyro unit.
    dev : ndarray (N,)
        Moving average of ``|gyro - bias|``, gyro unit.
    threshold : float
        ``k_gyro`` times the robust standard deviation of ``|gyro - bias|`` at rest.
    """

    rest: np.ndarray
    bias: np.ndarray
    dev: np.ndarray
    threshold: float


def gyro_rest(gyro, still, fs: float, *, k_gyro: float = 8.0, smooth_s: float = 0.25) -> GyroRest:
    """Samples where the gyro is at rest, given where the accelerometer is still.

    The rest value is the median of the gyro over the accelerometer-still samples,
    refined twice on the samples within three median deviations of it; a sample is at
    rest when the moving average (``smooth_s``, so one sample's noise does not break a
    rest) of ``|gyro - bias|`` is below ``k_gyro`` robust standard deviations (1.4826 x
    MAD per axis, root-sum-square) of the gyro at rest. Unit-free (raw counts allowed).

    Parameters
    ----------
    gyro : array (N, 3)
        Gyro samples, any unit.
    still : array (N,) bool
        Accelerometer-still samples (at least one).
    fs : float
        Sample rate, Hz.
    k_gyro : float, default 8
        Threshold in robust standard deviations.
    smooth_s : float, default 0.25
        Moving-average length of the deviation, s.
    """
    gyro = np.asarray(gyro, dtype=float)
    still = np.asarray(still, dtype=bool)
    if gyro.ndim != 2 or gyro.shape[1] != 3 or gyro.shape[0] != still.size:
        raise InputError(f"gyro samples must have shape ({still.size}, 3), got {gyro.shape}")
    if not np.all(np.isfinite(gyro)):
        row = int(np.flatnonzero(~np.all(np.isfinite(gyro), axis=1))[0]) + 1
        raise InputError("non-finite gyro sample", row=row)
    if not still.any():
        raise InputError("no still accelerometer samples: the log has no rests")
    b = np.median(gyro[still], axis=0)
    near = still
    for _ in range(2):
        dev = np.linalg.norm(gyro - b, axis=1)
        near = still & (dev < np.percentile(dev[still], 50) * 3)
        b = np.median(gyro[near], axis=0)
    dev = np.linalg.norm(gyro - b, axis=1)
    sg = 1.4826 * np.median(np.abs(gyro[near] - b), axis=0)
    sig = float(np.sqrt(np.sum(sg * sg))) or float(np.finfo(float).tiny)
    wg = max(3, int(round(smooth_s * fs)) | 1)
    wg = max(1, min(wg, dev.size if dev.size % 2 else dev.size - 1))  # a log shorter than it
    kern = np.ones(wg) / wg
    dev_s = np.convolve(dev, kern, mode="same")
    thr = float(k_gyro) * sig
    return GyroRest(rest=dev_s < thr, bias=b, dev=dev_s, threshold=thr)


def _time_checks(t, rate_hz: float | None):
    """``(t, fs)``: the stamps checked, and the caller's rate (the record's) or else the one
    the stamps give (:func:`inertialab.io.timestamps.stamps_rate_hz`)."""
    t = np.asarray(t, dtype=float)
    if t.ndim != 1 or t.size < 10:
        raise InputError(f"a raw log needs at least 10 samples, got {t.size}", column="t_s")
    bad = [i.row for i in detect_gaps(t).issues if i.kind in ("repeat", "backward")]
    if bad:
        raise InputError("t_s must be strictly increasing", column="t_s", row=bad[:5])
    if rate_hz is None:
        return t, stamps_rate_hz(t)
    if not (np.isfinite(rate_hz) and rate_hz > 0):
        raise InputError(f"argument 'rate_hz' must be positive, got {rate_hz}")
    return t, float(rate_hz)


def _kept_runs(t, static, fs: float, min_duration_s: float, trim_s: float):
    """``(start, stop)`` sample indices of the static runs of ``static`` (a gap longer
    than 2/fs ends a run) at least ``min_duration_s`` long, ``trim_s`` cut from each end."""
    gap = np.zeros(t.size, dtype=bool)  # the first sample after a step of over 2 / fs
    gap[[a for a, _ in detect_gaps(t, gap_factor=2.0, nominal_dt_s=1.0 / fs).segments[1:]]] = True
    edges = np.diff(np.r_[0, static.astype(np.int8), 0])
    runs = []
    for a0, b0 in zip(np.flatnonzero(edges == 1), np.flatnonzero(edges == -1)):
        cuts = a0 + np.flatnonzero(gap[a0 + 1:b0]) + 1
        bounds = np.r_[a0, cuts, b0]
        runs.extend(zip(bounds[:-1], bounds[1:]))
    ks, ke = [], []
    dt = 1.0 / fs
    for a0, b0 in runs:
        if t[b0 - 1] - t[a0] + dt < min_duration_s - 1e-9:
            continue
        keep = np.flatnonzero((t[a0:b0] >= t[a0] + trim_s - 1e-9) & (t[a0:b0] <= t[b0 - 1] - trim_s + 1e-9))
        if keep.size < 2:
            continue
        ks.append(a0 + keep[0])
        ke.append(a0 + keep[-1] + 1)
    return np.asarray(ks, dtype=int), np.asarray(ke, dtype=int)


def detect_static_intervals(t, acc, *, window_s: float = 1.0, t_init_s: float = 10.0,
                            k_thr: float = 6.0, threshold: float | None = None,
                            min_duration_s: float = 1.5, trim_s: float = 0.25,
                            gyro=None, k_gyro: float = 8.0,
                            rate_hz: float | None = None) -> StaticIntervals:
    """Detect static intervals in a raw log (spec 002 §2.4).

    Parameters
    ----------
    t : array (N,)
        Sample times, s, strictly increasing.
    acc : array (N, 3)
        Accelerometer samples (any unit; counts allowed).
    window_s : float, default 1.0
        Moving-variance window w, s.
    t_init_s : float, default 10.0
        Length of the initial rest used for s0, s (may be set up to the whole rest).
    k_thr : float, default 6
        Threshold multiplier of s0.
    threshold : float, optional
        Absolute threshold tau in the squared data unit (overrides ``k_thr``).
    min_duration_s : float, default 1.5
        Minimum run length d_min before trimming, s.
    trim_s : float, default 0.25
        Cut from each end of a kept run, s.
    gyro : array (N, 3), optional
        Gyro samples (any unit). When given, a sample is static only if the gyro is at
        rest too (:func:`gyro_rest` with ``k_gyro``): turns about the vertical are not
        rests.
    k_gyro : float, default 8
        Gyro threshold in robust standard deviations (the Ferraris detector's default).
    rate_hz : float, optional
        Sample rate, Hz: the record's (``record.timebase.rate_hz``); default the rate
        the stamps give (:func:`inertialab.io.timestamps.stamps_rate_hz`).

    Raises
    ------
    InputError
        Non-increasing time, no initial rest.

    Examples
    --------
    A minute at 100 Hz at rest (noise 0.01 m/s^2 per axis) but for a shake from 20 s to
    30 s: two rests, on either side of it, with the true gravity and noise:

    >>> import numpy as np
    >>> rng = np.random.default_rng(0)
    >>> t = np.arange(6000) / 100.0
    >>> acc = np.array([0.0, 0.0, 9.81]) + rng.normal(0.0, 0.01, (6000, 3))
    >>> shake = (t >= 20) & (t < 30)
    >>> acc[shake, 0] += 2.0 * np.sin(2 * np.pi * t[shake])
    >>> s = detect_static_intervals(t, acc)
    >>> bool(s.t_end[0] < 20.0 and s.t_start[1] > 30.0), s.n.size
    (True, 2)
    >>> bool(np.allclose(s.mean[:, 2], 9.81, atol=0.002)), bool(np.allclose(s.sd, 0.01, rtol=0.05))
    (True, True)
    """
    t, fs = _time_checks(t, rate_hz)
    a = np.asarray(acc, dtype=float)
    if a.shape != (t.size, 3):
        raise InputError(f"accelerometer samples must have shape ({t.size}, 3), got {a.shape}")
    if not np.all(np.isfinite(a)):
        row = int(np.flatnonzero(~np.all(np.isfinite(a), axis=1))[0]) + 1
        raise InputError("non-finite accelerometer sample", row=row)
    rest = initial_rest(t, a, window_s=window_s, t_init_s=t_init_s, check=threshold is None,
                        rate_hz=fs)
    s, s0 = rest.s, rest.s0
    if threshold is None:
        tau = float(k_thr) * s0
        kused: float | None = float(k_thr)
    else:
        tau = float(threshold)
        kused = None
        s0 = float("nan")
    static = s <= tau
    if gyro is not None and static.any():
        static = static & gyro_rest(gyro, static, fs, k_gyro=k_gyro).rest
    start, stop = _kept_runs(t, static, fs, min_duration_s, trim_s)
    mean = np.array([a[i:j].mean(axis=0) for i, j in zip(start, stop)]).reshape(-1, 3)
    sd = np.array([a[i:j].std(axis=0, ddof=1) for i, j in zip(start, stop)]).reshape(-1, 3)
    return StaticIntervals(
        start=start, stop=stop, t_start=t[start] if start.size else np.empty(0),
        t_end=t[stop - 1] if stop.size else np.empty(0), mean=mean, sd=sd,
        n=stop - start, threshold=tau, s0=s0, k_thr=kused, fs=fs)


@dataclass(frozen=True)
class ThresholdSweep:
    """Result of :func:`sweep_thresholds`.

    Attributes
    ----------
    best : StaticIntervals
        The intervals at the chosen threshold.
    k_best : float
    counts : dict
        Interval count per k_thr.
    scores : dict
        Score per k_thr that qualified (others absent).
    expected : int or None
    """

    best: StaticIntervals
    k_best: float
    counts: dict = field(default_factory=dict)
    scores: dict = field(default_factory=dict)
    expected: int | None = None


def sweep_thresholds(t, acc, *, k_values: Sequence[float] = tuple(range(2, 11)),
                     expected: int | None = None, min_count: int = 12,
                     score: Callable[[StaticIntervals], float] | None = None,
                     **detect_kw) -> ThresholdSweep:
    """Threshold sweep of spec 002 §2.4 step 4.

    Parameters
    ----------
    t, acc :
        As in :func:`detect_static_intervals`.
    k_values : sequence, default 2, 3, ..., 10
        Multipliers k_thr to try.
    expected : int, optional
        Required interval count (e.g. the schedule length). Without it, any k giving
        at least ``min_count`` intervals qualifies.
    min_count : int, default 12
    score : callable ``StaticIntervals -> float``, optional
        Lower is better (e.g. the calibration residual RMS). Without it the
        qualifying k closest to the default 6 is chosen.
    **detect_kw :
        Passed to :func:`detect_static_intervals` (``window_s``, ``t_init_s``,
        ``rate_hz`` ...).

    Raises
    ------
    InputError
        When no k qualifies; the message lists the count found at each k and what to change.
    """
    counts: dict = {}
    found: dict = {}
    for k in k_values:
        iv = detect_static_intervals(t, acc, k_thr=float(k), **detect_kw)
        counts[float(k)] = iv.count
        ok = iv.count == expected if expected is not None else iv.count >= min_count
        if ok:
            found[float(k)] = iv
    if not found:
        listing = ", ".join(f"k={k:g}: {c}" for k, c in counts.items())
        want = f"exactly {expected}" if expected is not None else f"at least {min_count}"
        most = max(counts.values()) if counts else 0
        if expected is not None and most > expected:
            hint = ("more intervals than expected: pauses during motion count as static; "
                    "raise argument 'min_duration_s' or check the schedule length")
        else:
            hint = ("make each pose last longer (at least 2 s of rest), keep the sensor still "
                    "while it rests, lower argument 'min_duration_s' or argument 'window_s', "
                    "or give argument 'threshold'")
        raise InputError(f"static-interval detection needs {want} intervals; found {listing}; {hint}")
    scores: dict = {}
    if score is not None:
        for k, iv in found.items():
            scores[k] = float(score(iv))
        kb = min(scores, key=lambda k: (scores[k], abs(k - 6.0)))
    else:
        kb = min(found, key=lambda k: abs(k - 6.0))
    return ThresholdSweep(best=found[kb], k_best=kb, counts=counts, scores=scores,
                          expected=expected)
