"""studies.triaxial: the demo study of spec 002 on the virtual lab."""

import json

from inertialab.studies import triaxial as st


def test_demo_quick_runs_and_reports():
    res = st.run_demo(st.QuickSettings(cs_seeds=1, acs_on_turntable=False))
    rows = {r["method"]: r for r in res.tables["turntable62_realistic"]}
    # S12 removes the mount bias: its eq.-21 RMSE is below the six-position baseline's
    assert rows["LM-S12"]["rmse_mps2"] < rows["lab six-position (12 par.)"]["rmse_mps2"]
    assert res.tables["rawlog62_counts"]["static_intervals"] == 62
    assert res.name == "triaxial" and len(res.headline) == 5
    from inertialab.report.figures.triaxial import section

    sec = section(res)
    assert sec.key == "triaxial" and len(sec.figures) == 4 and len(sec.tables) == 3
    json.dumps(sec.results, default=float)  # results.json material is JSON-ready


def test_turntable_methods_scored_against_the_same_sensor_frame_truth():
    # lab six-position -> LM-S12 on turntable62-realistic, every method
    # against the true gravity vectors in the sensor frame: ~21 % better (10 seeds, measured
    # 20.9 %; paper 25 %). Scoring S12 in its own fitted frame and the lab baseline against
    # unturned references inflated it to ~74 % (docs/results.md before the turned references).
    import numpy as np

    from inertialab.calib.triaxial import calibrate
    from inertialab.sim import triaxial_poses as tp
    from inertialab.workflows.triaxial import static_data_from_frame

    fair, own = [], []
    for seed in range(3):
        rec = tp.simulate("turntable62-realistic", seed=seed)
        sd = static_data_from_frame(rec.data, rec.meta)
        truth = st.sensor_frame_truth(rec)
        s12 = calibrate(sd.a, ref=sd.ref, objective="scalar12", g=sd.g)
        lab = calibrate(sd.a, ref=sd.ref, method="six-position", g=sd.g, refine_faces=False)
        fair.append((st.eq21_sensor_frame(lab, sd.a, truth).rmse,
                     st.eq21_sensor_frame(s12, sd.a, truth).rmse))
        own.append((st._eq21(lab, sd.a, sd.ref).rmse, st._eq21(s12, sd.a, sd.ref, s12.phi).rmse))
    fair, own = np.mean(fair, axis=0), np.mean(own, axis=0)
    gain_fair = 100 * (1 - fair[1] / fair[0])
    gain_own = 100 * (1 - own[1] / own[0])
    assert 10 < gain_fair < 35
    assert gain_own > 60
    # the truth is the sensor frame: a perfect model maps the clean outputs onto it exactly
    from inertialab.sensors import triaxial as tx

    rec = tp.simulate("turntable62-mount", seed=0)
    clean = rec.data[["true_ax_mps2", "true_ay_mps2", "true_az_mps2"]].to_numpy()
    assert np.allclose(tx.correct(rec.truth["x"], clean), st.sensor_frame_truth(rec), atol=1e-12)
