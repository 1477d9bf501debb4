"""Spectral lines (sinusoids) in a static record, and their Allan variance.

A static log often carries a sinusoid no sensor noise model holds: a building's or a
pump's vibration, a fan, a mains-related ripple. The two real ADIS16405 logs of
docs/noise-terms.md §10 carry a 0.54 Hz line and its third harmonic on every
accelerometer axis, 30-63x above the local noise floor. Its Allan deviation peaks at
tau = 0.37/f (a bump at 0.64 s) and falls like 1/tau after it; a five-term fit that
tries to follow the bump bends N by 10-20 %. IEEE Std 952-1997 Annex C lists the
sinusoidal term::

    sigma^2(tau) = A^2 (sin^2(pi f tau) / (pi f tau))^2

for a sinusoid of amplitude ``A`` (variance ``A^2/2``) at ``f`` Hz.

:func:`spectral_lines` finds the lines in a Welch periodogram (Hann window, 50 %
overlap): a bin whose power is at least :data:`LINE_RATIO` times the running median of
its neighbours (the local noise floor) starts a line; the line's variance is the power
above the floor summed over its contiguous bins (so a slowly wandering frequency is
still counted whole). With >= 30 averaged segments a noise bin's power is chi-square
with >= 60 degrees of freedom about the floor, so a ratio of 8 is not reached by noise
(P < 1e-30 per bin); the MEMS presets and white, flicker and random-walk records give
no line (tests).

Hand-written on scipy's ``welch``: no maintained library estimates line powers against
a local floor and reports them in Allan-variance terms.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

#: a bin this many times above the local floor (running median) is a line
LINE_RATIO = 8.0
#: the line's contiguous bins: down to this ratio around the peak
EDGE_RATIO = 2.0
#: running-median width in bins (the local floor)
FLOOR_BINS = 31
#: Welch segments: at most this length, and at least MIN_SEGMENTS of them
MAX_NPERSEG = 2**14
MIN_SEGMENTS = 30
#: lines below this many bins are not searched (the floor is not local there)
LOW_BINS = 16


@dataclass(frozen=True)
class Line:
    """One spectral line: frequency (Hz), variance (data unit^2), amplitude
    ``sqrt(2 variance)`` (data unit) and its ratio to the local floor."""

    f_hz: float
    variance: float
    ratio: float

    @property
    def amplitude(self) -> float:
        return float(np.sqrt(2.0 * self.variance))

    def to_dict(self, unit: str) -> dict:
        return {"f_hz": self.f_hz, "amplitude": self.amplitude, "unit": unit,
                "ratio_to_floor": self.ratio}

    @classmethod
    def from_dict(cls, d: dict) -> Line:
        return cls(f_hz=float(d["f_hz"]), variance=0.5 * float(d["amplitude"]) ** 2,
                   ratio=float(d.get("ratio_to_floor", float("nan"))))


def spectral_lines(y, rate_hz: float, *, max_lines: int = 4) -> tuple[Line, ...]:
    """The strongest spectral lines of a record (at most ``max_lines``), strongest first.

    ``y``: samples (NaN-free), ``rate_hz``: sample rate. A record too short for
    :data:`MIN_SEGMENTS` segments of 256 samples has no lines searched (empty tuple).
    """
    from scipy.ndimage import median_filter
    from scipy.signal import welch

    y = np.asarray(y, dtype=float)
    y = y[np.isfinite(y)]
    nper = min(MAX_NPERSEG, 2 ** int(np.floor(np.log2(max(y.size, 2) * 2 / (MIN_SEGMENTS + 1)))))
    if nper < 256:
        return ()
    f, p = welch(y - y.mean(), fs=rate_hz, nperseg=nper, detrend="linear")
    floor = median_filter(p, FLOOR_BINS, mode="nearest")
    ok = floor > 0
    ratio = np.where(ok, p / np.where(ok, floor, 1.0), 0.0)
    ratio[:LOW_BINS] = 0.0
    ratio[-2:] = 0.0
    df = float(f[1] - f[0])
    lines = []
    used = np.zeros(p.size, dtype=bool)
    for i in np.argsort(ratio)[::-1]:
        if ratio[i] < LINE_RATIO or len(lines) >= max_lines:
            break
        if used[i]:
            continue
        a = i
        while a > LOW_BINS and ratio[a - 1] >= EDGE_RATIO:
            a -= 1
        b = i
        while b < p.size - 1 and ratio[b + 1] >= EDGE_RATIO:
            b += 1
        used[a:b + 1] = True
        excess = np.clip(p[a:b + 1] - floor[a:b + 1], 0.0, None)
        var = float(np.sum(excess) * df)
        fc = float(np.sum(f[a:b + 1] * excess) / np.sum(excess))
        lines.append(Line(f_hz=fc, variance=var, ratio=float(ratio[i])))
    return tuple(lines)


def line_avar(taus_s, lines) -> np.ndarray:
    """Allan variance of the lines at ``taus_s`` (IEEE 952 sinusoidal term), data unit^2."""
    t = np.asarray(taus_s, dtype=float)
    out = np.zeros(t.shape)
    for ln in lines:
        x = np.pi * ln.f_hz * t
        out = out + 2.0 * ln.variance * np.sin(x) ** 4 / x**2
    return out


__all__ = ["Line", "line_avar", "spectral_lines"]
