"""Bounds within physics for fitted noise terms, applied to every method's result.

* **B within the curve**: a flicker floor of bias instability ``B`` holds the Allan
  deviation at ``0.664 B`` where it is flat (IEEE 952 C.1: sqrt(2 ln2 / pi) B), and the
  other terms only add to it, so the textbook reading is ``B <= min(ADEV) / 0.664``
  (the minimum over the curve's points). Two rules (:data:`B_RULES`), chosen by the
  caller (:func:`inertialab.noise.terms.fit.fit_noise_terms` ``b_rule``):

  ``"literal"`` (the numbers a user copies into a filter: ``allan --imu``, one log or
  ``--pool``, its table, JSON and exports)
      Every B, estimate or bound, is at most :data:`B_SCATTER` x min(ADEV)/0.664 of the
      curve it was read from (1.05 for the scatter of the minimum; the minimum over the
      curve's points after what the fit took off, the spectral lines, and over the
      record's own curve, which bounds the noise at a tau the line removal left out). A
      bound above it is that reading as a bound; a significant estimate above it is held
      to the reading, and stays an estimate (IEEE 952's own reading of B from the flat
      bottom): value = the reading, interval clipped to it (its lower end the model's,
      or the curve minimum's own lower limit where the model's lies above the
      reading), flag :data:`HELD` and a reason giving the model's own estimate and its
      interval. :func:`held_to_curve` applies it to terms fitted elsewhere (the pooled
      terms, after their interval is widened by the between-log spread).
  ``"interval"`` (the default: spec 001's single-series fit, ``allan`` without
  ``--imu``, the vibration study)
      A bound is held as above. A significant estimate is held to the curve's minimum
      *with its interval*: 1.05 x the least simultaneous 95 % upper limit of the curve's
      points / 0.664 (each point's one-sided upper limit at 1 - 0.05/k over the k
      points, the EDF of the fitted model's noise type where the curve's own
      identification is weak: :func:`inertialab.noise.terms.fit.model_intervals`, the
      sampling law under the model the estimate states); above 1.05 x min(ADEV)/0.664
      it is flagged ``above_curve_minimum`` with both readings in its reason. Why the
      default keeps this: spec 001 §6.2 asks the single-series fit to recover the
      simulated ``allan-bi`` preset's B within 20 % on 18 of 20 seeds, and a
      band-limited flicker's curve falls below 0.664 B past its longest corner, the
      last points scattering at EDF ~2-6. On ``allan-bi`` (10 h, 10 Hz; Gauss–Markov
      corners to 3,000 s) the *true* curve's minimum over the octave taus is
      0.0755 deg/h x 0.664 at 13,107 s, 24.5 % below its B = 0.1 deg/h; over 20 seeds
      the reading 1.05 min(ADEV)/0.664 is within 20 % of the truth on 7 (median
      0.66x), the minimum lying at the last two taus (EDF 1.5-6) on 11 (``python -m
      benchmarks.edf_coverage --literal``). The literal rule would fail the spec there;
      a filter's user, who copies one number, is given the reading the curve supports.
* **A term whose lower limit is below** :data:`RESOLVED` **of its value is a bound**:
  ``239 [0, 545]`` says nothing beyond ``<= 545``; so is a term estimated at 0 whose
  interval reaches above it (``0 [4e-11, 245]``), and a B the fitted model leaves out
  (GMWM's ``absent``) is the bound 1.05 min(ADEV)/0.664 the curve gives, never a bare 0.

:func:`bounded_terms` returns the terms with these rules applied, the reasons in each
changed term's ``reason``.
"""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np

#: sqrt(2 ln 2 / pi): the flat Allan deviation of a flicker floor B is this times B
BI = math.sqrt(2.0 * math.log(2.0) / math.pi)
#: B may exceed min(ADEV)/0.664 by the scatter of the curve's minimum
B_SCATTER = 1.05
#: family confidence of the curve's upper limits a significant B is held to (one-sided,
#: over all the curve's points at once: Bonferroni)
SIMULTANEOUS = 0.95
#: a lower limit below this fraction of the value leaves the term unresolved
RESOLVED = 1e-3
#: how a B is held to its curve (module text); the first is the default
B_RULES = ("interval", "literal")
#: the flag of a significant B held to the literal reading (``"literal"`` rule)
HELD = "held_to_curve_minimum"

__all__ = ["B_RULES", "B_SCATTER", "HELD", "RESOLVED", "SIMULTANEOUS", "b_ceiling",
           "bounded_terms", "curve_reading", "held_to_curve"]


def b_ceiling(result, factor: float, *, upper: bool = False) -> float:
    """``B_SCATTER * min(ADEV) / 0.664`` of the curve ``result`` (over every point with a
    positive deviation; ``upper``: over the points' simultaneous one-sided 95 % upper
    limits from the curve's EDF, :data:`SIMULTANEOUS`), in the B report unit
    (``factor``: report value per data-unit amplitude); NaN for an empty curve."""
    d = np.asarray(result.dev, dtype=float)
    ok = np.isfinite(d) & (d > 0)
    if not ok.any():
        return float("nan")
    if not upper:
        return B_SCATTER * float(d[ok].min()) / BI * factor
    from inertialab.noise.statistics.edf import chi2_interval

    e = np.asarray(result.edf, dtype=float)[ok]
    # two-sided 1 - 2(1 - SIMULTANEOUS)/k: one-sided upper tail (1 - SIMULTANEOUS)/k
    _, hi = chi2_interval(d[ok], e, 1.0 - 2.0 * (1.0 - SIMULTANEOUS) / int(ok.sum()))
    hi = hi[np.isfinite(hi)]
    return B_SCATTER * float(hi.min()) / BI * factor if hi.size else float("nan")


def curve_reading(curves, factor: float) -> tuple[float, float]:
    """``(ceiling, lower)`` of the literal rule over ``curves`` (deviation results, None
    skipped): ceiling ``B_SCATTER * min(ADEV) / 0.664`` over every point of every curve
    with a positive deviation, and the reading ``min(ADEV)/0.664``'s own lower limit
    (that point's ``ci_low``), both in the B report unit (``factor``: report value per
    data-unit amplitude); NaNs where no curve has a point."""
    best, low = math.inf, math.nan
    for r in curves:
        if r is None:
            continue
        d = np.asarray(r.dev, dtype=float)
        ok = np.isfinite(d) & (d > 0)
        if not ok.any():
            continue
        i = int(np.flatnonzero(ok)[np.argmin(d[ok])])
        if d[i] < best:
            best, low = float(d[i]), float(np.asarray(r.ci_low, dtype=float)[i])
    if not math.isfinite(best):
        return math.nan, math.nan
    return B_SCATTER * best / BI * factor, low / BI * factor


def _as_bound(term, upper: float, why: str):
    flags = tuple(f for f in term.flags if f != "upper_bound") + ("upper_bound",)
    reason = f"{term.reason}; {why}" if term.reason else why
    return replace(term, flags=flags, upper_bound=float(upper), ci=(0.0, float(upper)),
                   value=float(min(term.value, upper)) if math.isfinite(term.value)
                   else float(upper), reason=reason)


def _unresolved(term):
    """The term as a bound when its lower limit is below RESOLVED of its value."""
    if "not_observable" in term.flags or "upper_bound" in term.flags:
        return term
    lo, hi = term.ci
    v = term.value
    if not (math.isfinite(v) and math.isfinite(hi) and math.isfinite(lo) and hi > 0):
        return term
    if v <= 0:  # a fit at 0 whose interval still reaches hi: nothing beyond <= hi
        return _as_bound(term, hi, f"estimated at 0 with an interval up to {hi:.3g}: not "
                                   "resolved, an upper bound")
    if lo < RESOLVED * v:
        return _as_bound(term, hi, f"its lower limit {lo:.3g} is below {RESOLVED:g} of its "
                                   "value: not resolved, an upper bound")
    return term


def _absent_b(term, cap: float):
    """A B that the fitted model leaves out (GMWM's ``absent``: no flicker or
    Gauss–Markov process selected) as the bound the curve gives, ``cap``: the data do
    not exclude a flicker floor below the curve's minimum, so 0 is no estimate."""
    if "absent" not in term.flags or "upper_bound" in term.flags \
            or not math.isfinite(cap) or term.value > 0:
        return term
    return _as_bound(term, cap, f"the selected model has no bias-instability process; the "
                                f"curve bounds it at {B_SCATTER:g} x min(ADEV)/0.664 = "
                                f"{cap:.4g} {term.unit}")


def _b_within(term, cap: float, cap_upper: float):
    """B held to the curve: a bound to ``cap`` (min(ADEV)); a significant estimate to
    ``cap_upper`` (the least simultaneous 95 % upper limit: beyond it the estimate
    contradicts the curve), flagged when above ``cap``."""
    if not math.isfinite(cap) or "not_observable" in term.flags:
        return term
    why = (f"held to {B_SCATTER:g} x min(ADEV)/0.664 = {cap:.4g} {term.unit}, the most "
           "bias instability the curve allows")
    if "upper_bound" in term.flags:
        ub = term.upper_bound if math.isfinite(term.upper_bound) else term.ci[1]
        if not math.isfinite(ub) or ub > cap:
            return _as_bound(term, cap, why)
        return term
    if math.isfinite(cap_upper) and math.isfinite(term.value) and term.value > cap_upper:
        lo, _ = term.ci
        return replace(term, value=float(cap_upper), ci=(min(lo, cap_upper), cap_upper),
                       flags=(*term.flags, "above_curve_minimum"),
                       reason=(f"{term.reason}; " if term.reason else "")
                       + f"held to {B_SCATTER:g} x the curve's least simultaneous 95 % upper "
                         f"limit/0.664 = "
                         f"{cap_upper:.4g} {term.unit}; above {B_SCATTER:g} x "
                         f"min(ADEV)/0.664 = {cap:.4g}")
    if math.isfinite(term.value) and term.value > cap:
        return replace(term, flags=(*term.flags, "above_curve_minimum"),
                       reason=(f"{term.reason}; " if term.reason else "")
                       + f"above {B_SCATTER:g} x min(ADEV)/0.664 = {cap:.4g} {term.unit}, "
                         "within the curve's upper limits")
    return term


def _b_literal(term, cap: float, low: float):
    """B under the literal rule: a bound to ``cap``; a significant estimate above ``cap``
    held to it (value ``cap``, interval clipped, flag :data:`HELD`, its own estimate in
    the reason; ``low``: the reading's own lower limit, the interval's lower end where
    the model's lies above ``cap``); a held estimate's interval clipped to its value
    again (after the pooled widening)."""
    if not math.isfinite(cap) or "not_observable" in term.flags:
        return term
    if "upper_bound" in term.flags:
        return _b_within(term, cap, math.nan)
    v = term.value
    lo, hi = (float(c) for c in term.ci)
    if math.isfinite(v) and v > cap:
        low = low if math.isfinite(low) and low < cap else cap
        own = f"{v:.4g} [{lo:.4g}, {hi:.4g}]" if math.isfinite(lo) and math.isfinite(hi) \
            else f"{v:.4g}"
        why = (f"held to {B_SCATTER:g} x min(ADEV)/0.664 = {cap:.4g} {term.unit}, IEEE "
               f"952's reading of B from the curve's flat bottom (the most bias instability "
               f"the curve allows); the model's own estimate {own} {term.unit}")
        return replace(term, value=float(cap),
                       ci=(lo if math.isfinite(lo) and lo < cap else low, float(cap)),
                       flags=(*term.flags, HELD),
                       reason=f"{term.reason}; {why}" if term.reason else why)
    if HELD in term.flags and math.isfinite(hi) and hi > v:
        return replace(term, ci=(min(lo, v), float(v)))
    return term


def held_to_curve(terms, *curves):
    """``terms`` whose intervals were widened elsewhere (the pooled terms:
    :mod:`inertialab.workflows.imu_pool`) read again: a term whose lower limit fell below
    :data:`RESOLVED` of its value is an upper bound, and B is held to ``curves``, the
    curve(s) it was read from, under the literal rule (module text)."""
    new = {name: _unresolved(getattr(terms, name)) for name in ("N", "B", "K")}
    new["B"] = _b_literal(new["B"], *curve_reading(curves, terms.report_factor("B")))
    changed = {k: v for k, v in new.items() if v is not getattr(terms, k)}
    return replace(terms, **changed) if changed else terms


def bounded_terms(terms, result, conv, under_model, *, b_rule: str = "interval",
                  raw=None):
    """``terms`` (a :class:`~inertialab.noise.terms.base.NoiseTerms`) with the rules of
    the module text applied against the curve ``result`` they were read from; ``conv``
    the fit's unit converter; ``under_model`` the curve with its intervals under the
    fitted model (:func:`~inertialab.noise.terms.fit.model_intervals`, which the fit
    passes: this module does not import the fit); ``b_rule`` one of :data:`B_RULES`;
    ``raw``: the record's own curve where ``result`` is it less the spectral lines (the
    literal rule reads the minimum over both)."""
    if b_rule not in B_RULES:
        raise ValueError(f"b_rule must be one of {B_RULES}, got {b_rule!r}")
    new = {name: _unresolved(getattr(terms, name)) for name in ("Q", "N", "B", "K", "R")}
    f = conv.factor("B")
    new["B"] = _absent_b(new["B"], b_ceiling(result, f))
    if b_rule == "literal":
        new["B"] = _b_literal(new["B"], *curve_reading((result, raw), f))
    else:
        new["B"] = _b_within(new["B"], b_ceiling(result, f),
                             b_ceiling(under_model, f, upper=True))
    changed = {k: v for k, v in new.items() if v is not getattr(terms, k)}
    return replace(terms, **changed) if changed else terms
