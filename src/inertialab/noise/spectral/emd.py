"""Empirical mode decomposition as an analysis view (spec 001 §3.5, Fang et al. Fig. 2b).

The seed shows EMD only to document that it mode-mixes on a noisy FOG record; no
decision of the pipeline depends on it. Two back ends:

- ``backend="pyemd"``: the ``EMD-signal`` package (``pip install inertialab[emd]``);
  :func:`emd` raises ``ImportError`` with that hint when it is missing.
- ``backend="builtin"``: a short sifting loop written here (cubic-spline envelopes
  through the extrema via ``scipy.interpolate.CubicSpline``, end points mirrored, stop
  when the SD criterion < 0.3 or after 10 sifts, at most 10 IMFs), so that the view
  works without the extra. It is the textbook algorithm of Huang et al. (1998); no
  library in the core dependencies provides it.
- ``backend="auto"`` (default) uses PyEMD when installed, else the built-in loop.

:func:`hilbert_frequency` gives the instantaneous frequency of each IMF from the
analytic signal (``scipy.signal.hilbert``).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.interpolate import CubicSpline
from scipy.signal import hilbert

from inertialab.errors import InputError

__all__ = ["EMDResult", "emd", "hilbert_frequency", "pyemd_available"]


def pyemd_available() -> bool:
    """True when the optional ``EMD-signal`` package (module ``PyEMD``) is importable."""
    try:
        import PyEMD  # noqa: F401
    except ImportError:
        return False
    return True


@dataclass(frozen=True)
class EMDResult:
    """IMFs and residue: ``x = imfs.sum(0) + residue``.

    Attributes
    ----------
    imfs : ndarray (k, n)
    residue : ndarray (n,)
    n_sifts : list of int
        Sifting iterations per IMF (empty for the PyEMD back end).
    backend : str
    """

    imfs: np.ndarray
    residue: np.ndarray
    n_sifts: list
    backend: str


def _extrema(h: np.ndarray):
    d = np.diff(h)
    maxi = np.flatnonzero((d[:-1] > 0) & (d[1:] <= 0)) + 1
    mini = np.flatnonzero((d[:-1] < 0) & (d[1:] >= 0)) + 1
    return maxi, mini


def _envelope(t: np.ndarray, h: np.ndarray, idx: np.ndarray) -> np.ndarray:
    # mirror the two extrema nearest each end so the spline does not swing at the edges
    n = h.size
    left = idx[:2]
    right = idx[-2:]
    ti = np.concatenate([-t[left][::-1], t[idx], 2 * t[-1] - t[right][::-1]])
    hi = np.concatenate([h[left][::-1], h[idx], h[right][::-1]])
    ti, keep = np.unique(ti, return_index=True)
    return CubicSpline(ti, hi[keep])(t[:n])


def _builtin(x: np.ndarray, max_imfs: int, max_sifts: int, sd_stop: float) -> EMDResult:
    t = np.arange(x.size, dtype=float)
    r = x.copy()
    imfs, sifts = [], []
    for _ in range(max_imfs):
        maxi, mini = _extrema(r)
        if maxi.size < 2 or mini.size < 2:
            break
        h = r.copy()
        k = 0
        while k < max_sifts:
            maxi, mini = _extrema(h)
            if maxi.size < 2 or mini.size < 2:
                break
            k += 1
            m = 0.5 * (_envelope(t, h, maxi) + _envelope(t, h, mini))
            h_new = h - m
            sd = float(np.sum((h - h_new) ** 2) / max(np.sum(h**2), 1e-300))
            h = h_new
            if sd < sd_stop:
                break
        imfs.append(h)
        sifts.append(k)
        r = r - h
    arr = np.vstack(imfs) if imfs else np.zeros((0, x.size))
    return EMDResult(imfs=arr, residue=r, n_sifts=sifts, backend="builtin")


def emd(x, *, max_imfs: int = 10, max_sifts: int = 10, sd_stop: float = 0.3,
        backend: str = "auto") -> EMDResult:
    """Empirical mode decomposition of ``x`` (spec 001 §3.5).

    Parameters
    ----------
    x : array_like (n,)
    max_imfs : int, default=10
    max_sifts : int, default=10
    sd_stop : float, default=0.3
        Huang's SD stopping criterion.
    backend : {"auto", "builtin", "pyemd"}, default="auto"

    Returns
    -------
    EMDResult
    """
    x = np.asarray(x, dtype=float)
    if x.ndim != 1 or x.size < 8:
        raise InputError("emd needs a one-dimensional signal of at least 8 samples")
    if not np.all(np.isfinite(x)):
        raise InputError("emd: signal contains NaN or infinite values")
    if backend not in ("auto", "builtin", "pyemd"):
        raise InputError(f"emd backend must be auto, builtin or pyemd, got {backend!r}")
    if backend == "pyemd" or (backend == "auto" and pyemd_available()):
        try:
            from PyEMD import EMD
        except ImportError as exc:  # pragma: no cover - depends on the environment
            raise ImportError("backend='pyemd' needs the optional extra: "
                              "pip install 'inertialab[emd]'") from exc
        dec = EMD(std_thr=sd_stop, MAX_ITERATION=max_sifts)
        dec.emd(x, max_imf=max_imfs)
        imfs, residue = dec.get_imfs_and_residue()
        return EMDResult(imfs=np.atleast_2d(imfs), residue=np.asarray(residue),
                         n_sifts=[], backend="pyemd")
    return _builtin(x, int(max_imfs), int(max_sifts), float(sd_stop))


def hilbert_frequency(imfs, fs_hz: float) -> np.ndarray:
    """Instantaneous frequency (Hz) of each IMF from its analytic signal.

    Parameters
    ----------
    imfs : array_like (k, n)
    fs_hz : float

    Returns
    -------
    ndarray (k, n)
        The derivative of the unwrapped phase, the last sample repeated.
    """
    imfs = np.atleast_2d(np.asarray(imfs, dtype=float))
    phase = np.unwrap(np.angle(hilbert(imfs, axis=-1)), axis=-1)
    f = np.diff(phase, axis=-1) * fs_hz / (2 * np.pi)
    return np.concatenate([f, f[:, -1:]], axis=-1)
