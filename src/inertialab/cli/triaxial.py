"""``inertialab triaxial fit|apply`` and ``inertialab simulate triaxial-poses`` (spec 002).

Thin: parse, call :mod:`inertialab.workflows.triaxial`, print or write. The old
spellings ``calibrate triaxial`` and ``calibrate apply`` stay as hidden aliases for one
release.
"""

# No ``from __future__ import annotations``: typer reads the Annotated options of
# cli/options.py from the signature that reading_options builds, unevaluated.
import json
from pathlib import Path

import numpy as np
import typer

from inertialab.cli.common import (
    atomic_write_text,
    emit_json,
)
from inertialab.cli.options import JsonOpt, SeedOpt, reading_options
from inertialab.cli.runner import config_command
from inertialab.errors import InputError
from inertialab.io.mapping import ReadOptions
from inertialab.workflows import triaxial_run as wr
from inertialab.workflows.registries import export_help

_TARGETS_HELP = export_help("calibration")


def _read_schedule(file: Path, schedule: Path | None):
    """The pose schedule of a raw log: ``--schedule`` or ``<stem>.schedule.csv`` if present."""
    from inertialab.io.sidecar import read_schedule, schedule_path

    sp = schedule if schedule is not None else schedule_path(file)
    if schedule is None and not Path(sp).exists():
        return None, None
    return read_schedule(sp), sp  # the text front door: regular file, size, encoding


@config_command(wr.FitConfig)
def triaxial_fit(
    file: Path = typer.Argument(..., help="Static-record CSV (one row per pose) or raw log "
                                          "(t_s, ax, ay, az [, gx, gy, gz]); told apart by columns."),
    *, config, run, read: ReadOptions = None,
):
    """Calibrate a triaxial accelerometer (and gyro) from static records or a raw log."""
    from inertialab.workflows import triaxial as wf

    inputs = [file]

    def produce(bar):
        unit = None if config.unit is None else config.unit.lower()
        rec = wf.read(file, options=read, unit=unit, g_local=config.g_local)
        sched = None
        if wf.is_raw_log(rec):
            sched, sp = _read_schedule(file, None if config.schedule is None
                                       else Path(config.schedule))
            if sp is not None:
                inputs.append(sp)
        return wr.run_fit(rec, config, schedule=sched, name=file.name, progress=bar)

    run.execute("triaxial fit", produce, inputs=inputs, figures=_fit_figures)


def _fit_figures(res):
    """Sphere, norm error, coverage, convergence (and the per-method errors) of a fit."""
    import numpy as np

    from inertialab.report.figures.triaxial import (
        convergence_figure,
        coverage_figure,
        method_errors_figure,
        norm_error_figure,
        sphere_figure,
    )

    if not hasattr(res, "run"):  # a production-line batch: the table is the output
        return []
    fit, data, cor = res.run.fit, res.run.data, res.corrected()
    m, obj = fit.method, res.run.model.objective
    figs = [sphere_figure(data.a, cor, data.g, title=f"{res.name}: measured vs corrected "
                                                      f"({m}, {obj})"),
            norm_error_figure({f"{m}-{obj}": np.linalg.norm(cor, axis=1) - data.g}),
            coverage_figure(cor, title=f"{res.name}: pose coverage")]
    if fit.history is not None:
        figs.append(convergence_figure({m: [fit.history]}))
    if res.tables is not None:
        figs.append(method_errors_figure(res.tables["poses"],
                                         title=f"{res.name}: error per pose and method"))
    return figs


@config_command(wr.ApplyConfig, out=None)
def triaxial_apply(
    model_file: Path = typer.Argument(..., help="model.json from 'triaxial fit --out'."),
    file: Path = typer.Argument(..., help="Raw log or static-record file in the model's raw unit."),
    out: Path = typer.Option(..., "--out", help="Output record file (.csv or .parquet); a "
                                                "sidecar .meta.json is written beside it."),
    *, config, run, read: ReadOptions = None,
):
    """Apply a triaxial calibration: calibrated = correction_matrix @ (raw - offset)."""
    from inertialab.io import write_record
    from inertialab.workflows.registries import load_model

    if out.exists() and out.is_dir():
        raise InputError("--out must be a file for this command", path=out)

    def produce(bar):
        model = load_model(model_file, expected_type="triaxial-calibration")
        res = wr.run_apply(model, file, config, options=read, model_path=model_file,
                           output=out)
        write_record(res.data, out, res.meta)
        return res

    run.execute("triaxial apply", produce, inputs=[model_file, file])


@config_command(wr.FerrarisConfig)
def triaxial_ferraris(
    file: Path = typer.Argument(..., help="Raw log of a Ferraris session: t_s, ax ay az, gx gy gz "
                                          "(six static faces, then one turn about each axis)."),
    *, config, run, read: ReadOptions = None,
):
    """Ferraris protocol: accelerometer (12 parameters) and gyro (scale, misalignment, bias,
    g-sensitivity) from six static faces and a turn about each axis."""
    from inertialab.workflows import triaxial as wt

    def produce(bar):
        rec = wt.read(file, options=read, unit=config.unit, g_local=config.g_local)
        return wr.run_ferraris(rec, config, name=file.name, progress=bar)

    def figures(res):
        from inertialab.report.figures.triaxial import sections_figure

        s = res.session
        return [sections_figure(s.t, s.acc, s.gyro, s.sections, detection=s.detection,
                                title=f"{file.name}: Ferraris sections")]

    run.execute("triaxial ferraris", produce, figures=figures,
                inputs=[file] + ([Path(config.sections)] if config.sections else []))


def triaxial_export(
    model_file: Path = typer.Argument(..., help="model.json from 'triaxial fit' or 'triaxial "
                                                "ferraris'."),
    to: str = typer.Option(..., "--to", help=_TARGETS_HELP),
    out: Path = typer.Option(..., "--out", help="Output file (imu_tk: the stem of "
                                                "<stem>_acc.calib and <stem>_gyro.calib)."),
    drop_g_sensitivity: bool = typer.Option(False, "--drop-g-sensitivity",
                                            help="imu_tk: export a gyro with a g-sensitivity "
                                                 "without it."),
    force: bool = typer.Option(False, "--force", help="Export a flagged calibration anyway."),
    as_json: JsonOpt = False,
):
    """Export a triaxial calibration for another tool (--to: one of the registered targets)."""
    from inertialab.io.exporters import export_calibration, get
    from inertialab.workflows.registries import load_model

    fmt = get("calibration", to).target
    model = load_model(model_file, expected_type="triaxial-calibration")
    written = export_calibration(model, fmt, out, force=force,
                                 drop_g_sensitivity=drop_g_sensitivity)
    if as_json:
        emit_json("triaxial export", {"written": written, "format": fmt}, inputs=[model_file],
                  settings={"to": fmt, "drop_g_sensitivity": drop_g_sensitivity, "force": force},
                  units={})
        return
    print("written: " + ", ".join(written))


def simulate_triaxial(
    out: Path = typer.Option(..., "--out", help="Record file (.csv or .parquet)."),
    scenario: str = typer.Option("turntable62", "--scenario",
                                 help="sphere1000-clean | sphere100-clean | sphere1000-noisy | "
                                      "turntable62 | turntable62-mount | turntable62-realistic | "
                                      "sixface | rawlog62 | rawlog62-gyro | rawlog62-counts | line5000"),
    seed: SeedOpt = 0,
    g_local: float = typer.Option(9.8, "--g-local", help="Gravity of the virtual rig, m/s^2 "
                                                         "(paper: 9.8)."),
    n_units: int = typer.Option(5000, "--n-units", help="Units in line5000."),
    as_json: JsonOpt = False,
):
    """Write a virtual triaxial-poses record (raw logs also write <stem>.schedule.csv)."""
    from inertialab.io import write_record
    from inertialab.io.sidecar import schedule_path
    from inertialab.sim.triaxial_poses import SCENARIOS, simulate

    if scenario not in SCENARIOS:
        raise InputError(f"unknown scenario '{scenario}' (known: {', '.join(SCENARIOS)})")
    if out.exists() and out.is_dir():
        raise InputError("--out must be a file for this command", path=out)
    opts = {"n_units": n_units} if scenario == "line5000" else {}
    if scenario == "line5000":
        from inertialab.sim.triaxial_poses import simulate_line

        rec = simulate_line(n_units, seed=seed, g=g_local)
    else:
        rec = simulate(scenario, seed=seed, g=g_local)
    meta = dict(rec.meta)
    write_record(rec.data, out, meta)
    written = [str(out)]
    if rec.schedule is not None:
        sp = schedule_path(out)
        atomic_write_text(sp, rec.schedule[["pos_id", "pitch_deg", "heading_deg"]]
                          .to_csv(index=False, lineterminator="\n"))
        written.append(str(sp))
    summary = {"written": written, "scenario": scenario, "rows": int(len(rec.data)),
               "kind": rec.kind, "seed": seed, "true_params": meta.get("true_params"), **opts}
    if as_json:
        emit_json("simulate triaxial-poses", summary,
                  settings={"scenario": scenario, "seed": seed, "g_local": g_local},
                  units={"true_params": "m/s^2 (b), 1 (k), rad (theta)"})
        return
    print("written: " + ", ".join(written))


def simulate_ferraris(
    out: Path = typer.Option(..., "--out", help="Record file (.csv or .parquet); the true "
                                                "sections go to <stem>.sections.json."),
    seed: SeedOpt = 0,
    placement_deg: float = typer.Option(2.0, "--placement-deg",
                                        help="Hand-placement tilt per axis, deg (1 sigma)."),
    angle_sigma_deg: float = typer.Option(1.0, "--angle-sigma-deg",
                                          help="Error of each 360-deg turn, deg (1 sigma)."),
    counts: bool = typer.Option(False, "--counts", help="16-bit counts instead of m/s^2, deg/s."),
    as_json: JsonOpt = False,
):
    """Write a virtual Ferraris session (six hand-placed faces, three turns; 102.4 Hz)."""
    from inertialab.io import write_record
    from inertialab.sim.ferraris_session import simulate_ferraris as sim

    if out.exists() and out.is_dir():
        raise InputError("--out must be a file for this command", path=out)
    rec = sim(seed=seed, placement_deg=placement_deg, angle_sigma_deg=angle_sigma_deg,
              counts=counts)
    write_record(rec.data, out, rec.meta)
    sp = out.with_name(out.name.split(".")[0] + ".sections.json")
    atomic_write_text(sp, json.dumps(rec.truth["sections"], indent=1) + "\n")
    summary = {"written": [str(out), str(sp)], "rows": int(len(rec.data)), "seed": seed,
               "senses": rec.truth["senses"].tolist(),
               "angles_deg": [float(v) for v in np.rad2deg(rec.truth["angles_rad"])]}
    if as_json:
        emit_json("simulate ferraris-session", summary,
                  settings={"seed": seed, "placement_deg": placement_deg,
                            "angle_sigma_deg": angle_sigma_deg, "counts": counts},
                  units={"angles_deg": "deg"})
        return
    print("written: " + ", ".join(summary["written"]))


def register(app: typer.Typer, groups: dict) -> None:
    triaxial, calibrate, simulate = groups["triaxial"], groups["calibrate"], groups["simulate"]
    fit_cmd = reading_options(triaxial_fit)
    apply_cmd = reading_options(triaxial_apply)
    triaxial.command("fit")(fit_cmd)
    ferraris_cmd = reading_options(triaxial_ferraris)
    triaxial.command("apply")(apply_cmd)
    triaxial.command("ferraris")(ferraris_cmd)
    triaxial.command("export")(triaxial_export)
    calibrate.command("triaxial", hidden=True)(fit_cmd)
    calibrate.command("apply", hidden=True)(apply_cmd)
    calibrate.command("ferraris", hidden=True)(ferraris_cmd)
    simulate.command("triaxial-poses")(simulate_triaxial)
    simulate.command("ferraris-session")(simulate_ferraris)
