"""Theo1, TheoBR and TheoH (NIST SP 1065 §5.2.15-5.2.17).

* **Theo1** (SP 1065 eq. 30), ``m`` even, ``10 <= m <= N - 1`` in Stable32 (here any even
  ``m >= 2``), at averaging time ``tau = 0.75 m tau0``::

      Theo1 = 1 / (0.75 (N - m) (m tau0)^2) *
              sum_{i=0}^{N-m-1} sum_{d=0}^{m/2-1} [(x_i - x_{i+m/2-d}) + (x_{i+m} - x_{i+m/2+d})]^2
                                                   / (m/2 - d)

  Computed as ``m/2`` vector passes over ``i`` per tau (``O(N m)``), no Python loop
  over ``i`` (allantools' ``theo1`` loops over both indices in Python).
* **TheoBR** (eq. 31): Theo1 times the average ratio of the overlapping Allan variance
  to Theo1 at the same tau, ``Avar(9 + 3i) / Theo1(12 + 4i)``, ``i = 0 .. n``,
  ``n = floor(0.1 N / 3) - 3``: the data-derived bias removal of Howe & Tasset.
* **TheoH** (eq. 32): the overlapping Allan deviation for ``tau < k`` and TheoBR for
  ``tau >= k``, ``k`` the largest octave Allan tau within 10 % of the record length.

``bias_correction=True`` of :func:`theo1` multiplies the Theo1 variance by the ratio
``Avar/Theo1`` where the identified (or given) alpha per tau is not white FM, so
that it estimates the Allan variance, as Stable32 does: its ratio is the data's own
average ``Avar(9+3i)/Theo1(12+4i)``, ``i = 0 .. floor(N/6) - 3`` (Stable32's Theo1 tables
of PHASE.DAT: white FM printed uncorrected, flicker PM multiplied by exactly that ratio,
both reproduced to 4e-5). Below 24 points the published noise-type table ``a + b/(0.75
m)^c`` (Howe & Tasset 2004; SP 1065 §5.2.15; :data:`inertialab.noise.statistics.edf_clock.
THEO1_BIAS`) stands in. The factor the variance was divided by is
:attr:`DeviationResult.bias` per tau. TheoBR (:func:`theobr`) is its own statistic, with
SP 1065's ratio (``i <= floor(0.1 N/3) - 3``) at every tau. EDF: the Theo1 EDF of Howe & Peppler (SP 1065 §5.2.15,
:func:`inertialab.noise.statistics.edf_clock.edf_theo1`) for Theo1 and TheoBR, the OADEV EDF
(Greenhall & Riley) for TheoH's Allan part.
"""

from __future__ import annotations

import math

import numpy as np

from inertialab.errors import InputError
from inertialab.noise.statistics._clock import grid, interval, noise_types, phase_source
from inertialab.noise.statistics.allan import CorrectedResult, DeviationResult
from inertialab.noise.statistics.edf_clock import edf_theo1, theo1_bias
from inertialab.noise.statistics.identify import CONFIDENT

__all__ = ["theo1", "theo1_variance", "theobr", "theoh"]


def theo1_variance(x: np.ndarray, m: int, tau0: float) -> float:
    """Theo1 variance of phase ``x`` at even ``m`` (SP 1065 eq. 30)."""
    if m % 2 or m < 2:
        raise InputError(f"Theo1 needs an even averaging factor >= 2, got {m}")
    N = x.size
    n = N - m
    if n < 1:
        raise InputError(f"Theo1 at m = {m} needs more than {m} phase points")
    h = m // 2
    a = x[:n]
    c = x[m:m + n]
    base = a + c
    buf = np.empty(n)
    total = 0.0
    for d in range(h):
        np.subtract(base, x[h - d:h - d + n], out=buf)
        buf -= x[h + d:h + d + n]
        total += float(np.dot(buf, buf)) / (h - d)
    return total / (0.75 * n * (m * tau0) ** 2)


def _result(statistic, data, x, src, ms, taus, var, nt, tau0, confidence, alpha, input,
            bias_correction=False):
    m_equiv = np.maximum(np.round(taus / tau0).astype(np.int64), 1)
    alphas, sources, amethod = noise_types(src, m_equiv, "oadev", alpha,
                                           data="freq" if input == "rate" else "phase")
    bias = np.ones(ms.size)
    if bias_correction:  # Stable32's: none for white FM, the data's Avar/Theo1 otherwise
        kf = _stable32_ratio(x, tau0)
        ratio = np.where(alphas == 0, 1.0, kf if kf is not None else theo1_bias(alphas, ms))
        bias = np.where(np.isin(sources, CONFIDENT), 1.0 / ratio, 1.0)
        var = var / bias
    dev = np.sqrt(var)
    edfs = edf_theo1(x.size, ms, alphas)
    edfs = np.where(np.isfinite(edfs) & (edfs > 0), edfs, np.nan)
    lo, hi = interval(dev, edfs, confidence)
    kind = CorrectedResult if bias_correction else DeviationResult
    extra = {"bias": bias} if bias_correction else {}
    return kind(statistic=statistic, tau0_s=tau0, taus_s=taus, m=ms, dev=dev, n_terms=nt,
                alpha=alphas, edf=edfs, ci_low=lo, ci_high=hi, confidence=float(confidence),
                n_samples=int(np.asarray(data).size), input=input, alpha_method=amethod,
                edf_method="theo1-howe-peppler-sp1065", alpha_source=tuple(sources),
                **extra)


def theo1(data, *, rate_hz: float, taus="octave", input: str = "rate",
          confidence: float = 0.683, alpha=None, bias_correction: bool = False
          ) -> DeviationResult:
    """Theo1 deviation (SP 1065 eq. 30) at even m; ``taus_s = 0.75 m tau0``.

    ``bias_correction``: multiply the variance by the noise-type bias
    :func:`~inertialab.noise.statistics.edf_clock.theo1_bias` (module docstring).

    ``taus`` as :func:`inertialab.noise.statistics.allan.tau_grid` for m (octave: m = 2, 4, 8 ...;
    explicit seconds are Theo1 taus, ``m = tau / (0.75 tau0)`` rounded to even).

    Examples
    --------
    For white rate noise Theo1 at ``tau = 0.75 m tau0`` equals the Allan deviation at that
    tau, ``sigma / sqrt(tau / tau0)``:

    >>> import numpy as np
    >>> y = np.random.default_rng(0).normal(0.0, 1.0, 4000)
    >>> r = theo1(y, rate_hz=100.0, taus=4)
    >>> r.m.tolist(), bool(np.allclose(r.taus_s, 0.75 * r.m / 100.0))
    ([2, 26, 318, 4000], True)
    >>> bool(np.allclose(r.dev[:3] * np.sqrt(r.taus_s[:3] * 100.0), 1.0, atol=0.05))
    True
    """
    src, x = phase_source(data, rate_hz, input)
    tau0 = 1.0 / float(rate_hz)
    N = x.size
    ms = grid(N, taus, rate_hz, N - 1 - ((N - 1) % 2), even=True, mmin=2, scale=0.75)
    var = np.array([theo1_variance(x, int(m), tau0) for m in ms])
    nt = (N - ms) * (ms // 2)
    return _result("theo1", data, x, src, ms, 0.75 * ms * tau0, var, nt.astype(np.int64),
                   tau0, confidence, alpha, input, bias_correction=bias_correction)


def _stable32_ratio(x: np.ndarray, tau0: float):
    """Stable32's Theo1 bias ratio: ``(1/(n+1)) sum_i Avar(9+3i) / Theo1(12+4i)`` with
    ``n = floor(N/6) - 3`` (W. Riley, "Fast bias-removed Theo1 calculation with R"; the
    ratio Stable32's Run and Plot functions apply); None below 24 phase points."""
    return _br_ratio(x, tau0, n=int(math.floor(x.size / 6.0)) - 3)[0] if x.size >= 24 else None


def _br_ratio(x: np.ndarray, tau0: float, n: int | None = None) -> tuple[float, int]:
    """``(1/(n+1)) sum_i Avar(9+3i) / Theo1(12+4i)`` and n (SP 1065 eq. 31)."""
    N = x.size
    if n is None:
        n = int(math.floor(0.1 * N / 3.0)) - 3
    if n < 0:
        raise InputError(f"TheoBR needs at least 120 phase points, got {N}")
    tot = 0.0
    for i in range(n + 1):
        ma, mt = 9 + 3 * i, 12 + 4 * i
        d = x[2 * ma:] - 2.0 * x[ma:-ma] + x[:-2 * ma]
        avar = float(np.dot(d, d)) / (2.0 * (ma * tau0) ** 2 * d.size)
        tot += avar / theo1_variance(x, mt, tau0)
    return tot / (n + 1), n


def theobr(data, *, rate_hz: float, taus="octave", input: str = "rate",
           confidence: float = 0.683, alpha=None) -> DeviationResult:
    """Bias-removed Theo1 (SP 1065 eq. 31).

    Examples
    --------
    >>> import numpy as np
    >>> y = np.random.default_rng(0).normal(0.0, 1.0, 4000)
    >>> r = theobr(y, rate_hz=100.0, taus=4)
    >>> r.statistic, bool(np.allclose(r.dev[:3] * np.sqrt(r.taus_s[:3] * 100.0), 1.0, atol=0.05))
    ('theobr', True)
    """
    r = theo1(data, rate_hz=rate_hz, taus=taus, input=input, confidence=confidence,
              alpha=alpha)
    _, x = phase_source(data, rate_hz, input)
    ratio, _n = _br_ratio(x, r.tau0_s)
    f = math.sqrt(ratio)
    return CorrectedResult(**{**r.__dict__, "statistic": "theobr", "dev": r.dev * f,
                              "ci_low": r.ci_low * f, "ci_high": r.ci_high * f,
                              "bias": np.full(r.m.size, 1.0 / ratio)})


def theoh(data, *, rate_hz: float, taus="octave", input: str = "rate",
          confidence: float = 0.683, alpha=None) -> DeviationResult:
    """TheoH (SP 1065 eq. 32): OADEV for ``tau < k``, TheoBR for ``tau >= k``, ``k`` the
    largest octave OADEV tau within 10 % of the record length ``T = (N - 1) tau0``.

    Examples
    --------
    White rate noise of sigma 1 at 100 Hz: about ``sigma / sqrt(tau / tau0)`` on both sides
    of ``k``:

    >>> import numpy as np
    >>> y = np.random.default_rng(0).normal(0.0, 1.0, 4000)
    >>> r = theoh(y, rate_hz=100.0)
    >>> bool(np.allclose(r.dev * np.sqrt(r.taus_s * 100.0), 1.0, atol=0.1))
    True
    """
    from inertialab.noise.statistics.allan import oadev

    src, x = phase_source(data, rate_hz, input)
    tau0 = 1.0 / float(rate_hz)
    T = (x.size - 1) * tau0
    a = oadev(x, rate_hz=rate_hz, taus="octave", input="angle", confidence=confidence,
              alpha=alpha)
    k = float(a.taus_s[a.taus_s <= 0.1 * T].max()) if np.any(a.taus_s <= 0.1 * T) else \
        float(a.taus_s[0])
    b = theobr(x, rate_hz=rate_hz, taus=taus, input="angle", confidence=confidence,
               alpha=alpha)
    ka = a.taus_s < k
    kb = b.taus_s >= k
    cat = {f: np.concatenate((getattr(a, f)[ka], getattr(b, f)[kb]))
           for f in ("taus_s", "m", "dev", "n_terms", "alpha", "edf", "ci_low", "ci_high")}
    cat["bias"] = np.concatenate((np.ones(int(ka.sum())), b.bias[kb]))
    src_a = tuple(s for s, keep in zip(a.alpha_source, ka) if keep)
    src_b = tuple(s for s, keep in zip(b.alpha_source, kb) if keep)
    return CorrectedResult(statistic="theoh", tau0_s=tau0, confidence=float(confidence),
                           n_samples=int(np.asarray(data).size), input=input,
                           alpha_method=a.alpha_method, edf_method="oadev|theobr",
                           alpha_source=src_a + src_b, **cat)
