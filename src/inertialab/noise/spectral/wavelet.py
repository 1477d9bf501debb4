"""Mallat multiscale view: db4 decomposition, single-branch reconstruction, level rule.

Spec 001 §3.6. The pyramid algorithm is PyWavelets' ``wavedec`` with the db4 filters
and ``mode="symmetric"`` (half-sample symmetric extension, MATLAB ``"sym"``). The
single-branch reconstructions are MATLAB ``wrcoef`` equivalents obtained by
``pywt.waverec`` of the coefficient list with every other branch zeroed (never
``upcoef``, whose boundary handling differs), trimmed to the record length:

- ``A_L`` keeps ``cA_J`` and the details of levels ``L+1 .. J``;
- ``D_j`` keeps only ``cD_j``.

Then ``x = A_L + sum_{j<=L} D_j`` exactly (to rounding). Band of ``D_j`` is about
``[fs/2^(j+1), fs/2^j]``, of ``A_L`` about ``[0, fs/2^(L+1)]``.

:func:`select_level` is the spec's automatic level rule (eq. 6): on an analysis
window W (default P2 of the fixed-frequency record minus 5-s guards)

    delta_j = rms_W(A_j - A_{j+1}) / rms_W(A_{j+1} - beta_{j+1}),
    beta_{j+1} = median of A_{j+1} over the static reference (P1),

and ``L* = min{j in [3, 9] : delta_j <= 0.14}``, else 9.

Only the level rule and the bookkeeping are written here; the transform is pywt's.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass, field

import numpy as np
import pywt

from inertialab.errors import DataQualityWarning, InputError

__all__ = [
    "Decomposition",
    "LevelSelection",
    "approximation_band_hz",
    "decompose",
    "detail_band_hz",
    "select_level",
]

#: Seed level J of the db4 decomposition (spec 001 §3.6).
DEFAULT_LEVEL = 10
#: Threshold of the automatic level rule (spec 001 §3.6, eq. 6; calibrated on the virtual lab).
DELTA_THRESHOLD = 0.14


@dataclass(frozen=True)
class Decomposition:
    """A multilevel DWT of one signal and its single-branch reconstructions.

    Attributes
    ----------
    coeffs : list of ndarray
        ``[cA_J, cD_J, ..., cD_1]`` as returned by ``pywt.wavedec``.
    level : int
        J, the number of levels actually used (may be lower than requested).
    n : int
        Length of the input signal.
    wavelet, mode : str
        PyWavelets wavelet name and extension mode.
    requested_level : int
        The J asked for.
    """

    coeffs: list
    level: int
    n: int
    wavelet: str = "db4"
    mode: str = "symmetric"
    requested_level: int = DEFAULT_LEVEL
    _cache: dict = field(default_factory=dict, repr=False, compare=False)

    def _rec(self, keep) -> np.ndarray:
        c = [np.zeros_like(a) for a in self.coeffs]
        for i in keep:
            c[i] = self.coeffs[i]
        return pywt.waverec(c, self.wavelet, mode=self.mode)[: self.n]

    def approximation(self, level: int) -> np.ndarray:
        """``A_L``: reconstruction from ``cA_J`` and the details of levels > ``level``.

        Parameters
        ----------
        level : int
            L, 0 <= L <= J. ``A_0`` is the signal itself (to rounding).
        """
        level = int(level)
        if not 0 <= level <= self.level:
            raise InputError(f"approximation level must be in [0, {self.level}], got {level}")
        key = ("A", level)
        if key not in self._cache:
            # index 0 = cA_J, index i (1..J) = cD_{J+1-i}; keep details with j > level
            keep = [0] + [i for i in range(1, self.level + 1) if self.level + 1 - i > level]
            self._cache[key] = self._rec(keep)
        return self._cache[key]

    def detail(self, j: int) -> np.ndarray:
        """``D_j``: reconstruction from ``cD_j`` alone (1 <= j <= J)."""
        j = int(j)
        if not 1 <= j <= self.level:
            raise InputError(f"detail level must be in [1, {self.level}], got {j}")
        key = ("D", j)
        if key not in self._cache:
            self._cache[key] = self._rec([self.level + 1 - j])
        return self._cache[key]

    def details_sum(self, level: int) -> np.ndarray:
        """``D_1 + ... + D_L`` computed as ``x - A_L`` (exact up to rounding)."""
        if ("x",) not in self._cache:
            self._cache[("x",)] = self._rec(range(len(self.coeffs)))
        return self._cache[("x",)] - self.approximation(level)


def decompose(x, *, wavelet: str = "db4", level: int = DEFAULT_LEVEL,
              mode: str = "symmetric") -> Decomposition:
    """Mallat decomposition of ``x`` (spec 001 §3.6).

    Parameters
    ----------
    x : array_like, shape (n,)
        Signal (e.g. rate in deg/h), uniformly sampled.
    wavelet : str, default="db4"
        PyWavelets wavelet name; the seed uses Daubechies-4 (8 taps).
    level : int, default=10
        J. If ``pywt.dwt_max_level(n, filter_len) < J`` (n < 7168 for db4 and J=10),
        J is lowered to that maximum with a :class:`~inertialab.errors.DataQualityWarning`.
    mode : str, default="symmetric"
        Extension mode (MATLAB ``"sym"``).

    Returns
    -------
    Decomposition
    """
    # pywt needs a writeable contiguous buffer (read-only views come from pandas/memmaps)
    x = np.require(np.asarray(x, dtype=float), requirements=["C", "W"])
    if x.ndim != 1:
        raise InputError(f"signal must be one-dimensional, got shape {x.shape}")
    if not np.all(np.isfinite(x)):
        raise InputError("signal contains NaN or infinite values")
    w = pywt.Wavelet(wavelet)
    max_level = pywt.dwt_max_level(x.size, w.dec_len)
    if max_level < 1:
        raise InputError(f"signal of {x.size} samples is too short for one {wavelet} level")
    level = int(level)
    if level < 1:
        raise InputError(f"level must be >= 1, got {level}")
    used = level
    if max_level < level:
        used = max_level
        warnings.warn(
            f"{x.size} samples allow at most {max_level} {wavelet} levels; "
            f"decomposing to J={max_level} instead of {level}",
            DataQualityWarning, stacklevel=2)
    coeffs = pywt.wavedec(x, w, mode=mode, level=used)
    dec = Decomposition(coeffs=coeffs, level=used, n=x.size, wavelet=wavelet, mode=mode,
                        requested_level=level)
    return dec


def detail_band_hz(j: int, fs_hz: float) -> tuple[float, float]:
    """Nominal frequency band ``[fs/2^(j+1), fs/2^j]`` of ``D_j`` in Hz."""
    return fs_hz / 2 ** (j + 1), fs_hz / 2**j


def approximation_band_hz(level: int, fs_hz: float) -> tuple[float, float]:
    """Nominal band ``[0, fs/2^(L+1)]`` of ``A_L`` in Hz."""
    return 0.0, fs_hz / 2 ** (level + 1)


@dataclass(frozen=True)
class LevelSelection:
    """Result of the automatic level rule (spec 001 §3.6, eq. 6).

    Attributes
    ----------
    level : int
        L*, the chosen level.
    delta : dict[int, float]
        ``delta_j`` for each examined j (dimensionless).
    threshold : float
        The threshold used (default 0.14).
    j_range : tuple[int, int]
        Range of j examined (default (3, 9)).
    detail_power_window, detail_power_reference : dict[int, float]
        Mean square of ``D_j`` on the analysis window (P2) and on the reference (P1),
        in the squared signal unit ((deg/h)^2 for rates), j = 1..J.
    rule_met : bool
        False when no j met the threshold and the upper end of the range was returned.
    """

    level: int
    delta: dict
    threshold: float
    j_range: tuple
    detail_power_window: dict
    detail_power_reference: dict
    rule_met: bool


def _as_index(sel, n: int) -> np.ndarray:
    if isinstance(sel, slice):
        return np.arange(n)[sel]
    sel = np.asarray(sel)
    if sel.dtype == bool:
        if sel.size != n:
            raise InputError(f"boolean mask has {sel.size} entries, signal has {n}")
        return np.flatnonzero(sel)
    return sel.astype(int)


def select_level(x_or_dec, *, window, reference, threshold: float = DELTA_THRESHOLD,
                 j_range: tuple[int, int] = (3, 9), wavelet: str = "db4",
                 level: int = DEFAULT_LEVEL) -> LevelSelection:
    """Automatic level choice ``L*`` (spec 001 §3.6, eq. 6).

    Parameters
    ----------
    x_or_dec : array_like or Decomposition
        The signal (decomposed with ``wavelet``/``level``) or a ready decomposition.
    window : slice, bool mask or index array
        Analysis window W (default use: P2 of the fixed run minus 5-s guards).
    reference : slice, bool mask or index array
        Static reference over which ``beta_{j+1}`` (median of ``A_{j+1}``) is taken (P1).
    threshold : float, default=0.14
        ``L* = min{j : delta_j <= threshold}``.
    j_range : (int, int), default=(3, 9)
        Inclusive range of j; if no j qualifies, the upper end is returned.

    Returns
    -------
    LevelSelection
    """
    dec = x_or_dec if isinstance(x_or_dec, Decomposition) else decompose(
        x_or_dec, wavelet=wavelet, level=level)
    w = _as_index(window, dec.n)
    r = _as_index(reference, dec.n)
    if w.size == 0 or r.size == 0:
        raise InputError("level selection needs a non-empty analysis window and reference")
    j_lo, j_hi = int(j_range[0]), int(j_range[1])
    j_hi = min(j_hi, dec.level - 1)
    if j_hi < j_lo:
        raise InputError(
            f"decomposition has {dec.level} levels; the level rule needs at least {j_lo + 1}")
    delta: dict[int, float] = {}
    chosen = None
    for j in range(j_lo, j_hi + 1):
        a_j = dec.approximation(j)
        a_j1 = dec.approximation(j + 1)
        beta = float(np.median(a_j1[r]))
        num = float(np.sqrt(np.mean((a_j[w] - a_j1[w]) ** 2)))
        den = float(np.sqrt(np.mean((a_j1[w] - beta) ** 2)))
        d = num / den if den > 0 else float("inf")
        delta[j] = d
        if chosen is None and d <= threshold:
            chosen = j
    rule_met = chosen is not None
    if chosen is None:
        chosen = j_hi
    pw = {j: float(np.mean(dec.detail(j)[w] ** 2)) for j in range(1, dec.level + 1)}
    pr = {j: float(np.mean(dec.detail(j)[r] ** 2)) for j in range(1, dec.level + 1)}
    return LevelSelection(level=int(chosen), delta=delta, threshold=float(threshold),
                          j_range=(j_lo, j_hi), detail_power_window=pw,
                          detail_power_reference=pr, rule_met=rule_met)
