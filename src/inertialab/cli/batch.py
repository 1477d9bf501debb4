"""``inertialab batch CMD --inputs GLOB``: one command over many files on Dask.

Thin: the ``--tolerance`` rules (:func:`parse_tolerance`) and the ``--inputs`` globs
(:func:`expand_inputs`) are parsed here; the fleet runner is
:func:`inertialab.workflows.batch.run_batch`.
"""

# no "from __future__ import annotations": typer must see the Annotated shared options
import re
import sys
from collections.abc import Sequence
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
from inertialab.cli.options import JsonOpt, OutDirOpt, QuietOpt, reading_options
from inertialab.errors import InputError
from inertialab.io.mapping import ReadOptions

_ALIASES = {"allan": "allan", "triaxial fit": "calibrate-triaxial",
            "thermal apply": "thermal-compensate",
            # old spellings (one release)
            "calibrate-triaxial": "calibrate-triaxial", "calibrate triaxial": "calibrate-triaxial",
            "thermal-compensate": "thermal-compensate", "thermal compensate": "thermal-compensate"}

_CHECK = re.compile(r"^\s*([A-Za-z_][A-Za-z0-9_.]*)\s*(<=|>=|<|>|=)\s*(.+?)\s*$")


def parse_tolerance(text: str | Sequence[str] | None) -> tuple:
    """Parse ``--tolerance`` (``"adev_1s<=0.01,abs(bx)<=0.05,kx=0.99..1.01"``; repeated
    options or a list are joined) into :class:`inertialab.workflows.batch.Check` rules."""
    from inertialab.workflows.batch import Check

    if text is None:
        return ()
    parts = [text] if isinstance(text, str) else list(text)
    checks = []
    for part in parts:
        for raw in str(part).split(","):
            if not raw.strip():
                continue
            s = raw.strip()
            is_abs = False
            m_abs = re.match(r"^abs\(\s*([^)]+?)\s*\)(.*)$", s)
            if m_abs:
                is_abs = True
                s = m_abs.group(1) + m_abs.group(2)
            m = _CHECK.match(s)
            if m is None:
                raise InputError(f"--tolerance: {raw.strip()!r} is not KEY<=VALUE, KEY>=VALUE "
                                 "or KEY=LO..HI")
            key, op, val = m.groups()
            try:
                if op == "=":
                    lo_s, hi_s = val.split("..")
                    lo, hi = float(lo_s), float(hi_s)
                    if lo > hi:
                        raise ValueError
                    checks.append(Check(key, lo, hi, is_abs))
                elif op in ("<=", "<"):
                    checks.append(Check(key, hi=float(val), abs=is_abs))
                else:
                    checks.append(Check(key, lo=float(val), abs=is_abs))
            except ValueError:
                raise InputError(f"--tolerance: bad number or range in {raw.strip()!r}") from None
    return tuple(checks)


def expand_inputs(patterns: str | Sequence[str]) -> list[Path]:
    """The files of ``--inputs`` (:func:`inertialab.workflows.batch.expand_inputs`)."""
    from inertialab.workflows.batch import expand_inputs as expand

    return expand(patterns)


def register(app: typer.Typer, groups: dict) -> None:
    @app.command("batch")
    @reading_options
    def batch(
        cmd: list[str] = typer.Argument(..., help="allan | triaxial fit | thermal apply"),
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
        unit: str = typer.Option(None, "--unit", help="Unit suffix for columns without one."),
        rate: float = typer.Option(None, "--rate", help="Sample rate in Hz (allan)."),
        gaps: str = typer.Option("error", "--gaps", help="error | split (allan logs)."),
        g_local: float = typer.Option(None, "--g-local", help="Local gravity, m/s^2."),
        model: Path = typer.Option(None, "--model", help="Model file (thermal compensate)."),
        out: OutDirOpt = None,
        as_json: JsonOpt = False,
        quiet: QuietOpt = False,
        read: ReadOptions = None,
    ):
        """Run CMD on every file of --inputs (Dask), and write one table: per unit its
        key figures and pass/fail against --tolerance, plus the yield summary."""
        from inertialab.workflows.batch import run_batch

        name = _ALIASES.get(" ".join(cmd).strip().lower())
        if name is None:
            raise InputError(f"batch: unknown command '{' '.join(cmd)}' (allan, triaxial fit, "
                             "thermal apply)")
        if gaps not in ("error", "split"):
            raise InputError(f"--gaps must be 'error' or 'split', got '{gaps}'")
        # the reading options were built (and checked) once here: a bad map is a usage
        # error, not 200 unit errors; the workers get their plain-text form
        paths = expand_inputs(inputs)
        checks = parse_tolerance(tolerance)
        options = {k: v for k, v in {
            "map": read.column_map.to_text() or None, "sep": read.parse.sep,
            "decimal": read.parse.decimal, "skip_rows": read.parse.skip_rows, "unit": unit,
            "rate": rate, "gaps": gaps if name == "allan" else None, "g_local": g_local,
            "model": str(model) if model else None}.items() if v is not None}
        if model is not None and not Path(model).is_file():
            raise InputError("no such model file", path=model)
        # staged first: the Dask workers' scratch space lives inside its staging area
        d = prepare_out_dir(out) if out is not None else None
        with collect_warnings(quiet=quiet or as_json) as warns:
            with progress_bar(f"batch {name}", quiet=quiet) as bar:
                res = run_batch(name, paths, options=options, checks=checks,
                                scheduler=scheduler, workers=workers, progress=bar)
        errors = [u for u in res.units if u.status == "error"]
        if errors and strict:  # nothing written, one line
            raise InputError(f"{len(errors)} of {len(res.units)} units could not be processed "
                             f"(--strict); first: {errors[0].unit}: {errors[0].reason}")
        warns = list(warns) + [f"unit {u.unit}: {u.reason}" for u in errors]
        table = res.table()
        summary = res.summary()
        if d is not None:
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
