"""One module per study: ``section(result: StudyResult) -> Section`` with its figures."""
