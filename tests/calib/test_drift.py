"""calib.drift: per-series fit, holdout metrics, rolling origin, model file (spec 004 §5, A11)."""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from inertialab.calib.drift import DriftModel, fit_series
from inertialab.calib.drift_eval import evaluate_rolling_origin
from inertialab.calib.model_types import load_model
from inertialab.errors import DataQualityWarning, InputError
from inertialab.sim.drift import benchmark_process
from inertialab.workflows.drift import FitConfig, to_daily_grid

FAST = FitConfig(restarts=2, n_paths=50, baselines=("persistence", "ar_ls"))


def _s1_record(seed, drop_frac=0.0, n=120):
    y = benchmark_process("S1", n, seed)
    days = np.arange(n)
    keep = np.ones(n, bool)
    if drop_frac:
        drop = np.random.default_rng(seed + 1000).choice(np.arange(1, 99),
                                                         int(drop_frac * 100), replace=False)
        keep[drop] = False
    return pd.DataFrame({"unit_id": "S1", "day": days[keep], "bias_ug": y[keep]}), y


def test_holdout_metrics_and_skill_match_independent_computation():
    df, y = _s1_record(3)
    s = to_daily_grid(df, quantity="bias")["S1"]
    r = fit_series(s, FAST, origin_day=99, rng=1)
    assert r.origin_day == 99 and r.forecast["day"][0] == 100
    e = y[100:120] - np.asarray(r.forecast["value"])
    assert r.holdout["metrics"]["rmse"] == pytest.approx(np.sqrt(np.mean(e ** 2)), rel=1e-12)
    assert r.holdout["metrics"]["max_ae"] == pytest.approx(np.max(np.abs(e)), rel=1e-12)
    pers = np.sqrt(np.mean((y[100:120] - y[99]) ** 2))
    assert r.baselines["persistence"]["rmse"] == pytest.approx(pers, rel=1e-12)
    assert r.skill_vs_persistence == pytest.approx(1 - np.sqrt(np.mean(e ** 2)) / pers)


def test_a11_gaps_pipeline_never_scores_or_cv_samples_imputed_days():
    for seed in range(5):
        df, _ = _s1_record(seed, drop_frac=0.1)
        s = to_daily_grid(df, quantity="bias")["S1"]
        assert s.imputed.sum() > 0
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", DataQualityWarning)
            r = fit_series(s, FAST, origin_day=89, rng=seed)
        targets = np.asarray(r.model.order_selection_.targets)
        for k in range(r.model.order_selection_.H + 1):
            assert not np.any(s.imputed[targets - k])
        hd = np.asarray(r.holdout["day"])
        assert not np.any(s.imputed[hd])


@pytest.mark.filterwarnings("ignore::inertialab.errors.DataQualityWarning")
def test_rolling_origin_counts_and_paired_test():
    df, _ = _s1_record(2, n=100)
    s = to_daily_grid(df, quantity="bias")["S1"]
    rr = evaluate_rolling_origin(s, FAST, first=60, step=10)
    assert rr.origins == (60, 70, 80)
    assert len(rr.rmse["nar"]) == 3 and len(rr.rmse["persistence"]) == 3
    win = np.mean(np.asarray(rr.rmse["nar"]) < np.asarray(rr.rmse["persistence"]))
    assert rr.win_rate["persistence"] == pytest.approx(win)
    # the per-step error curve (Yue et al., spec 004, Figs. 6/8): persistence checked independently
    y = s.values
    want = [np.mean([abs(y[T - 1 + k] - y[T - 1]) for T in (60, 70, 80)]) for k in range(1, 21)]
    np.testing.assert_allclose(rr.step_mae["persistence"], want, rtol=1e-12)
    assert rr.step_n == (3,) * 20 and len(rr.step_mae["nar"]) == 20


@pytest.mark.filterwarnings("ignore::inertialab.errors.DataQualityWarning")
def test_direct_strategy_beside_recursive():
    # the direct strategy (one net per step) is scored like a baseline
    from dataclasses import replace

    df, y = _s1_record(4, n=120)
    s = to_daily_grid(df, quantity="bias")["S1"]
    st = replace(FAST, baselines=("persistence", "nar_direct"), horizon=5)
    r = fit_series(s, st, origin_day=99, rng=2)
    d = r.baselines["nar_direct"]
    assert "error" not in d and len(d["value"]) == 5
    assert d["rmse"] == pytest.approx(np.sqrt(np.mean((np.asarray(d["value"]) - y[100:105]) ** 2)))
    # same step-1 information as the recursive NAR: both close to the truth's scale
    assert d["rmse"] < 3 * np.std(y)


def test_model_fixture_v1_still_loads():
    # format-version-1 fixture (tests/data/README.md); the forecast is deterministic (seeded
    # paths), so it must reproduce the values recorded when the file was written, to 1e-9
    # relative (equal across machines to 1e-9 relative).
    from pathlib import Path

    m = load_model(Path(__file__).parents[1] / "data" / "models" / "storage-drift-v1.json",
                   expected_type="storage-drift")
    r = m.forecast(5)["QA001"]["bias"]
    np.testing.assert_allclose(r["forecast"]["value"],
                               [-146.67990250224574, -151.26293811483035, -132.16144721236924,
                                -147.88537436678504, -153.70912945822352], rtol=1e-9)
    np.testing.assert_allclose(r["forecast"]["hi95"][:2],
                               [-132.65856889665628, -125.75818281886932], rtol=1e-9)
    assert r["forecast"]["day"] == [60, 61, 62, 63, 64]


def test_check_horizon_bounds():
    from inertialab.calib.drift import MAX_HORIZON, check_horizon

    assert check_horizon(20) == 20 and check_horizon(MAX_HORIZON) == MAX_HORIZON
    for bad in (0, -1, MAX_HORIZON + 1, 10**8, 2.5, "x", None):
        with pytest.raises(InputError, match="argument 'horizon'"):
            check_horizon(bad)
    m = load_model(Path(__file__).parents[1] / "data" / "models" / "storage-drift-v1.json")
    with pytest.raises(InputError, match="from 1 to 1000"):
        m.forecast(10**8)


def test_model_payload_fuzz_is_always_input_error():
    # wrong-typed, non-finite or out-of-range payload fields are an
    # InputError at load (or the model forecasts finitely), never another exception
    import copy
    import json

    payload = json.loads((Path(__file__).parents[1] / "data" / "models"
                          / "storage-drift-v1.json").read_text())["payload"]
    e = payload["entries"]["QA001"]["bias"]
    cases = [("settings", "x"), ("settings", {"recal_quantile": 1.5}),
             ("settings", {"horizon": 10**8})]
    for key in ("origin_day", "step_days", "y_cal", "tolerance", "k_ref", "unit"):
        for v in (None, "x", [], float("nan"), 1e308, -1):
            cases.append((key, v))
    cases += [("nar", {"tail": None}), ("nar", {"members": []})]
    loaded = []
    for key, v in cases:
        q = copy.deepcopy(payload)
        if key == "settings":
            q["settings"] = v
        elif key == "nar":
            q["entries"]["QA001"]["bias"]["nar"].update(v)
        else:
            q["entries"]["QA001"]["bias"][key] = v
        try:
            m = DriftModel.from_dict(q)
        except InputError:
            continue
        r = m.forecast(3)["QA001"]["bias"]["forecast"]
        assert np.all(np.isfinite(r["value"])), (key, v)
        loaded.append((key, v))
    # legitimate (finite, in range): a negative origin day or calibrated value, a huge
    # calibrated value, tolerance or k_ref, and no k_ref (a bias entry)
    assert sorted(loaded, key=str) == sorted([
        ("origin_day", -1), ("y_cal", 1e308), ("y_cal", -1), ("tolerance", 1e308),
        ("k_ref", None), ("k_ref", 1e308)], key=str)
    assert e["origin_day"] == 59  # the fixture itself untouched
