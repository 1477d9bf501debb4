"""Tests of the vibration study: the pipeline on the virtual lab (spec 001 §3.11)."""

import warnings

import pytest

from inertialab.errors import DataQualityWarning, InputError
from inertialab.sensors.gyro_vibration import bias_shift_dph
from inertialab.studies.vibration import STUDY, simulate_pair
from inertialab.workflows.vibration import TERMS, FitConfig, analyse


@pytest.fixture(scope="module")
def short_pair():
    # shortened virtual lab: P1 = P3 = 300 s, fixed P2 = 300 s, sweep at 4 oct/min
    return simulate_pair(11, p1_s=300.0, p3_s=300.0, p2_fixed_s=300.0, sweep_oct_per_min=4.0)


@pytest.fixture(scope="module")
def short_result(short_pair):
    sweep, fixed = short_pair
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return analyse(sweep, fixed, FitConfig(views=False))


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
        r = analyse(sweep, None, FitConfig(views=False, level="auto"))
    assert r.residual_bias_dph is None and r.tables["compensation"] == {}
    assert r.level == r.level_selection.level
    assert set(r.tables["phases"]) == {"sweep/P1", "sweep/P2", "sweep/P3"}


def test_short_record_lowers_the_level_with_a_warning():
    # sweep of 29 s at 200 Hz: dwt_max_level(5800, 8) = 9 < 10 -> J lowered, warned
    sweep, fixed = simulate_pair(1, p1_s=7.5, p3_s=7.5, p2_fixed_s=25.0,
                                 sweep_oct_per_min=60.0)
    with pytest.warns(DataQualityWarning, match="levels"):
        r = analyse(sweep, fixed, FitConfig(views=False, goal=1e-2))
    assert r.metrics["level_rule"]["wavelet_level"] < 10


def test_bad_level():
    sweep, fixed = simulate_pair(1, p1_s=30.0, p3_s=30.0, p2_fixed_s=30.0,
                                 sweep_oct_per_min=60.0)
    with pytest.raises(InputError, match="level"):
        analyse(sweep, fixed, FitConfig(level=12, views=False))




def test_study_is_registered():
    from inertialab.studies.base import discover_studies

    assert discover_studies()["vibration"] is STUDY
    assert STUDY.quick.p1_s < STUDY.full.p1_s


def test_spread_by_validation_and_raw_phase_figures(short_pair):
    from inertialab.report.figures.vibration import figures, tables

    sweep, fixed = short_pair
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        r = analyse(sweep, fixed, FitConfig(spread="validate", spread_grid=(0.6, 1.2, 20.0),
                                            scalogram_phase_s=20.0))
    sel = r.fit["rbf"]["spread_selection"]
    assert r.fit["rbf"]["spread"] == sel["chosen"] == sel["grid"][
        int(sel["heldout_rmse"].index(min(sel["heldout_rmse"])))]
    assert r.model.spread == sel["chosen"]
    # raw per-phase bias and 10-s stability: vibration shifts the 500-Hz run's P2 bias
    raw = r.metrics["raw_phases"]
    assert set(raw) == {"sweep", "fixed"}
    shift = raw["fixed"]["bias"]["P2"] - raw["fixed"]["bias"]["P1"]
    assert shift == pytest.approx(float(bias_shift_dph(500.0)), abs=1.5)
    names = [f.name for f in figures(r)]
    assert "separation" in names and "sweep_waterfall" in names
    titles = [t.title for t in tables(r)]
    assert any("Raw records" in t for t in titles) and any("spread" in t for t in titles)
    with pytest.raises(InputError, match="spread"):
        analyse(sweep, None, FitConfig(spread="auto", views=False))
