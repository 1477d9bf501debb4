"""Every figure of the demo report (quick settings) is laid out in one pass with no text
clipped, overlapping or running into another axes."""

import importlib
import json
import re
import warnings

import matplotlib.pyplot as plt
import pytest

from inertialab.report import layout
from inertialab.studies.demo import select_studies


@pytest.fixture(scope="module")
def quick_results(quick_study):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return [quick_study(s.name) for s in select_studies()]


@pytest.mark.slow
def test_demo_figures_have_no_text_problems(quick_results):
    problems = {}
    n = 0
    for r in quick_results:
        mod = importlib.import_module(f"inertialab.report.figures.{r.name}")
        for f in mod.section(r).figures:
            fig = f.figure
            fig.set_dpi(100)
            assert layout.fit(fig), f"{r.name}/{f.name}: no one-pass layout"
            p = layout.text_problems(fig)
            if p:
                problems[f"{r.name}/{f.name}"] = p
            plt.close(fig)
            n += 1
    assert n >= 20
    assert problems == {}


@pytest.mark.slow
def test_report_drawn_in_two_processes_is_the_same_report(quick_results, tmp_path):
    from inertialab.report.build import write_report

    one = write_report(quick_results, tmp_path / "one", quick=True, jobs=1)
    two = write_report(quick_results, tmp_path / "two", quick=True, jobs=2)
    strip = lambda p: re.sub(r"\d{4}-\d\d-\d\d \d\d:\d\d UTC", "", p.read_text())  # noqa: E731
    assert strip(one["index"]) == strip(two["index"])
    a, b = (json.loads(p["results"].read_text()) for p in (one, two))
    a.pop("created_utc")
    b.pop("created_utc")
    assert a == b
