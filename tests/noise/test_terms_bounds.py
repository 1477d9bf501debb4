"""Bounds within physics (noise.terms._bounds): on short simulated records where B is
not resolved, every B bound is at most 1.05 min(ADEV)/0.664 of its curve (the analytic
reading of a flicker floor) and, under the literal rule, every B estimate too; a
significant estimate above that reading is held to it under the literal rule (flag,
reason with the model's own estimate) and kept under the default one; a bound's JSON
value is the bound, and a term whose lower limit is below 1e-3 of its value is a
bound."""

import math
from dataclasses import replace

import numpy as np
import pytest
from scipy import stats

from inertialab.errors import InputError
from inertialab.noise.statistics.allan import oadev
from inertialab.noise.terms._bounds import HELD, _unresolved, b_ceiling
from inertialab.noise.terms.base import NoiseTerm
from inertialab.noise.terms.fit import fit_noise_terms, held_to_curve
from inertialab.noise.terms.pooled import widen_term
from inertialab.sensors.gyro import simulate_gyro_noise

BI = math.sqrt(2 * math.log(2) / math.pi)


@pytest.mark.parametrize("method", ["wls", "gmwm"])
@pytest.mark.parametrize("seed", [0, 1, 2])
def test_every_b_within_the_curve(method, seed):
    # 3 min at 100 Hz of white noise plus a slow random walk: B is not resolved
    rng = np.random.default_rng(seed)
    n = 18_000
    y = 0.05 * rng.standard_normal(n) + np.cumsum(2e-4 * rng.standard_normal(n))
    r = oadev(y, rate_hz=100.0, taus="octave")
    t = fit_noise_terms(r, unit="dps", method=method, n_boot=20)
    b = t.B.upper_bound if "upper_bound" in t.B.flags else t.B.value
    cap = 1.05 * np.min(r.dev[r.dev > 0]) / BI * 3600.0  # deg/s -> deg/h
    if "above_curve_minimum" not in t.B.flags:
        assert b <= cap * (1 + 1e-9)
    # every B at most the curve's least simultaneous 95 % upper limit (scipy's chi2)
    ok = r.dev > 0
    k = int(ok.sum())
    hi = r.dev[ok] * np.sqrt(r.edf[ok] / stats.chi2.ppf(0.05 / k, r.edf[ok]))
    assert b <= 1.05 * np.nanmin(hi) / BI * 3600.0 * (1 + 1e-9)
    assert b_ceiling(r, 3600.0, upper=True) == pytest.approx(1.05 * np.nanmin(hi) / BI
                                                             * 3600.0, rel=1e-9)
    d = t.to_dict()["B"]
    if "upper_bound" in t.B.flags:
        assert d["bound"] == "upper" and d["value"] == pytest.approx(t.B.upper_bound)
    assert b_ceiling(r, 3600.0) == pytest.approx(cap, rel=1e-12)
    # the literal rule: every B, estimate or bound, within the reading
    lit = fit_noise_terms(r, unit="dps", method=method, n_boot=20, b_rule="literal")
    assert lit.to_dict()["B"]["value"] <= cap * (1 + 1e-12)
    assert lit.B.value <= cap * (1 + 1e-12)


def _allan_bi(n, seed):
    """The simulated allan-bi gyro (white rate + band-limited flicker B = 0.1 deg/h), n
    samples at 10 Hz, and its octave OADEV; its curve's minimum falls below 0.664 B."""
    y = simulate_gyro_noise(n, 10.0, "allan-bi", np.random.default_rng(seed))
    return oadev(y, rate_hz=10.0, taus="octave")


def test_literal_rule_holds_a_significant_estimate_to_the_reading():
    r = _allan_bi(60_000, 0)
    own = fit_noise_terms(r, unit="dph", n_boot=50)  # the default rule keeps the estimate
    held = fit_noise_terms(r, unit="dph", n_boot=50, b_rule="literal")
    cap = 1.05 * np.min(r.dev[r.dev > 0]) / BI  # deg/h
    assert own.B.significant and own.B.value > cap and HELD not in own.B.flags
    b = held.B
    assert b.significant and HELD in b.flags and "upper_bound" not in b.flags
    assert b.value == pytest.approx(cap, rel=1e-12) and b.ci[1] == pytest.approx(cap, rel=1e-12)
    # the interval's lower end is the model's (below the reading here)
    assert b.ci[0] == pytest.approx(own.B.ci[0], rel=1e-12) and b.ci[0] < cap
    # the reason gives the model's own estimate and interval (the default rule did not
    # move it: it lies within the curve's simultaneous upper limits)
    assert "held to" not in own.B.reason
    lo, hi = own.B.ci
    assert f"model's own estimate {own.B.value:.4g} [{lo:.4g}, {hi:.4g}] deg/h" in b.reason
    d = held.to_dict()["B"]
    assert d["value"] == pytest.approx(cap, rel=1e-12) and "bound" not in d
    assert HELD in d["flags"]
    # only B is held: the model and every other term are the fit's
    assert held.coefficients == own.coefficients
    assert all(repr(getattr(held, k)) == repr(getattr(own, k)) for k in "QNKR")  # NaN-safe


def test_held_interval_from_the_reading_when_the_model_lies_above_it():
    # the model's whole interval lies above the reading: the interval's lower end is the
    # minimum point's own lower limit / 0.664
    r = _allan_bi(60_000, 3)
    own = fit_noise_terms(r, unit="dph", n_boot=50)
    b = fit_noise_terms(r, unit="dph", n_boot=50, b_rule="literal").B
    d = np.where(r.dev > 0, r.dev, np.inf)
    i = int(np.argmin(d))
    cap = 1.05 * d[i] / BI
    assert own.B.ci[0] > cap and HELD in b.flags
    assert b.ci == pytest.approx((r.ci_low[i] / BI, cap), rel=1e-12)


def test_a_held_estimate_widened_elsewhere_is_clipped_again():
    r = _allan_bi(60_000, 3)
    t = fit_noise_terms(r, unit="dph", n_boot=50, b_rule="literal")
    wide = replace(t, B=widen_term(t.B, 0.2))
    assert wide.B.ci[1] > t.B.value
    again = held_to_curve(wide, r)
    assert again.B.value == t.B.value and again.B.ci[1] == pytest.approx(t.B.value)
    # a bound widened above the reading is that reading as a bound
    cap = 1.05 * np.min(r.dev[r.dev > 0]) / BI
    bound = replace(t.B, flags=("upper_bound",), upper_bound=3 * cap, ci=(0.0, 3 * cap))
    b = held_to_curve(replace(t, B=bound), r).B
    assert b.upper_bound == pytest.approx(cap) and b.to_dict()["bound"] == "upper"


def test_unknown_b_rule_is_refused():
    r = _allan_bi(6_000, 0)
    with pytest.raises(InputError, match="b_rule"):
        fit_noise_terms(r, unit="dph", n_boot=0, b_rule="loose")


def test_lower_limit_below_a_thousandth_makes_a_bound():
    t = NoiseTerm(value=239.0, unit="deg/h/sqrt(h)", ci=(1e-7, 545.0), method="gmwm",
                  tau_range_s=(1.0, 100.0))
    b = _unresolved(t)
    assert "upper_bound" in b.flags and b.upper_bound == 545.0
    d = b.to_dict()
    assert d["value"] == 545.0 and d["bound"] == "upper" and d["estimate"] == 239.0
    kept = NoiseTerm(value=239.0, unit="x", ci=(1.0, 545.0), method="wls",
                     tau_range_s=(1.0, 100.0))
    assert _unresolved(kept) is kept


def test_an_estimate_at_zero_below_its_interval_is_a_bound():
    # GMWM's B on 10 min of white accelerometer noise read "0 [3.861e-11, 244.6]": a
    # value outside its own interval, nothing resolved beyond <= 244.6
    t = NoiseTerm(value=0.0, unit="ug", ci=(3.861e-11, 244.6), method="gmwm",
                  tau_range_s=(1.0, 100.0))
    b = _unresolved(t)
    assert "upper_bound" in b.flags and b.upper_bound == 244.6 and b.ci == (0.0, 244.6)
    assert b.to_dict()["value"] == 244.6 and "estimated at 0" in b.reason
    absent = NoiseTerm(value=0.0, unit="ug", ci=(0.0, 0.0), method="gmwm",
                       tau_range_s=(1.0, 100.0), flags=("absent",))
    assert _unresolved(absent) is absent  # no interval above 0: the absent-B rule's case
