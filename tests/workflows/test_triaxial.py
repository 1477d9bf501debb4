"""workflows.triaxial: records -> static data (units, references, detection, saturation) and
the accelerometer + gyro session fit (spec 002 §2.3-2.4, §7.3)."""

import warnings

import numpy as np
import pytest

from inertialab.errors import InputError, UnderdeterminedError
from inertialab.sim import triaxial_poses as tp
from inertialab.workflows import triaxial as fc

X_TRUE = tp.X_MPU6050_A


def test_counts_with_lsb_per_g_folds_conversion_into_the_matrix():
    rec = tp.simulate("turntable62", seed=2)
    df = rec.data.copy()
    q = 16384 / 9.8
    for c in "xyz":
        df[f"a{c}_lsb"] = df.pop(f"a{c}_mps2") * q + 100.0
    meta = dict(rec.meta, units="lsb", lsb_per_g=16384, lsb_offset=100.0)
    sd = fc.static_data_from_frame(df, meta)
    assert not sd.counts
    f = fc.calibrate(sd.a, ref=sd.ref, objective="scalar", g=sd.g)
    m = fc.to_model(f, sd)
    raw = df[["ax_lsb", "ay_lsb", "az_lsb"]].to_numpy()
    ref = sd.ref
    # calibrated vectors agree with references to the noise + 0.05 deg reference error level
    assert np.sqrt(np.mean(np.sum((m.apply(raw) - ref) ** 2, axis=1))) < 0.03


def test_raw_counts_log_with_gyro_end_to_end():
    # counts log -> detection -> accelerometer -> gyro
    raw = tp.simulate("rawlog62-counts", seed=2)
    d = raw.data
    t = d["t_s"].to_numpy()
    data = fc.raw_log_data(t, d[["ax_lsb", "ay_lsb", "az_lsb"]].to_numpy(), raw.meta, suffix="lsb")
    assert data.intervals.count == 62
    run = fc.calibrate_record_data(data, objective="norm",
                                   gyro_raw=d[["gx_lsb", "gy_lsb", "gz_lsb"]].to_numpy(), t=t,
                                   gyro_suffix="lsb", meta=raw.meta)
    # accelerometer: sigma_rec ~ 0.04/sqrt(400) = 2e-3 m/s^2 -> parameter SEs ~1e-3; 3e-3 bound
    assert np.max(np.abs(run.fit.x - X_TRUE)) < 3e-3
    # gyro: within 4 standard errors (+1e-4 for the rest-bias leak, see test_gyro_triad)
    Mt = raw.truth["gyro_M"] / tp.GYRO_LSB_PER_RPS
    err = np.abs(run.gyro_fit.matrix - Mt) * tp.GYRO_LSB_PER_RPS
    assert np.all(err <= 4 * run.gyro_fit.stderr_matrix * tp.GYRO_LSB_PER_RPS + 1e-4)
    assert np.allclose(run.gyro_fit.bias / tp.GYRO_LSB_PER_RPS, tp.GYRO_BIAS, atol=1e-4)
    # the model maps raw gyro counts at rest to ~0 rad/s
    m = run.model
    rest = d[["gx_lsb", "gy_lsb", "gz_lsb"]].to_numpy()[:1000]
    assert np.max(np.abs(m.apply_gyro(rest).mean(axis=0))) < 1e-4
    assert m.gyro["raw_unit"] == "lsb" and m.static_intervals == 62


def test_gyro_counts_start_from_the_data_without_a_sensitivity():
    # a counts log without gyro_lsb_per_rps starts M_g from the data (motion
    # angle between gravity directions / integrated raw rate) and reaches the same optimum
    raw = tp.simulate("rawlog62-counts", seed=2)
    d = raw.data
    meta = {k: v for k, v in raw.meta.items() if k != "gyro_lsb_per_rps"}
    data = fc.raw_log_data(d["t_s"].to_numpy(), d[["ax_lsb", "ay_lsb", "az_lsb"]].to_numpy(), meta,
                           suffix="lsb", k_thr=6)
    kw = dict(gyro_raw=d[["gx_lsb", "gy_lsb", "gz_lsb"]].to_numpy(), t=d["t_s"].to_numpy(),
              gyro_suffix="lsb")
    free = fc.calibrate_record_data(data, meta=meta, **kw)
    hinted = fc.calibrate_record_data(data, meta=raw.meta, **kw)
    assert free.model.gyro["start_from"] == "data" and hinted.model.gyro["start_from"] == "unit"
    # the start is within a few per cent of the true 1/(131 LSB per deg/s)
    assert abs(free.gyro_nominal[0, 0] * tp.GYRO_LSB_PER_RPS - 1) < 0.05
    # the same optimum to 1e-6 of the matrix's scale (element-wise relative limits would
    # ask 1e-12 absolute of a near-zero off-diagonal, below the solver's stopping point;
    # the elements' standard errors are ~5e-7)
    scale = np.max(np.abs(hinted.gyro_fit.matrix))
    assert np.allclose(free.gyro_fit.matrix, hinted.gyro_fit.matrix, rtol=0, atol=1e-6 * scale)


def test_schedule_matched_in_time_order_and_count_mismatch():
    raw = tp.simulate("rawlog62", seed=0)
    d = raw.data
    t, a = d["t_s"].to_numpy(), d[["ax_mps2", "ay_mps2", "az_mps2"]].to_numpy()
    data = fc.raw_log_data(t, a, raw.meta, suffix="mps2", schedule=raw.schedule)
    f = fc.calibrate(data.a, ref=data.ref, objective="scalar", g=data.g)
    assert np.max(np.abs(f.x - X_TRUE)) < 3e-3
    with pytest.raises(InputError, match="exactly 61"):
        fc.raw_log_data(t, a, raw.meta, suffix="mps2", schedule=raw.schedule.iloc[:61])


def test_saturated_static_records_are_dropped_then_refused():
    rec = tp.simulate("turntable62", seed=0)
    df = rec.data.copy()
    for c in "xyz":
        df[f"a{c}_lsb"] = np.round(df.pop(f"a{c}_mps2") / 9.8 * 16384)
    df.loc[:55, "az_lsb"] = 32767  # 56 records at the rail
    meta = dict(rec.meta, units="lsb", lsb_per_g=16384)
    with warnings.catch_warnings(record=True) as w:
        warnings.simplefilter("always")
        sd = fc.static_data_from_frame(df, meta)
    assert any("saturated" in str(x.message) for x in w)
    assert sd.a.shape[0] == 6
    with pytest.raises(UnderdeterminedError, match="6 usable records"):
        fc.calibrate(sd.a, objective="norm", g=sd.g)


def test_absolute_threshold_in_working_units():
    raw = tp.simulate("rawlog62-counts", seed=2)
    d = raw.data
    t, a = d["t_s"].to_numpy(), d[["ax_lsb", "ay_lsb", "az_lsb"]].to_numpy()
    swept = fc.raw_log_data(t, a, raw.meta, suffix="lsb")
    # the sweep's threshold is k * s0 in (m/s^2)^2 (lsb_per_g known); reuse it as absolute
    fixed = fc.raw_log_data(t, a, raw.meta, suffix="lsb", threshold=swept.intervals.threshold)
    assert np.array_equal(fixed.intervals.start, swept.intervals.start)
    assert fixed.k_thr is None


def _g_as_mps2_record(tmp_path, factor=1.0 / 9.8):
    # static records in g written as m/s^2 (refused on reading: they look like g), or
    # three times too large (a wrong LSB size: read, then refused by the gate)
    from inertialab.sensors import triaxial as tx

    d = np.random.default_rng(2).standard_normal((30, 3))
    d /= np.linalg.norm(d, axis=1)[:, None]
    a = tx.forward(X_TRUE, 9.8 * d) * factor
    path = tmp_path / "g.static.csv"
    path.write_text("# g_local=9.8\npos_id,ax_mps2,ay_mps2,az_mps2\n" + "".join(
        f"{i + 1},{v[0]:.9f},{v[1]:.9f},{v[2]:.9f}\n" for i, v in enumerate(a)))
    return path


def test_garbage_fit_is_refused_forced_fit_is_flagged_and_apply_refuses_it(tmp_path):
    from inertialab.calib.triaxial_checks import ImplausibleCalibrationError

    with pytest.raises(InputError, match="look like g, not mps2"):
        fc.read(_g_as_mps2_record(tmp_path))
    rec = fc.read(_g_as_mps2_record(tmp_path, factor=3.0))
    session = fc.prepare(rec)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        with pytest.raises(ImplausibleCalibrationError, match="implausible: kx, ky, kz"):
            fc.fit(session)
        run = fc.fit(session, fc.FitConfig(force=True))
    assert run.model.flags and any("kx, ky, kz" in f for f in run.model.flags)
    d = run.model.to_dict()
    assert d["flags"] == run.model.flags
    assert type(run.model).from_dict(d).flags == run.model.flags
    with pytest.raises(InputError, match="flagged.*argument 'force'"):
        fc.apply(run.model, rec)
    out = fc.apply(run.model, rec, force=True)
    assert {"ax_mps2", "ay_mps2", "az_mps2"} <= set(out.data.columns)


def test_wrong_gyro_sensitivity_is_refused():
    # a stated gyro sensitivity (counts per rad/s) 4x off either way: the LM still finds the
    # gyro, whose scale relative to the stated nominal is then 1/4 or 4 - implausible
    raw = tp.simulate("rawlog62-counts", seed=2)
    d = raw.data
    data = fc.raw_log_data(d["t_s"].to_numpy(), d[["ax_lsb", "ay_lsb", "az_lsb"]].to_numpy(),
                           raw.meta, suffix="lsb", k_thr=6)
    session = fc.Session(data=data, meta=raw.meta, t=d["t_s"].to_numpy(),
                         gyro_raw=d[["gx_lsb", "gy_lsb", "gz_lsb"]].to_numpy(), gyro_suffix="lsb")
    from inertialab.calib.triaxial_checks import ImplausibleCalibrationError

    for factor, scale in ((4.0, "0.2"), (0.25, "3.9")):
        with pytest.raises(ImplausibleCalibrationError,
                           match=rf"implausible: m11, m22, m33 \(gyro scale m11 = {scale}"):
            fc.fit(session, fc.FitConfig(gyro_lsb_per_rps=tp.GYRO_LSB_PER_RPS / factor))
    assert not fc.fit(session, fc.FitConfig()).model.flags  # the header's value is right


def test_quality_eq21_per_pose_intervals_and_coverage():
    # eq.-21 quality, per-pose intervals and coverage on a turntable record with references (LM-S9)
    from scipy import stats

    from inertialab.metrics import vector_error
    from inertialab.sensors import triaxial as tx

    rec = tp.simulate("turntable62", seed=3)
    data = fc.static_data_from_frame(rec.data, rec.meta)
    run = fc.calibrate_record_data(data, objective="scalar")
    q = fc.quality(run)
    a_cal = tx.correct(run.fit.x, data.a)
    ve = vector_error(data.ref, a_cal)
    assert q["eq21"]["rmse_mps2"] == ve.rmse and q["eq21"]["sd_mps2"] == ve.sd
    assert len(q["per_pose"]) == 62 and q["per_pose"][0]["pos_id"] == 1
    assert np.isclose(q["per_pose"][5]["vector_error_mps2"], np.linalg.norm(data.ref[5] - a_cal[5]))
    assert q["dof"] == 62 * 3 - 9
    lo, hi = q["ci95"]["kx"]
    se = run.fit.stderr[3]
    assert np.isclose(hi - lo, 2 * stats.t.ppf(0.975, q["dof"]) * se)
    ev = q["coverage"]["eigenvalues"]
    assert np.isclose(sum(ev), 1.0) and min(ev) > 0.2  # the 62 poses cover the sphere


def test_ci95_covers_the_truth_about_95_percent():
    # 40 noisy sphere sets x 9 parameters: the fraction of intervals holding the truth
    hits = []
    for s in range(40):
        rec = tp.simulate("sphere1000-noisy", seed=300 + s)
        data = fc.static_data_from_frame(rec.data, rec.meta)
        q = fc.quality(fc.calibrate_record_data(data, objective="scalar"))
        for j, name in enumerate(("bx", "by", "bz", "kx", "ky", "kz", "theta_yz", "theta_zy",
                                  "theta_zx")):
            lo, hi = q["ci95"][name]
            hits.append(lo <= X_TRUE[j] <= hi)
    assert 0.90 <= np.mean(hits) <= 0.99


def test_the_study_in_one_module_one_config_and_the_old_names_warn():
    """workflows/triaxial.py holds the commands' settings and calls; the command's
    FitConfig is the settings of prepare and fit and its fields are the JSON keys of
    ``settings``; triaxial_run and the old Config still answer, with a DeprecationWarning."""
    import importlib
    import sys
    import warnings

    cfg = fc.FitConfig(t_init_s=5.0, bias_limit_mps2=2.0)
    assert {f.name: m["flag"] for f, m in fc.FitConfig.fields()
            if f.name in ("t_init_s", "bias_limit_mps2")} == {"t_init_s": "t-init",
                                                             "bias_limit_mps2": "bias-limit"}
    written = cfg.written()
    assert written["t_init_s"] == 5.0 and written["bias_limit_mps2"] == 2.0
    assert not set(fc.NOT_WRITTEN) & set(written)
    assert cfg.limits({"adc": {"bits": 12, "signed": False}}).bias == 2.0
    sys.modules.pop("inertialab.workflows.triaxial_run", None)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        old = importlib.import_module("inertialab.workflows.triaxial_run")
        assert fc.Config is fc.FitConfig
    assert old.run_fit is fc.run_fit and old.FitConfig is fc.FitConfig
    assert sum(issubclass(w.category, DeprecationWarning) for w in caught) == 2


def test_raw_log_detected_and_integrated_at_the_records_time_base():
    # the record decides the rate (here the caller's 101 Hz over the stamps' 100 Hz);
    # detection and the gyro integration take it from record.timebase
    from inertialab.io import validate_frame

    raw = tp.simulate("rawlog62-counts", seed=2)
    rec = validate_frame(raw.data, "triaxial_raw", meta=raw.meta, rate_hz=101.0)
    session = fc.prepare(rec, gyro=True, k_thr=6)
    assert rec.timebase.rate_hz == session.data.intervals.fs == 101.0
    plain = fc.prepare(validate_frame(raw.data, "triaxial_raw", meta=raw.meta), k_thr=6)
    assert plain.data.intervals.fs == 100.0  # the sidecar's fs_hz
