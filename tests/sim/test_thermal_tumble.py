"""Tests of the thermal-tumble rig (spec 000 §7, §8.1.1-8.1.3)."""

from __future__ import annotations

import hashlib
from dataclasses import replace

import numpy as np
import pandas as pd
import pytest

from inertialab.errors import InputError
from inertialab.io import read_record, validate_frame, write_record
from inertialab.sensors.pendulous import bias_0_180, scale_factor_eq3, tumble_positions
from inertialab.sim.thermal_tumble import (
    T_REF,
    Schedule,
    drift_truth,
    make_lot,
    run_tumble,
    simulate,
)


@pytest.fixture(scope="module")
def paper_run():
    return simulate("paper", lot_seed=0, unit=0)


def _csv_hash(df) -> str:
    return hashlib.sha256(df.to_csv(index=False).encode()).hexdigest()


def test_same_seed_identical_and_other_seed_different(paper_run):
    again = simulate("paper", lot_seed=0, unit=0)
    assert _csv_hash(again.frame) == _csv_hash(paper_run.frame)
    other = simulate("paper", lot_seed=0, unit=0, seed=1)
    assert _csv_hash(other.frame) != _csv_hash(paper_run.frame)
    # the run seed changes the noise, not the unit
    assert other.unit == paper_run.unit


def test_record_shape_and_schema(paper_run, tmp_path):
    f = paper_run.frame
    assert len(f) == 23 * 24
    assert f.groupby("temp_set_c").pos_index.nunique().eq(24).all()
    assert np.all(np.abs(f.temp_meas_c - f.temp_set_c) < 2.0)
    path = tmp_path / "run.csv"
    write_record(f, path, paper_run.meta)
    rec = read_record(path, "thermal_tumble")
    np.testing.assert_array_equal(rec.data["output_mv"].to_numpy(), f.output_mv.to_numpy())
    assert rec.meta["lot_seed"] == 0
    validate_frame(f, "thermal_tumble")


def test_generator_magnitudes_paper_preset(paper_run):
    """Spec 8.1.2 (lot seed 0, unit 0)."""
    f = paper_run.frame
    k1 = paper_run.unit.ref.k1
    u = f.pivot(index="temp_set_c", columns="pos_index", values="output_mv")
    bias = pd.Series(bias_0_180(u[0], u[12]), index=u.index)
    bd = (bias - bias.loc[T_REF]) / k1 * 1e3  # mg
    assert 1.4 <= np.max(np.abs(bd)) <= 2.0
    od = (u - u.loc[T_REF]) / k1 * 1e3
    assert 4.0 <= np.max(np.abs(od.to_numpy())) <= 6.5
    slope = (bd.loc[60.0] - bd.loc[50.0]) / 10.0 * 1e3  # µg/°C
    assert 8.0 <= slope <= 16.0


def test_eq3_on_noise_free_output_matches_closed_form():
    """Spec 8.1.3: (U - K0(T))/a_i = K1c(1 + dS) + K2(T) a_i + Kipc a_p + K1c delta(T) a_p/a_i."""
    unit = make_lot(0, "paper").unit(0)
    P = tumble_positions(24)
    r = unit.ref
    for T in (-40.0, 0.0, 25.0, 70.0):
        U = unit.output_mv(T, P.a_in_g, P.a_pend_g)
        k0 = bias_0_180(U[0], U[12])
        k = scale_factor_eq3(U, k0, P.a_in_g)
        dT = T - T_REF
        a, ap = P.a_in_g, P.a_pend_g
        m = a != 0
        ds = unit.scale_drift_ppm(T, a[m])
        k2 = r.k2 + 1e-6 * unit.coef["k2T"] * dT * r.k1
        delta = unit.delta_c_urad + unit.kd_urad_per_c * dT
        expected = (r.k1 * (1 + 1e-6 * ds) + k2 * a[m] + r.kip * ap[m]
                    + 1e-6 * r.k1 * delta * ap[m] / a[m])
        np.testing.assert_allclose(k[m], expected, rtol=1e-9)


def test_noise_floor_is_of_the_spec_order(paper_run):
    # spec 7.4: "about 3-4 µg" (its prototype 2.9); white 0.5 + RW 1/sqrt(h) over 14.6 h +
    # 1.1 arcsec of angle error (3.8 µg rms) give 4-5 µg here; noise-only (no angle error)
    # is the RW-dominated 2-3 µg.
    assert 2.5 <= paper_run.noise_floor_ug <= 6.0
    assert 1.0 <= paper_run.noise_only_ug <= paper_run.noise_floor_ug
    f = paper_run.frame
    k1 = paper_run.unit.ref.k1
    floor = np.sqrt(np.mean(((f.output_mv - f.true_output_mv) / k1) ** 2)) * 1e6
    assert floor == pytest.approx(paper_run.noise_floor_ug, rel=1e-12)


def test_drift_truth_is_zero_at_reference_and_matches_seed_size():
    unit = make_lot(0, "paper").unit(0)
    assert drift_truth(unit, T_REF, 1.0) == pytest.approx(0.0, abs=1e-15)
    # spec 7.2: bias drift -1747 µg at -40 °C (lot nominal; unit spread 0.1 %)
    assert unit.bias_drift_ug(-40.0) == pytest.approx(-1747.0, rel=0.01)


def test_units_of_a_lot_differ_and_presets_spread_as_specified():
    paper = make_lot(0, "paper")
    real = make_lot(0, "realistic")
    a, b = paper.unit(0), paper.unit(1)
    assert a.unit_id != b.unit_id and a.ref.k1 != b.ref.k1
    rel = abs(a.coef["b1"] / b.coef["b1"] - 1)
    assert rel < 0.01  # sr = 0.001
    spread = np.std([real.unit(i).coef["b1"] / 12.0 for i in range(40)])
    assert 0.08 < spread < 0.25  # sr = 0.15, 40 units: SD of the SD estimate ~ 11 %


def test_realistic_sensor_lag_and_down_pass():
    lot = make_lot(2, "realistic")
    run = run_tumble(lot, 0, schedule=replace(Schedule(), ramp="up_down"))
    f = run.frame
    assert len(f) == (23 + 22) * 24
    assert set(f.ramp_dir) == {"up", "down"}
    assert f.t_s.is_monotonic_increasing
    # sensor offset N(0, 0.5) makes meas - true temperature differ by a constant
    d = (f.temp_meas_c - f.true_temp_c).to_numpy()
    assert abs(np.median(d) - run.unit.temp_offset_c) < 0.05


def test_bad_arguments():
    with pytest.raises(InputError):
        make_lot(0, "optimistic")
    with pytest.raises(InputError):
        make_lot(-1, "paper")
