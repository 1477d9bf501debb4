"""Is each axis of an IMU log static? Motion refused per axis, with the reason.

Noise terms read from a record that moves describe the motion, not the sensor: a flight
log's Allan curves peak at 0.3-0.5 s and a five-term fit then gives densities 100 times
a real MEMS gyro's. Three tests, each independent of the noise-term fit:

* **broadband excess** (:func:`band_excess`): variance at short tau that white noise,
  flicker, random walk and lines cannot explain. A static sensor's spectrum never rises
  with frequency: flicker and random walk raise only its lowest bands (below ~0.05 Hz
  for MEMS), its own anti-alias or decimation low-pass (rate/10 to rate/2.5) lowers the
  top ones, quantisation is white. The Welch periodogram (Hann, segments of at most
  :data:`SEGMENT_S` s, linear detrend) is cut into octave bands from :data:`BAND_LO_HZ`
  up to ``rate/2``; the median power of each band, narrow lines masked (:func:`_line_mask`),
  is compared with the white floor (:func:`_white_floor`: the lowest band median once
  the roll-off bands at the top are dropped). A band :data:`EXCESS` times above the
  floor is motion. Measured by ``python -m benchmarks motion_check``: at most 1.71 on
  the presets (4 presets x 8 seeds x 0.05, 0.5 and 2 h, triads; 1.2 from 0.5 h on),
  1.38 on the two 2.8-h ADIS16405 logs, 1.22 on the static PX4 bench log, 1.41 on a
  bench with a 0.5-Hz wobble; every axis of simulated flight, handling and sway refused.
* **gross excursions** (:func:`excursion_fraction`): samples further than
  :data:`EXCURSION_SIGMAS` sigmas (the white floor's, or the robust spread of the
  samples about their level when larger: lines are no excursions) from the 10-s block
  median; more than :data:`EXCURSION_FRACTION` of the samples is motion (shocks,
  handling).
* **gravity turning** (:func:`gravity_turn_deg`): the accelerometer triad's 1-s block
  means change direction by more than :data:`TURN_DEG` (and 6 times their own noise
  angle): every accelerometer axis is not static.

The curve-shape rule of :func:`inertialab.noise.terms.fit.not_static_reason` (a rise that
reaches 1 s) is kept beside these. A narrow line (a fan, a pump, a 0.5-Hz wobble: its
power within a few bins) is masked here and reported with the terms as a line, not as
motion; a broad hump (a sway of a few tenths of a hertz) is motion.
"""

from __future__ import annotations

import math

import numpy as np

__all__ = ["EXCESS", "band_excess", "excursion_fraction", "gravity_turn_deg",
           "motion_reasons"]

#: lowest band edge, Hz: below it flicker and random walk raise a static spectrum
BAND_LO_HZ = 0.2
#: Welch segment length, s (at most; a short record takes a quarter of itself)
SEGMENT_S = 32.0
#: a band median this many times the white floor is motion
EXCESS = 4.0
#: narrow-line masking: a bin this many times its local running median
LINE_RATIO = 8.0
#: samples this many white sigmas from the local level are excursions ...
EXCURSION_SIGMAS = 12.0
#: ... and more than this fraction of them is motion
EXCURSION_FRACTION = 1e-3
#: the gravity direction may wander this much (degrees) on a static bench
TURN_DEG = 1.0
#: a narrow line holds this fraction of its excess power ...
LINE_CORE = 0.8
#: ... within this many periodogram bins of its peak (the Hann main lobe is +-2 bins)
LINE_BINS = 3
#: a top band below this fraction of the band under it is the low-pass roll-off ...
ROLL_OFF = 0.9
#: ... when its lower edge is at or above rate / ROLL_OFF_FROM. MEMS anti-alias filters
#: sit at rate/10 to rate/2.5 (the presets, the PX4 and ADIS16405 logs); 60 lets a
#: corner at rate/50 pass (a static preset filtered there: 0 of 6 refused, at rate/100:
#: 6 of 6) and still lets no motion through (flight, handling and sway low-passed at
#: rate/10 to rate/100: every axis refused; with 100, 2 of 12 sway axes pass; without
#: the limit, half the handling and sway axes: motion falling into the filter's
#: roll-off would be taken for it). ``benchmarks.motion_check`` measures both sides.
ROLL_OFF_FROM = 60.0
#: least bins in a band for its median to count
MIN_BINS = 5


def _periodogram(y, rate_hz: float):
    from scipy.signal import welch

    nper = int(2 ** math.floor(math.log2(max(8.0, min(y.size / 4.0, rate_hz * SEGMENT_S)))))
    return welch(y - y.mean(), fs=rate_hz, nperseg=nper, detrend="linear")


def _line_mask(p) -> np.ndarray:
    """Bins of narrow lines (and their skirts): True where a line sits.

    A run of bins :data:`LINE_RATIO` times above the running median of their
    neighbours, widened to its skirts (down to 2 times), is a line when at least
    :data:`LINE_CORE` of its excess power lies within :data:`LINE_BINS` bins of its peak
    (a sinusoid under the Hann window: its main lobe); a broader hump (a sway, random
    motion of a few tenths of a hertz) is left in its band."""
    from scipy.ndimage import median_filter

    floor = median_filter(p, 31, mode="nearest")
    r = np.where(floor > 0, p / np.where(floor > 0, floor, 1.0), 0.0)
    mask = np.zeros(p.size, dtype=bool)
    done = np.zeros(p.size, dtype=bool)
    for i in np.nonzero(r >= LINE_RATIO)[0]:
        if done[i]:
            continue
        a, b = i, i
        while a > 0 and r[a - 1] >= 2.0:
            a -= 1
        while b < r.size - 1 and r[b + 1] >= 2.0:
            b += 1
        done[a:b + 1] = True
        excess = np.clip(p[a:b + 1] - floor[a:b + 1], 0.0, None)
        k = int(np.argmax(p[a:b + 1]))
        core = excess[max(0, k - LINE_BINS):k + LINE_BINS + 1].sum()
        if core >= LINE_CORE * excess.sum():
            mask[a:b + 1] = True
    return mask


def _white_floor(bands, rate_hz: float) -> float:
    """The white-noise plateau of the band medians ``[(f_low, f_high, median), ...]``:
    the top bands whose median falls below :data:`ROLL_OFF` times the band under them
    (the sensor's own anti-alias or decimation low-pass, corner above
    ``rate / ROLL_OFF_FROM``) are dropped, and the lowest of the rest is the floor
    (flicker and random walk only raise the low bands, lines are masked)."""
    k = len(bands)
    while (k > 1 and bands[k - 1][0] >= rate_hz / ROLL_OFF_FROM
           and bands[k - 1][2] < ROLL_OFF * bands[k - 2][2]):
        k -= 1
    return min(b[2] for b in bands[:k])


def band_excess(y, rate_hz: float):
    """``(ratio, f_low, f_high, floor_psd)`` of the octave band most above the white
    floor (lines masked), or None when the record is too short for two bands."""
    y = np.asarray(y, dtype=float)
    y = y[np.isfinite(y)]
    if y.size < 64 or not np.ptp(y) > 0:
        return None
    f, p = _periodogram(y, rate_hz)
    keep = ~_line_mask(p)
    lo = max(BAND_LO_HZ, 6.0 * float(f[1]))
    bands = []
    while lo * 2.0 <= 0.45 * rate_hz:
        sel = keep & (f >= lo) & (f < 2.0 * lo)
        if sel.sum() >= MIN_BINS:
            bands.append((lo, 2.0 * lo, float(np.median(p[sel]))))
        lo *= 2.0
    if len(bands) < 2:
        return None
    floor = _white_floor(bands, rate_hz)
    if not floor > 0:
        return None
    top = max(bands, key=lambda b: b[2])
    return top[2] / floor, top[0], top[1], floor


def excursion_fraction(y, rate_hz: float, floor_psd: float) -> float:
    """Fraction of samples further than :data:`EXCURSION_SIGMAS` white sigmas
    (``sqrt(floor_psd rate/2)``) from the median of their 10-s block."""
    y = np.asarray(y, dtype=float)
    y = y[np.isfinite(y)]
    sigma = math.sqrt(floor_psd * rate_hz / 2.0)
    m = max(1, int(round(10.0 * rate_hz)))
    k = y.size // m
    if k == 0 or not sigma > 0:
        return 0.0
    level = np.repeat(np.median(y[: k * m].reshape(k, m), axis=1), m)
    level = np.concatenate([level, np.full(y.size - level.size, level[-1])])
    dev = np.abs(y - level)
    # the robust spread holds what sits in most samples (noise, and lines: a 0.5-Hz
    # wobble is not an excursion); sparse shocks do not move it
    sigma = max(sigma, 1.4826 * float(np.median(dev)))
    return float(np.mean(dev > EXCURSION_SIGMAS * sigma))


def gravity_turn_deg(acc, rate_hz: float) -> tuple[float, float]:
    """``(largest angle, noise angle)`` in degrees between the accelerometer triad's
    1-s block means (at least 8 blocks) and their median direction."""
    a = np.asarray(acc, dtype=float)
    a = a[np.all(np.isfinite(a), axis=1)]
    m = max(1, min(int(round(rate_hz)), a.shape[0] // 8))
    k = a.shape[0] // m
    if k < 2:
        return 0.0, 0.0
    blocks = a[: k * m].reshape(k, m, 3)
    means = blocks.mean(axis=1)
    norm = np.linalg.norm(means, axis=1)
    if not np.all(norm > 0):
        return 0.0, 0.0
    ref = np.median(means, axis=0)
    ref = ref / np.linalg.norm(ref)
    cos = np.clip(means @ ref / norm, -1.0, 1.0)
    ang = np.degrees(np.arccos(cos))
    noise = float(np.degrees(np.median(np.linalg.norm(blocks.std(axis=1), axis=1))
                             / math.sqrt(m) / np.median(norm)))
    return float(ang.max()), noise


def _axis_reason(y, rate_hz: float) -> str | None:
    ex = band_excess(y, rate_hz)
    if ex is None:
        return None
    ratio, f_lo, f_hi, floor = ex
    if ratio > EXCESS:
        return (f"its power between {f_lo:.3g} and {f_hi:.3g} Hz is {ratio:.3g} times the "
                f"white-noise floor (more than {EXCESS:g}; narrow lines masked): broadband "
                "motion or vibration, not sensor noise")
    frac = excursion_fraction(y, rate_hz, floor)
    if frac > EXCURSION_FRACTION:
        return (f"{100 * frac:.2g} % of its samples lie more than {EXCURSION_SIGMAS:g} "
                "noise sigmas from their 10-s level: shocks or handling, not sensor noise")
    return None


def motion_reasons(columns: dict, rate_hz: float) -> dict:
    """``{axis: reason}`` for every axis of ``columns`` (axis -> samples, data unit)
    that is not static; axes that pass are absent."""
    out = {}
    for name, y in columns.items():
        why = _axis_reason(y, rate_hz)
        if why:
            out[name] = why
    if all(a in columns for a in ("ax", "ay", "az")):
        acc = np.column_stack([np.asarray(columns[a], dtype=float) for a in ("ax", "ay", "az")])
        ang, noise = gravity_turn_deg(acc, rate_hz)
        # a triad whose mean is lost in its noise (no gravity: a zero-mean record) has no
        # direction to follow
        if noise < 5.0 and ang > max(TURN_DEG, 6.0 * noise):
            why = (f"the gravity direction turns by {ang:.3g} deg over the record (more than "
                   f"{max(TURN_DEG, 6.0 * noise):.2g} deg): the sensor was tilted or moved")
            for a in ("ax", "ay", "az"):
                out.setdefault(a, why)
    return out
