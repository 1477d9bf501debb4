"""Spectral views of a rate record: Welch amplitude spectrum and CWT scalogram.

Spec 001 §3.5. Analysis views only: no decision of the pipeline depends on them.

- :func:`welch_asd` is ``scipy.signal.welch`` (Hann window, segment 2^14 or the whole
  signal, 50 % overlap, one-sided density) returned as an amplitude spectral density
  in (unit)/sqrt(Hz). For white rate noise of ARW N (deg/h·sqrt(s)) the floor is
  sqrt(2)·N (one-sided), i.e. N [deg/sqrt(h)] = floor / (60 sqrt(2)).
- :func:`alias_frequency` folds drive harmonics into [0, fs/2].
- :func:`cwt_scalogram` is ``pywt.cwt`` (``method="fft"``; the convolution method is about
  40x slower) with the complex Morlet ``cmor1.5-1.0`` on 96 log-spaced scales whose
  centre frequencies span [fs/2^12, fs/2]. Long records are processed in blocks of
  2^16 samples with 10 % overlap on each side (the overlaps are discarded) and the
  power ``|W|^2`` is averaged onto at most 4096 time columns, so memory stays bounded.
  The block loop and the column averaging are the only hand-written parts.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pywt
from scipy import signal

from inertialab.errors import InputError

__all__ = ["Scalogram", "Spectrum", "alias_frequency", "cwt_scalogram", "welch_asd"]


@dataclass(frozen=True)
class Spectrum:
    """One-sided amplitude spectral density.

    Attributes
    ----------
    freq_hz : ndarray
        Frequencies, 0 .. fs/2 (Hz).
    asd : ndarray
        Amplitude spectral density in (signal unit)/sqrt(Hz), one-sided.
    nperseg : int
        Segment length used.
    fs_hz : float
    """

    freq_hz: np.ndarray
    asd: np.ndarray
    nperseg: int
    fs_hz: float


def welch_asd(x, fs_hz: float, *, nperseg: int = 2**14, overlap: float = 0.5,
              window: str = "hann", detrend: str | bool = "constant") -> Spectrum:
    """One-sided amplitude spectral density by Welch's method (spec 001 §3.5).

    Parameters
    ----------
    x : array_like (n,)
        Rate samples (deg/h for a gyro log).
    fs_hz : float
        Sample rate in Hz.
    nperseg : int, default=2**14
        Segment length; the whole signal if shorter.
    overlap : float, default=0.5
        Fraction of segment overlap.
    window : str, default="hann"
    detrend : str or False, default="constant"

    Returns
    -------
    Spectrum
        ``asd`` in (unit of x)/sqrt(Hz).
    """
    x = np.asarray(x, dtype=float)
    if x.ndim != 1 or x.size < 2:
        raise InputError("welch_asd needs a one-dimensional signal of at least 2 samples")
    if not fs_hz > 0:
        raise InputError(f"sample rate must be positive, got {fs_hz}")
    seg = int(min(nperseg, x.size))
    f, pxx = signal.welch(x, fs=fs_hz, window=window, nperseg=seg,
                          noverlap=int(round(overlap * seg)), detrend=detrend,
                          scaling="density", return_onesided=True)
    return Spectrum(freq_hz=f, asd=np.sqrt(pxx), nperseg=seg, fs_hz=float(fs_hz))


def alias_frequency(f_hz, fs_hz: float, harmonics=(1, 2, 3)) -> np.ndarray:
    """Apparent frequency of drive harmonics after sampling at ``fs_hz``.

    ``f_alias = |((h f + fs/2) mod fs) - fs/2|`` for each harmonic h (spec 001 §3.5).

    Returns
    -------
    ndarray, shape (len(harmonics),) + shape(f_hz)
    """
    f = np.asarray(f_hz, dtype=float)
    h = np.asarray(harmonics, dtype=float).reshape((-1,) + (1,) * f.ndim)
    return np.abs(np.mod(h * f + fs_hz / 2.0, fs_hz) - fs_hz / 2.0)


@dataclass(frozen=True)
class Scalogram:
    """Block-averaged CWT power.

    Attributes
    ----------
    time_s : ndarray (n_cols,)
        Centre time of each column (s, from the first sample).
    freq_hz : ndarray (n_scales,)
        Centre frequency of each scale (Hz), decreasing with scale.
    scales : ndarray (n_scales,)
    power : ndarray (n_scales, n_cols)
        Mean ``|W|^2`` per column, in (signal unit)^2.
    wavelet : str
    """

    time_s: np.ndarray
    freq_hz: np.ndarray
    scales: np.ndarray
    power: np.ndarray
    wavelet: str

    @property
    def power_db(self) -> np.ndarray:
        """``10 log10(power)`` (dB re 1 unit^2), floored at the smallest positive value."""
        p = self.power
        pos = p[p > 0]
        floor = pos.min() if pos.size else 1e-300
        return 10.0 * np.log10(np.maximum(p, floor))


def cwt_scalogram(x, fs_hz: float, *, wavelet: str = "cmor1.5-1.0", n_scales: int = 96,
                  f_min_hz: float | None = None, f_max_hz: float | None = None,
                  block: int = 2**16, overlap: float = 0.1, max_columns: int = 4096,
                  method: str = "fft") -> Scalogram:
    """CWT scalogram of ``x`` (spec 001 §3.5, Fang et al. Fig. 2c).

    Parameters
    ----------
    x : array_like (n,)
    fs_hz : float
        Sample rate in Hz.
    wavelet : str, default="cmor1.5-1.0"
        Complex Morlet, bandwidth 1.5, centre frequency 1.0.
    n_scales : int, default=96
        Log-spaced scales.
    f_min_hz, f_max_hz : float, default fs/2^12 and fs/2
        Range of centre frequencies.
    block : int, default=2**16
        Samples per transformed window; ``overlap`` × block samples at each end of a
        window are discarded (they serve as the neighbours' edges), so consecutive
        windows advance by ``(1 - 2 overlap) × block``.
    overlap : float, default=0.1
    max_columns : int, default=4096
        Time columns kept (block-averaged power).
    method : {"fft", "conv"}, default="fft"

    Returns
    -------
    Scalogram
    """
    x = np.asarray(x, dtype=float)
    n = x.size
    if x.ndim != 1 or n < 8:
        raise InputError("cwt_scalogram needs a one-dimensional signal of at least 8 samples")
    if not fs_hz > 0:
        raise InputError(f"sample rate must be positive, got {fs_hz}")
    f_min = fs_hz / 2**12 if f_min_hz is None else float(f_min_hz)
    f_max = fs_hz / 2.0 if f_max_hz is None else float(f_max_hz)
    if not 0 < f_min < f_max:
        raise InputError(f"need 0 < f_min < f_max, got {f_min}, {f_max}")
    fc = pywt.central_frequency(wavelet)
    freqs = np.geomspace(f_max, f_min, int(n_scales))
    scales = fc * fs_hz / freqs
    n_cols = int(min(max_columns, n))
    edges = np.linspace(0, n, n_cols + 1).round().astype(int)
    col_of = np.repeat(np.arange(n_cols), np.diff(edges))  # column index of every sample
    sums = np.zeros((scales.size, n_cols))
    counts = np.bincount(col_of, minlength=n_cols).astype(float)
    pad = int(round(overlap * block))
    core = max(1, int(block) - 2 * pad)
    x0 = x - x.mean()
    for s in range(0, n, core):
        e = min(n, s + core)
        lo, hi = max(0, s - pad), min(n, e + pad)
        coef, _ = pywt.cwt(x0[lo:hi], scales, wavelet, sampling_period=1.0 / fs_hz,
                           method=method)
        p = np.abs(coef[:, s - lo:e - lo]) ** 2
        cols = col_of[s:e]
        # sum the block's samples into their columns, one scale row at a time
        for i in range(scales.size):
            sums[i] += np.bincount(cols, weights=p[i], minlength=n_cols)
    power = sums / np.maximum(counts, 1.0)
    centres = 0.5 * (edges[:-1] + edges[1:] - 1) / fs_hz
    return Scalogram(time_s=centres, freq_hz=freqs, scales=scales, power=power,
                     wavelet=wavelet)
