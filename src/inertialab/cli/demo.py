"""``inertialab demo``: every registered study on the virtual lab, one HTML report."""

from __future__ import annotations

import sys
from pathlib import Path

import typer

from inertialab.cli.common import (
    collect_warnings,
    emit_json,
    prepare_out_dir,
    print_table,
    progress_bar,
)
from inertialab.cli.options import JsonOpt, QuietOpt, SeedOpt


def register(app: typer.Typer, groups: dict) -> None:
    @app.command("demo")
    def demo(
        out: Path = typer.Option(Path("inertialab-report"), "--out",
                                 help="Report directory (index.html, results.json)."),
        quick: bool = typer.Option(False, "--quick", help="Quick settings (about a minute)."),
        study: list[str] = typer.Option(None, "--study",
                                        help="Run only this study (repeatable): allan, "
                                             "vibration, thermal, triaxial, dual, drift."),
        seed: SeedOpt = None,
        as_json: JsonOpt = False,
        quiet: QuietOpt = False,
    ):
        """Run the studies on the virtual lab and write a self-contained HTML report.

        The report's figures are drawn in two processes when a second CPU is idle, else in
        this one; the environment variable INERTIALAB_REPORT_JOBS sets the count (the page
        is the same byte for byte).
        """
        from inertialab.report.build import write_report
        from inertialab.studies.demo import SUMMARY_COLUMNS, run_studies, select_studies

        select_studies(study)  # validates names before any work
        with collect_warnings(quiet=quiet or as_json) as warns:
            results = run_studies(study, quick=quick, seed=seed,
                                  progress=lambda label: progress_bar(label, quiet=quiet))
            paths = write_report(results, prepare_out_dir(out), quick=quick)
        rows = paths["rows"]
        if as_json:
            emit_json("demo", {"report": str(paths["index"]), "results": str(paths["results"]),
                               "summary": [dict(zip(SUMMARY_COLUMNS, r)) for r in rows],
                               "wall_s": {r.name: r.wall_s for r in results}},
                      settings={"quick": quick, "study": study or [], "seed": seed},
                      warnings_=warns)
            return
        if not results:
            print("No studies are registered yet; the report says so.")
        else:
            print_table(list(SUMMARY_COLUMNS), rows,
                        title="inertialab demo: our figures beside the papers'")
        print(f"report: {paths['index']}")
        print(f"results: {paths['results']}")
        sys.stdout.flush()
