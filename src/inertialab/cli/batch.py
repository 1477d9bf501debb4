"""``inertialab batch CMD --inputs GLOB``: one command over many files on Dask."""

from __future__ import annotations

import sys
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

_ALIASES = {"allan": "allan", "calibrate-triaxial": "calibrate-triaxial",
            "calibrate triaxial": "calibrate-triaxial", "thermal-compensate": "thermal-compensate",
            "thermal compensate": "thermal-compensate"}


def register(app: typer.Typer, groups: dict) -> None:
    @app.command("batch")
    def batch(
        cmd: list[str] = typer.Argument(..., help="allan | calibrate triaxial | thermal compensate"),
        inputs: list[str] = typer.Option(..., "--inputs", help="Glob of input files, e.g. "
                                         "'lot7/*.csv' (quote it; repeat for more)."),
        scheduler: str = typer.Option("local", "--scheduler", help="local (a LocalCluster), "
                                      "serial (no Dask), or a scheduler address tcp://host:8786."),
        workers: int = typer.Option(2, "--workers", help="Worker processes of the LocalCluster."),
        tolerance: list[str] = typer.Option(None, "--tolerance", help="Pass/fail rules: "
                                            "KEY<=V, KEY>=V, abs(KEY)<=V, KEY=LO..HI (comma-"
                                            "separated or repeated)."),
        strict: bool = typer.Option(False, "--strict", help="Exit 2 when any unit could not "
                                    "be processed."),
        map_: str = typer.Option(None, "--map", help="Column map target=source[:unit],..."),
        map_file: Path = typer.Option(None, "--map-file", help="Column map JSON/TOML file."),
        unit: str = typer.Option(None, "--unit", help="Unit suffix for columns without one."),
        rate: float = typer.Option(None, "--rate", help="Sample rate in Hz (allan)."),
        gaps: str = typer.Option("error", "--gaps", help="error | split (allan logs)."),
        g_local: float = typer.Option(None, "--g-local", help="Local gravity, m/s^2."),
        model: Path = typer.Option(None, "--model", help="Model file (thermal compensate)."),
        out: Path = typer.Option(None, "--out", help="Directory for units.csv, summary.json "
                                 "and batch.png."),
        as_json: bool = typer.Option(False, "--json", help="Print one JSON object."),
        quiet: bool = typer.Option(False, "--quiet"),
    ):
        """Run CMD on every file of --inputs (Dask), and write one table: per unit its
        key figures and pass/fail against --tolerance, plus the yield summary."""
        from inertialab.workflows.batch import expand_inputs, parse_tolerance, run_batch

        name = _ALIASES.get(" ".join(cmd).strip().lower())
        if name is None:
            raise InputError(f"batch: unknown command '{' '.join(cmd)}' (allan, calibrate "
                             "triaxial, thermal compensate)")
        if gaps not in ("error", "split"):
            raise InputError(f"--gaps must be 'error' or 'split', got '{gaps}'")
        from inertialab.io.mapping import ReadOptions

        ReadOptions.from_cli(map_, map_file)  # a bad map is a usage error, not 200 unit errors
        paths = expand_inputs(inputs)
        checks = parse_tolerance(tolerance)
        options = {k: v for k, v in {
            "map": map_, "map_file": str(map_file) if map_file else None, "unit": unit,
            "rate": rate, "gaps": gaps if name == "allan" else None, "g_local": g_local,
            "model": str(model) if model else None}.items() if v is not None}
        with collect_warnings(quiet=quiet or as_json) as warns:
            with progress_bar(f"batch {name}", quiet=quiet) as bar:
                res = run_batch(name, paths, options=options, checks=checks,
                                scheduler=scheduler, workers=workers, progress=bar)
        errors = [u for u in res.units if u.status == "error"]
        warns = list(warns) + [f"unit {u.unit}: {u.reason}" for u in errors]
        table = res.table()
        summary = res.summary()
        if out is not None:
            d = prepare_out_dir(out)
            atomic_write_text(d / "units.csv", table.to_csv(index=False))
            import json

            from inertialab.cli.common import json_ready
            atomic_write_text(d / "summary.json", json.dumps(json_ready(res.to_dict()),
                                                            indent=2, allow_nan=False))
            from inertialab.report.figures.batch import batch_figure

            write_figures([batch_figure(res)], d)
        settings = {"command": name, "scheduler": scheduler, "workers": workers,
                    "tolerance": [c.text() for c in checks], "strict": strict, **options}
        if as_json:
            emit_json("batch", {"summary": summary, "units": [u.to_dict() for u in res.units]},
                      inputs=paths, settings=settings,
                      units={"wall_s": "s", "yield": "1"}, warnings_=warns)
        else:
            keys = [k for k in res.figure_keys() if k not in ("n_samples", "n_positions")][:6]
            rows = [[u.unit, u.status, *[u.figures.get(k) for k in keys],
                     "; ".join(u.failed) or u.reason] for u in res.units]
            print_table(["unit", "status", *keys, "why"], rows,
                        title=f"batch {name}: {summary['n_pass']}/{summary['n_units']} pass "
                              f"(yield {100 * summary['yield']:.1f} %)")
        if errors and not quiet and not as_json:
            sys.stderr.write(f"warning: {len(errors)} of {len(res.units)} units could not be "
                             "processed (see the table)\n")
        if errors and strict:
            raise InputError(f"{len(errors)} of {len(res.units)} units could not be processed "
                             f"(--strict); first: {errors[0].unit}: {errors[0].reason}")
