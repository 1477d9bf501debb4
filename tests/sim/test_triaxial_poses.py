"""Virtual-lab rig triaxial-poses (spec 002 §2.2, §6)."""

import numpy as np
import pytest

from inertialab.errors import InputError
from inertialab.sensors import triaxial as tx
from inertialab.sim import triaxial_poses as tp


def test_turntable_schedule_62_positions_and_faces():
    p, h = tp.turntable_angles()
    assert p.size == 62
    assert [int(np.sum(p == q)) for q in (0, 30, 60, 90, 120, 150, 180)] == [1, 8, 14, 16, 14, 8, 1]
    r = tp.turntable_direction(p, h)
    assert np.allclose(np.linalg.norm(r, axis=1), 1.0)
    # §2.2: (90, 0) -> +x, (90, 90) -> +y, (0, .) -> +z, (180, .) -> -z
    assert np.allclose(tp.turntable_direction(90, 0), [1, 0, 0], atol=1e-15)
    assert np.allclose(tp.turntable_direction(90, 90), [0, 1, 0], atol=1e-15)
    assert np.allclose(tp.turntable_direction(180, 0), [0, 0, -1], atol=1e-15)


def test_attitude_gravity_matches_direction():
    p, h = tp.turntable_angles()
    C = tp.attitude(p, h)
    assert np.allclose(C[:, :, 2], tp.turntable_direction(p, h), atol=1e-14)
    assert np.allclose(C @ np.swapaxes(C, 1, 2), np.eye(3), atol=1e-14)


def test_clean_sphere_is_exact_forward_model():
    rec = tp.simulate("sphere1000-clean", seed=0)
    d = rec.data
    a = d[["ax_mps2", "ay_mps2", "az_mps2"]].to_numpy()
    r = 9.8 * d[["ref_x", "ref_y", "ref_z"]].to_numpy()
    assert len(d) == 1000
    assert np.max(np.abs(tx.correct(tp.X_MPU6050_A, a) - r)) < 1e-12


def test_noisy_sphere_noise_level():
    rec = tp.simulate("sphere1000-noisy", seed=3)
    d = rec.data
    a = d[["ax_mps2", "ay_mps2", "az_mps2"]].to_numpy()
    clean = d[["true_ax_mps2", "true_ay_mps2", "true_az_mps2"]].to_numpy()
    # 3000 draws: sample SD within 5 % of 0.04 (SE of an SD ~ 1.3 %)
    assert np.isclose(np.std(a - clean), tp.SIGMA_S, rtol=0.05)


def test_mount_scenario_applies_phi():
    rec = tp.simulate("turntable62-mount", seed=0)
    d = rec.data
    clean = d[["true_ax_mps2", "true_ay_mps2", "true_az_mps2"]].to_numpy()
    actual = rec.truth["directions_actual"]
    expect = tx.forward(tp.X_MPU6050_A, 9.8 * actual, phi=tp.PHI_MOUNT)
    assert np.allclose(clean, expect, atol=1e-13)
    # reference error 0.05 deg: angle between nominal and actual directions ~ sqrt(2)*0.05 deg RMS
    nom = d[["ref_x", "ref_y", "ref_z"]].to_numpy()
    ang = np.degrees(np.arccos(np.clip(np.sum(nom * actual, axis=1), -1, 1)))
    assert 0.03 < np.sqrt(np.mean(ang**2)) < 0.11


def test_realistic_is_quantised():
    d = tp.simulate("turntable62-realistic", seed=0).data
    q = 9.8 / tp.LSB_PER_G
    lsb = d["ax_mps2"].to_numpy() / q
    assert np.allclose(lsb, np.round(lsb), atol=1e-6)


def test_sixface_has_faces():
    d = tp.simulate("sixface", seed=0).data
    assert list(d["face"]) == ["+x", "-x", "+y", "-y", "+z", "-z"]


def test_same_seed_same_data_different_seed_different():
    a = tp.simulate("turntable62", seed=5).data
    b = tp.simulate("turntable62", seed=5).data
    c = tp.simulate("turntable62", seed=6).data
    assert a.equals(b) and not a.equals(c)


def test_raw_counts_log_with_gyro_is_integer_and_consistent():
    rec = tp.simulate("rawlog62-counts", seed=0)
    d = rec.data
    for c in ("ax_lsb", "gz_lsb"):
        v = d[c].to_numpy()
        assert np.array_equal(v, np.round(v))
    assert rec.meta["units"] == "lsb" and rec.meta["lsb_per_g"] == 16384.0
    # the first dwell: gyro reads the bias (rad/s * LSB per rad/s), within noise
    first = d.iloc[:1400]
    b = first[["gx_lsb", "gy_lsb", "gz_lsb"]].mean().to_numpy() / tp.GYRO_LSB_PER_RPS
    assert np.allclose(b, tp.GYRO_BIAS, atol=5e-5)  # SE = 7e-4/sqrt(1400) + rounding ~ 2e-5
    assert len(rec.schedule) == 62


def test_raw_log_gyro_rates_rotate_gravity_direction():
    # integrating the true body rates over a transition maps up_j to up_{j+1}
    rec = tp.simulate("rawlog62-gyro", seed=0)
    om, up, db = rec.truth["omega_body_rps"], rec.truth["up_body"], rec.truth["dwell_bounds"]
    a, b = db[20, 1] - 1, db[21, 0]
    R = np.eye(3)
    for k in range(a, b):
        R = R @ tx.rotation(0.5 * (om[k] + om[k + 1]) * 0.01)
    assert np.allclose(R.T @ up[a], up[b], atol=1e-4)  # trapezoid error ~1e-5


def test_line5000_truth_ranges_small_batch():
    rec = tp.simulate_line(200, seed=1)
    X = rec.truth["X"]
    assert len(rec.data) == 200 * 18
    assert np.all(np.abs(X[:, :2]) <= 0.49) and np.all(np.abs(X[:, 2]) <= 0.78)
    assert np.all((X[:, 3:6] >= 0.97) & (X[:, 3:6] <= 1.03)) and np.all(np.abs(X[:, 6:]) <= 0.02)
    assert np.allclose(np.linalg.norm(tp.rig18(), axis=1), 1.0)


def test_unknown_scenario():
    with pytest.raises(InputError, match="unknown"):
        tp.simulate("nope")
