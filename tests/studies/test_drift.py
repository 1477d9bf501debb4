"""studies.drift: the demo study."""

from __future__ import annotations

from inertialab.calib.drift import DriftSettings
from inertialab.studies.drift import STUDY

FAST = DriftSettings(restarts=2, n_paths=50, baselines=("persistence", "ar_ls"))


def test_study_registered_with_budgeted_settings():
    assert STUDY.name == "drift"
    assert STUDY.quick.n_units <= STUDY.full.n_units
