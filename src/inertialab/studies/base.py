"""The study protocol: what a paper's reproduction gives the demo and the report.

A module ``inertialab/studies/<name>.py`` that takes part in ``inertialab demo`` defines
a module-level ``STUDY = Study(...)`` and is listed in
:data:`inertialab.studies.STUDIES`. The demo finds them (:func:`discover_studies`), runs
``study.run(settings, progress)`` with the study's ``quick`` or ``full`` settings
and hands the :class:`StudyResult` to the report, which turns it into a section with
``inertialab.report.figures.<name>.section(result)``. Workflows never draw.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import asdict, dataclass, field, is_dataclass
from typing import Any

from inertialab.progress import NullProgress, Progress  # noqa: F401 - re-exported
from inertialab.studies import STUDIES

#: Canonical order of the studies in the demo and the report (:data:`inertialab.studies.STUDIES`).
STUDY_ORDER = tuple(s.name for s in STUDIES)


@dataclass(frozen=True)
class Headline:
    """One line of the demo summary table: our figure beside the paper's.

    ``ours`` and ``paper`` are numbers or short strings (the paper may give only a
    qualitative claim, or nothing: ``None``); ``unit`` names their unit ("1" for a
    dimensionless ratio or count; an empty unit is shown as "1"). ``data`` says where
    ``ours`` comes from: ``"virtual lab"`` (the demo's simulated rigs) or ``"user data"``
    (a record the user supplied); the paper's figure is always the paper's own rig.
    """

    label: str
    ours: float | str | None
    paper: float | str | None = None
    unit: str = ""
    data: str = "virtual lab"


@dataclass
class StudyResult:
    """What a study's demo run hands to the report.

    Attributes
    ----------
    name : study key (one of :data:`STUDY_ORDER`)
    title : section title
    settings : the settings used (JSON-ready dict, seeds included)
    headline : the summary-table lines
    tables : JSON-ready numbers (also written to results.json)
    data : arrays and objects the figures need (not written to results.json)
    text : short paragraphs for the report section (what was done)
    wall_s : wall time of the run in seconds
    """

    name: str
    title: str
    settings: dict
    headline: list[Headline] = field(default_factory=list)
    tables: dict = field(default_factory=dict)
    data: dict = field(default_factory=dict)
    text: list[str] = field(default_factory=list)
    wall_s: float = 0.0


@dataclass(frozen=True)
class Study:
    """A demo-able study.

    ``quick`` and ``full`` are settings dataclass instances; ``run(settings,
    progress)`` returns a :class:`StudyResult`.
    """

    name: str
    title: str
    quick: Any
    full: Any
    run: Callable[[Any, Progress], StudyResult]


def settings_dict(settings) -> dict:
    """A settings dataclass as a JSON-ready dict."""
    if is_dataclass(settings):
        return asdict(settings)
    return dict(settings)


def discover_studies() -> dict[str, Study]:
    """All ``STUDY`` objects of the study modules, in :data:`STUDY_ORDER`."""
    from inertialab.studies import study_modules

    found: dict[str, Study] = {}
    for mod in study_modules():
        study = getattr(mod, "STUDY", None)
        if isinstance(study, Study):
            found[study.name] = study
    order = {n: i for i, n in enumerate(STUDY_ORDER)}
    return dict(sorted(found.items(), key=lambda kv: order.get(kv[0], len(order))))
