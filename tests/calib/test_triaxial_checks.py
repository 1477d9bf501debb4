"""calib.triaxial_checks: never a silent garbage model."""

import warnings
from types import SimpleNamespace

import numpy as np
import pytest

from inertialab.calib.triaxial import calibrate
from inertialab.calib.triaxial_checks import (
    Limits,
    check_accel,
    check_gyro,
    refusal,
    weak_parameters,
)
from inertialab.sensors import triaxial as tx
from inertialab.sim import triaxial_poses as tp

X_TRUE = tp.X_MPU6050_A


def sphere(n, seed):
    d = np.random.default_rng(seed).standard_normal((n, 3))
    return d / np.linalg.norm(d, axis=1)[:, None]


def test_good_fit_has_no_findings():
    a = tx.forward(X_TRUE, 9.8 * sphere(30, 1))
    f = calibrate(a, objective="norm", g=9.8)
    assert check_accel(f, a, None, 9.8) == []


def test_cap_of_poses_is_not_identifiable_and_names_the_weak_parameters():
    # 12 poses within ~25 deg of +z: the z bias and scale trade off (cond ~4e8)
    rng = np.random.default_rng(0)
    d = np.column_stack([rng.uniform(-0.4, 0.4, (12, 2)), np.ones(12)])
    d /= np.linalg.norm(d, axis=1)[:, None]
    a = tx.forward(X_TRUE, 9.8 * d) + 1e-4 * rng.standard_normal((12, 3))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        f = calibrate(a, objective="norm", g=9.8)
    found = check_accel(f, a, None, 9.8)
    assert [x.kind for x in found] == ["not identifiable"]
    assert set(found[0].parameters) == {"bz", "kz"}
    # the remedy asks for gravity-up directions away from the crowded +z cap
    assert "gravity-up along" in found[0].remedy and "(-0.06, +0.04, -1.00)" in found[0].remedy
    msg = refusal(found)
    assert "\n" not in msg and "bz, kz" in msg and "argument 'force'" in msg


def test_data_in_g_labelled_mps2_is_garbage_and_every_bound_says_so():
    # the silent-garbage case: LM converges to |b| ~ 1e3 m/s^2, |k| ~ 100
    a = tx.forward(X_TRUE, 9.8 * sphere(30, 2)) / 9.8
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        f = calibrate(a, objective="norm", g=9.8)
    kinds = {(x.kind, x.parameters) for x in check_accel(f, a, None, 9.8)}
    assert ("implausible", ("bx", "by", "bz")) in kinds
    assert ("implausible", ("kx", "ky", "kz")) in kinds


def test_norm_tolerance_catches_a_moving_pose():
    d = sphere(30, 3)
    a = tx.forward(X_TRUE, 9.8 * d)
    a[4] *= 1.1  # one "rest" that was a motion: |a| 10 % off
    f = calibrate(a, objective="norm", g=9.8)
    found = check_accel(f, a, None, 9.8)
    assert any(x.parameters == ("|a|",) and "pose 5" in x.what for x in found)
    # a looser declared tolerance accepts it
    assert not any(x.parameters == ("|a|",) for x in
                   check_accel(f, a, None, 9.8, limits=Limits(norm_tol=2.0)))


def test_bias_limit_is_declared_by_the_caller():
    a = tx.forward(X_TRUE, 9.8 * sphere(30, 4))
    f = calibrate(a, objective="norm", g=9.8)
    # true b = (0.25, -0.35, 0.55) m/s^2
    found = check_accel(f, a, None, 9.8, limits=Limits(bias=0.4))
    assert [x.parameters for x in found] == [("bz",)]
    found = check_accel(f, a, None, 9.8, limits=Limits(bias=0.3))
    assert [x.parameters for x in found] == [("by", "bz")]


def test_weak_parameters_of_a_rank_deficient_jacobian():
    J = np.array([[1.0, 1.0, 0.0], [2.0, 2.0, 0.0], [0.0, 0.0, 1.0], [1.0, 1.0, 3.0]])
    cond, names = weak_parameters(J, ["p", "q", "r"])
    assert not np.isfinite(cond) or cond > 1e12
    assert names == ("p", "q")  # p and q only ever appear as p + q


def test_gyro_checks_scale_and_missing_rotations():
    M0 = np.eye(3) / 131.0 * np.pi / 180  # counts -> rad/s
    good = SimpleNamespace(matrix=M0 @ np.eye(3), bias=np.array([10.0, -5.0, 3.0]), cond=1e3,
                           stderr_matrix=1e-3 * np.abs(M0))
    assert check_gyro(good, M0) == []
    wrong = SimpleNamespace(matrix=10 * M0, bias=np.zeros(3), cond=1e3, stderr_matrix=None)
    (f,) = check_gyro(wrong, M0)
    assert f.kind == "implausible" and f.parameters == ("m11", "m22", "m33")
    se = 1e-3 * np.ones((3, 3))
    se[:, 2] = 5.0  # the z column is unknown: no rotation about z
    blind = SimpleNamespace(matrix=M0, bias=np.zeros(3), cond=1e14, stderr_matrix=se @ M0)
    (f,) = check_gyro(blind, M0)
    assert f.kind == "not identifiable" and f.parameters == ("m13", "m23", "m33")
    assert f.remedy == "add rotations about the sensor's z axis"
    hot = SimpleNamespace(matrix=M0, bias=np.array([0.0, 0.0, 50.0 * 131]), cond=1e3,
                          stderr_matrix=None)  # 50 deg/s
    (f,) = check_gyro(hot, M0)
    assert f.parameters == ("bgz",)


@pytest.mark.parametrize("seed", [0, 1])
def test_counts_mode_unsigned_offsets_are_not_biases(seed):
    # unsigned 16-bit counts around mid-scale 32768: the common offset is no bias
    rng = np.random.default_rng(seed)
    x = np.r_[32768 + rng.uniform(-200, 200, 3), 640 * (1 + rng.uniform(-0.03, 0.03, 3)),
              rng.uniform(-0.02, 0.02, 3)]
    a = tx.forward(x, 9.80665 * sphere(38, 10 + seed))
    f = calibrate(a, objective="norm", g=9.80665, counts=True)
    assert check_accel(f, a, None, 9.80665, counts=True) == []


# ------------------------------------------------------------ counts logs and their ADC

def test_adc_range_detected_or_declared():
    from inertialab.calib.triaxial_checks import adc_range

    assert adc_range([32000, 33500, 40000]).text() == \
        "unsigned 16-bit ADC (detected), zero at 32768"
    assert (adc_range([-300, 2000]).signed, adc_range([-300, 2000]).bits) == (True, 12)
    r = adc_range([1, 2], {"bits": 16, "signed": False})
    assert (r.zero, r.source) == (32768.0, "declared")


def _unsigned_counts_session(tmp_path, shift=32768.0, gyro_extra=0.0):
    """The simulated 62-pose counts log (signed, MPU-6050 style) moved to an unsigned
    16-bit ADC (zero at mid-scale 32768), written without any stated sensitivity, as an
    Xsens MTi raw log is (imu_tk's xsens_acc.mat/xsens_gyro.mat are not in the index we
    can copy from, so the log is simulated)."""
    from inertialab.io import write_record
    from inertialab.workflows import triaxial as fc

    raw = tp.simulate("rawlog62-counts", seed=2)
    d = raw.data.copy()
    for c in ("ax_lsb", "ay_lsb", "az_lsb", "gx_lsb", "gy_lsb", "gz_lsb"):
        d[c] = d[c] + shift + (gyro_extra if c.startswith("g") else 0.0)
    meta = {k: v for k, v in raw.meta.items()
            if k not in ("lsb_per_g", "lsb_offset", "gyro_lsb_per_rps", "units")}
    p = write_record(d, tmp_path / "unsigned.csv", meta)
    return raw, fc.prepare(fc.read(p), gyro=True, k_thr=6)


def test_unsigned_counts_log_calibrates_without_force(tmp_path):
    from inertialab.workflows import triaxial as fc

    raw, session = _unsigned_counts_session(tmp_path)
    # the gate before: the mid-scale offset read as a rate (bgx ~ 4.4 rad/s) refused it
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        run = fc.fit(session, fc.FitConfig(method="lm", objective="norm"))
    assert not run.model.flags
    old = check_gyro(run.gyro_fit, run.gyro_nominal)  # without the ADC range
    assert old and old[-1].parameters == ("bgx", "bgy", "bgz")
    # and the fit is the signed log's: accelerometer offsets 32768 higher, same scale
    sig_meta = {k: v for k, v in raw.meta.items() if k not in ("lsb_per_g", "lsb_offset",
                                                               "gyro_lsb_per_rps")}
    from inertialab.io import write_record

    p = write_record(raw.data, tmp_path / "signed.csv", sig_meta)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        ref = fc.fit(fc.prepare(fc.read(p), gyro=True, k_thr=6),
                     fc.FitConfig(method="lm", objective="norm"))
    np.testing.assert_allclose(run.fit.x[:3] - 32768.0, ref.fit.x[:3], atol=1e-3)
    np.testing.assert_allclose(run.fit.x[3:], ref.fit.x[3:], rtol=1e-6, atol=1e-9)
    # the gyro matrix matches the truth to 1 % (sensitivity found in the data)
    Mt = raw.truth["gyro_M"] / tp.GYRO_LSB_PER_RPS
    assert np.max(np.abs(run.gyro_fit.matrix / Mt - 1)[np.abs(Mt) > 0.5 * Mt.max()]) < 0.01
    np.testing.assert_allclose(run.gyro_fit.bias - 32768.0, ref.gyro_fit.bias, atol=0.5)


def test_counts_bias_far_from_the_adc_zero_is_refused_naming_the_range(tmp_path):
    from inertialab.calib.triaxial_checks import ImplausibleCalibrationError
    from inertialab.workflows import triaxial as fc

    # a gyro whose zero sits 12000 counts above mid-scale: not an ADC offset a part has
    _, session = _unsigned_counts_session(tmp_path, gyro_extra=12000.0)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        with pytest.raises(ImplausibleCalibrationError,
                           match=r"implausible: bgx, bgy, bgz \(bgx = \+1\d{4}\.\d, "
                                 r"bgy = .* counts from the ADC zero \(unsigned 16-bit ADC "
                                 r"\(detected\), zero at 32768\) beyond ±8192 counts\)"):
            fc.fit(session, fc.FitConfig(method="lm", objective="norm"))
