"""``inertialab thermal fit / apply / export`` (spec 000): each one call to
:mod:`inertialab.workflows.thermal` through the runner (:mod:`inertialab.cli.runner`)."""

from pathlib import Path
from typing import Annotated

import typer

from inertialab.cli.common import prepare_out_dir, write_figures
from inertialab.cli.options import reading_options
from inertialab.cli.runner import config_command, load_model, read_imu_thermal_log, read_record
from inertialab.errors import InputError
from inertialab.io.mapping import ReadOptions
from inertialab.report import commands
from inertialab.workflows import thermal as wt
from inertialab.workflows import thermal_imu as wi


def _read(path: Path, read: ReadOptions):
    return read_record(path, "thermal_tumble", options=read)


def _load(model: Path):
    return load_model(model, expected_type="thermal-compensation")


def _apply_command(name: str):
    """The body of ``thermal apply``."""

    @reading_options
    @config_command(wt.ApplyConfig, out="file!", out_help="Output record (.csv or .parquet); "
                                                          "a sidecar .meta.json is written "
                                                          "beside it.")
    def thermal_apply(
        model: Annotated[Path, typer.Argument(help="model.json from 'thermal fit'.")],
        file: Annotated[Path, typer.Argument(help="thermal_tumble record to compensate.")],
        figure: Annotated[Path | None, typer.Option(
            "--figure", help="Also write the drift before/after compensation per input "
                             "level (Fu et al., spec 000, Fig. 9, the transfer figure) to this .png; needs "
                             "a full tumble with a 55 °C set point.")] = None,
        *, config, run, read: ReadOptions | None = None,
    ):
        """Compensate a record with a thermal model; writes comp_output_mv, comp_a_g, status."""
        if (m := load_model(model)).MODEL_TYPE == "thermal-imu":  # six corrected columns
            return run.execute(name, lambda bar: wi.run_imu_apply(m, _read_imu(file), out=run.out),
                               inputs=lambda res: [model, {"path": str(file), "sha256": res.sha256}])
        if figure is not None and (figure.suffix.lower() != ".png" or figure.is_dir()):
            raise InputError("--figure must name a .png file", path=figure)

        def draw(res, _):
            if figure is None:
                return
            if res.res.drift is None:
                raise InputError("--figure needs a record with a full tumble at every set "
                                 "point and one at the reference temperature", path=file)
            write_figures([commands.thermal_transfer(res, figure.stem)], figure.parent)

        run.execute(name, lambda bar: wt.run_apply(_load(model), _read(file, read), config,
                                                   out=run.out, source=str(model)),
                    inputs=lambda res: [model, {"path": str(file), "sha256": res.sha256}],
                    after=draw)

    return thermal_apply


@config_command(wt.FitConfig)
def thermal_fit(
    ctx: typer.Context,
    file: Annotated[Path, typer.Argument(help="thermal_tumble record (CSV or Parquet).")],
    export: Annotated[list[str] | None, typer.Option("--export", help=wi.EXPORT_HELP)] = None,
    *, config, run, read: ReadOptions | None = None,
):
    """Fit integrated temperature-compensation models on a thermal tumble record.

    --out writes model.json (IAFSA-SCM-ANFIS when fitted, else the first method),
    models/ (every method), result.json and figures of the saved model."""
    pairs, given = wi.pair_exports(export, ctx.args), wi.given(ctx.get_parameter_source)
    if config.imu or export:  # a drone IMU temperature ramp (docs/thermal-imu.md)
        imu_config = wi.imu_config(config, given)  # refuse bad settings before reading
        return run.execute("thermal fit --imu", lambda bar: wi.run_imu_fit(
            _read_imu(file), imu_config, exports=pairs),
            inputs=lambda res: [{"path": str(file), "sha256": res.sha256}],
            figures=commands.thermal_imu_fit)
    config.validate()  # refuse bad settings before reading the record

    run.execute("thermal fit", lambda bar: wt.run_fit(_read(file, read), config, progress=bar),
                inputs=lambda res: [{"path": str(file), "sha256": res.sha256}],
                figures=commands.thermal_fit)


@reading_options
@config_command(wt.ExportConfig, out=None)
def thermal_export(
    model: Annotated[Path, typer.Argument(help="model.json of a fuzzy thermal model.")],
    c: Annotated[Path, typer.Option("--c", help="Directory for the C99 .h/.c pair.")],
    *, config, run, read: ReadOptions | None = None,
):
    """Export a fuzzy thermal model as dependency-free C99 (inputs clamped, status flag)."""
    def produce(bar):
        rec = _read(config.unit_record, read) if config.unit_record is not None else None
        res = wt.run_export(_load(model), config, unit_record=rec)
        res.write(prepare_out_dir(c))
        return res.with_inputs([model] + ([] if rec is None else [
            {"path": str(config.unit_record), "sha256": rec.sha256}]))

    run.execute("thermal export", produce, inputs=lambda res: res.inputs)


def register(app: typer.Typer, groups: dict) -> None:
    thermal = groups["thermal"]
    thermal.command("fit", context_settings={"allow_extra_args": True})(
        reading_options(thermal_fit))
    thermal.command("apply")(_apply_command("thermal apply"))
    thermal.command("export")(thermal_export)


__all__ = ["register"]


def _read_imu(path):
    """A drone IMU temperature-ramp log, read by the runner."""
    return read_imu_thermal_log(path)
