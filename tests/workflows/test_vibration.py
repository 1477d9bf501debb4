"""Tests of the vibration workflow (spec 001 §3.7-3.11, §4; issue 4)."""

import warnings

import numpy as np
import pandas as pd
import pytest

from inertialab.errors import DataQualityWarning, ExtrapolationWarning, InputError
from inertialab.io import load_model, save_model
from inertialab.sensors.gyro_vibration import bias_shift_dph
from inertialab.workflows.vibration import (
    TERMS,
    VibrationConfig,
    VibrationModel,
    analyse,
    bias_targets,
    residual_metrics,
    run_from_frame,
    simulate_pair,
)


def _frame(n1=400, n2=300, n3=300, fs=100.0, f=50.0, rate=None):
    n = n1 + n2 + n3
    on = np.zeros(n, dtype=np.int8)
    on[n1:n1 + n2] = 1
    fr = np.where(on == 1, f, 0.0)
    ph = np.where(np.arange(n) < n1, 1, np.where(on == 1, 2, 3)).astype(np.int8)
    x = np.zeros(n) if rate is None else rate
    return pd.DataFrame({"t_s": np.arange(n) / fs, "rate_dph": x, "vib_on": on,
                         "vib_freq_hz": fr, "vib_acc_g": 5.0 * on, "phase": ph})


# ------------------------------------------------------------------ loader checks (issue §6)

def test_run_from_frame_segments_phases():
    r = run_from_frame(_frame(), {"experiment": "fixed"})
    assert (r.k_on, r.k_off) == (400, 699) and r.fs_hz == pytest.approx(100.0, rel=1e-12)
    assert r.p1 == slice(0, 400) and r.p2 == slice(400, 700) and r.p3 == slice(700, 1000)
    assert r.experiment == "fixed"


def test_dtheta_input_and_unit_conversion():
    # dtheta in arcsec per sample: rate = dtheta/tau0 (1 (deg/h) s = 1 arcsec exactly)
    df = _frame().drop(columns=["rate_dph"])
    df["dtheta_arcsec"] = 0.01  # at 100 Hz -> 1 deg/h
    np.testing.assert_allclose(run_from_frame(df).rate_dph, 1.0)
    df = _frame().rename(columns={"rate_dph": "rate_dps"})
    df["rate_dps"] = 1.0 / 3600
    np.testing.assert_allclose(run_from_frame(df).rate_dph, 1.0, rtol=1e-12)


@pytest.mark.parametrize("mutate, match", [
    (lambda d: d.drop(columns=["vib_on"]), "no vibration phases"),
    (lambda d: d.assign(vib_on=0, vib_freq_hz=0.0, phase=1), "never 1"),
    (lambda d: d.drop(columns=["vib_freq_hz"]), "vib_freq_hz"),
    (lambda d: d.assign(vib_freq_hz=np.where(np.arange(len(d)) == 450, 0.0, d.vib_freq_hz)),
     "while vibrating"),
    (lambda d: d.assign(t_s=d.t_s + np.where(np.arange(len(d)) > 500, 0.003, 0.0)),
     "non-uniform"),
    (lambda d: d.assign(phase=np.where(np.arange(len(d)) == 10, 3, d.phase)), "phase"),
    (lambda d: d.assign(vib_on=np.where(np.arange(len(d)) == 500, 0, d.vib_on)), "contiguous"),
    (lambda d: d.drop(columns=["rate_dph"]), "rate column"),
])
def test_bad_records_are_input_errors(mutate, match):
    with pytest.raises(InputError, match=match):
        run_from_frame(mutate(_frame()), path="bad.csv")


def test_vibration_from_the_first_sample_is_an_error():
    d = _frame()
    d["vib_on"] = np.where(np.arange(len(d)) < 700, 1, 0)
    d["vib_freq_hz"] = np.where(d["vib_on"] == 1, 50.0, 0.0)
    d = d.drop(columns=["phase"])
    with pytest.raises(InputError, match="P1 is empty"):
        run_from_frame(d)


def test_record_ending_in_vibration_warns():
    d = _frame(n3=0)
    with pytest.warns(DataQualityWarning, match="no P3"):
        r = run_from_frame(d.drop(columns=["phase"]))
    assert "P3" not in r.phase_slices()


# ------------------------------------------------------------------ targets and metrics

def test_bias_targets_exact_on_a_known_curve():
    # approximation = beta + g(f) in P2, beta in P1 -> each bin mean is g at the bin's
    # frequencies (1-Hz bins of a linear sweep) within the curvature of g over 1 Hz
    fs = 200.0
    n1, n2, n3 = 2000, 100_000, 2000
    n = n1 + n2 + n3
    f = np.zeros(n)
    f[n1:n1 + n2] = np.linspace(1.0, 500.0, n2)
    on = (f > 0).astype(np.int8)
    df = pd.DataFrame({"t_s": np.arange(n) / fs, "rate_dph": np.zeros(n), "vib_on": on,
                       "vib_freq_hz": f})
    run = run_from_frame(df)
    beta = 0.7
    approx = beta + np.where(on == 1, bias_shift_dph(f), 0.0)
    tg = bias_targets(run, approx, guard_s=0.0)
    assert tg.beta_dph == pytest.approx(beta)
    assert tg.f_hz[0] == 1.0 and tg.f_hz[-1] == 500.0 and np.all(np.diff(tg.f_hz) == 1)
    # bins at the ends are half-filled (centres at the range ends); skip them
    np.testing.assert_allclose(tg.e_dph[1:-1], bias_shift_dph(tg.f_hz[1:-1]), atol=2e-3)
    assert np.all(tg.count[1:-1] >= 8)
    # option of spec §3.7: every 2^L-th sample of the guarded P2 window
    ts = bias_targets(run, approx, guard_s=1.0, mode="samples", level=6)
    k = np.arange(n1 + 200, n1 + n2 - 200)[::64]
    np.testing.assert_array_equal(ts.f_hz, f[k])
    np.testing.assert_allclose(ts.e_dph, approx[k] - beta)
    with pytest.raises(InputError):
        bias_targets(run, approx, mode="nope")


def test_residual_metrics_on_constructed_signal():
    fs = 10.0
    n1, n2, n3 = 1000, 1000, 1000
    x = np.concatenate([np.full(n1, 1.0), np.full(n2, 3.0), np.full(n3, 1.0)])
    x[n1 + 500] = 10.0  # a spike inside the guarded P2 window
    x[n1] = -4.0  # a spike at the onset
    df = _frame(n1, n2, n3, fs=fs, rate=x)
    run = run_from_frame(df)
    m = residual_metrics(x, run, guard_s=10.0, edge_s=10.0)
    # P2 without 100-sample guards: 800 samples of 3 with one 10 -> mean 3 + 7/800
    assert m["delta_b"] == pytest.approx(2.0 + 7.0 / 800)
    assert m["edge_on"] == pytest.approx(5.0)  # |-4 - 1|
    assert m["edge_off"] == pytest.approx(2.0)
    assert m["mean"]["P3"] == pytest.approx(1.0)
    assert m["stability_10s"]["P1"] == pytest.approx(0.0)


# ------------------------------------------------------------------ model

def test_model_fits_clips_and_round_trips(tmp_path):
    f = np.arange(1.0, 501.0)
    e = bias_shift_dph(f)
    m = VibrationModel().fit(f, e)
    assert m.rbf_.mse_ <= 1e-4
    # the 4th-order polynomial misses the 470-Hz resonance (check 15's note: ~+3 deg/h at
    # 500 Hz even without noise; here the noise-free curve, error > 1 deg/h)
    assert abs(m.predict([500.0], model="poly")[0] - e[-1]) > 1.0
    assert abs(m.predict([500.0])[0] - e[-1]) < 0.05
    with pytest.warns(ExtrapolationWarning, match="clipped"):
        v = m.predict([600.0])
    assert v[0] == pytest.approx(m.predict([500.0])[0])
    p = tmp_path / "model.json"
    save_model(m, p, units={"f": "hz", "bias": "dph"})
    m2 = load_model(p, expected_type="vibration-compensation")
    xs = np.linspace(1, 500, 77)
    np.testing.assert_array_equal(m.predict(xs), m2.predict(xs))
    np.testing.assert_array_equal(m.predict(xs, model="poly"), m2.predict(xs, model="poly"))


def test_compensate_subtracts_model_only_while_vibrating():
    f = np.arange(1.0, 501.0)
    m = VibrationModel().fit(f, bias_shift_dph(f))
    n = 5000
    x = np.random.default_rng(0).normal(size=n)
    on = np.zeros(n, bool)
    on[2000:3000] = True
    fr = np.where(on, 300.0, 0.0)
    approx = np.zeros(n)
    out = m.compensate(x, on, fr, approx=approx)
    np.testing.assert_allclose(out[~on], 0.0)
    np.testing.assert_allclose(out[on], -m.predict([300.0])[0])
    raw = m.compensate(x, on, fr, apply_to="raw", model="poly")
    np.testing.assert_allclose(raw[~on], x[~on])
    with pytest.raises(RuntimeError):
        VibrationModel().predict([1.0])


# ------------------------------------------------------------------ end to end

@pytest.fixture(scope="module")
def short_pair():
    # shortened virtual lab: P1 = P3 = 300 s, fixed P2 = 300 s, sweep at 4 oct/min
    return simulate_pair(11, p1_s=300.0, p3_s=300.0, p2_fixed_s=300.0, sweep_oct_per_min=4.0)


@pytest.fixture(scope="module")
def short_result(short_pair):
    sweep, fixed = short_pair
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return analyse(sweep, fixed, VibrationConfig(views=False))


def test_pipeline_json_shape(short_result):
    j = short_result.to_json()
    assert set(j) == {"level", "delta_j", "tables", "residual_bias_dph", "fit"}
    assert set(j["tables"]) == {"phases", "decomposition", "compensation"}
    assert set(j["tables"]["phases"]) == {f"{r}/P{k}" for r in ("sweep", "fixed") for k in (1, 2, 3)}
    assert set(j["tables"]["compensation"]) == {"raw", "A6", "rbf", "poly"}
    for table in j["tables"].values():
        for row in table.values():
            assert set(row) == set(TERMS)
            for t in row.values():
                assert {"value", "unit", "ci", "method", "tau_range_s"} <= set(t)
    assert set(j["residual_bias_dph"]) == {"rbf", "poly"}
    assert set(j["fit"]["rbf"]) >= {"neurons", "train_rmse", "heldout_rmse"}
    assert set(j["fit"]["poly"]) >= {"train_rmse", "heldout_rmse"}
    assert j["level"] == 6 and set(j["delta_j"]) == {str(k) for k in range(3, 10)}


def test_pipeline_numbers_against_simulated_truth(short_result):
    r = short_result
    # vibration inflates ARW (x1.5 at 500 Hz) and Q (jitter adds q/sqrt(12) in quadrature ->
    # x sqrt(2)); P2/P1 ratios of the 500-Hz run above 1.2 (check 13 threshold)
    ph = r.tables["phases"]
    for k in ("Q", "N"):
        assert ph["fixed/P2"][k]["value"] / ph["fixed/P1"][k]["value"] > 1.2
    # P1 N close to the simulated 0.01 deg/sqrt(h) (300 s of 200 Hz: +-10 %)
    assert ph["fixed/P1"]["N"]["value"] == pytest.approx(0.01, rel=0.1)
    # seed goal reached on the targets; the RBF truth RMSE is reported
    assert r.fit["rbf"]["train_mse"] <= 1e-4
    assert r.fit["rbf"]["truth_rmse"] is not None
    # compensation removes most of the 9-10 deg/h offset of P2 (A6 residual ~ b_v(500) +
    # thermal drift); the RBF residual is below a quarter of it
    res = r.metrics["residual"]
    assert res["A6"]["delta_b"] == pytest.approx(float(bias_shift_dph(500.0)), abs=1.5)
    assert abs(res["rbf"]["delta_b"]) < 0.25 * res["A6"]["delta_b"]


def test_sweep_alone_omits_compensation(short_pair):
    sweep, _ = short_pair
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        r = analyse(sweep, None, VibrationConfig(views=False, level="auto"))
    assert r.residual_bias_dph is None and r.tables["compensation"] == {}
    assert r.level == r.level_selection.level
    assert set(r.tables["phases"]) == {"sweep/P1", "sweep/P2", "sweep/P3"}


def test_short_record_lowers_the_level_with_a_warning():
    # sweep of 29 s at 200 Hz: dwt_max_level(5800, 8) = 9 < 10 -> J lowered, warned
    sweep, fixed = simulate_pair(1, p1_s=7.5, p3_s=7.5, p2_fixed_s=25.0,
                                 sweep_oct_per_min=60.0)
    with pytest.warns(DataQualityWarning, match="levels"):
        r = analyse(sweep, fixed, VibrationConfig(views=False, goal=1e-2))
    assert r.metrics["level_rule"]["wavelet_level"] < 10


def test_bad_level():
    sweep, fixed = simulate_pair(1, p1_s=30.0, p3_s=30.0, p2_fixed_s=30.0,
                                 sweep_oct_per_min=60.0)
    with pytest.raises(InputError, match="level"):
        analyse(sweep, fixed, VibrationConfig(level=12, views=False))


# ------------------------------------------------------------------ model-file fixtures

def test_model_fixtures_v1_still_load():
    # tests/data/models/{vibration-compensation,rbf}-v1.json were written by save_model
    # (format version 1) from the noise-free b_v curve at 1, 6, ..., 496 Hz (see
    # tests/data/README.md); they must load and give the numbers they gave when written
    from pathlib import Path

    d = Path(__file__).resolve().parents[1] / "data" / "models"
    m = load_model(d / "vibration-compensation-v1.json", expected_type="vibration-compensation")
    r = load_model(d / "rbf-v1.json", expected_type="rbf")
    xs = [1.0, 251.0, 466.0, 471.0, 496.0]
    np.testing.assert_allclose(m.predict(xs), [1.0653066257322124, 1.0653066257322124,
                                               11.048343910112356, 11.15847209049774,
                                               9.577668603119587], rtol=1e-12)
    np.testing.assert_allclose(m.predict(xs, model="poly"),
                               [0.309375921068482, 1.3899868922768408, 9.62237831701889,
                                10.019117392023443, 12.190639731371528], rtol=1e-12)
    np.testing.assert_allclose(r.predict(xs), [1.2734459157895253, 1.2734459157895253,
                                               11.048343910112354, 11.158472090497739,
                                               9.577668603119587], rtol=1e-12)
    assert m.level == 6 and m.rbf_.n_neurons_ == 40 and r.n_neurons_ == 30
