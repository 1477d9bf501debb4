"""``inertialab demo``: every registered study on the virtual lab, one HTML report, run
through the command runner (:mod:`inertialab.report.demo_run`)."""

# no "from __future__ import annotations": typer must see the Annotated shared options
from pathlib import Path

import typer

from inertialab.cli.common import prepare_out_dir, progress_bar
from inertialab.cli.runner import config_command
from inertialab.report import demo_run as dr


def register(app: typer.Typer, groups: dict) -> None:
    @app.command("demo")
    @config_command(dr.DemoConfig, out=None)
    def demo(
        out: Path = typer.Option(Path("inertialab-report"), "--out",
                                 help="Report directory (index.html, results.json)."),
        study: list[str] = typer.Option(None, "--study",
                                        help="Run only this study (repeatable): allan, "
                                             "vibration, thermal, triaxial, dual, drift."),
        *, config, run,
    ):
        """Run the studies on the virtual lab and write a self-contained HTML report.

        The report's figures are drawn in two processes when a second CPU is idle, else in
        this one; the environment variable INERTIALAB_REPORT_JOBS sets the count (the page
        is the same byte for byte).
        """
        from inertialab.studies.demo import select_studies

        select_studies(study)  # validates names before the output directory is registered
        quiet = run.quiet or run.as_json
        run.execute("demo", lambda bar: dr.run(
            config, prepare_out_dir(out), study=study,
            progress=lambda label: progress_bar(label, quiet=quiet)))
