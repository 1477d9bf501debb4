"""The thermal study in the demo and its report section (issue 5 item 4)."""

from __future__ import annotations

from inertialab.report.figures.thermal import section
from inertialab.workflows.base import discover_studies
from inertialab.workflows.thermal import STUDY


def test_quick_study_runs_and_builds_its_section():
    assert discover_studies()["thermal"] is STUDY
    res = STUDY.run(STUDY.quick, None)
    t = res.tables
    assert set(t["models"]) == {"ann", "fis", "anfis", "scm-anfis", "iafsa-scm-anfis",
                                "poly-sep", "poly-2d"}
    # even the quick settings keep the fuzzy models >= 10x below the raw drift
    for m in ("fis", "anfis", "scm-anfis", "iafsa-scm-anfis"):
        assert t["models"][m]["rmse_ug"] < t["raw_rms_ug"] / 10
    assert t["transfer"]["raw_max_drift_ug"] > 3000
    assert t["transfer"]["comp_max_drift_ug"] < 100
    sec = section(res)
    assert sec.key == "thermal" and len(sec.figures) == 3
    assert sec.tables[0].rows[0][0] == "ANN"
    labels = [h.label for h in res.headline]
    assert "test RMSE IAFSA-SCM-ANFIS" in labels
