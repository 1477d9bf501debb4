"""workflows.ferraris: record -> sections -> fit -> model -> apply."""

import json
import warnings

import numpy as np
import pytest

from inertialab.calib.model_types import load_model
from inertialab.calib.triaxial_checks import ImplausibleCalibrationError
from inertialab.io import write_record
from inertialab.io.modelfile import save_model
from inertialab.sim.ferraris_session import simulate_ferraris
from inertialab.workflows import ferraris as wf
from inertialab.workflows import triaxial as wt


@pytest.fixture(scope="module")
def session_file(tmp_path_factory):
    d = tmp_path_factory.mktemp("ferraris")
    rec = simulate_ferraris(seed=5, placement_deg=0.2, angle_sigma_deg=0.3)
    path = d / "session.csv"
    write_record(rec.data, path, rec.meta)
    return path, rec


def test_fit_model_file_and_apply_give_physics_back(session_file, tmp_path):
    path, rec = session_file
    record = wt.read(path)
    run = wf.fit(wf.prepare(record))
    assert run.model.method == "ferraris" and not run.model.flags
    save_model(run.model, tmp_path / "m.json", units=wf.result_units(run))
    model = load_model(tmp_path / "m.json", expected_type="triaxial-calibration")
    assert np.array_equal(model.gyro["g_sensitivity"], run.fit.K_ga)
    out = wt.apply(model, record)
    a = out.data[["ax_mps2", "ay_mps2", "az_mps2"]].to_numpy()
    w = out.data[["gx_rps", "gy_rps", "gz_rps"]].to_numpy()
    secs = rec.truth["sections"]
    # |a| = g at rest on every face
    for face in ("x_p", "x_a", "y_p", "y_a", "z_p", "z_a"):
        i, j = secs[face]["start"], secs[face]["end"]
        assert abs(np.linalg.norm(a[i:j].mean(axis=0)) - 9.81) < 1e-3
    # rate ~ 0 at rest; each turn integrates to its true angle about the vertical
    i, j = secs["z_p"]["start"], secs["z_p"]["end"]
    assert np.max(np.abs(w[i:j].mean(axis=0))) < 2e-4
    for k, ax in enumerate("xyz"):
        i, j = secs[f"{ax}_rot"]["start"], secs[f"{ax}_rot"]["end"]
        angle = w[i:j].sum(axis=0) / 102.4
        up = a[i:j].mean(axis=0) / np.linalg.norm(a[i:j].mean(axis=0))
        # the fit assumed 360 deg; the true turn differs by N(0, 0.3 deg)
        assert abs(angle @ up - np.sign(rec.truth["angles_rad"][k]) * 2 * np.pi) < np.deg2rad(1.5)
    # the gyro of a Ferraris model needs the accelerations (g-sensitivity)
    with pytest.raises(Exception, match="argument 'acc'"):
        model.apply_gyro(w[:3])


def test_sections_file_and_detection_agree(session_file, tmp_path):
    path, rec = session_file
    sp = tmp_path / "sections.json"
    sp.write_text(json.dumps(rec.truth["sections"]))
    record = wt.read(path)
    given = wf.fit(wf.prepare(record, sections=sp))
    found = wf.fit(wf.prepare(record))
    assert given.session.detection is None and found.session.detection is not None
    assert np.allclose(given.fit.faces.T, found.fit.faces.T, rtol=2e-3, atol=2e-3)
    assert np.allclose(given.fit.M_g, found.fit.M_g, rtol=5e-3, atol=2e-5)
    payload = wf.result_payload(given)
    assert payload["sections"] == rec.truth["sections"] and not payload["sections_detected"]
    assert all(abs(v["raw_angle_deg"] - 360) < 10 for v in payload["turns"].values())


def test_wrong_turn_angle_is_refused_and_force_flags(session_file):
    path, rec = session_file
    session = wf.prepare(wt.read(path))
    # stating 90-deg turns for 360-deg ones makes the gyro 4x too sensitive: implausible
    with pytest.raises(ImplausibleCalibrationError, match="K_g11, K_g22, K_g33"):
        wf.fit(session, wf.FerrarisConfig(rotation_deg=90))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        run = wf.fit(session, wf.FerrarisConfig(rotation_deg=90, force=True))
    assert run.model.flags


def test_intervals_cover_the_truth_on_a_careful_session(session_file):
    path, rec = session_file
    run = wf.fit(wf.prepare(wt.read(path)))
    ci = wf.result_payload(run)["ci95"]
    assert {"bx", "kz", "theta_zx", "bgx", "kga11"} <= set(ci)
    # gyro bias (deg/s raw): the truth inside its 95 % interval on every axis
    for c, b in zip("xyz", rec.truth["b_g_dps"]):
        lo, hi = ci[f"bg{c}"]
        assert lo <= b <= hi
