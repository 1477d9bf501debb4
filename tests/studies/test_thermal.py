"""The thermal study in the demo, its report section and the bootstrap of spec 000 §8.4."""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from inertialab.calib.thermal import drift
from inertialab.report.figures.thermal import section
from inertialab.sim.thermal_tumble import simulate
from inertialab.studies.base import discover_studies
from inertialab.studies.thermal import STUDY, bootstrap
from inertialab.workflows.thermal import FitConfig, fit_thermal, prepare_samples

FAST = FitConfig(method="all", fish=4, generations=2, search_epochs=5, epochs=30,
                 ann_max_epochs=60)


def test_quick_study_runs_and_builds_its_section(quick_study):
    assert discover_studies()["thermal"] is STUDY
    res = quick_study("thermal")
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


def test_bootstrap_bands_contain_the_point_estimate():
    samples = prepare_samples(simulate("paper", 0, 0).frame)
    model = fit_thermal(samples, replace(FAST, method=("scm-anfis",))).models["scm-anfis"]
    b = bootstrap(samples, model, FAST, n_boot=4, epochs=5, rng=1)
    own = drift(model, samples, own_unit=True)
    assert b.std_ug.shape == (samples.n,)
    assert np.all(b.band_hi_ug >= b.band_lo_ug)
    # bands are tens of µg at most where the drift is millig-level: resampling works
    assert np.median(b.band_hi_ug - b.band_lo_ug) < 100
    inside = (own.comp_ug >= b.band_lo_ug - 20) & (own.comp_ug <= b.band_hi_ug + 20)
    assert inside.mean() > 0.9
