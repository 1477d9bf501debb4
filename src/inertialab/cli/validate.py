"""``inertialab validate FILE --kind KIND``: check a rig file against its record schema
(one call to :func:`inertialab.workflows.validate.run` through the runner)."""

from pathlib import Path

import typer

from inertialab.cli.options import reading_options
from inertialab.cli.runner import config_command
from inertialab.config import Config
from inertialab.io.mapping import ReadOptions
from inertialab.workflows import validate as wv


def register(app: typer.Typer, groups: dict) -> None:
    @app.command("validate")
    @reading_options
    @config_command(Config, out=None)
    def validate(
        file: Path = typer.Argument(..., help="Record file: text table, Parquet, .npy, .mat, "
                                              "HDF5, ROS bag, PX4 ULog."),
        kind: str = typer.Option(..., "--kind", help="A record kind (gyro_log, thermal_tumble, "
                                 "triaxial_static, triaxial_raw, dual_tumble, storage_drift, "
                                 "clock_log) or an analysis (allan, imu, vibration, ferraris, triaxial): "
                                 "runs the checks its commands run before computing."),
        *, config, run, read: ReadOptions = None,
    ):
        """Read FILE as a record of KIND, run the checks the commands of KIND run before
        computing, and report its columns, units, size, time base and time stamps (rate,
        jitter, gaps, dropped and repeated samples), or the first problem (file, column
        and row), the same one-line error the commands give."""
        run.execute("validate", lambda bar: wv.run(file, kind, read), inputs=[file])
