"""The six-axis mode of ``inertialab allan --imu`` (old spelling ``allan-imu``): six IMU
axes in one call, with Kalibr/ROS export (registered by :mod:`inertialab.cli.allan`)."""

from __future__ import annotations

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


def run_six_axes(*, file, export=None, rostopic="/imu0", read=None, unit=None, rate=None,
                 gaps=None, g_local=None, method="wls", out=None, as_json=False,
                 quiet=False, command="allan"):
    """The six-axis mode of ``allan --imu`` (old spelling ``allan-imu``): read, analyse,
    export, print or emit JSON. ``read`` is the command's
    :class:`~inertialab.io.mapping.ReadOptions`."""
    from inertialab.io import read_record
    from inertialab.io.mapping import ReadOptions
    from inertialab.workflows.imu_noise import analyse_record, export_yaml

    export, export_file = export if export else (None, None)
    if export is not None and export not in ("kalibr", "ros"):
        raise InputError(f"--export must be 'kalibr' or 'ros', got '{export}'")
    if gaps not in (None, "error", "split"):
        raise InputError(f"--gaps must be 'error' or 'split', got '{gaps}'")
    ro = read if read is not None else ReadOptions()
    with collect_warnings(quiet=quiet or as_json) as warns:
        rec = read_record(file, "gyro_log", unit=unit, rate_hz=rate, g_local=g_local,
                          gaps=gaps, options=ro)
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
