"""One module per study: ``section(result: StudyResult) -> Section`` with its figures."""

#: The face is the study modules themselves (``report/figures/<study>.py``), listed in
#: :func:`inertialab.report.build.figure_modules`; no names are re-exported here.
__all__: list[str] = []
