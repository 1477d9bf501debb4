"""Turn study results into report sections (each study's ``report.figures.<name>``)."""

from __future__ import annotations

import importlib

from inertialab.report.html import rasterise, render_report
from inertialab.report.section import Section, Table
from inertialab.studies.base import StudyResult
from inertialab.studies.demo import summary_rows


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


def write_report(results: list[StudyResult], out_dir, *, quick: bool = False) -> dict:
    """Sections, summary table and ``index.html`` + ``results.json`` for study results.

    Returns the written paths (``index``, ``results``) and the summary ``rows``.
    """
    sections = [section_for(r) for r in results]
    rows = summary_rows(results)
    notes = [f"{r.name}: {r.wall_s:.1f} s" for r in results]
    paths = render_report(sections, out_dir, summary=rows, notes=notes, quick=quick,
                          extra={"wall_s": {r.name: r.wall_s for r in results}})
    return {**paths, "rows": rows}
