"""The demo: run the registered studies on the virtual lab with QUICK or FULL settings.

Used by ``inertialab demo`` and by ``benchmarks/demo.py`` (which measures the time
budgets of: full run <= 3 min, quick <= 60 s on 2 cores).
"""

from __future__ import annotations

import dataclasses
import time
from collections.abc import Callable

from inertialab.errors import InputError
from inertialab.studies.base import (
    STUDY_ORDER,
    NullProgress,
    Progress,
    StudyResult,
    discover_studies,
)


def select_studies(names: list[str] | None = None) -> list:
    """The studies to run, in canonical order; unknown names are an InputError."""
    available = discover_studies()
    if not names:
        return list(available.values())
    out = []
    for n in names:
        if n not in available:
            known = ", ".join(available) or "none registered"
            valid = ", ".join(STUDY_ORDER)
            raise InputError(f"unknown study '{n}' (registered: {known}; names: {valid})")
        out.append(available[n])
    return out


def run_studies(names: list[str] | None = None, *, quick: bool = False, seed: int | None = None,
                progress: Callable[[str], Progress] | None = None) -> list[StudyResult]:
    """Run studies and return their results.

    Parameters
    ----------
    names : study keys (default: all registered)
    quick : use each study's QUICK settings (else FULL)
    seed : replaces the ``seed`` field of each study's settings when it has one
    progress : factory ``progress(label) -> context manager with update(done, total, note)``
    """
    results = []
    for study in select_studies(names):
        settings = study.quick if quick else study.full
        if seed is not None and dataclasses.is_dataclass(settings) and any(
                f.name == "seed" for f in dataclasses.fields(settings)):
            settings = dataclasses.replace(settings, seed=int(seed))
        t0 = time.perf_counter()
        if progress is None:
            res = study.run(settings, NullProgress())
        else:
            with progress(study.title) as bar:
                res = study.run(settings, bar)
        res.wall_s = time.perf_counter() - t0
        results.append(res)
    return results


#: Columns of the summary table (report, results.json, ``demo --json``).
SUMMARY_COLUMNS = ("study", "data", "figure", "ours", "paper", "unit")


def summary_rows(results: list[StudyResult]) -> list[list]:
    """Rows ``[study, data, figure, ours, paper, unit]`` for the summary table; ``data``
    is "virtual lab" or "user data", and every row has a unit ("1" = dimensionless)."""
    rows = []
    for r in results:
        for h in r.headline:
            rows.append([r.name, h.data, h.label, h.ours, h.paper, h.unit or "1"])
    return rows
