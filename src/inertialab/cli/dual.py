"""``inertialab dual fit`` and ``inertialab dual design`` (spec 003), each one call to
:mod:`inertialab.workflows.dual` through the runner.

No ``from __future__ import annotations`` here: the shared options are ``Annotated``
aliases that typer must see as objects through :func:`~inertialab.cli.options.reading_options`.
"""

from pathlib import Path

import typer

from inertialab.cli.options import reading_options
from inertialab.cli.runner import config_command, read_record
from inertialab.errors import InputError
from inertialab.io.mapping import ReadOptions
from inertialab.report import commands
from inertialab.workflows import dual as wd


@reading_options
@config_command(wd.FitConfig)
def dual_fit(
    files: list[Path] = typer.Argument(..., help="dual_tumble record(s); two files with "
                                                 "opposite OA signs add the two-orientation fit."),
    *, config, run, read: ReadOptions,
):
    """Calibrate two accelerometers tumbled on a dividing head (g^2 model, LS, EBR)."""
    if len(files) > 2:
        raise InputError("give one record, or two for the two-orientation fit")
    config.validate()  # refuse bad settings before reading

    def produce(bar):
        records = [read_record(f, "dual_tumble", g_local=config.g_local, options=read)
                   for f in files]
        return wd.run_fit(records, config, sensitivity=run.out is not None)

    run.execute("dual fit", produce, inputs=files, figures=commands.dual_fit)


@config_command(wd.DesignConfig, out=None)
def dual_design(*, config, run):
    """D-optimal dividing-head positions for the identifiable g^2 harmonic model."""
    run.execute("dual design", lambda bar: wd.run_design(config))


def register(app: typer.Typer, groups: dict) -> None:
    dual = groups["dual"]
    dual.command("fit")(dual_fit)
    dual.command("design")(dual_design)
