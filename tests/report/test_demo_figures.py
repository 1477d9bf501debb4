"""Every figure of the demo report (quick settings) is laid out in one pass with no text
clipped, overlapping or running into another axes (issue 18 item 11)."""

import importlib
import warnings

import matplotlib.pyplot as plt
import pytest

from inertialab.report import layout
from inertialab.studies.demo import run_studies


@pytest.fixture(scope="module")
def quick_results():
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return run_studies(quick=True)


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
