"""An honest record-length plan (``allan --imu --plan``): a length for K on every axis,
with its 95 % interval from the fitted parameters' uncertainty.

:func:`inertialab.workflows.imu_drift.axis_plan` gives the length at which K (and B) is
read within +-20 % at 95 % under the fitted model, and nothing where the model holds no
K. Here, per axis:

* **K a bound** (not significant, or held at zero): the length at which a K *at its
  bound* would be resolved within +-20 % (``k_at_bound: true``). It is the shortest
  record that could show such a K; a smaller K needs longer, so the interval's upper
  end is open (None);
* **the interval** ``needed_h_95``: the plan recomputed with K at the ends of its
  interval (the shortest length with K at its upper limit, the longest with K at its
  lower limit: a smaller random walk needs a longer record), the other terms at their
  values. K's interval dominates the spread (the halves of one ADIS16405 log gave
  single lengths of 3.8-128 h).
"""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np

__all__ = ["axis_plan_with_interval", "report_factor"]


def report_factor(terms, name: str) -> float:
    """Report unit of a term per its native unit (data unit based) for a fit."""
    return terms.report_factor(name)


def _with_k(axis, k_report: float, tau0: float):
    """The axis with its terms' K set to ``k_report`` (the K report unit): the five-term
    coefficient ``c_1 = K^2 / 3``, and for a GMWM fit its random-walk process."""
    terms = axis.terms
    c = list(terms.coefficients)
    c[3] = (k_report / report_factor(terms, "K")) ** 2 / 3.0
    gm = terms.gmwm
    if gm and gm.get("processes"):
        procs = [d for d in gm["processes"] if d["process"] != "RW"]
        procs.append({"process": "RW", "params": {"gamma2": 3.0 * c[3] * tau0}})
        gm = {**gm, "processes": procs}
    return replace(axis, terms=replace(terms, coefficients=tuple(c), gmwm=gm))


def _needed(axis, rate_hz: float, n: int, k_report: float | None):
    from inertialab.workflows.imu_drift import axis_plan

    if k_report is None or not (math.isfinite(k_report) and k_report > 0):
        return None
    try:
        h = axis_plan(_with_k(axis, k_report, 1.0 / rate_hz), rate_hz, n).get("needed_h")
    except (ValueError, ArithmeticError, np.linalg.LinAlgError):
        return None
    return float(h) if h is not None and math.isfinite(h) else None


def axis_plan_with_interval(axis, rate_hz: float, n_samples: int) -> dict:
    """:func:`inertialab.workflows.imu_drift.axis_plan` of the axis, with a K length on
    every axis that has a K value or bound, and ``needed_h_95`` (module text)."""
    from inertialab.workflows.imu_drift import axis_plan

    out = axis_plan(axis, rate_hz, n_samples)
    k = axis.terms.K
    bound = bool({"upper_bound", "not_observable"} & set(k.flags))
    lo, hi = (float(v) for v in k.ci)
    if bound or out.get("needed_h") is None:
        ub = k.upper_bound if math.isfinite(k.upper_bound) else hi
        h = _needed(axis, rate_hz, n_samples, ub)
        if h is None:
            return out
        out = {**out, "needed_h": h, "k_at_bound": True, "long_enough": False,
               "needed_h_95": [h, None],
               "reason": f"K is a bound here (<= {ub:.4g} {k.unit}): the length at which "
                         "a K at its bound would be read within +-20 %; a smaller K "
                         "needs longer"}
        return out
    short = _needed(axis, rate_hz, n_samples, hi)
    long_ = _needed(axis, rate_hz, n_samples, lo) if lo > 0 else None
    return {**out, "k_at_bound": False, "needed_h_95": [short, long_]}
