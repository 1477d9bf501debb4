"""Tests of kernel-CV order selection and Nadaraya-Watson (spec 004 §3.1, A1, A11)."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from inertialab.errors import DataQualityWarning, InputError
from inertialab.learn.order_cv import NadarayaWatson, lag_targets, select_order_cv
from inertialab.sim.drift import benchmark_process


@pytest.mark.parametrize(("name", "true_p", "need"), [("S1", 2, 85), ("S2", 3, 70)])
def test_a1_order_recovered_on_benchmarks(name, true_p, need):
    # A1: n = 100, H = 6, c = 0.5, seeds 0..99: p-hat = 2 in >= 85 % (S1), = 3 in >= 70 % (S2).
    # (measured: 96 and 76, as the spec's review re-run)
    hits = sum(select_order_cv(benchmark_process(name, 100, s)).order == true_p
               for s in range(100))
    assert hits >= need


def _loo_brute(y, H, p, h):
    """Independent leave-one-out NW CV score with explicit loops (no shift trick)."""
    z = (y - y.mean()) / y.std(ddof=1)
    T = range(H, y.size)
    tot = 0.0
    for t in T:
        num = den = 0.0
        for s in T:
            if s == t:
                continue
            d2 = sum((z[t - k] - z[s - k]) ** 2 for k in range(1, p + 1))
            w = np.exp(-d2 / (2 * h * h))
            num += w * z[s]
            den += w
        tot += (z[t] - num / den) ** 2
    return tot / len(T)


def test_scores_match_brute_force():
    y = benchmark_process("S2", 70, 4)
    res = select_order_cv(y, H=3, c=0.8)
    assert res.H == 3 and res.m == 67
    for p in (1, 2, 3):
        h = 0.8 * res.m ** (-1 / (p + 4))
        assert res.bandwidths[p - 1] == pytest.approx(h, rel=1e-15)
        # same sums in another order: rounding only
        assert res.scores[p - 1] == pytest.approx(_loo_brute(y, 3, p, h), rel=1e-9)


def test_bandwidth_cv_never_worse_than_rule():
    y = benchmark_process("S1", 100, 7)
    rule = select_order_cv(y)
    cv = select_order_cv(y, bandwidth="cv")
    # c = 0.5 is in the grid, so each CV(p) can only go down
    assert np.all(np.asarray(cv.scores) <= np.asarray(rule.scores) + 1e-15)
    assert set(cv.constants) <= {0.25, 0.35, 0.5, 0.7, 1.0, 1.4}


def test_h_reduced_with_warning_on_short_series():
    y = benchmark_process("S1", 40, 0)
    with pytest.warns(DataQualityWarning, match="H reduced from 6 to 3"):
        res = select_order_cv(y)
    assert res.H == 3 and res.m >= 30
    with pytest.raises(InputError):
        select_order_cv(y[:10])


def test_constant_series_warns():
    with pytest.warns(DataQualityWarning, match="constant"):
        res = select_order_cv(np.full(100, 3.0))
    assert res.order == 1


def test_a11_gaps_masking():
    # A11: 10 % of interior days removed; the order changes in <= 25 % of seeds and no
    # CV target or lag touches a removed day.
    changed = 0
    for s in range(100):
        y = benchmark_process("S1", 100, s)
        p0 = select_order_cv(y).order
        drop = np.random.default_rng(1000 + s).choice(np.arange(1, 99), 10, replace=False)
        y2 = y.copy()
        y2[drop] = np.nan
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", DataQualityWarning)  # H shrinks with gaps
            res = select_order_cv(y2)
        t = np.asarray(res.targets)
        for k in range(res.H + 1):
            assert np.all(np.isfinite(y2[t - k]))
        changed += res.order != p0
    assert changed <= 25


def test_usable_mask_excludes_imputed_days():
    usable = np.ones(100, bool)
    usable[50] = False  # e.g. an interpolated day
    t = lag_targets(usable, 2)
    assert not np.any((t >= 50) & (t <= 52))
    assert 49 in t and 53 in t


def test_ties_go_to_smaller_order():
    # a series whose lags beyond 1 carry the same information: an exact period-2 cycle;
    # with lag 1 the next value is known, so CV(1) = CV(2) = ... up to rounding.
    y = np.tile([1.0, -1.0], 50)
    res = select_order_cv(y, H=3)
    assert res.order == 1


def test_nadaraya_watson_limits():
    rng = np.random.default_rng(0)
    X = rng.normal(size=(30, 2))
    y = rng.normal(size=30)
    # very wide kernel -> the sample mean; very narrow -> the nearest sample's target
    wide = NadarayaWatson(bandwidth=1e6).fit(X, y).predict(X[:5] + 0.01)
    np.testing.assert_allclose(wide, y.mean(), rtol=1e-9)
    narrow = NadarayaWatson(bandwidth=1e-4).fit(X, y).predict(X[:5] + 1e-6)
    np.testing.assert_allclose(narrow, y[:5], rtol=1e-9)
    with pytest.raises(RuntimeError):
        NadarayaWatson().predict(X)
