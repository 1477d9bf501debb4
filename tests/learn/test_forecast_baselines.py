"""Tests of the forecast baselines (spec 004 §4; acceptance A12)."""

from __future__ import annotations

import numpy as np
import pytest

from inertialab.errors import InputError
from inertialab.learn.forecast_baselines import (
    BASELINES,
    ARIMAByAIC,
    ARLeastSquares,
    ExpSaturation,
    KernelNAR,
    Persistence,
    PolyTrend,
    WindowMean,
    make_baseline,
)
from inertialab.learn.order_cv import NadarayaWatson
from inertialab.sim.drift import benchmark_process, simulate_storage_batch


def test_a12_ar_ls_equals_statsmodels_autoreg():
    from statsmodels.tsa.ar_model import AutoReg

    y = benchmark_process("AR2", 150, 3)
    for p in (1, 2, 4):
        ours = ARLeastSquares(order=p).fit(y)
        ref = AutoReg(y, lags=p, trend="c").fit()
        # both are the same least-squares problem: agreement to 1e-8 (A12)
        np.testing.assert_allclose(ours.coef_, ref.params, atol=1e-8, rtol=1e-8)
        np.testing.assert_allclose(ours.forecast(5).values, ref.forecast(5), atol=1e-8)


def test_a12_exponential_fit_recovers_tau_on_nav_aging():
    # A12: the nav aging component b0 + A (1 - e^(-t/tau)) alone (noise-free), units with
    # |A| >= 15 ug: tau within 20 %.
    b = simulate_storage_batch(20, 100, "nav", rng=np.random.SeedSequence(0))
    t = np.arange(80)
    checked = 0
    for p in b.params:
        if abs(p["a_ug"]) < 15:
            continue
        y = p["b0_ug"] + p["a_ug"] * (1 - np.exp(-t / p["tau_d"]))
        m = ExpSaturation().fit(y)
        assert m.tau_ == pytest.approx(p["tau_d"], rel=0.2)
        checked += 1
    assert checked >= 10


def test_ar_aic_order_matches_statsmodels():
    # same criterion on the same common sample (hold back H = 6): same order as
    # statsmodels' ar_select_order (its AIC differs from ours by a constant only)
    from statsmodels.tsa.ar_model import ar_select_order

    for s in range(5):
        y = benchmark_process("AR2", 200, s)
        ref = ar_select_order(y, maxlag=6, ic="aic", trend="c").ar_lags
        assert ARLeastSquares(order="aic").fit(y).order_ == max(ref)


def test_ar_skips_samples_touching_gaps():
    y = benchmark_process("AR2", 200, 2)
    full = ARLeastSquares(order=2).fit(y)
    y2 = y.copy()
    y2[100] = np.nan
    gap = ARLeastSquares(order=2).fit(y2)
    # independent: the same regression with rows 100, 101, 102 removed
    t = np.array([i for i in range(2, 200) if i not in (100, 101, 102)])
    X = np.column_stack([np.ones(t.size), y[t - 1], y[t - 2]])
    coef = np.linalg.lstsq(X, y[t], rcond=None)[0]
    np.testing.assert_allclose(gap.coef_, coef, rtol=1e-10)
    assert not np.allclose(gap.coef_, full.coef_)


def test_persistence_and_window_mean():
    y = np.array([1.0, 2, 3, np.nan, 5, 6, 7, 8, 9])
    np.testing.assert_array_equal(Persistence().fit(y).forecast(3).values, 9.0)
    # last 7 days: 3, nan, 5, 6, 7, 8, 9 -> mean of the six present
    assert WindowMean().fit(y).forecast(2).values[0] == pytest.approx(38 / 6)


def test_poly_trend_extrapolates_exact_quadratic():
    t = np.arange(60.0)
    y = 1.0 + 0.02 * t - 3e-4 * t ** 2
    m = PolyTrend().fit(y)
    k = np.arange(60, 70)
    np.testing.assert_allclose(m.forecast(10).values, 1.0 + 0.02 * k - 3e-4 * k ** 2, atol=1e-9)
    assert m.degree_ in (2, 3)


def test_exp_ar1_adds_decaying_residual():
    t = np.arange(80.0)
    rng = np.random.default_rng(0)
    r = np.zeros(80)
    for i in range(1, 80):
        r[i] = 0.8 * r[i - 1] + rng.normal(0, 0.5)
    y = 10 + 5 * (1 - np.exp(-t / 12)) + r
    m = ExpSaturation(ar1=True).fit(y)
    plain = ExpSaturation().fit(y)
    f = m.forecast(20).values - plain.forecast(20).values
    # the AR(1) part decays geometrically by phi each step
    np.testing.assert_allclose(f[1:] / f[:-1], m.phi_, rtol=1e-9)
    assert 0.5 < m.phi_ < 0.95


def test_kernel_nar_first_step_is_nadaraya_watson():
    y = benchmark_process("S1", 100, 4)
    m = KernelNAR().fit(y)
    p = m.order_
    z = (y - y.mean()) / y.std(ddof=1)
    t = np.arange(p, 100)
    X = np.column_stack([z[t - k] for k in range(1, p + 1)])
    h = 0.5 * (100 - 6) ** (-1 / (p + 4))
    ref = NadarayaWatson(bandwidth=h).fit(X, z[t]).predict(z[::-1][:p][None, :])[0]
    assert m.forecast(3).values[0] == pytest.approx(ref * y.std(ddof=1) + y.mean(), rel=1e-12)


@pytest.mark.slow
def test_arima_matches_ar_on_ar1_series():
    # A pure AR(1) with mean 5: the AIC-best ARIMA's one-step forecast agrees with the
    # AR(1) least-squares forecast within 0.1 innovation SD (both estimate the same model).
    rng = np.random.default_rng(0)
    x = np.zeros(300)
    for t in range(1, 300):
        x[t] = 0.7 * x[t - 1] + rng.normal()
    y = 5 + x
    m = ARIMAByAIC(p_max=1, q_max=0, d_values=(0,)).fit(y)  # small grid: ARIMA fits are slow
    ar = ARLeastSquares(order=1).fit(y)
    f = m.forecast(5)
    assert abs(f.values[0] - ar.forecast(1).values[0]) < 0.1
    assert np.all(f.lo95 < f.values) and np.all(f.values < f.hi95)


def test_registry_and_errors():
    y = benchmark_process("S1", 80, 0)
    for name in BASELINES:
        if name == "arima":
            continue
        f = make_baseline(name).fit(y).forecast(4)
        assert f.values.shape == (4,) and np.all(np.isfinite(f.values))
    with pytest.raises(InputError):
        make_baseline("oracle")
    with pytest.raises(RuntimeError):
        Persistence().forecast(2)
    with pytest.raises(InputError):
        Persistence().fit(y).forecast(0)
    y2 = y.copy()
    y2[-1] = np.nan
    with pytest.raises(InputError):
        Persistence().fit(y2)
