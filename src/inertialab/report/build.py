"""Turn study results into report sections (each study's ``report.figures.<name>``)."""

from __future__ import annotations

import importlib

from inertialab.report.html import rasterise
from inertialab.report.section import Section, Table
from inertialab.studies.base import StudyResult


def section_for(result: StudyResult) -> Section:
    """The report section of a study result.

    Uses ``inertialab.report.figures.<result.name>.section`` when the study ships one,
    else a plain section with the headline table and the text.
    """
    try:
        mod = importlib.import_module(f"inertialab.report.figures.{result.name}")
    except ModuleNotFoundError as exc:
        if exc.name != f"inertialab.report.figures.{result.name}":
            raise
        mod = None
    if mod is not None and hasattr(mod, "section"):
        sec = mod.section(result)
    else:
        sec = Section(key=result.name, title=result.title, paragraphs=list(result.text))
        sec.results = dict(result.tables)
    if not sec.settings:
        sec.settings = dict(result.settings)
    if not sec.results:
        sec.results = dict(result.tables)
    if result.headline and not any(t.title.startswith("Headline") for t in sec.tables):
        sec.tables.insert(0, Table(
            title="Headline figures: ours beside the paper's",
            columns=["figure", "ours", "paper", "unit"],
            rows=[[h.label, h.ours, h.paper, h.unit] for h in result.headline]))
    sec.results.setdefault("wall_s", result.wall_s)
    return rasterise(sec)
