"""``inertialab drift fit|evaluate|apply|forecast`` (spec 004). Each command is one call to
:mod:`inertialab.workflows.drift` through the runner (:mod:`inertialab.cli.runner`):
its options come from the workflow's ``Config``.

No ``from __future__ import annotations`` here: typer must see the option annotations
as objects through the decorators.
"""

from pathlib import Path

import typer

from inertialab.cli.options import reading_options
from inertialab.cli.runner import config_command, load_model, read_record
from inertialab.config import Config
from inertialab.io.mapping import ReadOptions
from inertialab.report import commands
from inertialab.workflows import drift as wf


@reading_options
@config_command(wf.FitConfig)
def drift_fit(file: Path = typer.Argument(..., help="storage_drift record (CSV or Parquet)."),
              *, config, run, read: ReadOptions):
    """Fit NAR models per unit and quantity, forecast, and schedule re-calibration."""
    run.execute("drift fit", lambda bar: wf.run_fit(
        read_record(file, "storage_drift", options=read), config, progress=bar),
        inputs=[file], figures=commands.drift_fit)


@reading_options
@config_command(wf.EvaluateConfig)
def drift_evaluate(file: Path = typer.Argument(..., help="storage_drift record (CSV or "
                                                         "Parquet)."),
                   *, config, run, read: ReadOptions):
    """Rolling-origin evaluation: refit at origins FIRST, FIRST+STEP, ..., N-K and
    compare NAR with the baselines (per-origin RMSE, win rates, Wilcoxon, per-step
    error curve; spec 004)."""
    run.execute("drift evaluate", lambda bar: wf.run_evaluate(
        read_record(file, "storage_drift", options=read), config, progress=bar),
        inputs=[file], figures=commands.drift_evaluate)


@reading_options
@config_command(Config, out="file")
def drift_apply(model: Path = typer.Argument(..., help="model.json written by 'drift fit "
                                                       "--out'."),
                file: Path = typer.Argument(..., help="Later storage_drift record (same units; "
                                                      "a 'day' column or dates; optional "
                                                      "output_ma and a_ref_g columns)."),
                *, config, run, read: ReadOptions):
    """Compensate a later record with the forecast bias and scale factor: residuals
    with and without the forecast, and a = I/k - b for an output current (spec 004)."""
    run.execute("drift apply", lambda bar: wf.run_apply(
        load_model(model, expected_type="storage-drift"),
        read_record(file, "storage_drift", options=read), out=run.out, model_path=model),
        inputs=[model, file])


@config_command(wf.ForecastConfig, out=None)
def drift_forecast(model: Path = typer.Argument(..., help="model.json written by 'drift fit "
                                                          "--out'."),
                   *, config, run):
    """Forecast again from a saved storage-drift model."""
    run.execute("drift forecast", lambda bar: wf.run_forecast(
        load_model(model, expected_type="storage-drift"), config), inputs=[model])


def register(app: typer.Typer, groups: dict) -> None:
    drift = groups["drift"]
    drift.command("fit")(drift_fit)
    drift.command("evaluate")(drift_evaluate)
    drift.command("apply")(drift_apply)
    drift.command("forecast")(drift_forecast)
