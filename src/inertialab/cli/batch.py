"""``inertialab batch CMD --inputs GLOB``: one command over many files on Dask, through
the runner: :func:`inertialab.workflows.batch.prepare` checks the command, the files
and the ``--tolerance`` rules before any work, :func:`inertialab.workflows.batch.run`
runs the fleet (:func:`inertialab.workflows.batch.run_batch`).
"""

# no "from __future__ import annotations": typer must see the Annotated shared options
import typer

from inertialab.cli.options import reading_options
from inertialab.cli.runner import config_command
from inertialab.io.mapping import ReadOptions
from inertialab.report import commands
from inertialab.workflows import batch as wb
from inertialab.workflows.batch import expand_inputs, parse_tolerance

__all__ = ["expand_inputs", "parse_tolerance", "register"]


def register(app: typer.Typer, groups: dict) -> None:
    @app.command("batch")
    @reading_options
    @config_command(wb.BatchConfig)
    def batch(
        cmd: list[str] = typer.Argument(..., help="allan | triaxial fit | thermal apply"),
        inputs: list[str] = typer.Option(..., "--inputs", help="Glob of input files, e.g. "
                                         "'lot7/*.csv' (quote it; repeat for more)."),
        *, config, run, read: ReadOptions = None,
    ):
        """Run CMD on every file of --inputs (Dask), and write one table: per unit its
        key figures and pass/fail against --tolerance, plus the yield summary."""
        job = wb.prepare(cmd, inputs, config, read)
        run.execute("batch", lambda bar: wb.run(job, progress=bar), inputs=job.paths,
                    figures=commands.batch)
