"""``inertialab allan FILE``.

One ``allan`` command with every option: one series
(:mod:`inertialab.workflows.allan`) or, with ``--imu``, six IMU axes
(:mod:`inertialab.workflows.imu_noise`, Kalibr/ROS export). Thin: parse the options, read the record, call
the workflow, print the table and the noise terms (or its JSON object), write
the figure, ``result.json`` and ``model.json`` with ``--out``.
"""

# no "from __future__ import annotations": typer must see the Annotated shared options
from pathlib import Path

import typer

from inertialab.cli.options import reading_options
from inertialab.cli.runner import config_command
from inertialab.errors import InputError
from inertialab.io.mapping import ReadOptions
from inertialab.workflows import allan_run as wa
from inertialab.workflows.imu_options import check_options
from inertialab.workflows.registries import export_targets

_EXPORT_HELP = ("TARGET FILE (six-axis mode, repeatable): write the noise densities and "
                "random walks (continuous time, SI) for " + " | ".join(export_targets("noise")))
_IMU_HELP = ("Analyse gyro x/y/z and accelerometer x/y/z together (one table, one figure, "
             "noise densities and random walks).")


def _allan_command():
    """The ``allan`` command: one function, every option."""

    @reading_options
    @config_command(wa.AllanConfig)
    def allan(
        files: list[Path] = typer.Argument(..., help="Log file: CSV/Parquet (gyro_log) or .npy "
                                           "(needs --rate, --unit); several: --imu --pool."),
        imu: bool = typer.Option(False, "--imu", help=_IMU_HELP),
        export: tuple[str, str] = typer.Option(None, "--export", help=_EXPORT_HELP),
        rostopic: str = typer.Option("/imu0", "--rostopic", help="IMU topic in the Kalibr, "
                                     "OpenVINS and VINS files (six-axis mode)."),
        force: bool = typer.Option(False, "--force", help="Export despite axes not static."),
        *, config, run, read: ReadOptions = None,
    ):
        """Allan family with confidence intervals and the Q N B K R noise terms; --imu:
        six IMU axes in one table and figure, with Kalibr/ROS export."""
        command, file = "allan", files[0]
        if len(files) > 1 or config.pool:  # several logs as one model
            from inertialab.report.figures.imu_noise import imu_figures
            from inertialab.workflows.imu_pool import run_pool
            return run.execute(command, lambda bar: run_pool(
                files, config, imu=imu, export=export, read=read, progress=bar),
                inputs=[str(f) for f in files], figures=lambda r: imu_figures(r.imu))
        if imu or export:
            from inertialab.cli.imu_noise import run_six_axes

            if not imu:
                raise InputError("--export needs --imu (six-axis noise parameters)")
            c = config
            check_options(file, c.method, export and rostopic, **c.drift_settings())
            return run_six_axes(file=file, export=export, rostopic=rostopic, read=read,
                                unit=c.unit, rate=c.rate, gaps=c.gaps, g_local=c.g_local,
                                method=c.method, out=run.out, as_json=run.as_json,
                                quiet=run.quiet, command=command, terms=c.terms is not False,
                                drift=c.drift_settings() | {"warmup": c.warmup},
                                confidence=c.confidence, force=force)
        if any(v not in (None, False) for v in config.drift_settings().values()):
            raise InputError("--predict-drift, --check-on, --plan, --inflate, --warmup need --imu")
        config.check()  # refuse bad settings before reading

        def figures(res):
            from inertialab.report.figures.allan import deviation_figure
            from inertialab.report.figures.noise_terms import allan_terms_figure

            figs = [deviation_figure(res.res)]
            if res.res.terms is not None and res.res.oadev is not None:
                figs.append(allan_terms_figure(res.res.oadev, res.res.terms))
            return figs

        run.execute("allan", lambda bar: wa.run(file, config, options=read, progress=bar),
                    inputs=[file], figures=figures)

    return allan


def register(app: typer.Typer, groups: dict) -> None:
    from inertialab.cli.imu_noise import RepeatedExport as Cls
    app.command("allan", cls=Cls)(_allan_command())
