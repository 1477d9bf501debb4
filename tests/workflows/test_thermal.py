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
    ThermalConfig,
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
    (sp,) = make_splits(s, ThermalConfig(), rng=0)
    return fit_model(s, sp, "scm-anfis", ThermalConfig(epochs=20))


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
    res = fit(s, ThermalConfig(methods=("fis", "poly-2d")))
    assert list(res.metrics) == ["fis", "poly-2d"]
    summ = res.summary()
    assert summ["model_method"] == "fis" and summ["n_samples"] == 552
    assert summ["models"]["fis"]["rmse_ug"] < res.raw_rms_ug / 10


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
