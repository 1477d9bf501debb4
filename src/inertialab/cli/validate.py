"""``inertialab validate FILE --kind KIND``: check a rig file against its record schema."""

from __future__ import annotations

from pathlib import Path

import typer

from inertialab.cli.common import collect_warnings, emit_json, print_table


def register(app: typer.Typer, groups: dict) -> None:
    @app.command("validate")
    def validate(
        file: Path = typer.Argument(..., help="Record file (.csv, .parquet, .npy)."),
        kind: str = typer.Option(..., "--kind", help="gyro_log, thermal_tumble, triaxial_static, "
                                                      "triaxial_raw, dual_tumble, storage_drift"),
        unit: str = typer.Option(None, "--unit", help="Unit suffix for columns without one."),
        rate: float = typer.Option(None, "--rate", help="Sample rate in Hz (.npy logs)."),
        as_json: bool = typer.Option(False, "--json", help="Print one JSON object."),
        quiet: bool = typer.Option(False, "--quiet"),
    ):
        """Read FILE as a record of KIND and report its columns, units and size, or the
        first problem (file, column and row)."""
        from inertialab.io import read_record

        with collect_warnings(quiet=quiet or as_json) as warns:
            rec = read_record(file, kind, unit=unit, rate_hz=rate)
        cols = list(rec.arrays) + [c for c in rec.data.columns]
        if as_json:
            emit_json("validate", {"kind": rec.kind, "rows": rec.n, "columns": cols,
                                   "column_units": rec.units, "meta": rec.meta,
                                   "sha256": rec.sha256},
                      inputs=[file], settings={"kind": kind, "unit": unit, "rate_hz": rate},
                      warnings_=warns)
            return
        print_table(["column", "unit"], [[c, rec.units.get(c, "")] for c in cols],
                    title=f"{file}: valid {rec.kind} record, {rec.n} rows")
