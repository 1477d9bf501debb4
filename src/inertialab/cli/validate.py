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
        kind: str = typer.Option(..., "--kind", help="A record kind (gyro_log, thermal_tumble, "
                                 "triaxial_static, triaxial_raw, dual_tumble, storage_drift, "
                                 "clock_log) or an analysis (allan, imu, vibration, ferraris, triaxial): "
                                 "runs the checks its commands run before computing."),
        as_json: JsonOpt = False,
        quiet: QuietOpt = False,
        read: ReadOptions = None,
    ):
        """Read FILE as a record of KIND, run the checks the commands of KIND run before
        computing, and report its columns, units, size, time base and time stamps (rate,
        jitter, gaps, dropped and repeated samples), or the first problem (file, column
        and row), the same one-line error the commands give."""
        from inertialab.io.preflight import read_for

        with collect_warnings(quiet=quiet or as_json) as warns:
            rec = read_for(file, kind, options=read)
        cols = list(rec.arrays) + [c for c in rec.data.columns]
        if as_json:
            emit_json("validate", {"kind": rec.kind, "checked_as": kind, "rows": rec.n, "columns": cols,
                                   "column_units": rec.units, "meta": rec.meta,
                                   "timestamps": rec.meta.get("timestamps"),
                                   "timebase": rec.timebase.to_dict() if rec.timebase else None,
                                   "sha256": rec.sha256},
                      inputs=[file], settings={"kind": kind, "unit": read.unit,
                                               "rate_hz": read.rate_hz, **read.settings()},
                      warnings_=warns)
            return
        print(f"{file}: valid {kind} record ({rec.kind}), {rec.n} rows")
        print_table(["column", "unit"], [[c, rec.units.get(c, "") or _unit_of(c)]
                                          for c in cols])
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


def _unit_of(column: str) -> str:
    """The unit a fixed column's name carries (``t_s`` -> s, ``temp_c`` -> c), else ''."""
    from inertialab.units import SUFFIXES, split_suffix

    suf = split_suffix(column)[1]
    return suf if suf in SUFFIXES else ""
