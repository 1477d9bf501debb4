"""The six-axis mode of ``inertialab allan --imu`` (old spelling ``allan-imu``): six IMU
axes in one call, with Kalibr/ROS export (registered by :mod:`inertialab.cli.allan`)."""

from __future__ import annotations

from inertialab.cli import common as C


def run_six_axes(*, file, export=None, rostopic=None, read=None, unit=None, rate=None,
                 gaps=None, g_local=None, method="wls", out=None, as_json=False,
                 quiet=False, command="allan", terms=True, drift=None, confidence=None):
    """The six-axis mode of ``allan --imu`` (old spelling ``allan-imu``): read, analyse,
    export, print or emit JSON. ``read`` is the command's
    :class:`~inertialab.io.mapping.ReadOptions`; ``drift`` the drift settings of
    :func:`~inertialab.workflows.imu_noise.analyse_file`."""
    from inertialab.io.mapping import ReadOptions
    from inertialab.workflows.imu_drift import display_tables
    from inertialab.workflows.imu_noise import analyse_file, export_noise_file

    ro = read if read is not None else ReadOptions()
    with C.collect_warnings(quiet=quiet or as_json) as warns:
        with C.progress_bar("allan-imu", quiet=quiet) as bar:
            rec, res = analyse_file(file, read=ro, unit=unit, rate=rate, gaps=gaps,
                                    g_local=g_local, method=method, terms=terms,
                                    export=export, progress=bar, confidence=confidence,
                                    **(drift or {}))
    export, export_file = export if export else (None, None)
    if export is not None:
        export = export_noise_file(res, export, export_file, rostopic=rostopic or rec.topic,
                                   inflate=(drift or {}).get("inflate"))
    payload = {"imu": res.to_dict(), "sha256_canonical": rec.sha256}
    if out is not None:
        import json

        from inertialab.report.figures.imu_noise import imu_figures

        d = C.prepare_out_dir(out)
        C.write_figures(imu_figures(res), d)
        C.atomic_write_text(d / "result.json", json.dumps(C.json_ready(payload), indent=2,
                                                       allow_nan=False))
    if as_json:
        settings = {**res.settings, "map": ro.column_map.to_text() or None,
                    "parse": ro.parse.to_dict(), "gaps": gaps, "export": export,
                    "export_file": str(export_file) if export_file else None}
        return C.emit_json(command, payload, inputs=[file], settings=settings,
                         units={"rate_hz": "Hz"}, warnings_=warns)
    for title, cols, rows in display_tables(res, file):
        C.print_table(cols, rows, title=title)
