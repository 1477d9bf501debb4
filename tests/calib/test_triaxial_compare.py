"""calib.triaxial_compare: per-method parameter tables and the six-face error comparison
from the user's data (spec 002 Tables 3-6, 8-9, 11-12 and Fig. 8)."""

import numpy as np
import pytest

from inertialab.calib import triaxial_compare as tc
from inertialab.sensors.triaxial import correct
from inertialab.sim import triaxial_poses as tp
from inertialab.workflows import triaxial as wf


@pytest.fixture(scope="module")
def sixface_runs():
    rec = tp.simulate("sixface", seed=0)
    session = wf.Session(data=wf.static_data_from_frame(rec.data, rec.meta), meta=rec.meta)
    cfg = wf.FitConfig(objective="scalar", max_generations=150)
    runs, skipped = wf.fit_methods(session, cfg, wf.methods_from("all"))
    return session, runs, skipped


def test_every_method_that_can_run_does_and_the_others_say_why(sixface_runs):
    _, runs, skipped = sixface_runs
    assert list(runs) == ["lm", "acs", "cs", "pso", "six-position"]
    # the ellipsoid needs >= 10 poses; six faces are too few, and the reason is kept
    assert list(skipped) == ["ellipsoid"] and "6 usable records" in skipped["ellipsoid"]
    # each setting reached only the methods that use it (no refusal for six-position)
    assert runs["acs"].fit.iterations <= 150 and runs["six-position"].fit.method == "six-position"


def test_parameter_table_holds_the_fitted_parameters_and_intervals(sixface_runs):
    _, runs, _ = sixface_runs
    table = tc.parameter_table(runs)
    assert len(table) == 9 * len(runs)
    for name, run in runs.items():
        rows = table[table["method"] == name]
        assert rows["parameter"].tolist() == ["bx", "by", "bz", "kx", "ky", "kz", "theta_yz", "theta_zy", "theta_zx"]
        np.testing.assert_array_equal(rows["value"].to_numpy(), run.fit.x)
        np.testing.assert_array_equal(rows["stderr"].to_numpy(), np.asarray(run.fit.stderr))
        # 95 % t-interval, 18 residuals - 9 parameters = 9 dof (t = 2.262)
        half = (rows["ci95_high"] - rows["ci95_low"]).to_numpy() / 2
        np.testing.assert_allclose(half, 2.2621571627 * np.asarray(run.fit.stderr), rtol=1e-9)
        assert set(rows["unit"]) == {"m/s^2", "1", "rad"}
    md = tc.markdown(table)
    assert md.count("\n") == len(table) + 2 and f"{runs['lm'].fit.x[0]:.6g}" in md


def test_six_face_errors_are_eq21_of_each_model_against_the_face_references(sixface_runs):
    session, runs, _ = sixface_runs
    poses = tc.pose_error_table(runs)
    data = session.data
    for name, run in runs.items():
        rows = poses[poses["method"] == name]
        assert rows["pose"].tolist() == ["+x", "-x", "+y", "-y", "+z", "-z"]
        a_cal = correct(run.fit.x, data.a)  # independent of quality(): direct eq. 21
        np.testing.assert_allclose(rows["vector_error_mps2"], np.linalg.norm(data.ref - a_cal,
                                                                             axis=1), rtol=1e-12)
        np.testing.assert_allclose(rows["norm_error_mps2"],
                                   np.linalg.norm(a_cal, axis=1) - data.g, rtol=1e-12)
    summ = tc.error_summary(poses).set_index("method")
    e = poses.loc[poses["method"] == "lm", "vector_error_mps2"].to_numpy()
    assert summ.loc["lm", "eq21_rmse_mps2"] == pytest.approx(np.sqrt(np.mean(e**2)), rel=1e-12)
    assert summ.loc["lm", "eq21_sd_mps2"] == pytest.approx(np.std(e, ddof=1), rel=1e-12)
    # the six-position face fit puts every face on |a| = g
    assert summ.loc["six-position", "norm_max_abs_mps2"] < 1e-9


def test_method_list_parsing():
    assert wf.methods_from("lm, acs,lm") == ["lm", "acs"]
    with pytest.raises(wf.InputError, match="argument 'method'"):
        wf.methods_from("lm,gauss")
