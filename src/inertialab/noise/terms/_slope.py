"""Automated IEEE 952 slope reading of the noise terms (spec 001 §3.4 item 1).

Local slopes over three consecutive taus, the longest run within 0.15 of each target
slope (>= 3 points), an EDF-weighted fixed-slope line through it. B is read on the
longest run with ``|slope| <= 0.1`` at its minimum, IEEE 952's flat region, with the
N and K lines read on their own runs subtracted there (``sigma_B^2 = sigma^2 - N^2/tau -
K^2 tau/3``); without a flat run the minimum gives an upper bound (flag
``B_bound``). Missing runs give NaN with flag ``not_observable``. Intervals: chi-square
on the points' EDF, widened to span the reading of every point of the run where those
differ by more (flag ``read_spread``: the curve bends inside the slope tolerance, and the
line's height depends on where it is read), and to span the percentiles of the reading
over curves resampled around the observed one (flag ``boot_spread``: which points form
the run, and which is the flat minimum, move with the noise; a point's chi-square
interval does not carry that). Measured on the MEMS presets before the resampling: B
and K covered 1-62 % and 2-16 % (docs/noise-terms.md §8).
"""

from __future__ import annotations

import math

import numpy as np
from scipy.special import ndtri

from inertialab.noise.terms.base import (
    _NAMES,
    _REPORT,
    BI_FACTOR,
    NoiseTerm,
    NoiseTerms,
    local_slopes,
    span_intervals,
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


#: local slope -> the term whose noise type sets the octave correlation of the bootstrap
#: (Q N B K R, as :data:`inertialab.noise.terms.base._TERM_ALPHA`)
_SLOPE_EDGES = (-0.75, -0.25, 0.25, 0.75)
#: bootstrap replicates of the reading (each re-reads a resampled curve)
N_BOOT_SLOPE = 200


#: target log-log slope and gain (sigma = gain x amplitude x tau^slope) of each line read
_TARGETS = {"Q": (-1.0, math.sqrt(3)), "N": (-0.5, 1.0), "K": (0.5, 1 / math.sqrt(3)),
            "R": (1.0, 1 / math.sqrt(2))}


def _read(taus, dev, edf):
    """The IEEE 952 reading of one curve: ``{name: (amp, sd_ln, run, own)}`` for Q N K R
    (``amp`` in the data unit; ``run`` the slice read; ``own`` every point's reading over
    ``amp``; None where no run of 3 points), the coefficients, and ``(i, frac, flags,
    range)`` of B (module docstring)."""
    s = local_slopes(taus, dev)
    out, coeffs = {}, [float("nan")] * 5
    for name, (slope, gain) in _TARGETS.items():
        a, b = _longest_run(np.abs(s - slope) <= 0.15)
        if b - a < 3:
            out[name] = None
            continue
        lt, ld, w = np.log(taus[a:b]), np.log(dev[a:b]), edf[a:b]
        lnc = float(np.sum(w * (ld - slope * lt)) / np.sum(w))
        sd_ln = math.sqrt(1.0 / np.sum(2.0 * w))
        coeffs[_NAMES.index(name)] = math.exp(2.0 * lnc)  # sigma = C tau^slope -> c = C^2
        out[name] = (math.exp(lnc) / gain, sd_ln, (a, b), np.exp(ld - slope * lt - lnc))
    a, b = _longest_run(np.abs(s) <= 0.1)
    if b - a >= 1:
        i, flags, rng_s = a + int(np.argmin(dev[a:b])), (), (float(taus[a]), float(taus[b - 1]))
    else:
        i, flags, rng_s = int(np.argmin(dev)), ("B_bound",), (float(taus.min()),
                                                               float(taus.max()))
    # IEEE 952 flat region: remove the white and random-walk lines read on their runs
    sub = 0.0
    if math.isfinite(coeffs[1]):
        sub += coeffs[1] / taus[i]
    if math.isfinite(coeffs[3]):
        sub += coeffs[3] * taus[i]
    frac = math.sqrt(max(1.0 - sub / dev[i] ** 2, 0.0)) if not flags else 1.0
    coeffs[2] = float((dev[i] * frac) ** 2)
    return out, coeffs, (i, frac, flags, rng_s)


def _boot_readings(taus, dev, edf, m, conf, n_boot, seed):
    """Percentiles of the reading over curves resampled around the observed one
    (``dev^2 chi2(edf)/edf`` with the octave correlation of the noise type the local
    slope shows, as the least-squares bootstrap): ``{name: (lo, hi)}`` of the amplitude
    (data unit; B: ``dev frac``), NaN where fewer than half the replicates read it."""
    from inertialab.noise.terms.least_squares import _draw_avar

    dom = np.searchsorted(_SLOPE_EDGES, local_slopes(taus, dev))
    draws = np.sqrt(_draw_avar(dev**2, edf, dom, m, n_boot, np.random.default_rng(seed)))
    reads = {k: [] for k in ("Q", "N", "B", "K", "R")}
    for d in draws:
        out, _, (i, frac, _, _) = _read(taus, d, edf)
        for name, r in out.items():
            if r is not None:
                reads[name].append(r[0])
        reads["B"].append(d[i] * frac)
    q = (0.5 * (1 - conf), 0.5 * (1 + conf))
    return {k: (tuple(float(x) for x in np.quantile(v, q)) if len(v) >= n_boot // 2
                else (float("nan"), float("nan"))) for k, v in reads.items()}


def _span_boot(ci, boot, scale):
    """``ci`` widened to the bootstrap interval ``boot`` (amplitude, times ``scale``) and
    whether it widened."""
    new = span_intervals(ci, (boot[0] * scale, boot[1] * scale))
    return new, new != tuple(ci)


def fit_slope(result, sel, conv, rate_hz, n_boot: int = N_BOOT_SLOPE, seed: int = 0):
    """Automated IEEE 952 slope reading (see module docstring)."""
    taus = np.asarray(result.taus_s, float)[sel]
    dev = np.asarray(result.dev, float)[sel]
    edf = np.asarray(result.edf, float)[sel]
    edf = np.where(np.isfinite(edf) & (edf > 0), edf, 1.0)
    lo_ci = np.asarray(result.ci_low, float)[sel]
    hi_ci = np.asarray(result.ci_high, float)[sel]
    conf = float(result.confidence)
    z = float(ndtri(0.5 * (1 + conf)))  # (norm.ppf; scipy.stats costs 0.5 s to import)
    out, coeffs, (i, frac, bflags, rng_s) = _read(taus, dev, edf)
    boot = (_boot_readings(taus, dev, edf, np.asarray(result.m, float)[sel], conf, n_boot, seed)
            if n_boot > 0 else {})
    terms = {}
    for name in _TARGETS:
        if out[name] is None:
            terms[name] = NoiseTerm(value=float("nan"), unit=_REPORT[conv.kind][name],
                                    ci=(float("nan"), float("nan")), method="slope",
                                    tau_range_s=(float("nan"), float("nan")),
                                    flags=("not_observable",))
            continue
        amp, sd_ln, (a, b), own = out[name]
        k = conv.value(name, 1.0)
        val = k * amp * conv.f
        ci = (val * math.exp(-z * sd_ln), val * math.exp(z * sd_ln))
        # the points of the run read the line at different heights (the neighbouring
        # terms and the sensor filter bend the curve inside the 0.15 slope tolerance): the
        # interval also spans every point's own reading, so a reading biased by that
        # bending is not given an interval that excludes the truth (measured on the MEMS
        # presets: N -1.3..-1.6 % with 0 % coverage of the EDF-only interval)
        flags = ()
        if own.min() < math.exp(-z * sd_ln) or own.max() > math.exp(z * sd_ln):
            flags = ("read_spread",)
            ci = (min(ci[0], val * float(own.min())), max(ci[1], val * float(own.max())))
        ci, widened = _span_boot(ci, boot.get(name, (float("nan"),) * 2), k * conv.f)
        flags += ("boot_spread",) if widened else ()
        dens = per = None
        if name == "N":
            dens, per = conv.n_extras(amp * conv.f, rate_hz)
        terms[name] = NoiseTerm(value=val, unit=_REPORT[conv.kind][name], ci=ci, method="slope",
                                tau_range_s=(float(taus[a]), float(taus[b - 1])),
                                sd=val * sd_ln, density=dens, per_sample_std=per, flags=flags,
                                reason=_reason(flags))
    kB = conv.value("B", 1.0)
    val = kB * dev[i] * frac * conv.f / BI_FACTOR
    ci = (kB * lo_ci[i] * frac * conv.f / BI_FACTOR, kB * hi_ci[i] * frac * conv.f / BI_FACTOR)
    ci, widened = _span_boot(ci, boot.get("B", (float("nan"),) * 2), kB * conv.f / BI_FACTOR)
    flags = bflags + (("boot_spread",) if widened else ())
    terms["B"] = NoiseTerm(value=val, unit=_REPORT[conv.kind]["B"], ci=ci, method="slope",
                           tau_range_s=rng_s, flags=flags, reason=_reason(flags),
                           sd=val / math.sqrt(2 * edf[i]))
    rng_all = (float(taus.min()), float(taus.max()))
    return NoiseTerms(**terms, kind=conv.kind, unit=conv.unit, method="slope",
                      coefficients=tuple(float(c) for c in coeffs), tau_range_s=rng_all,
                      rate_hz=float(rate_hz), confidence=conf, statistic=result.statistic,
                      g_local=conv.g)


def _reason(flags) -> str:
    why = []
    if "read_spread" in flags:
        why.append("interval spans the readings of every point of the run, which differ by "
                   "more than the EDF interval")
    if "boot_spread" in flags:
        why.append("interval spans the readings of curves resampled around this one (the "
                   "run and the flat point move with the noise)")
    return "; ".join(why)
