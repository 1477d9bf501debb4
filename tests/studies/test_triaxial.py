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
