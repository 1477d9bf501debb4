"""``inertialab allan FILE``.

One ``allan`` command with every option, each mode one call through the runner
(:meth:`inertialab.cli.runner.Run.execute`): one series (the runner reads the record
:func:`inertialab.workflows.allan.reading` names; :func:`inertialab.workflows.allan.run`)
or, with ``--imu``, six IMU axes (:func:`inertialab.workflows.imu_noise.run`: the runner
reads the log and a ``--check-on`` log; the workflow writes every ``--export`` once the
result is complete), or with ``--pool`` several logs as one model
(:func:`inertialab.workflows.imu_pool.run_pool`: the runner reads every log and a
``--check-on`` log). The runner prints the tables (or the
JSON object) and writes the figures and ``result.json`` (and ``model.json``) with ``--out``.
"""

# no "from __future__ import annotations": typer must see the Annotated shared options
from pathlib import Path

import typer
from typer.core import TyperCommand

from inertialab.cli.options import reading_options
from inertialab.cli.runner import config_command, read_record
from inertialab.errors import InputError
from inertialab.io.mapping import ReadOptions
from inertialab.workflows import allan as wa
from inertialab.workflows.imu_options import check_options
from inertialab.workflows.registries import export_targets

_EXPORT_HELP = ("TARGET FILE (six-axis mode, repeatable): write the noise densities and "
                "random walks (continuous time, SI) for " + " | ".join(export_targets("noise")))
_IMU_HELP = ("Analyse gyro x/y/z and accelerometer x/y/z together (one table, one figure, "
             "noise densities and random walks).")


class RepeatedExport(TyperCommand):
    """``allan``'s parser, every ``--export TARGET FILE`` kept (click keeps the last)."""

    seen: tuple = ()

    def parse_args(self, ctx, args):
        RepeatedExport.seen = tuple((args[i + 1], args[i + 2]) for i in range(len(args) - 2)
                                    if args[i] == "--export")
        return super().parse_args(ctx, args)


def _six_axes(run, file: Path, config, *, export, rostopic, force, read):
    """``allan --imu FILE``: the settings and every export checked, then one call through
    the runner (the log, and a ``--check-on`` log, read there)."""
    from inertialab.report.figures.imu_noise import imu_figures
    from inertialab.workflows import imu_noise as wn

    check_options(file, config.method, export and rostopic, **config.drift_settings())
    pairs = wn.export_pairs(export, seen=RepeatedExport.seen)
    wn.check_settings(config, pairs)

    def produce(bar):
        rec = read_record(file, "gyro_log", **wn.reading(config), options=read)
        other = wn.check_log(config)
        check = None if other is None else _read_log(other, config, read)
        return wn.run(rec, config, check=check, exports=pairs, rostopic=rostopic,
                      force=force, read=read, progress=bar)

    return run.execute("allan", produce, inputs=[file], figures=lambda r: imu_figures(r.imu))


def _read_log(path, config, read):
    """One log of a pool, or a ``--check-on`` log, read as ``allan --imu`` reads a log. A
    column map applies to the logs whose columns it names: a log that has none of its
    sources but the axes under their own names (``gx_dps`` ...) is read by those, with a
    warning naming it (logs of one pool may differ in column names)."""
    import warnings
    from dataclasses import replace

    from inertialab.errors import DataQualityWarning
    from inertialab.workflows import imu_noise as wn

    try:
        return read_record(path, "gyro_log", **wn.reading(config), options=read)
    except InputError as exc:
        cmap = getattr(read, "column_map", None)
        if not cmap or "mapped source column not in the file" not in str(exc):
            raise
        try:
            rec = read_record(path, "gyro_log", **wn.reading(config),
                              options=replace(read, column_map=type(cmap)()))
        except InputError:
            raise exc from None
    warnings.warn(f"{path}: the column map names columns this log does not have; it is read "
                  "by its own column names", DataQualityWarning, stacklevel=2)
    return rec


def _pool(run, files, config, *, imu, export, read):
    """``allan --imu LOG1 LOG2 ... --pool``: the settings checked, then one call through
    the runner (every log, each with its own units and time base, and a ``--check-on``
    log read there; a log that cannot be read is refused naming it before any fit)."""
    from inertialab.report.figures.imu_noise import imu_figures
    from inertialab.workflows import imu_noise as wn
    from inertialab.workflows import imu_pool as wp

    wp.check_pool(files, config, imu=imu, export=export)

    def produce(bar):
        recs = [_read_log(f, config, read) for f in files]
        other = wn.check_log(config)
        check = None if other is None else _read_log(other, config, read)
        return wp.run_pool(recs, config, check=check, progress=bar)

    return run.execute("allan", produce, inputs=[str(f) for f in files],
                       figures=lambda r: imu_figures(r.imu))


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
        file = files[0]
        if len(files) > 1 or config.pool:  # several logs as one model
            return _pool(run, files, config, imu=imu, export=export, read=read)
        if imu or export:
            if not imu:
                raise InputError("--export needs --imu (six-axis noise parameters)")
            return _six_axes(run, file, config, export=export, rostopic=rostopic, force=force,
                             read=read)
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

        def produce(bar):
            kind, kw = wa.reading(file, config, read)
            return wa.run(read_record(file, kind, **kw), config, progress=bar)

        run.execute("allan", produce, inputs=[file], figures=figures)

    return allan


def register(app: typer.Typer, groups: dict) -> None:
    app.command("allan", cls=RepeatedExport)(_allan_command())
