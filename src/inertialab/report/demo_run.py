"""``inertialab demo`` as one call: the registered studies on the virtual lab and their
HTML report, a :class:`DemoConfig` in, a :class:`DemoResult` out (the shape every
command's workflow has, so the command line's runner prints or emits it like any
other). It lives on the report floor because it writes the report
(:func:`inertialab.report.build.write_report`) from the studies' results."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from inertialab.config import Config, seed_setting, setting
from inertialab.result import ResultBase

__all__ = ["DemoConfig", "DemoResult", "run"]


@dataclass(frozen=True)
class DemoConfig(Config):
    """Settings of ``demo`` (the studies to run are the command's ``--study``)."""

    quick: bool = setting(False, help="Quick settings (about a minute).")
    seed: int | None = seed_setting(default=None)


@dataclass
class DemoResult(ResultBase):
    """The studies' results and the report written from them (``paths``: ``index``,
    ``results``, ``rows`` of the summary table)."""

    results: list
    paths: dict
    settings: dict
    units = {}

    def to_json(self) -> dict:
        from inertialab.studies.demo import SUMMARY_COLUMNS

        return {"report": str(self.paths["index"]), "results": str(self.paths["results"]),
                "summary": [dict(zip(SUMMARY_COLUMNS, r)) for r in self.paths["rows"]],
                "wall_s": {r.name: r.wall_s for r in self.results}}

    def artifacts(self) -> dict:
        return {}

    def summary_rows(self) -> list:
        from inertialab.studies.demo import SUMMARY_COLUMNS

        if not self.results:
            rows = ["No studies are registered yet; the report says so."]
        else:
            rows = [("inertialab demo: our figures beside the papers'",
                     list(SUMMARY_COLUMNS), self.paths["rows"])]
        return rows + [f"report: {self.paths['index']}", f"results: {self.paths['results']}"]


def run(config: DemoConfig, out_dir: Path, *, study=None, progress=None) -> DemoResult:
    """Run the studies (``study``: names, None for all) and write the report into
    ``out_dir`` (a directory registered for the command's output transaction).
    ``progress(label)``: a progress sink per study."""
    from inertialab.report.build import write_report
    from inertialab.studies.demo import run_studies, select_studies

    config.validate()
    select_studies(study)  # validates names before any work
    results = run_studies(study, quick=config.quick, seed=config.seed, progress=progress)
    paths = write_report(results, out_dir, quick=config.quick)
    return DemoResult(results, paths, {"quick": config.quick, "study": list(study or []),
                                       "seed": config.seed})
