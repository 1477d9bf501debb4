"""``inertialab allan --imu`` (old spelling ``allan-imu``): six IMU axes, Kalibr/ROS export."""

from __future__ import annotations

import json

from typer.core import TyperCommand

from inertialab.cli import common as C
from inertialab.cli.options import flagged


class RepeatedExport(TyperCommand):
    """``allan``'s parser, every ``--export TARGET FILE`` kept (click keeps the last)."""

    def parse_args(self, ctx, args):
        RepeatedExport.seen = tuple((args[i + 1], args[i + 2]) for i in range(len(args) - 2)
                                    if args[i] == "--export")
        return super().parse_args(ctx, args)


def run_six_axes(*, file, export=None, rostopic=None, read=None, unit=None, rate=None,
                 gaps=None, g_local=None, method="wls", out=None, as_json=False,
                 quiet=False, command="allan", terms=True, drift=None, confidence=None,
                 force=False):
    """``allan --imu``: read, analyse, export every ``--export``, print or emit JSON."""
    from inertialab.io.mapping import ReadOptions
    from inertialab.report.figures.imu_noise import imu_figures
    from inertialab.workflows.imu_drift import display_tables
    from inertialab.workflows.imu_noise import analyse_file, export_pairs, write_exports

    ro = read if read is not None else ReadOptions()
    pairs = export_pairs(export, seen=getattr(RepeatedExport, "seen", ()))
    with C.collect_warnings(quiet=quiet or as_json) as warns:
        with C.progress_bar("allan-imu", quiet=quiet) as bar:
            rec, res = analyse_file(file, read=ro, unit=unit, rate=rate, gaps=gaps,
                                    g_local=g_local, method=method, terms=terms, progress=bar,
                                    export=pairs, confidence=confidence, **(drift or {}))
    written = write_exports(res, pairs, rostopic=rostopic or rec.topic, force=force, drift=drift)
    payload = {"imu": res.to_dict(), "sha256_canonical": rec.sha256}
    if out is not None:
        d = C.prepare_out_dir(out)
        C.write_figures(imu_figures(res), d)
        C.atomic_write_text(d / "result.json", json.dumps(C.json_ready(payload), indent=2,
                                                       allow_nan=False))
    if as_json:
        settings = {**res.settings, "map": ro.column_map.to_text() or None,
                    "parse": ro.parse.to_dict(), "gaps": gaps, **written}
        return C.emit_json(command, payload, inputs=[file], settings=settings,
                         units={"rate_hz": "Hz"}, warnings_=warns)
    for title, cols, rows in display_tables(res, file):
        C.print_table(cols, rows, title=title)
    print(flagged("\n".join(res.notes())))
