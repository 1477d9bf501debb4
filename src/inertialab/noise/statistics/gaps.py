"""Gap-resistant Allan deviations for records with missing samples.

A missing sample is NaN (a time-stamp gap becomes NaN samples on the nominal grid in the
workflow; nothing is interpolated). Like allantools ``gradev`` and Stable32, every
summand that touches a missing value is left out and the variance is the mean of the
summands that remain:

* phase input (``input="angle"``): the second difference ``x[i+2m] - 2 x[i+m] + x[i]``
  is used when its three phase points exist;
* rate / frequency input (``input="rate"``): ``tau0 (sum y[i+m .. i+2m) - sum y[i .. i+m))``
  is used when none of its ``2m`` samples is missing (prefix sums with the gaps counted
  alongside, ``O(N)`` per tau; integrating across a gap, as ``gradev`` does for frequency
  data, would shift every later phase point).

Per tau the result reports the summands used and the fraction of the gap-free count
(:attr:`GapResult.used_fraction`) and the number of gaps in the record
(:attr:`GapResult.n_gaps`: runs of consecutive missing samples). The interval uses the
SP 1065 Table 5 EDF at the effective record length ``used_fraction * N``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from inertialab.errors import InputError
from inertialab.noise.statistics import registry
from inertialab.noise.statistics._clock import (  # noqa: F401 - many_m re-export
    grid,
    interval,
    many_m,
)
from inertialab.noise.statistics.allan import DeviationResult

__all__ = ["GAP_STATISTICS", "GapResult", "count_gaps", "gap_deviation"]

#: Statistics with a gap-resistant form.
GAP_STATISTICS = registry.with_gaps()  # declared in inertialab.noise.statistics.registry

#: per statistic: (stride kind, order of the phase difference); "1" overlapping, "m"
#: non-overlapping, "mod" modified (the difference averaged over m consecutive starts)
_SPAN = {"oadev": ("1", 2), "adev": ("m", 2), "mdev": ("mod", 2), "tdev": ("mod", 2),
         "ohdev": ("1", 3), "hdev": ("m", 3)}
#: variance = sum(d^2) / (NORM m^2 tau0^2 n): Allan 2, Hadamard 6, modified 2 m^2 (the
#: inner sum of m differences is squared, so MVAR = sum / (2 m^4 tau0^2 n))
_NORM = {"oadev": 2.0, "adev": 2.0, "ohdev": 6.0, "hdev": 6.0, "mdev": 2.0, "tdev": 2.0}
_COEF = {2: (1.0, -2.0, 1.0), 3: (-1.0, 3.0, -3.0, 1.0)}


def _summands(statistic, x, bad, n_phase, m, span, order):
    """The statistic's summands at lag ``m`` (phase differences of ``order`` taken from
    ``x(index array)``), a mask of the gap-free ones and the count a gap-free record has.

    Phase input (``bad is None``): a summand is gap-free when every phase point it reads
    is finite. Frequency input: when none of the frequency samples it spans is missing
    (``bad(i, j)`` tells a gap in samples ``i .. j-1``).
    """
    if span == "mod":
        n_d = n_phase - order * m
        i = np.arange(n_d)
        d = sum(c * x(i + q * m) for q, c in enumerate(_COEF[order]))
        # the modified summand: sum of m consecutive differences (prefix sums, gaps as 0)
        fin = np.isfinite(d)
        C = np.concatenate(([0.0], np.cumsum(np.where(fin, d, 0.0))))
        G = np.concatenate(([0], np.cumsum(~fin)))
        j = np.arange(n_d - m + 1)
        out = (C[j + m] - C[j]) / m
        if bad is None:
            good = (G[j + m] - G[j]) == 0
        else:  # frequency samples j .. j + (order + 1) m - 2
            good = ~bad(j, j + (order + 1) * m - 1)
        return out, good, j.size
    stride = 1 if span == "1" else m
    i = np.arange(0, n_phase - order * m, stride)
    d = sum(c * x(i + q * m) for q, c in enumerate(_COEF[order]))
    good = np.isfinite(d) if bad is None else ~bad(i, i + order * m)
    return d, good, i.size


@dataclass(frozen=True)
class GapResult(DeviationResult):
    """A :class:`DeviationResult` of a record with gaps: ``n_gaps`` (runs of missing
    samples) and ``used_fraction`` per tau (summands used / summands without gaps)."""

    n_gaps: int = 0
    n_missing: int = 0
    used_fraction: np.ndarray = field(default_factory=lambda: np.zeros(0))

    def to_dict(self) -> dict:
        d = super().to_dict()
        d.update({"n_gaps": int(self.n_gaps), "n_missing": int(self.n_missing),
                  "used_fraction": [float(v) for v in self.used_fraction]})
        return d


def count_gaps(values) -> tuple[int, int]:
    """``(runs of consecutive NaN, NaN samples)``."""
    bad = ~np.isfinite(np.asarray(values, dtype=float))
    if not bad.any():
        return 0, 0
    starts = np.flatnonzero(bad & ~np.concatenate(([False], bad[:-1])))
    return int(starts.size), int(bad.sum())


def gap_deviation(statistic: str, data, *, rate_hz: float, taus="octave", input: str = "rate",
                  confidence: float = 0.683, alpha=None) -> GapResult:
    """Gap-resistant ``oadev``/``ohdev`` (stride 1), ``adev``/``hdev`` (stride m) or
    ``mdev``/``tdev`` of ``data`` with NaN gaps.

    ``alpha`` (noise type per tau) defaults to 0 (white FM / white rate) for the
    interval: the lag-1 identification needs contiguous data.

    Examples
    --------
    A dropout of 500 samples (NaN) in white rate noise of sigma 1 at 100 Hz: the curve
    still reads ``sigma / sqrt(m)`` and says what it skipped:

    >>> import numpy as np
    >>> y = np.random.default_rng(0).normal(0.0, 1.0, 10_000)
    >>> y[3000:3500] = np.nan
    >>> r = gap_deviation("oadev", y, rate_hz=100.0, taus=[0.01, 0.04, 0.16])
    >>> r.n_gaps, r.n_missing
    (1, 500)
    >>> bool(np.allclose(r.dev * np.sqrt(r.m), 1.0, atol=0.03))
    True
    """
    if statistic not in GAP_STATISTICS:
        raise InputError(f"statistic '{statistic}' has no gap-resistant form (use "
                         f"{', '.join(GAP_STATISTICS)}; argument 'stats')")
    if input not in ("rate", "angle"):
        raise InputError(f"input must be 'rate' or 'angle', got '{input}'")
    rate = float(rate_hz)
    if not math.isfinite(rate) or rate <= 0:
        raise InputError(f"rate_hz must be positive and finite, got {rate_hz}")
    v = np.asarray(data, dtype=np.float64)
    if v.ndim != 1:
        raise InputError(f"data must be one-dimensional, got shape {v.shape}")
    if np.isinf(v).any():
        raise InputError("data contains infinity (a gap is NaN)")
    tau0 = 1.0 / rate
    ok = np.isfinite(v)
    if ok.sum() < 3:
        raise InputError(f"too few valid samples ({int(ok.sum())})")
    n_gaps, n_missing = count_gaps(v)
    n_phase = v.size + 1 if input == "rate" else v.size
    ms = grid(n_phase, taus, rate, (n_phase - 1) // 2)
    if input == "rate":
        y = np.where(ok, v - np.mean(v[ok]), 0.0)
        S = np.concatenate(([0.0], np.cumsum(y)))
        B = np.concatenate(([0], np.cumsum(~ok)))
    var = np.full(ms.size, np.nan)
    used = np.zeros(ms.size, dtype=np.int64)
    frac = np.zeros(ms.size)
    span, order = _SPAN[statistic]
    for k, m in enumerate(int(q) for q in ms):
        if input == "rate":
            # phase differences from the prefix sums of y (gaps as 0); a summand is used
            # when none of the frequency samples it spans is missing
            x = lambda i, _S=S: tau0 * _S[i]  # noqa: E731
            bad = lambda i, j: (B[j] - B[i]) != 0  # noqa: E731  # y[i .. j) has a gap
        else:
            x = lambda i, _v=v: _v[i]  # noqa: E731
            bad = None
        d, good, full = _summands(statistic, x, bad, n_phase, m, span, order)
        dg = d[good]
        used[k] = dg.size
        frac[k] = dg.size / full if full > 0 else 0.0
        if dg.size:
            var[k] = float(np.dot(dg, dg)) / (_NORM[statistic] * m * m * dg.size) / tau0 ** 2
            if statistic == "tdev":  # TVAR = tau^2 / 3 MVAR
                var[k] *= (m * tau0) ** 2 / 3.0
    keep = used > 0
    if not keep.any():
        raise InputError("no difference without a gap at any tau")
    ms, var, used, frac = ms[keep], var[keep], used[keep], frac[keep]
    dev = np.sqrt(var)
    alphas = np.broadcast_to(np.asarray(0 if alpha is None else alpha, dtype=np.int64),
                             ms.shape).copy()
    from inertialab.noise.statistics import edf as _edf

    if statistic in ("oadev", "adev"):
        edfs = np.array([float(_edf.edf_oadev_sp1065(max(3, int(round(f * n_phase))), int(m),
                                                     max(min(int(a), 2), -2)))
                         for f, m, a in zip(frac, ms, alphas)])
    else:  # Greenhall's EDF at the effective record length
        edfs = np.array([float(_edf.edf(statistic, max(order * int(m) + 2,
                                                       int(round(f * n_phase))), int(m),
                                        max(min(int(a), 2), -2))[0][0])
                         for f, m, a in zip(frac, ms, alphas)])
    if statistic in ("adev", "hdev"):
        edfs = np.minimum(edfs, used.astype(float))
    lo, hi = interval(dev, edfs, confidence)
    return GapResult(statistic=statistic, tau0_s=tau0, taus_s=ms * tau0, m=ms, dev=dev,
                     n_terms=used, alpha=alphas, edf=edfs, ci_low=lo, ci_high=hi,
                     confidence=float(confidence), n_samples=int(v.size), input=input,
                     alpha_method="user" if alpha is not None else "assumed-wfm",
                     edf_method=("sp1065-table5-effective-n" if statistic in ("oadev", "adev")
                                else "greenhall-effective-n"),
                     alpha_source=("user" if alpha is not None else "assumed",) * ms.size,
                     n_gaps=n_gaps, n_missing=n_missing, used_fraction=frac)
