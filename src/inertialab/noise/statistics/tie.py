"""Time interval error statistics: MTIE and TIE rms (ITU-T G.810).

On the phase ``x`` (s for a clock; for rate input the integrated rate, mean removed,
as the rest of the family), window ``m + 1`` points (``tau = m tau0``):

* **MTIE(tau)** = ``max_i [max(x[i..i+m]) - min(x[i..i+m])]``, the largest peak-to-peak
  phase excursion over any window (Stable32 "fast (u)" / allantools ``mtie``). Sliding
  maxima and minima by :func:`scipy.ndimage.maximum_filter1d` (van Herk / Gil-Werman,
  ``O(N)`` per tau whatever m, no window matrix).
* **TIE rms(tau)** = ``sqrt(mean_i (x[i+m] - x[i])^2)`` (allantools ``tierms``).

Both are in the unit of the phase (s); they are not variances and carry no chi-square
interval (``edf``, ``ci_low``, ``ci_high`` are NaN). ``n_terms`` is ``N - m``.
"""

from __future__ import annotations

import numpy as np

from inertialab.noise.statistics._clock import grid, phase_source
from inertialab.noise.statistics.allan import DeviationResult

__all__ = ["mtie", "tierms"]


def _result(statistic, data, ms, tau0, dev, nt, input, confidence):
    nan = np.full(ms.size, np.nan)
    return DeviationResult(statistic=statistic, tau0_s=tau0, taus_s=ms * tau0, m=ms,
                           dev=np.asarray(dev, dtype=float), n_terms=nt,
                           alpha=np.zeros(ms.size, dtype=np.int64), edf=nan, ci_low=nan,
                           ci_high=nan.copy(), confidence=float(confidence),
                           n_samples=int(np.asarray(data).size), input=input,
                           alpha_method="none", edf_method="none",
                           alpha_source=("none",) * ms.size)


def mtie(data, *, rate_hz: float, taus="octave", input: str = "rate",
         confidence: float = 0.683) -> DeviationResult:
    """Maximum time interval error per tau (unit of the phase).

    Examples
    --------
    The largest peak-to-peak phase (the integrated, mean-removed rate) over any window of
    ``m + 1`` points, against a brute-force loop:

    >>> import numpy as np
    >>> y = np.random.default_rng(0).normal(0.0, 1.0, 500)
    >>> x = np.concatenate(([0.0], np.cumsum(y - y.mean()))) / 100.0
    >>> r = mtie(y, rate_hz=100.0, taus=[0.1])
    >>> brute = max(np.ptp(x[i:i + 11]) for i in range(x.size - 10))
    >>> bool(np.isclose(r.dev[0], brute))
    True
    """
    from scipy.ndimage import maximum_filter1d, minimum_filter1d

    _, x = phase_source(data, rate_hz, input)
    tau0 = 1.0 / float(rate_hz)
    N = x.size
    ms = grid(N, taus, rate_hz, N - 1)
    dev = np.empty(ms.size)
    for k, m in enumerate(int(v) for v in ms):
        w = m + 1
        # window [i, i + m] for i = 0 .. N - w: filters centred at i + w//2 (origin 0)
        hi = maximum_filter1d(x, size=w, mode="nearest")
        lo = minimum_filter1d(x, size=w, mode="nearest")
        c = w // 2
        dev[k] = float(np.max(hi[c:N - w + 1 + c] - lo[c:N - w + 1 + c]))
    return _result("mtie", data, ms, tau0, dev, (N - ms).astype(np.int64), input, confidence)


def tierms(data, *, rate_hz: float, taus="octave", input: str = "rate",
           confidence: float = 0.683) -> DeviationResult:
    """TIE rms per tau (unit of the phase).

    Examples
    --------
    White rate noise of sigma 1 at 100 Hz: the phase is a random walk, so the TIE over ``m``
    samples has rms ``sigma tau0 sqrt(m)``:

    >>> import numpy as np
    >>> y = np.random.default_rng(0).normal(0.0, 1.0, 4000)
    >>> r = tierms(y, rate_hz=100.0, taus=[0.01, 0.04, 0.16])
    >>> bool(np.allclose(r.dev / (0.01 * np.sqrt(r.m)), 1.0, atol=0.02))
    True
    """
    _, x = phase_source(data, rate_hz, input)
    tau0 = 1.0 / float(rate_hz)
    N = x.size
    ms = grid(N, taus, rate_hz, N - 1)
    dev = np.empty(ms.size)
    for k, m in enumerate(int(v) for v in ms):
        d = x[m:] - x[:-m]
        dev[k] = float(np.sqrt(np.dot(d, d) / d.size))
    return _result("tierms", data, ms, tau0, dev, (N - ms).astype(np.int64), input, confidence)
