"""Allan study: the demo on the virtual lab and its report section."""

from __future__ import annotations

import pytest

from inertialab.studies import allan as S
from inertialab.studies.base import settings_dict


def test_demo_quick_runs_and_recovers(quick_study):
    r = quick_study("allan")
    assert r.name == "allan" and r.settings == settings_dict(S.STUDY.quick)
    rows = {row["term"]: row for row in r.tables["allan_test"]["terms"]}
    # 2-h allan-test record: Q and N within 3 % (edf in the thousands), B within 30 %
    assert rows["Q"]["wls"] == pytest.approx(0.5, rel=0.03)
    assert rows["N"]["wls"] == pytest.approx(0.01, rel=0.03)
    assert rows["B"]["wls"] == pytest.approx(0.1, rel=0.3)
    rec = r.tables["recovery"]
    assert rec["N_within_5pct"][0] == rec["N_within_5pct"][1] == 10


def test_report_section_of_demo(quick_study):
    from inertialab.report.figures.allan import section

    r = quick_study("allan")
    s = section(r)
    assert s.key == "allan" and len(s.figures) == 2 and len(s.tables) == 2
    # the recovery table reports the counts the study computed
    assert s.tables[1].rows[0][1:] == r.tables["recovery"]["N_within_5pct"]

