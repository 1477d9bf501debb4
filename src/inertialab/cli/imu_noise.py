"""``inertialab allan-imu FILE``: six IMU axes in one call, with Kalibr/ROS export.

(The noise-core owner's ``inertialab allan`` had no ``--imu`` yet when this was
written; this command is the six-axis path. Same reading options as ``batch``.)
"""

from __future__ import annotations

from pathlib import Path

import typer

from inertialab.cli.common import (
    atomic_write_text,
    collect_warnings,
    emit_json,
    prepare_out_dir,
    print_table,
    progress_bar,
    write_figures,
)
from inertialab.errors import InputError


def register(app: typer.Typer, groups: dict) -> None:
    @app.command("allan-imu")
    def allan_imu(
        file: Path = typer.Argument(..., help="IMU log (.csv/.txt/.parquet) with gx/gy/gz and/"
                                    "or ax/ay/az columns, or mapped with --map."),
        export: tuple[str, str] = typer.Option(None, "--export", help="STYLE FILE: "
                                               "write the noise parameters as YAML for kalibr "
                                               "or ros, e.g. --export kalibr imu.yaml."),
        rostopic: str = typer.Option("/imu0", "--rostopic", help="IMU topic in the Kalibr file."),
        map_: str = typer.Option(None, "--map", help="Column map target=source[:unit],..."),
        map_file: Path = typer.Option(None, "--map-file", help="Column map JSON/TOML file."),
        sep: str = typer.Option(None, "--sep", help="Field separator (default: sniffed)."),
        decimal: str = typer.Option(None, "--decimal", help="Decimal mark . or , (default: "
                                    "sniffed)."),
        skip_rows: int = typer.Option(None, "--skip-rows", help="Preamble lines before the "
                                      "header."),
        unit: str = typer.Option(None, "--unit", help="Unit suffix for columns without one."),
        rate: float = typer.Option(None, "--rate", help="Sample rate, Hz (default from t_s)."),
        gaps: str = typer.Option("error", "--gaps", help="error | split (dropouts, repeats)."),
        g_local: float = typer.Option(None, "--g-local", help="Local gravity, m/s^2."),
        method: str = typer.Option("wls", "--method", help="wls | ols | slope (noise terms)."),
        out: Path = typer.Option(None, "--out", help="Directory for imu_allan.png and "
                                 "result.json."),
        as_json: bool = typer.Option(False, "--json", help="Print one JSON object."),
        quiet: bool = typer.Option(False, "--quiet"),
    ):
        """Overlapping Allan deviation and Q N B K R of gyro x/y/z and accelerometer x/y/z
        together: one table, one figure with six curves and their fits, and the noise
        densities and random walks for Kalibr or ROS."""
        return run_six_axes(file=file, export=export, rostopic=rostopic, map_=map_,
                            map_file=map_file, sep=sep, decimal=decimal, skip_rows=skip_rows,
                            unit=unit, rate=rate, gaps=gaps, g_local=g_local, method=method,
                            out=out, as_json=as_json, quiet=quiet, command="allan-imu")


def run_six_axes(*, file, export=None, rostopic="/imu0", map_=None, map_file=None, sep=None,
                 decimal=None, skip_rows=None, unit=None, rate=None, gaps="error", g_local=None,
                 method="wls", out=None, as_json=False, quiet=False, command="allan-imu"):
    """The six-axis analysis behind ``allan-imu`` and ``allan --imu``: read, analyse,
    export, print or emit JSON."""
    from inertialab.io import read_record
    from inertialab.io.mapping import ReadOptions
    from inertialab.workflows.imu_noise import analyse_record, export_yaml

    export, export_file = export if export else (None, None)
    if export is not None and export not in ("kalibr", "ros"):
        raise InputError(f"--export must be 'kalibr' or 'ros', got '{export}'")
    if gaps not in ("error", "split"):
        raise InputError(f"--gaps must be 'error' or 'split', got '{gaps}'")
    ro = ReadOptions.from_cli(map_, map_file, sep=sep, decimal=decimal, skip_rows=skip_rows)
    with collect_warnings(quiet=quiet or as_json) as warns:
        rec = read_record(file, "gyro_log", unit=unit, rate_hz=rate, g_local=g_local,
                          column_map=ro.column_map or None, parse=ro.parse, gaps=gaps)
        with progress_bar("allan-imu", quiet=quiet) as bar:
            res = analyse_record(rec, rate_hz=rate, method=method, g_local=g_local,
                                 progress=bar)
    if export is not None:
        atomic_write_text(export_file, export_yaml(res, export, rostopic=rostopic))
    payload = {"imu": res.to_dict(), "sha256_canonical": rec.sha256}
    if out is not None:
        import json

        from inertialab.cli.common import json_ready
        from inertialab.report.figures.imu_noise import imu_figure

        d = prepare_out_dir(out)
        write_figures([imu_figure(res)], d)
        atomic_write_text(d / "result.json", json.dumps(json_ready(payload), indent=2,
                                                       allow_nan=False))
    settings = {**res.settings, "map": ro.column_map.to_text() or None,
                "parse": ro.parse.to_dict(), "gaps": gaps, "export": export,
                "export_file": str(export_file) if export_file else None}
    if as_json:
        emit_json(command, payload, inputs=[file], settings=settings,
                  units={"rate_hz": "Hz"}, warnings_=warns)
        return
    cols, rows = res.table()
    print_table(cols[:6], [r[:6] for r in rows],
                title=f"{file}: IMU noise, {res.n_samples} samples at {res.rate_hz:g} Hz "
                      "(densities continuous-time, SI)")
