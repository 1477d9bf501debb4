"""Tests of the NAR forecaster (spec 004 §3.7-3.10; acceptance A5, A6, A7, A9, A10)."""

from __future__ import annotations

import json
import warnings

import numpy as np
import pytest

from inertialab.errors import DataQualityWarning, InputError
from inertialab.learn.forecast_baselines import ARLeastSquares, Persistence
from inertialab.learn.mlp_lm import forward
from inertialab.learn.nar import AUTO_H_MAX, SPEC_H, NARForecaster, auto_lag_bound, whiteness
from inertialab.sim.drift import benchmark_process


@pytest.mark.parametrize("preset", ["paper", "strict"])
def test_a5_first_closed_loop_step_equals_open_loop(preset):
    y = benchmark_process("S1", 100, 3)
    m = NARForecaster(restarts=4, preset=preset, rng=1).fit(y)
    p = m.order_
    f = m.forecast(5, intervals=False).values
    lags = y[::-1][:p]  # y_T, y_{T-1}, ...
    # independent: normalise, evaluate each retained member's net, combine, de-normalise
    z = 2 * (lags - y.min()) / (y.max() - y.min()) - 1
    outs = [forward(m.members_[i].theta, z[None, :], 10)[0] for i in m.chosen_]
    one = np.median(outs) if preset == "strict" else outs[0]
    one = (one + 1) * (y.max() - y.min()) / 2 + y.min()
    assert abs(f[0] - one) < 1e-12
    assert abs(f[0] - m.one_step(lags[None, :])[0]) < 1e-12


def _a6(proc, seeds):
    r_nar, r_ar, r_p, o_nar, o_ar = [], [], [], [], []
    for s in seeds:
        y = benchmark_process(proc, 120, s)
        yi, yh = y[:100], y[100:]
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            m = NARForecaster(H=SPEC_H, restarts=10, preset="strict", rng=s).fit(yi)
            f = m.forecast(20, intervals=False).values
        ar = ARLeastSquares(order=m.order_).fit(yi)
        r_nar.append(np.sqrt(np.mean((f - yh) ** 2)))
        r_ar.append(np.sqrt(np.mean((ar.forecast(20).values - yh) ** 2)))
        r_p.append(np.sqrt(np.mean((Persistence().fit(yi).forecast(20).values - yh) ** 2)))
        lags = np.column_stack([y[100 - k:120 - k] for k in range(1, m.order_ + 1)])
        o_nar.append(np.sqrt(np.mean((m.one_step(lags) - yh) ** 2)))
        o_ar.append(np.sqrt(np.mean((ar.one_step(lags) - yh) ** 2)))
    med = np.median
    return med(r_nar) / med(r_ar), med(r_nar) / med(r_p), med(o_nar) / med(o_ar)


@pytest.mark.slow
def test_a6_nar_beats_ar_and_persistence_on_s1():
    # A6: seeds 0..49, S = 10, R = 10, median ensemble, block split: ratios <= 0.8
    # (measured 0.76 and 0.56; the review's prototype had 0.72 and 0.53)
    vs_ar, vs_p, _ = _a6("S1", range(50))
    assert vs_ar <= 0.8
    assert vs_p <= 0.8


@pytest.mark.slow
def test_a7_no_spurious_benefit_on_linear_ar2():
    # A7: on a linear AR(2) the NAR must not be much worse than AR(p-hat):
    # <= 1.1 x both over 20 steps and one step (measured 1.05 and 1.06)
    vs_ar, _, one = _a6("AR2", range(50))
    assert vs_ar <= 1.1
    assert one <= 1.1


def test_a9_same_seed_bit_identical_and_seed_matters():
    y = benchmark_process("S2", 100, 0)
    a = NARForecaster(restarts=3, rng=7).fit(y).forecast(20)
    b = NARForecaster(restarts=3, rng=7).fit(y).forecast(20)
    c = NARForecaster(restarts=3, rng=8).fit(y).forecast(20)
    for x, z in ((a.values, b.values), (a.lo95, b.lo95), (a.hi95, b.hi95)):
        np.testing.assert_array_equal(x, z)
    assert not np.array_equal(a.values, c.values)


@pytest.mark.slow
def test_a10_whiteness_rule():
    # A10: passes on N(0,1) (n = 100) in >= 90 % of seeds; fails on AR(1), phi = 0.6, in
    # >= 90 %. 300 seeds each: binomial SE ~1.3 %, measured rates 94-95 % / ~99 %.
    white = ar = 0
    for s in range(300):
        g = np.random.default_rng(s)
        white += whiteness(g.normal(size=100)).passed
        e = g.normal(size=300)
        x = np.zeros(300)
        for t in range(1, 300):
            x[t] = 0.6 * x[t - 1] + e[t]
        ar += not whiteness(x[200:]).passed
    assert white >= 270
    assert ar >= 270


def test_whiteness_acf_matches_statsmodels():
    from statsmodels.tsa.stattools import acf

    e = np.random.default_rng(1).normal(size=90)
    w = whiteness(e)
    np.testing.assert_allclose(w.acf, acf(e, nlags=20, fft=False)[1:], rtol=1e-12)
    assert w.bound == pytest.approx(1.96 / np.sqrt(90))
    assert w.allowed == 2


def test_intervals_ordered_and_cover_the_simulated_truth():
    # S1 with its known noise (sd 0.1): 95 % intervals of 20 seeds x 20 steps should
    # cover most holdout values; 80 % is a loose floor for an approximate method.
    cover = total = 0
    for s in range(8):
        y = benchmark_process("S1", 120, 100 + s)
        m = NARForecaster(H=SPEC_H, restarts=4, preset="strict", rng=s, n_paths=100).fit(y[:100])
        f = m.forecast(20)
        assert np.all(f.lo95 <= f.median) and np.all(f.median <= f.hi95)
        cover += np.sum((y[100:] >= f.lo95) & (y[100:] <= f.hi95))
        total += 20
    assert cover / total >= 0.8
    paths = m.forecast_paths(20)
    assert paths.shape == (2 * 100, 20)  # ceil(4 / 2) members x 100 paths


def test_model_roundtrip_forecasts_identical():
    y = benchmark_process("S1", 100, 2)
    m = NARForecaster(restarts=3, preset="strict", rng=4).fit(y)
    d = json.loads(json.dumps(m.to_dict()))
    m2 = NARForecaster.from_dict(d)
    a, b = m.forecast(10), m2.forecast(10)
    np.testing.assert_array_equal(a.values, b.values)
    np.testing.assert_array_equal(a.hi95, b.hi95)


def test_block_split_and_fit_metrics():
    y = benchmark_process("S2", 100, 5)
    m = NARForecaster(order=3, restarts=2, preset="strict", rng=0).fit(y)
    vm = m.members_[0].val_mask
    q = m.sample_index_.size
    assert q == 97
    n_val = int(np.floor(0.1 * q + 0.5))
    assert vm.sum() == n_val and np.all(vm[-n_val:])
    e = y[m.sample_index_] - m.fitted_
    fm = m.fit_metrics()
    assert fm["all"]["rmse"] == pytest.approx(np.sqrt(np.mean(e ** 2)), rel=1e-12)
    assert fm["all"]["max_ae"] == pytest.approx(np.max(np.abs(e)), rel=1e-12)
    assert fm["validation"]["n"] == n_val


def test_constant_series_degrades_to_persistence():
    with pytest.warns(DataQualityWarning, match="constant"):
        m = NARForecaster(restarts=2).fit(np.full(50, 1.25))
    f = m.forecast(5)
    np.testing.assert_array_equal(f.values, 1.25)


def test_gaps_are_skipped_in_samples():
    y = benchmark_process("S1", 100, 0)
    y[40:46] = np.nan  # a long gap: no sample may use it as lag or target
    m = NARForecaster(order=2, restarts=2, rng=0).fit(y)
    t = m.sample_index_
    assert not np.any((t >= 40) & (t <= 47))
    assert np.all(np.isfinite(m.fitted_))


def test_errors():
    with pytest.raises(RuntimeError):
        NARForecaster().forecast(3)
    with pytest.raises(InputError):
        NARForecaster(preset="fancy").fit(np.arange(30.0))
    y = np.arange(30.0)
    y[-1] = np.nan
    with pytest.raises(InputError):
        NARForecaster().fit(y)


def test_hidden_grid_chooses_by_mean_validation_mse():
    # spec 004 §3.2 option hidden_grid: every size trains from the same
    # R seeds; S is the size with the lowest mean validation MSE over the restarts, and
    # the chosen members are exactly those of a plain fit with that size
    from inertialab.sim.drift import benchmark_process

    y = benchmark_process("S1", 100, 5)
    g = NARForecaster(order=2, hidden_grid=(2, 6), restarts=3, preset="strict", rng=4).fit(y)
    assert set(g.hidden_scores_) == {2, 6}
    assert g.hidden_ == min(g.hidden_scores_, key=lambda k: (g.hidden_scores_[k], k))
    for S in (2, 6):
        plain = NARForecaster(order=2, hidden=S, restarts=3, preset="strict", rng=4).fit(y)
        assert g.hidden_scores_[S] == pytest.approx(
            np.mean([m.val_mse for m in plain.members_]), rel=1e-12)
        if S == g.hidden_:
            np.testing.assert_array_equal(g.forecast(5).values, plain.forecast(5).values)
    back = NARForecaster.from_dict(g.to_dict())
    np.testing.assert_array_equal(back.forecast(5).values, g.forecast(5).values)
    with pytest.raises(InputError, match="validation split"):
        NARForecaster(order=2, hidden_grid=(2, 4), val_fraction=0.0).fit(y)


def test_auto_lag_bound_is_the_largest_the_spec_data_rule_allows():
    # spec 004 §3.1: H = 6 and m >= 10 H CV targets, m = n - H, i.e. H <= n / 11;
    # "auto" takes the largest such H, never below 6, at most AUTO_H_MAX
    assert auto_lag_bound(30) == SPEC_H and auto_lag_bound(100) == 9
    assert auto_lag_bound(500) == AUTO_H_MAX == 40 and auto_lag_bound(10**6) == AUTO_H_MAX
    for n in range(11 * SPEC_H, 11 * AUTO_H_MAX):
        H = auto_lag_bound(n)
        assert n - H >= 10 * H and n - (H + 1) < 10 * (H + 1)
    y = benchmark_process("S1", 100, 0)
    m = NARForecaster(restarts=1, rng=0).fit(y)
    assert m.order_selection_.H == 9
    assert NARForecaster(H=6, restarts=1, rng=0).fit(y).order_selection_.H == 6
    with pytest.raises(InputError, match="argument 'H'"):
        NARForecaster(H="big", restarts=1).fit(y)


def test_mackey_glass_learner_beats_ar6_and_persistence_reduced():
    # , CI-sized (benchmarks/drift.py has the 500-value, 6-origin run):
    # Mackey-Glass tau = 17, 220 training values before T = 220 and 300, R = 1 restart,
    # 20-step closed loop, RMSE pooled. Target NAR <= 0.5 x AR(6) and <= 0.25 x
    # persistence (measured 3.6e-4 vs 0.093 and 0.30). The cause of the spec-H = 6 miss
    # (p <= 6 consecutive lags of a 17-unit delay system): "auto" (H = 20) lets the
    # kernel CV pick an order beyond the delay.
    from inertialab.sim.drift import mackey_glass

    x = mackey_glass(320)
    err = {"nar": [], "ar6": [], "persistence": []}
    for T in (220, 300):
        train, truth = x[T - 220:T], x[T:T + 20]
        m = NARForecaster(restarts=1, rng=T).fit(train)
        assert m.order_selection_.H == 20 and m.order_ > 17
        err["nar"].append(m.forecast(20, intervals=False).values - truth)
        err["ar6"].append(ARLeastSquares(order=6).fit(train).forecast(20).values - truth)
        err["persistence"].append(Persistence().fit(train).forecast(20).values - truth)
    rmse = {k: np.sqrt(np.mean(np.square(v))) for k, v in err.items()}
    assert rmse["nar"] <= 0.5 * rmse["ar6"]
    assert rmse["nar"] <= 0.25 * rmse["persistence"]
