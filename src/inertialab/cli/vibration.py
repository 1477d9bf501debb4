"""``inertialab vibration fit|apply`` (spec 001): each one call to
:mod:`inertialab.workflows.vibration` through the runner. A bare ``inertialab
vibration SWEEP [FIXED]`` is routed to ``vibration fit`` by :mod:`inertialab.cli.main`.
"""

from pathlib import Path

import typer

from inertialab.cli.options import reading_options
from inertialab.cli.runner import config_command, load_model, read_record
from inertialab.io.mapping import ReadOptions
from inertialab.report import commands
from inertialab.workflows import vibration as wv


@reading_options
@config_command(wv.FitConfig)
def vibration_fit(
    sweep_file: Path = typer.Argument(..., help="Sweep record (E1), gyro_log with vib_on, "
                                                "vib_freq_hz."),
    fixed_file: Path = typer.Argument(None, help="Fixed-frequency record (E2) to "
                                                 "compensate (optional)."),
    *, config, run, read: ReadOptions = None,
):
    """FOG under vibration: phase-wise Allan terms, db4 separation, RBF bias compensation
    (fit the bias model on the sweep; compensate the fixed run when given)."""
    config.validate()  # refuse bad settings before reading

    def produce(bar):
        sweep, fixed = (None if f is None else read_record(f, "gyro_log", options=read)
                        for f in (sweep_file, fixed_file))
        return wv.run_fit(sweep, fixed, config, views=run.out is not None, progress=bar)

    run.execute("vibration", produce, figures=commands.vibration_fit,
                inputs=[sweep_file] + ([fixed_file] if fixed_file is not None else []))


@reading_options
@config_command(wv.ApplyConfig, out="file!", out_help="Output record (CSV or Parquet) with "
                                                      "rate_comp_dph; a sidecar is written "
                                                      "beside it.")
def vibration_apply(
    model_file: Path = typer.Argument(..., help="model.json written by 'inertialab "
                                                "vibration fit --out'."),
    record_file: Path = typer.Argument(..., help="Record to compensate (gyro_log with "
                                                 "vib_on, vib_freq_hz)."),
    *, config, run, read: ReadOptions = None,
):
    """Apply a saved vibration-compensation model to a new record."""
    run.execute("vibration apply", lambda bar: wv.run_apply(
        load_model(model_file, expected_type="vibration-compensation"),
        read_record(record_file, "gyro_log", options=read), config, out=run.out,
        model_path=model_file),
        inputs=[model_file, record_file])


def register(app: typer.Typer, groups: dict) -> None:
    groups["vibration"].command("fit")(vibration_fit)
    groups["vibration"].command("apply")(vibration_apply)
