"""Total deviations of the modified and Hadamard kind: MTOTDEV, TTOTDEV, HTOTDEV.

Definitions of NIST SP 1065 (Riley 2008) §5.2.12-5.2.14 as Stable32 computes them:

* **MTOTDEV** (eq. 27): for each of the ``N - 3m + 1`` phase subsequences of ``3m``
  points, remove the linear trend estimated from the means of its first and last halves,
  extend it by uninverted even reflection to ``9m`` points, and average the ``6m``
  squared second differences of its ``m``-point means; ``Mod Totvar =
  sum / (2 m^2 tau^2 (N - 3m + 1))`` (with the ``1/(6m)`` average inside).
* **TTOTDEV** (eq. 28): ``tau / sqrt(3) * MTOTDEV`` (SP 1065 prints tau cubed by mistake).
* **HTOTDEV** (eq. 29): the same on ``3m``-point subsequences of the *frequency* data
  (Hadamard: second differences of ``m``-point frequency means, ``1/6`` normalisation);
  at ``m = 1`` the overlapping Hadamard deviation (Riley: "for best consistency").

**Bias corrections** (``bias_correction=True``; on by default for clock inputs in the
workflow): the variances are divided by Stable32's noise-dependent factors
(:mod:`inertialab.noise.statistics.edf_clock`): Mod Totvar and TTOT ``WPM 0.94, FPM 0.83, WFM 0.73,
FFM 0.70, RWFM 0.69``; Htotvar ``WFM 0.995, FFM 0.851, RWFM 0.771, FWFM 0.717, RRFM
0.679`` (phase noise 1.0; none at m = 1, the OHDEV point). The factor used per tau is
:attr:`TotalResult.bias` (1.0 when off).

EDF (:mod:`inertialab.noise.statistics.edf_clock`): MTOT and TTOT by SP 1065 Table 8 (``edf = b (N/m)
- c``, N phase points) for ``m >= 16`` and the MDEV EDF below; HTOT by the Htotvar formula
``(N/m)/(b0 + b1 m/N)`` for ``m >= 16`` and SP 1065 Table 5 below and for phase noise
(Stable32's printed bounds; docs/allan.md). Computation: blocks of subsequences
as 2-D arrays (memory bounded by ``block_elems``), ``O(N m)`` per tau, the same cost class
as Stable32 and allantools (which loops in Python).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from inertialab.noise.statistics._clock import grid, interval, noise_types, phase_source
from inertialab.noise.statistics.allan import CorrectedResult
from inertialab.noise.statistics.edf_clock import (
    HTOT_BIAS,
    MTOT_BIAS,
    edf_htotdev,
    edf_mtotdev,
    htot_bias,
    mtot_bias,
)
from inertialab.noise.statistics.identify import CONFIDENT

__all__ = ["MTOT_BIAS", "HTOT_BIAS", "TotalResult", "htotdev", "mtotdev", "ttotdev"]

_BLOCK = 1 << 21  # elements per 2-D block (16 MiB of float64)


@dataclass(frozen=True)
class TotalResult(CorrectedResult):
    """A :class:`DeviationResult` of a total statistic (``bias``: the factor applied per
    tau, 1.0 for none; also under the key ``bias`` of :meth:`to_dict`)."""

    def to_dict(self) -> dict:
        d = super().to_dict()
        d["bias"] = [float(v) for v in self.bias]
        return d


def _detrended_reflected_means(seg: np.ndarray, m: int, centre: bool) -> np.ndarray:
    """``(B, 8m+1)`` m-point sums of the detrended, evenly reflected 9m sequences of the
    ``(B, 3m)`` subsequences ``seg``."""
    L = 3 * m
    h1, h2 = L // 2, (L + 1) // 2
    mean1 = seg[:, :h1].mean(axis=1)
    mean2 = seg[:, h2:].mean(axis=1)
    dist = 0.5 * L if L % 2 == 0 else 0.5 * (L - 1) + 1.0
    slope = (mean2 - mean1) / dist
    t = np.arange(L, dtype=np.float64)
    if centre:
        t = t - np.floor(L / 2)
    x0 = seg - slope[:, None] * t
    rev = x0[:, ::-1]
    xs = np.concatenate((rev, x0, rev), axis=1)
    c = np.zeros((xs.shape[0], xs.shape[1] + 1))
    np.cumsum(xs, axis=1, out=c[:, 1:])
    return c[:, m:] - c[:, :-m]  # sums over [j, j+m), j = 0 .. 8m


def _tot_sum(x: np.ndarray, m: int, centre: bool) -> float:
    """``sum over subsequences of (1/(6m)) sum_j ((S_j - 2 S_{j+m} + S_{j+2m})/m)^2``."""
    L = 3 * m
    nsub = x.size - L + 1
    rows = max(1, _BLOCK // (9 * m + 1))
    total = 0.0
    base = np.arange(L)
    for b0 in range(0, nsub, rows):
        idx = np.arange(b0, min(b0 + rows, nsub))[:, None] + base
        S = _detrended_reflected_means(x[idx], m, centre)
        d = (S[:, :6 * m] - 2.0 * S[:, m:7 * m] + S[:, 2 * m:8 * m]) / m
        total += float(np.einsum("ij,ij->", d, d)) / (6.0 * m)
    return total


def _finish(statistic, src, x, ms, var, nt, tau0, taus, confidence, alpha, bias_correction,
            edf_stat, n_samples, input):
    alphas, sources, amethod = noise_types(src, ms, statistic, alpha,
                                           data="freq" if input == "rate" else "phase",
                                           n_terms=nt)
    if bias_correction:
        b = mtot_bias(alphas) if statistic in ("mtotdev", "ttotdev") else htot_bias(alphas)
        if statistic == "htotdev":
            b = np.where(ms == 1, 1.0, b)  # m = 1 is OHDEV
        b = np.where(np.isin(sources, CONFIDENT), b, 1.0)  # no type, no correction
    else:
        b = np.ones(ms.size)
    var = var / b
    dev = np.sqrt(var)
    N = x.size
    if statistic in ("mtotdev", "ttotdev"):
        edfs = edf_mtotdev(N, ms, alphas)
        emethod = "sp1065-table8|mdev-greenhall(m<16)"
    else:
        edfs = edf_htotdev(N, ms, alphas)
        emethod = "htotvar-howe2000|sp1065-table5(m<16, PM)"
    lo, hi = interval(dev, edfs, confidence)
    return TotalResult(statistic=statistic, tau0_s=tau0, taus_s=taus, m=ms, dev=dev,
                       n_terms=nt, alpha=alphas, edf=np.asarray(edfs, dtype=float),
                       ci_low=lo, ci_high=hi, confidence=float(confidence),
                       n_samples=int(n_samples), input=input, alpha_method=amethod,
                       edf_method=emethod, alpha_source=tuple(sources), bias=b)


def mtotdev(data, *, rate_hz: float, taus="octave", input: str = "rate",
            confidence: float = 0.683, alpha=None, bias_correction: bool = False,
            _tdev: bool = False) -> TotalResult:
    """Modified total deviation (SP 1065 eq. 27); ``m <= N/3`` (N phase points).

    Parameters as :func:`inertialab.noise.statistics.allan.deviation`; ``bias_correction`` divides
    the variance by :data:`MTOT_BIAS` of the noise type per tau.

    Examples
    --------
    With Stable32's bias correction it estimates the modified Allan deviation (white rate
    noise of sigma 1 at 100 Hz):

    >>> import numpy as np
    >>> y = np.random.default_rng(0).normal(0.0, 1.0, 4000)
    >>> from inertialab.noise.statistics.allan import mdev
    >>> mt = mtotdev(y[:2000], rate_hz=100.0, taus=[0.04, 0.16], bias_correction=True)
    >>> md = mdev(y[:2000], rate_hz=100.0, taus=[0.04, 0.16])
    >>> mt.bias.tolist(), bool(np.allclose(mt.dev, md.dev, rtol=0.1))
    ([0.73, 0.73], True)
    """
    src, x = phase_source(data, rate_hz, input)
    tau0 = 1.0 / float(rate_hz)
    N = x.size
    ms = grid(N, taus, rate_hz, N // 3)
    var = np.empty(ms.size)
    nt = np.empty(ms.size, dtype=np.int64)
    for k, m in enumerate(int(v) for v in ms):
        s = _tot_sum(x, m, centre=False)
        nsub = N - 3 * m + 1
        var[k] = s / (2.0 * (m * tau0) ** 2 * nsub)
        nt[k] = nsub
    name = "ttotdev" if _tdev else "mtotdev"
    res = _finish(name, src, x, ms, var, nt, tau0, ms * tau0, confidence, alpha,
                  bias_correction, "mdev", np.asarray(data).size, input)
    if not _tdev:
        return res
    f = res.taus_s / np.sqrt(3.0)
    return TotalResult(**{**res.__dict__, "dev": res.dev * f, "ci_low": res.ci_low * f,
                          "ci_high": res.ci_high * f})


def ttotdev(data, *, rate_hz: float, taus="octave", input: str = "rate",
            confidence: float = 0.683, alpha=None, bias_correction: bool = False) -> TotalResult:
    """Time total deviation ``tau/sqrt(3) * MTOTDEV`` (SP 1065 eq. 28); unit of the rate
    times seconds (s for fractional frequency).

    Examples
    --------
    >>> import numpy as np
    >>> y = np.random.default_rng(0).normal(0.0, 1.0, 4000)
    >>> tt = ttotdev(y[:2000], rate_hz=100.0, taus=[0.04, 0.16])
    >>> mt = mtotdev(y[:2000], rate_hz=100.0, taus=[0.04, 0.16])
    >>> bool(np.allclose(tt.dev, tt.taus_s / np.sqrt(3) * mt.dev))
    True
    """
    return mtotdev(data, rate_hz=rate_hz, taus=taus, input=input, confidence=confidence,
                   alpha=alpha, bias_correction=bias_correction, _tdev=True)


def htotdev(data, *, rate_hz: float, taus="octave", input: str = "rate",
            confidence: float = 0.683, alpha=None, bias_correction: bool = False) -> TotalResult:
    """Hadamard total deviation (SP 1065 eq. 29) on the frequency data; ``m <= M/3``
    (M frequency points); ``m = 1`` is the overlapping Hadamard deviation.

    Examples
    --------
    At ``m = 1`` the overlapping Hadamard deviation; for white rate noise of sigma 1 about
    ``1/sqrt(m)`` (the Hadamard variance of white noise is the Allan variance):

    >>> import numpy as np
    >>> y = np.random.default_rng(0).normal(0.0, 1.0, 4000)
    >>> from inertialab.noise.statistics.allan import ohdev
    >>> h = htotdev(y, rate_hz=100.0, taus=[0.01, 0.16])
    >>> bool(np.isclose(h.dev[0], ohdev(y, rate_hz=100.0, taus=[0.01]).dev[0], rtol=1e-12))
    True
    >>> bool(np.allclose(h.dev * np.sqrt(h.m), 1.0, atol=0.05))
    True
    """
    from inertialab.noise.statistics.allan import ohdev

    src, x = phase_source(data, rate_hz, input)
    tau0 = 1.0 / float(rate_hz)
    if input == "rate":
        y = np.asarray(data, dtype=np.float64)
    else:
        y = np.diff(x) / tau0
    M = y.size
    ms = grid(x.size, taus, rate_hz, M // 3)
    var = np.empty(ms.size)
    nt = np.empty(ms.size, dtype=np.int64)
    for k, m in enumerate(int(v) for v in ms):
        if m == 1:
            r = ohdev(x, rate_hz=rate_hz, taus=[tau0], input="angle", alpha=0)
            var[k] = float(r.dev[0]) ** 2
            nt[k] = int(r.n_terms[0])
            continue
        s = _tot_sum(y, m, centre=True)
        nsub = M - 3 * m + 1
        var[k] = s / (6.0 * nsub)
        nt[k] = nsub
    return _finish("htotdev", src, x, ms, var, nt, tau0, ms * tau0, confidence, alpha,
                   bias_correction, "ohdev", np.asarray(data).size, input)
