"""``inertialab validate FILE --kind KIND``: check a rig file against its record schema."""

from __future__ import annotations

from pathlib import Path

import typer

from inertialab.cli.common import collect_warnings, emit_json, print_table
from inertialab.cli.options import JsonOpt, QuietOpt, reading_options
from inertialab.io.mapping import ReadOptions


def register(app: typer.Typer, groups: dict) -> None:
    @app.command("validate")
    @reading_options
    def validate(
        file: Path = typer.Argument(..., help="Record file: text table, Parquet, .npy, .mat, "
                                              "HDF5, ROS bag, PX4 ULog."),
        kind: str = typer.Option(..., "--kind", help="gyro_log, thermal_tumble, triaxial_static, "
                                                      "triaxial_raw, dual_tumble, storage_drift"),
        as_json: JsonOpt = False,
        quiet: QuietOpt = False,
        read: ReadOptions = None,
    ):
        """Read FILE as a record of KIND and report its columns, units, size and time
        stamps (rate, jitter, gaps, dropped and repeated samples), or the first problem
        (file, column and row)."""
        from inertialab.io import read_record

        with collect_warnings(quiet=quiet or as_json) as warns:
            rec = read_record(file, kind, options=read)
        cols = list(rec.arrays) + [c for c in rec.data.columns]
        if as_json:
            emit_json("validate", {"kind": rec.kind, "rows": rec.n, "columns": cols,
                                   "column_units": rec.units, "meta": rec.meta,
                                   "timestamps": rec.meta.get("timestamps"),
                                   "timebase": rec.timebase.to_dict() if rec.timebase else None,
                                   "sha256": rec.sha256},
                      inputs=[file], settings={"kind": kind, "unit": read.unit,
                                               "rate_hz": read.rate_hz, **read.settings()},
                      warnings_=warns)
            return
        print_table(["column", "unit"], [[c, rec.units.get(c, "")] for c in cols],
                    title=f"{file}: valid {rec.kind} record, {rec.n} rows")
        tb = rec.timebase
        if tb is not None:
            print(f"time base: {tb.rate_hz:.6g} Hz (tau0 {tb.tau0_s:.6g} s, from the "
                  f"{ {'argument': 'rate option', 'sidecar': 'sidecar fs_hz'}.get(tb.source, tb.source)}), "
                  f"{tb.n_missing} samples lost on its grid")
        ts = rec.meta.get("timestamps")
        if ts and ts.get("n", 0) > 1:
            print(f"time stamps: {ts['mean_rate_hz']:.6g} Hz mean over the kept samples, jitter {ts['jitter_s']:.3g} s, "
                  f"{ts['n_gaps']} gaps ({ts['n_dropped']} samples dropped), "
                  f"{ts['n_repeated']} repeated, {ts['n_out_of_order']} out of order")
