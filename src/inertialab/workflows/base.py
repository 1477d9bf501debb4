"""Transitional re-export (issue 13): the study protocol lives in
:mod:`inertialab.studies.base`, progress sinks in :mod:`inertialab.progress`.
Removed when every study module has moved."""

from inertialab.progress import NullProgress, Progress  # noqa: F401
from inertialab.studies.base import (  # noqa: F401
    STUDY_ORDER,
    Headline,
    Study,
    StudyResult,
    discover_studies,
    settings_dict,
)
