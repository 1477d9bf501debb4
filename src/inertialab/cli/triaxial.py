"""``inertialab triaxial fit|ferraris|apply|export`` (spec 002), each one call to
:mod:`inertialab.workflows.triaxial` (``ferraris``: :mod:`inertialab.workflows.ferraris`)
through the runner.
"""

# No ``from __future__ import annotations``: typer reads the Annotated options of
# cli/options.py from the signature that reading_options builds, unevaluated.
from pathlib import Path

import typer

from inertialab.cli.options import reading_options
from inertialab.cli.runner import config_command, load_model
from inertialab.io.mapping import ReadOptions
from inertialab.report import commands
from inertialab.workflows import ferraris as wf
from inertialab.workflows import triaxial as wt
from inertialab.workflows.registries import export_help

_TARGETS_HELP = export_help("calibration")


def _load(model_file: Path):
    return load_model(model_file, expected_type="triaxial-calibration")


@config_command(wt.FitConfig)
def triaxial_fit(
    file: Path = typer.Argument(..., help="Static-record CSV (one row per pose) or raw log "
                                          "(t_s, ax, ay, az [, gx, gy, gz]); told apart by columns."),
    *, config, run, read: ReadOptions = None,
):
    """Calibrate a triaxial accelerometer (and gyro) from static records or a raw log."""
    run.execute("triaxial fit", lambda bar: wt.run_fit_file(file, config, options=read,
                                                            progress=bar),
                inputs=lambda res: res.inputs, figures=commands.triaxial_fit)


@config_command(wt.ApplyConfig, out="file!", out_help="Output record file (.csv or .parquet); "
                                                      "a sidecar .meta.json is written beside it.")
def triaxial_apply(
    model_file: Path = typer.Argument(..., help="model.json from 'triaxial fit --out'."),
    file: Path = typer.Argument(..., help="Raw log or static-record file in the model's raw unit."),
    *, config, run, read: ReadOptions = None,
):
    """Apply a triaxial calibration: calibrated = correction_matrix @ (raw - offset)."""
    run.execute("triaxial apply", lambda bar: wt.run_apply(
        _load(model_file), file, config, options=read, model_path=model_file, output=run.out),
        inputs=[model_file, file])


@config_command(wf.FerrarisConfig)
def triaxial_ferraris(
    file: Path = typer.Argument(..., help="Raw log of a Ferraris session: t_s, ax ay az, gx gy gz "
                                          "(six static faces, then one turn about each axis)."),
    *, config, run, read: ReadOptions = None,
):
    """Ferraris protocol: accelerometer (12 parameters) and gyro (scale, misalignment, bias,
    g-sensitivity) from six static faces and a turn about each axis."""
    def produce(bar):
        rec = wt.read(file, options=read, unit=config.unit, g_local=config.g_local)
        return wf.run_ferraris(rec, config, name=file.name, progress=bar)

    run.execute("triaxial ferraris", produce, figures=commands.triaxial_ferraris,
                inputs=[file] + ([Path(config.sections)] if config.sections else []))


@config_command(wt.ExportConfig, out="file!", out_help="Output file (imu_tk: the stem of "
                                                       "<stem>_acc.calib and <stem>_gyro.calib).")
def triaxial_export(
    model_file: Path = typer.Argument(..., help="model.json from 'triaxial fit' or 'triaxial "
                                                "ferraris'."),
    to: str = typer.Option(..., "--to", help=_TARGETS_HELP),
    *, config, run,
):
    """Export a triaxial calibration for another tool (--to: one of the registered targets)."""
    run.execute("triaxial export", lambda bar: wt.run_export(_load(model_file), to, run.out,
                                                             config), inputs=[model_file])


def register(app: typer.Typer, groups: dict) -> None:
    triaxial = groups["triaxial"]
    fit_cmd = reading_options(triaxial_fit)
    apply_cmd = reading_options(triaxial_apply)
    triaxial.command("fit")(fit_cmd)
    ferraris_cmd = reading_options(triaxial_ferraris)
    triaxial.command("apply")(apply_cmd)
    triaxial.command("ferraris")(ferraris_cmd)
    triaxial.command("export")(triaxial_export)
