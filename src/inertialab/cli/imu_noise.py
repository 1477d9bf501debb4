"""The six-axis mode of ``inertialab allan --imu`` (old spelling ``allan-imu``): six IMU
axes in one call, with Kalibr/ROS export (registered by :mod:`inertialab.cli.allan`)."""

from __future__ import annotations

from contextvars import ContextVar

from typer.core import TyperCommand

from inertialab.cli import common as C

#: every ``--export TARGET FILE`` of the command line being run
_EXPORTS: ContextVar = ContextVar("inertialab_exports", default=())


class RepeatedExport(TyperCommand):
    """The ``allan`` command's parser with ``--export TARGET FILE`` repeatable: every
    occurrence is kept (click keeps only the last of a two-value option), and the last
    is passed on as usual."""

    def parse_args(self, ctx, args):
        pairs, rest, i = [], [], 0
        while i < len(args):
            if args[i] == "--":
                rest += args[i:]
                break
            if args[i] == "--export" and i + 2 < len(args):
                pairs.append((args[i + 1], args[i + 2]))
            rest.append(args[i])
            i += 1
        _EXPORTS.set(tuple(pairs))
        return super().parse_args(ctx, rest)


def exports_given(export):
    """Every ``--export TARGET FILE`` of the command line (several when repeated), else
    ``export`` as given."""
    seen = list(_EXPORTS.get())
    if export and len(seen) > 1 and tuple(seen[-1]) == tuple(export):
        return seen
    return export


def run_six_axes(*, file, export=None, rostopic=None, read=None, unit=None, rate=None,
                 gaps=None, g_local=None, method="wls", out=None, as_json=False,
                 quiet=False, command="allan", terms=True, drift=None, confidence=None,
                 force=False):
    """The six-axis mode of ``allan --imu`` (old spelling ``allan-imu``): read, analyse,
    export (every ``--export``; refused before anything is written while an axis is not
    static, unless ``force``), print or emit JSON. ``read`` is the command's
    :class:`~inertialab.io.mapping.ReadOptions`; ``drift`` the drift settings of
    :func:`~inertialab.workflows.imu_noise.analyse_file`."""
    from inertialab.io.mapping import ReadOptions
    from inertialab.workflows.imu_drift import display_tables
    from inertialab.workflows.imu_noise import (
        analyse_file,
        export_noise_file,
        export_pairs,
        export_refusal,
    )

    ro = read if read is not None else ReadOptions()
    pairs = export_pairs(exports_given(export))
    with C.collect_warnings(quiet=quiet or as_json) as warns:
        with C.progress_bar("allan-imu", quiet=quiet) as bar:
            rec, res = analyse_file(file, read=ro, unit=unit, rate=rate, gaps=gaps,
                                    g_local=g_local, method=method, terms=terms,
                                    export=pairs, progress=bar, confidence=confidence,
                                    **(drift or {}))
    if pairs:
        export_refusal(res, force=force)  # before any file is written
    written = [(export_noise_file(res, t, f, rostopic=rostopic or rec.topic,
                                  inflate=(drift or {}).get("inflate"), force=force), f)
               for t, f in pairs]
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
                    "parse": ro.parse.to_dict(), "gaps": gaps,
                    "export": written[-1][0] if written else None,
                    "export_file": str(written[-1][1]) if written else None,
                    "exports": [{"target": t, "file": str(f)} for t, f in written],
                    "force": bool(force)}
        return C.emit_json(command, payload, inputs=[file], settings=settings,
                         units={"rate_hz": "Hz"}, warnings_=warns)
    for title, cols, rows in display_tables(res, file):
        C.print_table(cols, rows, title=title)
    import typer

    for line in res.notes():
        typer.echo(line)
