"""workflows.drift: daily grid, bad input, whole-record fits (spec 004 §2.2; A9)."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from inertialab.calib.drift import DriftModel
from inertialab.calib.model_types import load_model
from inertialab.errors import DataQualityWarning, InputError
from inertialab.io import validate_frame
from inertialab.io.modelfile import save_model
from inertialab.sim.drift import benchmark_process, simulate_storage_batch
from inertialab.workflows.drift import FitConfig, fit_drift, to_daily_grid

FAST = FitConfig(restarts=2, n_paths=50, baselines=("persistence", "ar_ls"))


def _frame(days, bias_mg, unit="U1", sf=None, **extra):
    d = {"unit_id": unit, "day": days, "bias_mg": bias_mg}
    if sf is not None:
        d["sf_ma_per_g"] = sf
    d.update(extra)
    return pd.DataFrame(d)


def test_grid_averages_repeats_and_fills_short_gaps_only():
    # day 0 tested twice; days 3-4 missing (gap 2 -> imputed); days 6-9 missing (gap 4 ->
    # segment split); days 10-20 present
    days = [0, 0, 1, 2, 5] + list(range(10, 21))
    vals = [1.0, 3.0, 2.0, 2.0, 5.0] + [7.0] * 11
    ts = [f"2025-01-{d + 1:02d}T08:00:00Z" for d in days]
    ts[1] = "2025-01-01T16:00:00Z"
    df = _frame(days, vals, timestamp=pd.to_datetime(ts, utc=True))
    s = to_daily_grid(df, quantity="bias")["U1"]
    assert s.unit == "ug" and s.step_days == 1
    np.testing.assert_allclose(s.values[:3], [2000.0, 2000.0, 2000.0])  # mg -> ug, mean
    assert s.n_rep[0] == 2 and s.rep_sd[0] == pytest.approx(np.std([1000, 3000], ddof=1))
    # linear interpolation between day 2 (2000) and day 5 (5000)
    np.testing.assert_allclose(s.values[3:5], [3000.0, 4000.0])
    assert s.imputed[3] and s.imputed[4] and not s.usable[3]
    assert np.all(np.isnan(s.values[6:10]))
    assert s.segment[5] == 0 and s.segment[10] == 1
    np.testing.assert_array_equal(s.day, np.arange(21))


def test_units_of_measure_are_converted():
    days = np.arange(30)
    b = np.linspace(1, 2, 30)
    a = to_daily_grid(_frame(days, b), quantity="bias")["U1"].values
    ug = pd.DataFrame({"unit_id": "U1", "day": days, "bias_ug": b * 1000})
    np.testing.assert_allclose(to_daily_grid(ug, quantity="bias")["U1"].values, a)
    # scale factor in ppm of the unit's mean K1
    sf = 1.3 * (1 + 1e-6 * np.linspace(-50, 50, 30))
    s = to_daily_grid(_frame(days, b, sf=sf), quantity="sf")["U1"]
    assert s.k_ref == pytest.approx(1.3, rel=1e-12)
    np.testing.assert_allclose(s.values, np.linspace(-50, 50, 30), atol=1e-6)
    # a bias in mA needs K1: b[g] = b[mA] / K1
    ma = pd.DataFrame({"unit_id": "U1", "day": days, "bias_ma": b * 1.3e-3,
                       "sf_ma_per_g": np.full(30, 1.3)})
    np.testing.assert_allclose(to_daily_grid(ma, quantity="bias")["U1"].values, a)


def test_hampel_screen_flags_spikes_only_and_invalid_rows_dropped():
    # smooth drift + N(0, 10) scatter + two 8-sigma spikes; the screen (5 x 1.4826 MAD)
    # must flag both spikes and, at 5 sigma, almost nothing else (P(|z| > 5) ~ 6e-7/day)
    rng = np.random.default_rng(4)
    days = np.arange(100)
    y = 50 * (1 - np.exp(-days / 15)) + rng.normal(0, 10, 100)
    y[[30, 70]] += 80.0
    valid = np.ones(100, bool)
    valid[50] = False
    df = pd.DataFrame({"unit_id": "U1", "day": days, "bias_ug": y, "valid": valid})
    plain = to_daily_grid(df, quantity="bias")["U1"]
    assert plain.imputed[50] and not plain.observed[50]  # invalid row dropped, then imputed
    s = to_daily_grid(df, quantity="bias", hampel=True)["U1"]
    assert set(np.flatnonzero(s.screened)) == {30, 70}
    assert not s.usable[30] and s.imputed[30]  # screened days become gaps, then imputed
    np.testing.assert_allclose(s.values[30], (y[29] + y[31]) / 2)


def test_weekly_programme_uses_native_step():
    days = np.arange(0, 7 * 40, 7)
    s = to_daily_grid(_frame(days, np.sin(days / 30.0)), quantity="bias")["U1"]
    assert s.step_days == 7 and s.values.size == 40
    np.testing.assert_array_equal(s.day, days)


def test_duplicates_conflicting_is_error_identical_is_dropped():
    ts = pd.to_datetime(["2025-01-01", "2025-01-01", "2025-01-02"], utc=True)
    bad = pd.DataFrame({"unit_id": "U1", "timestamp": ts, "bias_mg": [1.0, 1.5, 2.0]})
    with pytest.raises(InputError, match="rows 1 and 2"):
        to_daily_grid(bad, quantity="bias")
    same = pd.DataFrame({"unit_id": "U1", "timestamp": ts, "bias_mg": [1.0, 1.0, 2.0]})
    with pytest.warns(DataQualityWarning, match="duplicate"):
        s = to_daily_grid(same, quantity="bias")["U1"]
    assert s.n_rep[0] == 1


def test_dates_out_of_order_are_sorted_with_warning():
    days = np.arange(40)
    b = np.cos(days / 5.0)
    df = pd.DataFrame({"unit_id": "U1", "date": pd.date_range("2025-01-01", periods=40)
                       .strftime("%Y-%m-%d"), "bias_mg": b})
    shuffled = df.iloc[np.random.default_rng(0).permutation(40)].reset_index(drop=True)
    with pytest.warns(DataQualityWarning, match="sorted"):
        rec = validate_frame(shuffled, "storage_drift")
    s = to_daily_grid(rec.data, quantity="bias")["U1"]
    np.testing.assert_allclose(s.values, b * 1000)


def test_unknown_unit_is_input_error():
    df = pd.DataFrame({"unit_id": "U1", "day": np.arange(5), "bias_furlong": np.ones(5)})
    with pytest.raises(InputError, match="furlong"):
        validate_frame(df, "storage_drift")


@pytest.mark.filterwarnings("ignore::inertialab.errors.DataQualityWarning")
def test_a9_fit_drift_reproducible_and_model_roundtrip(tmp_path):
    b = simulate_storage_batch(2, 60, "nav", rng=5)
    f1 = fit_drift(b.frame, meta=b.meta, settings=FAST, origin_day=49)
    f2 = fit_drift(b.frame, meta=b.meta, settings=FAST, origin_day=49)
    for (_, _, r1), (_, _, r2) in zip(f1.iter(), f2.iter()):
        assert r1.forecast == r2.forecast
        assert r1.holdout["metrics"] == r2.holdout["metrics"]
    p = save_model(f1.model, tmp_path / "m.json", units={"bias": "ug", "sf": "ppm"})
    m = load_model(p, expected_type="storage-drift")
    assert isinstance(m, DriftModel)
    again = m.forecast(20)
    for u, q, r in f1.iter():
        np.testing.assert_array_equal(again[u][q]["forecast"]["value"], r.forecast["value"])
        np.testing.assert_array_equal(again[u][q]["forecast"]["hi95"], r.forecast["hi95"])
        assert again[u][q]["recalibration_day"] == r.recalibration_day


def test_short_record_reduces_h_and_constant_unit_warns():
    days = np.arange(40)
    df = pd.concat([
        _frame(days, benchmark_process("S1", 40, 0) * 1e-3, unit="A"),
        _frame(days, np.full(40, 0.5), unit="B"),
    ])
    with pytest.warns(DataQualityWarning) as rec:
        fit = fit_drift(df, settings=FAST, quantities=("bias",))
    msgs = " ".join(str(w.message) for w in rec)
    assert "H reduced" in msgs and "constant" in msgs
    const = fit.results["B"]["bias"]
    np.testing.assert_allclose(const.forecast["value"], 500.0, rtol=1e-12)  # mg -> ug rounding


def test_sf_in_volts_per_g_uses_the_load_resistor():
    # spec 004 §1: k[mA/g] = 1000 k[V/g] / R[ohm]; 6.5 V/g over 5000 ohm
    # is 1.3 mA/g (not 6.5 "mA/g")
    days = np.arange(30)
    ppm = 20.0 * np.sin(days / 5.0)
    k_vpg = 6.5 * (1 + 1e-6 * ppm)
    col = pd.DataFrame({"unit_id": "U1", "day": days, "sf_v_per_g": k_vpg,
                        "load_ohm": np.full(30, 5000.0)})
    s = to_daily_grid(col, quantity="sf")["U1"]
    assert s.k_ref == pytest.approx(1000 * np.mean(k_vpg) / 5000.0, rel=1e-12)
    assert s.k_ref == pytest.approx(1.3, rel=1e-4)
    np.testing.assert_allclose(s.values, 1e6 * (k_vpg - k_vpg.mean()) / k_vpg.mean(),
                               rtol=0, atol=1e-8)
    # the same from the sidecar, per unit; and the native (mA/g) figures follow k_ref
    side = col.drop(columns="load_ohm")
    s2 = to_daily_grid(side, quantity="sf", meta={"load_ohm": {"U1": 5000.0}})["U1"]
    assert s2.k_ref == pytest.approx(s.k_ref, rel=1e-15)
    assert s2.to_native(100.0) == pytest.approx(1e-4 * 1.3, rel=1e-4)
    # a bias in mA converts with that K1 in mA/g: 1.3e-3 mA over 1.3 mA/g is 1000 ug
    side["bias_ma"] = 1.3e-3
    b = to_daily_grid(side, quantity="bias", meta={"load_ohm": 5000.0})["U1"]
    np.testing.assert_allclose(b.values, 1e6 * 1.3e-3 / (1000 * k_vpg / 5000.0), rtol=1e-12)
    # no resistor anywhere, or a non-positive one: one-line InputError naming the fix
    with pytest.raises(InputError, match="needs the load resistor"):
        to_daily_grid(side, quantity="sf")
    bad = col.copy()
    bad.loc[3, "load_ohm"] = 0.0
    with pytest.raises(InputError, match="row 4"):
        to_daily_grid(bad, quantity="sf")


@pytest.mark.filterwarnings("ignore::inertialab.errors.DataQualityWarning")
def test_apply_compensates_a_later_record_with_the_forecast():
    # spec 004 §9: a = I / k_hat - b_hat on a later record; residuals
    # with and without the forecast. Constant bias and scale factor make the forecast exact
    # (persistence), so the compensation must return the input acceleration exactly.
    from inertialab.io import validate_frame
    from inertialab.workflows.drift import apply, fit

    days = np.arange(40)
    rng = np.random.default_rng(3)
    drift_ug = 80.0 * (1 - np.exp(-days / 8.0)) + rng.normal(0, 2.0, 40)
    fit_df = pd.concat([
        _frame(days, np.full(40, 0.25), unit="C", sf=np.full(40, 1.3)),
        _frame(days, 0.5 + 1e-3 * drift_ug, unit="D", sf=1.25 * (1 + 1e-6 * drift_ug)),
    ])
    rec = validate_frame(fit_df[fit_df["day"] <= 29], "storage_drift")
    model = fit(rec, FAST, origin_day=29).model
    later = fit_df[fit_df["day"] >= 28].copy()
    a_ref = np.where(later["day"] % 2 == 0, 1.0, -1.0)
    k_true = later["sf_ma_per_g"].to_numpy()
    later["output_ma"] = k_true * (a_ref + 1e-3 * later["bias_mg"].to_numpy())
    later["a_ref_g"] = a_ref
    out, summary = apply(model, validate_frame(later, "storage_drift"))
    c = out[out["unit_id"] == "C"]
    np.testing.assert_array_equal(c["status"], [1, 1] + [0] * 10)  # days 28, 29 <= origin
    np.testing.assert_allclose(c["bias_hat_ug"], 250.0, rtol=1e-12)
    np.testing.assert_allclose(c["sf_hat_ma_per_g"], 1.3, rtol=1e-12)
    np.testing.assert_allclose(c["a_error_ug"], 0.0, atol=1e-6)
    assert summary["C"]["bias"]["rmse_compensated"] == pytest.approx(0.0, abs=1e-9)
    # unit D: the forecast of day d is the model's forecast at step d - 29, and the
    # compensated acceleration is I / k_hat - b_hat computed independently
    d = out[(out["unit_id"] == "D") & (out["status"] == 0)]
    fc = model.forecast(10)["D"]
    np.testing.assert_allclose(d["bias_hat_ug"], fc["bias"]["forecast"]["value"], rtol=1e-12)
    k_hat = model.entries["D"]["sf"]["k_ref"] * (1 + 1e-6 * np.asarray(fc["sf"]["forecast"]["value"]))
    i_ma = later.loc[later["day"] >= 30].query("unit_id == 'D'")["output_ma"].to_numpy()
    np.testing.assert_allclose(d["a_g"], i_ma / k_hat - 1e-6 * d["bias_hat_ug"].to_numpy(),
                               rtol=1e-12)
    meas = 1e3 * later.query("unit_id == 'D' and day >= 30")["bias_mg"].to_numpy()
    assert summary["D"]["bias"]["rmse_compensated"] == pytest.approx(
        np.sqrt(np.mean((meas - d["bias_hat_ug"].to_numpy()) ** 2)), rel=1e-12)
    # a unit the model does not hold is an error naming it
    bad = later.assign(unit_id="Z")
    with pytest.raises(InputError, match="Z are not in the model"):
        apply(model, validate_frame(bad, "storage_drift"))


def test_the_study_in_one_module_and_the_old_name_warns():
    """workflows/drift.py holds the commands' settings and calls; drift_run still answers,
    with a DeprecationWarning; the estimator's names load on first use; FitConfig is the
    estimator's settings (order and hidden_grid read as the flags give them) and
    DriftSettings its deprecated former name."""
    import importlib
    import sys
    import warnings

    from inertialab.calib.drift import DEFAULT_BASELINES
    from inertialab.workflows import drift

    assert drift.DEFAULT_BASELINES is DEFAULT_BASELINES
    cfg = drift.FitConfig(order="4", hidden_grid="2, 4")
    assert (cfg.nar_order, cfg.hidden_sizes, cfg.tolerance("sf")) == (4, (2, 4), 50.0)
    assert drift.FitConfig(order=None).nar_order is None
    with pytest.warns(DeprecationWarning, match="FitConfig"):
        old = drift.DriftSettings(order=4, hidden_grid=(2, 4))
    assert (old.nar_order, old.hidden_sizes) == (4, (2, 4))
    for kw, name in (({"order": "0"}, "'order'"), ({"hidden_grid": "2,x"}, "'hidden_grid'"),
                     ({"recal_quantile": 0.0}, "'recal_quantile'")):
        with pytest.raises(InputError, match=name):
            drift.FitConfig(**kw).validate()
    sys.modules.pop("inertialab.workflows.drift_run", None)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        old = importlib.import_module("inertialab.workflows.drift_run")
    assert old.run_fit is drift.run_fit and old.FitConfig is drift.FitConfig
    assert any(issubclass(w.category, DeprecationWarning) for w in caught)


def test_forecast_takes_its_config_and_matches_the_model():
    """``run_forecast(model, ForecastConfig)``: the forecast is the model's own for the
    horizon given (the fit's when None); settings = the config | the model's seed; a bad
    horizon is refused naming it; a bare horizon still works, with a warning."""
    from pathlib import Path

    from inertialab.workflows.drift import ForecastConfig, run_forecast

    model = load_model(Path(__file__).parents[1] / "data" / "models" / "storage-drift-v1.json",
                       expected_type="storage-drift")
    res = run_forecast(model, ForecastConfig(horizon=7))
    assert res.settings == {"horizon": 7, "seed": model.settings.get("seed")}
    for u, qs in model.forecast(7).items():
        for q, e in qs.items():
            got = res.per_unit[u][q]["forecast"]
            assert len(got["day"]) == 7
            np.testing.assert_array_equal(got["value"], e["forecast"]["value"])
    fit_k = model.settings["horizon"]
    u, q = next((u, q) for u, qs in model.entries.items() for q in qs)
    assert len(run_forecast(model).per_unit[u][q]["forecast"]["day"]) == fit_k
    for bad in (0, 1001, 2.5):
        with pytest.raises(InputError, match="'horizon' must be an integer"):
            run_forecast(model, ForecastConfig(horizon=bad))
    with pytest.warns(DeprecationWarning, match="ForecastConfig"):
        old = run_forecast(model, 7)
    assert old.per_unit == res.per_unit
