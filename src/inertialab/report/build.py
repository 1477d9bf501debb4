"""Turn study results into report sections (each study's ``report.figures.<name>``,
listed in :func:`figure_modules`)."""

from __future__ import annotations

import contextlib
import gc
import multiprocessing
import os
import sys
import traceback
import warnings

from inertialab.errors import InputError
from inertialab.report.html import rasterise, render_report
from inertialab.report.section import Section, Table
from inertialab.studies.base import StudyResult
from inertialab.studies.demo import summary_rows


def figure_module(name: str):
    """The figure module ``inertialab.report.figures.<name>`` (imported here, explicitly:
    matplotlib loads when a report is drawn, not when the package is imported)."""
    if name == "allan":
        from inertialab.report.figures import allan as mod
    elif name == "vibration":
        from inertialab.report.figures import vibration as mod
    elif name == "thermal":
        from inertialab.report.figures import thermal as mod
    elif name == "triaxial":
        from inertialab.report.figures import triaxial as mod
    elif name == "dual":
        from inertialab.report.figures import dual as mod
    elif name == "drift":
        from inertialab.report.figures import drift as mod
    elif name == "batch":
        from inertialab.report.figures import batch as mod
    else:
        raise KeyError(f"no figure module {name!r}")
    return mod


def figure_modules() -> dict:
    """Study name -> its figure module: one per :data:`inertialab.studies.STUDIES` entry,
    in that order, then ``batch`` (the fleet report).

    Examples
    --------
    >>> sorted(figure_modules())
    ['allan', 'batch', 'drift', 'dual', 'thermal', 'triaxial', 'vibration']
    """
    from inertialab.studies import STUDIES

    return {name: figure_module(name) for name in [s.name for s in STUDIES] + ["batch"]}


def section_for(result: StudyResult) -> Section:
    """The report section of a study result.

    Uses the ``section`` of the study's figure module (:func:`figure_modules`) when it
    has one, else a plain section with the headline table and the text.
    """
    mod = figure_modules().get(result.name)
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


@contextlib.contextmanager
def _collect_per_section():
    """Automatic garbage collection off while sections are drawn; the caller collects
    the youngest generation (the closed figures' reference cycles) after each section.

    matplotlib allocates hundreds of thousands of small objects per section; each
    automatic full collection also walks every object the studies left alive (their
    results), which cost ~15 % of the report's CPU. A collection of
    generation 0 after a section walks only what the section allocated."""
    was = gc.isenabled()
    gc.disable()
    try:
        yield lambda: gc.collect(0)
    finally:
        if was:
            gc.enable()


#: Relative drawing cost of each study's section (full demo): the
#: process pool starts the costly ones first.
_COST_HINT = {"vibration": 10, "thermal": 4, "drift": 3, "dual": 2, "triaxial": 2, "allan": 1}

#: Environment variable that sets the number of drawing processes (1: draw in this one).
JOBS_ENV = "INERTIALAB_REPORT_JOBS"

_PENDING: list = []  # the results a forked drawing process reads (set before the fork)


def report_jobs(jobs: int | None = None) -> int:
    """Processes that draw the report's sections: ``jobs`` if given, else the
    :data:`JOBS_ENV` variable, else 2 when a second CPU is idle (1-minute load average
    below CPUs - 1), else 1; never more than the CPUs, and 1 where processes cannot be
    forked (not Linux, or a daemon process). On a busy machine a second process only
    competes for the same cores (measured: load ~5 on 2 cores, 5.2 s wall with two
    processes against 4.4 s with one)."""
    cpus = os.cpu_count() or 1
    if jobs is None:
        env = os.environ.get(JOBS_ENV, "").strip()
        if env:
            try:
                jobs = int(env)
            except ValueError:
                raise InputError(f"{JOBS_ENV} must be an integer, got {env!r}") from None
        else:
            try:
                idle = os.getloadavg()[0] < cpus - 1
            except OSError:
                idle = False
            jobs = 2 if idle else 1
    jobs = max(1, int(jobs))
    if jobs > 1 and not _can_fork():
        return 1
    return min(jobs, cpus)


def _can_fork() -> bool:
    return (sys.platform.startswith("linux")
            and "fork" in multiprocessing.get_all_start_methods()
            and not multiprocessing.current_process().daemon)


def _section_job(i: int):
    """Draw section ``i`` of :data:`_PENDING` in a forked process: the section (figures
    as PNG bytes), the warnings raised, or the traceback of a failure."""
    gc.disable()  # this process's own collector; generation 0 is collected below
    with warnings.catch_warnings(record=True) as caught:
        try:
            sec = section_for(_PENDING[i])
        except BaseException:  # the parent draws it again to raise the real error
            return i, None, [], traceback.format_exc()
        finally:
            gc.collect(0)
    return i, sec, [(str(w.message), w.category, w.filename, w.lineno) for w in caught], None


def _draw_here(results: list[StudyResult]) -> list[Section]:
    """The sections drawn in this process, one after the other."""
    with _collect_per_section() as collected:
        out = []
        for r in results:
            out.append(section_for(r))
            collected()
    return out


def _warm_up(results) -> None:
    """Import matplotlib and the figure modules and draw one small figure here, before
    the fork, so that each drawing process inherits the loaded fonts and modules instead
    of loading them again."""
    import matplotlib.pyplot as plt

    from inertialab.report.html import figure_png

    figure_modules()
    fig, ax = plt.subplots(figsize=(2.0, 1.5))
    ax.plot([1.0, 10.0], [1.0, 10.0])
    ax.set_yscale("log")
    ax.set_title("warm-up", fontsize=9)
    ax.set_xlabel("x")
    figure_png(fig)


def draw_sections(results: list[StudyResult], *, jobs: int | None = None) -> list[Section]:
    """The report sections of ``results`` in order, figures drawn to PNG.

    With ``jobs`` > 1 (see :func:`report_jobs`) the sections are drawn in that many forked
    processes, the costliest first; warnings raised there are raised again here, and a
    section that fails there is drawn again here so that its error is raised as is. The
    PNGs are the same bytes either way (tested).
    """
    jobs = min(report_jobs(jobs), len(results))
    if jobs <= 1:
        return _draw_here(results)
    _warm_up(results)
    order = sorted(range(len(results)), key=lambda i: -_COST_HINT.get(results[i].name, 1))
    global _PENDING
    _PENDING = list(results)
    try:
        with multiprocessing.get_context("fork").Pool(jobs) as pool:
            done = pool.map(_section_job, order, chunksize=1)
    except Exception:  # the pool itself failed (e.g. a section it could not send
        # back): draw everything here, where any real error is raised as is
        return _draw_here(results)
    finally:
        _PENDING = []
    sections: list[Section | None] = [None] * len(results)
    for i, sec, caught, error in done:
        for message, category, filename, lineno in caught:
            warnings.warn_explicit(message, category, filename, lineno)
        sections[i] = sec if error is None else section_for(results[i])
    return sections  # type: ignore[return-value]


def write_report(results: list[StudyResult], out_dir, *, quick: bool = False,
                 jobs: int | None = None) -> dict:
    """Sections, summary table and ``index.html`` + ``results.json`` for study results.

    ``jobs``: processes that draw the figures (:func:`report_jobs`). Returns the written
    paths (``index``, ``results``) and the summary ``rows``.

    Examples
    --------
    One study's result: its headline line becomes the summary row, its tables and wall
    time go to ``results.json``:

    >>> import json
    >>> import tempfile
    >>> from pathlib import Path
    >>> from inertialab.studies.base import Headline, StudyResult
    >>> tmp = tempfile.TemporaryDirectory()
    >>> result = StudyResult(name="demo", title="A demo", settings={"seed": 0},
    ...                      headline=[Headline("ARW", 0.101, 0.1, "deg/sqrt(h)", "virtual lab")],
    ...                      tables={"arw": 0.101}, wall_s=0.5)
    >>> out = write_report([result], Path(tmp.name), jobs=1)
    >>> out["rows"]
    [['demo', 'virtual lab', 'ARW', 0.101, 0.1, 'deg/sqrt(h)']]
    >>> json.loads(out["results"].read_text())["studies"]["demo"]["results"]
    {'arw': 0.101, 'wall_s': 0.5}
    >>> out["index"].name
    'index.html'
    >>> tmp.cleanup()
    """
    sections = draw_sections(results, jobs=jobs)
    rows = summary_rows(results)
    notes = [f"{r.name}: {r.wall_s:.1f} s" for r in results]
    paths = render_report(sections, out_dir, summary=rows, notes=notes, quick=quick,
                          extra={"wall_s": {r.name: r.wall_s for r in results}})
    return {**paths, "rows": rows}
