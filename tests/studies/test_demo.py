"""The demo's summary table: every row says where our figure comes from and has a unit."""

from inertialab.studies.base import Headline, StudyResult
from inertialab.studies.demo import SUMMARY_COLUMNS, summary_rows


def test_summary_rows_carry_data_source_and_unit():
    res = StudyResult(name="x", title="X", settings={}, headline=[
        Headline("ratio", 1.5, "clearly > 1"),
        Headline("rmse", 4.0, 5.0, "ug", data="user data"),
    ])
    rows = summary_rows([res])
    assert [dict(zip(SUMMARY_COLUMNS, r)) for r in rows] == [
        {"study": "x", "data": "virtual lab", "figure": "ratio", "ours": 1.5,
         "paper": "clearly > 1", "unit": "1"},
        {"study": "x", "data": "user data", "figure": "rmse", "ours": 4.0, "paper": 5.0,
         "unit": "ug"},
    ]
