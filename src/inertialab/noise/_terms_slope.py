"""Automated IEEE 952 slope reading of the noise terms (spec 001 §3.4 item 1).

Local slopes over three consecutive taus, the longest run within 0.15 of each target
slope (>= 3 points), an EDF-weighted fixed-slope line through it. B is read on the
longest run with ``|slope| <= 0.1`` at its minimum, IEEE 952's flat region, with the
N and K lines read on their own runs subtracted there (``sigma_B^2 = sigma^2 - N^2/tau -
K^2 tau/3``; issue 14 item 2); without a flat run the minimum gives an upper bound (flag
``B_bound``). Missing runs give NaN with flag ``not_observable``. Intervals: chi-square
on the points' EDF (not a bootstrap), widened to span the reading of every point of the
run where those differ by more (flag ``read_spread``: the curve bends inside the slope
tolerance, and the line's height depends on where it is read).
"""

from __future__ import annotations

import math

import numpy as np
from scipy.stats import norm

from inertialab.noise._terms_base import (
    _NAMES,
    _REPORT,
    BI_FACTOR,
    NoiseTerm,
    NoiseTerms,
    local_slopes,
)


def _longest_run(mask: np.ndarray):
    best, cur, start = (0, 0), 0, 0
    for i, v in enumerate(mask):
        if v:
            if cur == 0:
                start = i
            cur += 1
            if cur > best[1] - best[0]:
                best = (start, i + 1)
        else:
            cur = 0
    return best


def fit_slope(result, sel, conv, rate_hz):
    """Automated IEEE 952 slope reading (see module docstring)."""
    taus = np.asarray(result.taus_s, float)[sel]
    dev = np.asarray(result.dev, float)[sel]
    edf = np.asarray(result.edf, float)[sel]
    edf = np.where(np.isfinite(edf) & (edf > 0), edf, 1.0)
    lo_ci = np.asarray(result.ci_low, float)[sel]
    hi_ci = np.asarray(result.ci_high, float)[sel]
    conf = float(result.confidence)
    z = float(norm.ppf(0.5 * (1 + conf)))
    s = local_slopes(taus, dev)
    targets = {"Q": (-1.0, math.sqrt(3)), "N": (-0.5, 1.0), "K": (0.5, 1 / math.sqrt(3)),
               "R": (1.0, 1 / math.sqrt(2))}
    terms = {}
    coeffs = [float("nan")] * 5
    for name, (slope, gain) in targets.items():
        a, b = _longest_run(np.abs(s - slope) <= 0.15)
        if b - a < 3:
            terms[name] = NoiseTerm(value=float("nan"), unit=_REPORT[conv.kind][name],
                                    ci=(float("nan"), float("nan")), method="slope",
                                    tau_range_s=(float("nan"), float("nan")),
                                    flags=("not_observable",))
            continue
        lt, ld, w = np.log(taus[a:b]), np.log(dev[a:b]), edf[a:b]
        lnc = float(np.sum(w * (ld - slope * lt)) / np.sum(w))
        sd_ln = math.sqrt(1.0 / np.sum(2.0 * w))
        C = math.exp(lnc)
        amp = C / gain  # sigma = gain * amp * tau^slope
        j = _NAMES.index(name)
        coeffs[j] = float(C**2)  # sigma = C tau^slope -> c_k = C^2, k = 2 slope
        k = conv.value(name, 1.0)
        val = k * amp * conv.f
        ci = (val * math.exp(-z * sd_ln), val * math.exp(z * sd_ln))
        # the points of the run read the line at different heights (the neighbouring
        # terms and the sensor filter bend the curve inside the 0.15 slope tolerance): the
        # interval also spans every point's own reading, so a reading biased by that
        # bending is not given an interval that excludes the truth (measured on the MEMS
        # presets: N -1.3..-1.6 % with 0 % coverage of the EDF-only interval)
        own = np.exp(ld - slope * lt - lnc)
        flags = ()
        if own.min() < math.exp(-z * sd_ln) or own.max() > math.exp(z * sd_ln):
            flags = ("read_spread",)
            ci = (min(ci[0], val * float(own.min())), max(ci[1], val * float(own.max())))
        dens = per = None
        if name == "N":
            dens, per = conv.n_extras(amp * conv.f, rate_hz)
        terms[name] = NoiseTerm(value=val, unit=_REPORT[conv.kind][name], ci=ci, method="slope",
                                tau_range_s=(float(taus[a]), float(taus[b - 1])),
                                sd=val * sd_ln, density=dens, per_sample_std=per, flags=flags,
                                reason=("interval spans the readings of every point of the "
                                        "run, which differ by more than the EDF interval"
                                        if flags else ""))
    # B from the flat run
    a, b = _longest_run(np.abs(s) <= 0.1)
    kB = conv.value("B", 1.0)
    if b - a >= 1:
        i = a + int(np.argmin(dev[a:b]))
        flags = ()
        rng_s = (float(taus[a]), float(taus[b - 1]))
    else:
        i = int(np.argmin(dev))
        flags = ("B_bound",)
        rng_s = (float(taus.min()), float(taus.max()))
    # IEEE 952 flat region: remove the white and random-walk lines read on their runs
    sub = 0.0
    if math.isfinite(coeffs[1]):
        sub += coeffs[1] / taus[i]
    if math.isfinite(coeffs[3]):
        sub += coeffs[3] * taus[i]
    frac = math.sqrt(max(1.0 - sub / dev[i] ** 2, 0.0)) if not flags else 1.0
    val = kB * dev[i] * frac * conv.f / BI_FACTOR
    ci = (kB * lo_ci[i] * frac * conv.f / BI_FACTOR, kB * hi_ci[i] * frac * conv.f / BI_FACTOR)
    coeffs[2] = float((dev[i] * frac) ** 2)
    terms["B"] = NoiseTerm(value=val, unit=_REPORT[conv.kind]["B"], ci=ci, method="slope",
                           tau_range_s=rng_s, flags=flags,
                           sd=val / math.sqrt(2 * edf[i]))
    rng_all = (float(taus.min()), float(taus.max()))
    return NoiseTerms(**terms, kind=conv.kind, unit=conv.unit, method="slope",
                      coefficients=tuple(coeffs), tau_range_s=rng_all,
                      rate_hz=float(rate_hz), confidence=conf, statistic=result.statistic,
                      g_local=conv.g)


