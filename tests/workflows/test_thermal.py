"""Tests of inertialab.workflows.thermal: prepare (record validation, reference
temperature from the sidecar), fit and apply with its reference-temperature policy
(spec 000 §2.3, §3.1, §3.7)."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from inertialab.errors import InputError, MissingReferenceError
from inertialab.io import read_record, write_record
from inertialab.sim.thermal_tumble import simulate
from inertialab.workflows.thermal import (
    FitConfig,
    apply,
    drift,
    fit,
    fit_model,
    make_splits,
    prepare,
    prepare_samples,
)


@pytest.fixture(scope="module")
def run_a():
    return simulate("paper", 0, 0)


@pytest.fixture(scope="module")
def run_b():
    return simulate("paper", 0, 1, seed=1000)


@pytest.fixture(scope="module")
def model(run_a):
    s = prepare_samples(run_a.frame)
    (sp,) = make_splits(s, FitConfig(), rng=0)
    return fit_model(s, sp, "scm-anfis", FitConfig(epochs=20))


# -- prepare -------------------------------------------------------------------------------
def test_missing_reference_set_point_is_refused(run_a):
    f = run_a.frame[run_a.frame.temp_set_c != 55.0]
    with pytest.raises(MissingReferenceError, match="reference temperature 55"):
        prepare_samples(f)


def test_too_few_positions_is_refused(run_a):
    f = run_a.frame.drop(run_a.frame.index[(run_a.frame.temp_set_c == 10.0)
                                           & (run_a.frame.pos_index == 5)])
    with pytest.raises(InputError, match="set point 10 °C .* 23 distinct positions"):
        prepare_samples(f)


def test_temperature_far_from_set_point_is_refused_with_the_row(run_a):
    f = run_a.frame.copy()
    f.loc[40, "temp_meas_c"] += 3.0
    with pytest.raises(InputError, match="row 41"):
        prepare_samples(f)


def test_prepare_takes_the_reference_temperature_from_the_sidecar(run_a, tmp_path):
    # shift every temperature by -5 °C: the reference set point is now 50 °C, which
    # only the sidecar's reference_temp_C can tell
    f = run_a.frame.copy()
    for c in ("temp_set_c", "temp_meas_c"):
        f[c] = f[c] - 5.0
    p = tmp_path / "shifted.csv"
    write_record(f, p, dict(run_a.meta) | {"reference_temp_C": 50.0})
    s = prepare(read_record(p, "thermal_tumble"))
    assert s.reference_temp_c == 50.0
    base = prepare_samples(run_a.frame)
    np.testing.assert_allclose(s.y_mv, base.y_mv, rtol=0, atol=1e-9)
    write_record(f, p, dict(run_a.meta) | {"reference_temp_C": "hot"})
    with pytest.raises(InputError, match="not a number"):
        prepare(read_record(p, "thermal_tumble"))


def test_fit_verb_scores_the_requested_models(run_a):
    s = prepare_samples(run_a.frame)
    res = fit(s, FitConfig(method=("fis", "poly-2d")))
    assert list(res.metrics) == ["fis", "poly-2d"]
    summ = res.summary()
    assert summ["model_method"] == "fis" and summ["n_samples"] == 552
    assert summ["models"]["fis"]["rmse_ug"] < res.raw_rms_ug / 10


def test_random_streams_are_keyed_by_method_name_not_position(run_a):
    """A model's numbers do not depend on which other models are fitted
    beside it or in which order (before: IAFSA on interp_T seed 2 gave 4.15 µg alone and
    26.8 µg with all methods)."""
    s = prepare_samples(run_a.frame)
    cfg = FitConfig(fish=3, generations=2, search_epochs=3, epochs=10, ann_max_epochs=30,
                    seed=2)
    alone = fit(s, replace(cfg, method=("iafsa-scm-anfis",)))
    mixed = fit(s, replace(cfg, method=("ann", "fis", "iafsa-scm-anfis")))
    swapped = fit(s, replace(cfg, method=("iafsa-scm-anfis", "fis", "ann")))
    a = alone.metrics["iafsa-scm-anfis"].rmse_ug
    assert mixed.metrics["iafsa-scm-anfis"].rmse_ug == a
    assert swapped.metrics["iafsa-scm-anfis"].rmse_ug == a
    assert mixed.search["params"] == alone.search["params"]
    assert mixed.metrics["ann"].rmse_ug == swapped.metrics["ann"].rmse_ug
    # different methods still draw different streams, and the seed still matters
    other = fit(s, replace(cfg, method=("iafsa-scm-anfis",), seed=3))
    assert other.search["params"] != alone.search["params"]


# -- apply ---------------------------------------------------------------------------------
def _record(run, tmp_path, name):
    p = tmp_path / f"{name}.csv"
    write_record(run.frame, p, run.meta)
    return read_record(p, "thermal_tumble")


def test_apply_uses_the_records_own_tumble_for_another_unit(model, run_b, tmp_path):
    rec = _record(run_b, tmp_path, "b")
    res = apply(model, rec, source="m.json")
    assert res.reference == "record"
    assert res.meta["compensated_with"] == "m.json" and res.meta["reference"] == "record"
    assert {"comp_output_mv", "comp_a_g", "status"} <= set(res.frame.columns)
    assert len(res.frame) == len(rec.data)
    # the §3.7 mapping through unit B's own 55 °C coefficients is what makes transfer
    # work: the drift equals calib's transfer drift, and the acceleration is far closer
    # to the truth than when B is read in A's frame
    sb = prepare_samples(run_b.frame)
    assert res.drift.comp_max_ug == pytest.approx(drift(model, sb).comp_max_ug, rel=1e-12)
    forced = apply(model, rec, reference="model")
    assert forced.reference == "model" and forced.drift is None

    def err(r):
        return np.sqrt(np.mean((r.frame.comp_a_g - r.frame.true_a_in_g) ** 2)) * 1e6

    assert err(res) < 50 and err(forced) > 10 * err(res)


def test_apply_keeps_the_model_unit_for_its_own_record(model, run_a, tmp_path):
    res = apply(model, _record(run_a, tmp_path, "a"))
    assert res.reference == "model"
    assert res.summary()["n_rows"] == 552


def test_apply_reference_argument_is_checked(model, run_a, run_b, tmp_path):
    with pytest.raises(InputError, match="argument 'reference'"):
        apply(model, _record(run_a, tmp_path, "a"), reference="magic")
    part = replace(run_b, frame=run_b.frame[run_b.frame.temp_set_c != 55.0])
    rec = _record(part, tmp_path, "no55")
    with pytest.raises(MissingReferenceError):
        apply(model, rec, reference="record")
    assert apply(model, rec).reference == "model"  # auto falls back to the model's unit


# -- non-finite and out-of-range numbers ---------------------------------
@pytest.mark.parametrize("set_point", [10.0, 55.0])
def test_a_1e308_cell_is_an_input_error_naming_the_row(run_a, set_point):
    f = run_a.frame.copy()
    i = int(np.flatnonzero((f.temp_set_c == set_point) & (f.pos_index == 3))[0])
    f.loc[f.index[i], "output_mv"] = 1e308
    with pytest.raises(InputError, match="output_mv") as ex:
        prepare_samples(f)
    if set_point != 55.0:
        assert f"row {i + 1}" in str(ex.value)


def test_a_large_but_finite_glitch_is_refused_too(run_a):
    f = run_a.frame.copy()
    f.loc[f.index[100], "output_mv"] += 5000.0  # a 5 g "drift"
    with pytest.raises(InputError, match="row 101.*not a temperature drift"):
        prepare_samples(f)


def test_compensate_refuses_nan_in_and_nan_out(model, run_a):
    from inertialab.calib.thermal import compensate

    T = np.array([20.0, 25.0])
    with pytest.raises(InputError, match="column 'output_mv', row 2"):
        compensate(model, T, np.array([500.0, np.nan]))
    from inertialab.learn.anfis import ANFIS

    reg = ANFIS.from_dict(model.regressor.to_dict())
    reg.fis_.consequents[:] = np.nan
    with pytest.raises(InputError, match="non-finite output"):
        compensate(replace(model, regressor=reg), T, np.array([500.0, 600.0]))


def test_model_files_with_nan_or_nonsense_are_refused(model, tmp_path):
    import json

    from inertialab.calib.model_types import load_model
    from inertialab.io.modelfile import save_model

    save_model(model, tmp_path / "m.json")
    env = json.loads((tmp_path / "m.json").read_text())
    cases = {"ref": ("ref", "k1", float("nan")), "cons": None, "range": None,
             "method": ("method", None, "rm -rf")}
    for name, change in cases.items():
        e = json.loads(json.dumps(env))
        pl = e["payload"]
        if name == "cons":
            pl["regressor"]["fis"]["consequents"][0][0] = float("inf")
        elif name == "range":
            pl["t_range_c"] = [70.0, -40.0]
        elif change[1] is None:
            pl[change[0]] = change[2]
        else:
            pl[change[0]][change[1]] = change[2]
        (tmp_path / f"{name}.json").write_text(json.dumps(e))
        # refused either by the shared model-file checks (non-finite numbers) or by the
        # thermal model's own plausibility checks
        with pytest.raises(InputError, match="thermal model|non-finite|thermal-compensation"):
            load_model(tmp_path / f"{name}.json")
    assert load_model(tmp_path / "m.json").method == "scm-anfis"


def test_apply_with_a_1e308_cell_is_an_error_naming_the_row(model, run_b, tmp_path):
    f = run_b.frame.copy()
    f.loc[f.index[7], "output_mv"] = 1e308
    p = tmp_path / "big.csv"
    write_record(f, p, run_b.meta)
    # the record's tumble is refused (auto falls back to the model's unit); then the
    # model input overflows on that row: an error, not a NaN or clamped output
    with pytest.raises(InputError, match="row 8"):
        apply(model, read_record(p, "thermal_tumble"))


def test_the_study_in_one_module_and_the_old_name_warns():
    """workflows/thermal.py holds the commands' settings and calls and starts without the
    estimator floor; thermal_run still answers, with a DeprecationWarning; the command's
    spelling (visual, step, try_number, crowd) is the estimator's; the former class
    ThermalConfig (fish_visual ...) warns and gives the same settings."""
    import importlib
    import sys
    import warnings

    from inertialab.calib.thermal import fish_params
    from inertialab.workflows import thermal

    cfg = thermal.FitConfig(method="fis", visual=0.5, step=0.2, try_number=7, crowd=0.5)
    assert fish_params(cfg) == {"visual": 0.5, "step": 0.2, "try_number": 7, "crowd": 0.5}
    with pytest.warns(DeprecationWarning, match="FitConfig"):
        old_cfg = thermal.ThermalConfig(methods=("fis",), fish_visual=0.5, fish_step=0.2,
                                        fish_try_number=7, fish_crowd=0.5)
    assert old_cfg.methods == ("fis",) and replace(old_cfg, method="fis") == cfg
    sys.modules.pop("inertialab.workflows.thermal_run", None)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        old = importlib.import_module("inertialab.workflows.thermal_run")
    assert old.run_fit is thermal.run_fit and old.FitConfig is thermal.FitConfig
    assert any(issubclass(w.category, DeprecationWarning) for w in caught)
