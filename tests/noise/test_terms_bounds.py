"""Bounds within physics (noise.terms._bounds): on short simulated records where B is
not resolved, every B (estimate or bound) is at most 1.05 min(ADEV)/0.664 of its curve
(the analytic reading of a flicker floor), a bound's JSON value is the bound, and a term
whose lower limit is below 1e-3 of its value is a bound."""

import math

import numpy as np
import pytest
from scipy import stats

from inertialab.noise.statistics.allan import oadev
from inertialab.noise.terms._bounds import _unresolved, b_ceiling
from inertialab.noise.terms.base import NoiseTerm
from inertialab.noise.terms.fit import fit_noise_terms

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
