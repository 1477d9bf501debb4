"""calib.ferraris against the truth of the virtual Ferraris session."""

import json

import numpy as np
import pytest

from inertialab.calib import ferraris as fr
from inertialab.errors import InputError
from inertialab.sim.ferraris_session import simulate_ferraris

FS = 102.4


def arrays(rec):
    d = rec.data
    cols = ("ax_mps2", "ay_mps2", "az_mps2", "gx_dps", "gy_dps", "gz_dps")
    if "ax_lsb" in d.columns:
        cols = tuple(c.replace("_mps2", "_lsb").replace("_dps", "_lsb") for c in cols)
    x = d[list(cols)].to_numpy()
    return x[:, :3], x[:, 3:]


def frame(tr, fit):
    """Rotation from the housing frame to the fit's output frame (nearest orthogonal)."""
    Qt = np.linalg.solve(tr["T_a"], fit.faces.T)
    u, _, vt = np.linalg.svd(Qt)
    return u @ vt


@pytest.mark.parametrize("seed", [0, 3])
def test_detection_finds_every_section_and_sense(seed):
    rec = simulate_ferraris(seed=seed)
    acc, gyr = arrays(rec)
    det = fr.detect_sections(acc, gyr, FS)
    truth = rec.truth["sections"]
    for name in fr.SECTIONS:
        i, j = det.sections[name]
        ti, tj = truth[name]["start"], truth[name]["end"]
        if name.endswith("_rot"):  # the turn lies inside the motion between two rests
            assert i <= ti + 5 and j >= tj - 5 and (j - i) < (tj - ti) + 1.0 * FS
        else:  # the face rest lies inside the true dwell (x_p merges with the first rest)
            assert i >= ti - (6 * FS if name == "x_p" else 0) and j <= tj and j - i > 4 * FS
    assert det.senses == dict(zip(fr.ROT_SECTIONS, rec.truth["senses"].astype(int).tolist()))


def test_turns_about_the_vertical_are_not_rests_even_with_a_still_accelerometer():
    # no shake: during a turn about the vertical the accelerometer is as still as at rest;
    # only the gyro tells the turn from a rest (the failure of an accelerometer-only detector)
    rec = simulate_ferraris(seed=2, shake_mps2=0.0)
    acc, gyr = arrays(rec)
    det = fr.detect_sections(acc, gyr, FS)
    i, j = rec.truth["sections"]["y_rot"]["start"], rec.truth["sections"]["y_rot"]["end"]
    mid = slice(i + (j - i) // 4, j - (j - i) // 4)
    assert np.all(det.acc_var[mid] < det.thresholds["acc_var"])  # accelerometer "still"
    assert not det.rest_mask[mid].any()  # but not a rest
    assert set(det.sections) == set(fr.SECTIONS)


def test_careful_hand_recovers_the_truth():
    # faces within 0.2 deg, exact 360-deg turns: everything to noise level
    rec = simulate_ferraris(seed=5, placement_deg=0.2, angle_sigma_deg=0.0)
    acc, gyr = arrays(rec)
    tr = rec.truth
    f = fr.fit_ferraris(acc, gyr, FS, fr.detect_sections(acc, gyr, FS).sections, g=9.81)
    Q = frame(tr, f)
    dps = np.rad2deg(1.0)
    # accelerometer: scale (row norms, imucal's K_a) and bias
    assert np.allclose(np.linalg.norm(f.faces.T, axis=1) / np.linalg.norm(tr["T_a"], axis=1),
                       1, atol=1e-3)
    assert np.max(np.abs(f.faces.b - tr["b_a"])) < 0.01
    # gyro in the fit's frame: T_g (raw per rad/s), bias, g-sensitivity
    assert np.max(np.abs(f.T_g / dps - tr["T_g_dps"] @ Q)) < 0.01
    assert np.allclose(np.linalg.norm(f.T_g, axis=1) / dps, np.linalg.norm(tr["T_g_dps"], axis=1),
                       rtol=1e-3)
    assert np.max(np.abs(f.b_g - tr["b_g_dps"])) < 0.003
    assert np.max(np.abs(f.K_ga - tr["K_ga_dps"] @ Q)) < 1e-3


@pytest.mark.parametrize("seed", range(4))
def test_rough_hand_gravity_exact_scales_to_second_order(seed):
    # 2 deg per-axis placement tilts, 1 deg turn errors: |a| = g on every face; scale
    # factors are second order in the tilt (measured max 0.19 % accelerometer); the gyro
    # scales carry the turn-angle error plus the tilt's shear of the frame (measured max
    # 1.0 % over 10 seeds). Misalignments are first order in the tilt: not tested tighter
    # than the placement itself.
    rec = simulate_ferraris(seed=seed)
    acc, gyr = arrays(rec)
    tr = rec.truth
    f = fr.fit_ferraris(acc, gyr, FS, fr.detect_sections(acc, gyr, FS).sections, g=9.81)
    assert np.max(np.abs(f.faces.norm_residual)) < 1e-4 * 9.81
    ka = np.linalg.norm(f.faces.T, axis=1) / np.linalg.norm(tr["T_a"], axis=1)
    assert np.max(np.abs(ka - 1)) < 5e-3
    kg = np.linalg.norm(f.T_g, axis=1) / np.rad2deg(1) / np.linalg.norm(tr["T_g_dps"], axis=1)
    assert np.max(np.abs(kg - 1)) < 0.015
    Q = frame(tr, f)
    assert np.rad2deg(np.arccos((np.trace(Q) - 1) / 2)) < 3 * 2.0 * np.sqrt(3)


def test_counts_session_and_section_list_round_trip(tmp_path):
    rec = simulate_ferraris(seed=6, counts=True, placement_deg=0.2, angle_sigma_deg=0.0)
    acc, gyr = arrays(rec)
    path = tmp_path / "s.sections.json"
    path.write_text(json.dumps(rec.truth["sections"]))
    secs = fr.load_sections(path, len(acc))
    f = fr.fit_ferraris(acc, gyr, FS, secs, g=9.81)
    # counts: T_a in counts per m/s^2 = 16384/9.81 x the true gain
    ka = np.linalg.norm(f.faces.T, axis=1) / (16384 / 9.81 * np.linalg.norm(rec.truth["T_a"], axis=1))
    assert np.allclose(ka, 1, atol=2e-3)
    kg = np.linalg.norm(f.T_g, axis=1) / (131 * np.rad2deg(1) * np.linalg.norm(rec.truth["T_g_dps"],
                                                                               axis=1))
    assert np.allclose(kg, 1, atol=2e-3)
    assert fr.sections_to_dict(secs) == rec.truth["sections"]


def test_bad_section_lists_are_one_line_errors(tmp_path):
    good = {s: {"start": 10 * i, "end": 10 * i + 5} for i, s in enumerate(fr.SECTIONS)}
    bad = dict(good)
    del bad["y_rot"]
    with pytest.raises(InputError, match="lacks y_rot"):
        fr.sections_from_dict(bad, 1000)
    bad = dict(good, x_a={"start": 5, "end": 5000})
    with pytest.raises(InputError, match="x_a.*outside"):
        fr.sections_from_dict(bad, 1000)
    p = tmp_path / "x.json"
    p.write_text("{not json")
    with pytest.raises(InputError, match="not a JSON section list"):
        fr.load_sections(p, 1000)


def test_a_session_without_turns_names_what_is_missing():
    rec = simulate_ferraris(seed=0)
    acc, gyr = arrays(rec)
    n = rec.truth["sections"]["x_rot"]["start"] - 200
    with pytest.raises(InputError, match="not found: x_rot, y_rot, z_rot"):
        fr.detect_sections(acc[:n], gyr[:n], FS)


def test_model_fixture_ferraris_v1_still_loads_and_applies():
    # tests/data/models/triaxial-calibration-ferraris-v1.json (provenance in
    # tests/data/README.md): a Ferraris model with g-sensitivity and a flag; the outputs
    # below were printed (10 significant digits) when it was written
    from pathlib import Path

    from inertialab.calib.model_types import load_model

    path = (Path(__file__).resolve().parents[1] / "data" / "models"
            / "triaxial-calibration-ferraris-v1.json")
    m = load_model(path, expected_type="triaxial-calibration")
    assert m.method == "ferraris" and m.flags == ["example flag: written with force"]
    pa = np.array([[0.3, -0.2, 9.9], [9.7, 0.1, 0.5]])
    pg = np.array([[1.0, -0.5, 0.4], [30.0, 2.0, -1.0]])
    a = m.apply(pa)
    want_a = np.array([[8.0010487094e-02, 2.0379824341e-01, 9.2421108850e+00],
                       [9.2551069631e+00, 5.0935751676e-01, -6.8204784102e-03]])
    assert np.allclose(a, want_a, rtol=1e-9, atol=1e-11)
    want_w = np.array([[-0.0054506114, 0.007351117, -0.0015776419],
                       [0.4935467686, 0.0501567982, -0.0277670934]])
    assert np.allclose(m.apply_gyro(pg, acc=a), want_w, rtol=1e-8, atol=1e-10)


def test_model_fixture_ferraris_calibration_v1_loads_typed_and_applies():
    # tests/data/models/ferraris-calibration-v1.json: the payload of the fixture above under
    # the tag of its own class; same numbers out, and it serves where a triaxial
    # calibration is asked for
    from pathlib import Path

    from inertialab.calib.base import GyroBlock, gyro_block
    from inertialab.calib.model_types import load_model
    from inertialab.calib.triaxial import TriaxialCalibration

    models = Path(__file__).resolve().parents[1] / "data" / "models"
    m = load_model(models / "ferraris-calibration-v1.json", expected_type="triaxial-calibration")
    old = load_model(models / "triaxial-calibration-ferraris-v1.json")
    assert type(m) is fr.FerrarisCalibration and isinstance(m, TriaxialCalibration)
    assert type(old) is TriaxialCalibration  # the tag decides the class
    assert isinstance(m.gyro, GyroBlock) and gyro_block(m) is m.gyro
    assert m.to_dict() == old.to_dict()
    pa = np.array([[0.3, -0.2, 9.9], [9.7, 0.1, 0.5]])
    pg = np.array([[1.0, -0.5, 0.4], [30.0, 2.0, -1.0]])
    a = m.apply(pa)
    want_w = np.array([[-0.0054506114, 0.007351117, -0.0015776419],
                       [0.4935467686, 0.0501567982, -0.0277670934]])
    assert np.array_equal(a, old.apply(pa))
    assert np.allclose(m.apply_gyro(pg, acc=a), want_w, rtol=1e-8, atol=1e-10)
    # the typed block computes the same rates as the stored layout's formula
    assert np.array_equal(m.gyro.apply(pg, acc=a), old.apply_gyro(pg, acc=a))
    with pytest.raises(InputError, match="expected 'thermal-compensation'"):
        load_model(models / "ferraris-calibration-v1.json", expected_type="thermal-compensation")
    # a triaxial calibration does not serve where a Ferraris one is asked for
    with pytest.raises(InputError, match="expected 'ferraris-calibration'"):
        load_model(models / "triaxial-calibration-v1.json", expected_type="ferraris-calibration")


def test_to_model_is_a_ferraris_calibration_that_round_trips(tmp_path):
    from inertialab.calib.model_types import load_model, save_model

    rec = simulate_ferraris(seed=2, placement_deg=0.5)
    acc, gyr = arrays(rec)
    f = fr.fit_ferraris(acc, gyr, FS, fr.detect_sections(acc, gyr, FS).sections, g=9.81)
    m = fr.to_model(f, acc_unit="mps2", gyro_unit="dps", g=9.81, n_samples=len(acc))
    assert type(m) is fr.FerrarisCalibration
    assert np.array_equal(m.gyro.correction_matrix, f.M_g)
    assert np.array_equal(m.gyro.g_sensitivity, f.K_ga)
    assert m.gyro["turns"]["x_rot"]["sense"] == int(f.senses[0])
    path = save_model(m, tmp_path / "m.json")
    assert json.loads(path.read_text())["type"] == "ferraris-calibration"
    back = load_model(path)
    assert type(back) is fr.FerrarisCalibration
    assert json.dumps(back.to_dict(), sort_keys=True, default=list) == \
        json.dumps(m.to_dict(), sort_keys=True, default=list)
    w = back.apply_gyro(gyr[:50], acc=back.apply(acc[:50]))
    assert np.array_equal(w, m.apply_gyro(gyr[:50], acc=m.apply(acc[:50])))
    # no gyro block: not a Ferraris calibration
    d = m.to_dict()
    d["gyro"] = None
    with pytest.raises(InputError, match="no gyro block"):
        fr.FerrarisCalibration.from_dict(d)
