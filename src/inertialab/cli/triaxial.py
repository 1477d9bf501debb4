"""``inertialab triaxial fit|apply`` and ``inertialab simulate triaxial-poses`` (spec 002).

Thin: parse, call :mod:`inertialab.workflows.triaxial`, print or write. The old
spellings ``calibrate triaxial`` and ``calibrate apply`` stay as hidden aliases for one
release.
"""

# No ``from __future__ import annotations``: typer reads the Annotated options of
# cli/options.py from the signature that reading_options builds, unevaluated.
import functools
import json
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
from inertialab.cli.options import (
    JsonOpt,
    OutDirOpt,
    QuietOpt,
    SeedOpt,
    flagged,
    reading_options,
)
from inertialab.errors import InputError
from inertialab.io.mapping import ReadOptions
from inertialab.jsonable import to_jsonable


def _flag_errors(fn):
    """Library messages name arguments; on the command line they name the flags."""
    @functools.wraps(fn)
    def wrapper(*args, **kwargs):
        try:
            return fn(*args, **kwargs)
        except InputError as exc:
            text = flagged(str(exc))
            if text == str(exc):
                raise
            raise InputError(text) from None

    return wrapper


def _read_schedule(file: Path, schedule: Path | None):
    """The pose schedule of a raw log: ``--schedule`` or ``<stem>.schedule.csv`` if present."""
    import pandas as pd

    from inertialab.io.sidecar import schedule_path

    sp = schedule if schedule is not None else schedule_path(file)
    if schedule is None and not Path(sp).exists():
        return None, None
    if not Path(sp).exists():
        raise InputError("no such schedule file", path=sp)
    sched = pd.read_csv(sp, comment="#", skipinitialspace=True)
    sched.columns = [c.strip().lower() for c in sched.columns]
    return sched, sp


def triaxial_fit(
    file: Path = typer.Argument(..., help="Static-record CSV (one row per pose) or raw log "
                                          "(t_s, ax, ay, az [, gx, gy, gz]); told apart by columns."),
    method: str = typer.Option("lm", "--method", help="lm | acs | cs | pso | six-position | ellipsoid"),
    objective: str = typer.Option("norm", "--objective",
                                  help="norm (J_H, field mode) | norm2 (J_H2) | scalar (S9, "
                                       "needs references) | scalar12 (S12, with mount rotation)"),
    unit: str = typer.Option(None, "--unit", help="Unit of suffix-less ax/ay/az: mps2 | g | lsb "
                                                  "(overrides suffixes and header)."),
    lsb_per_g: float = typer.Option(None, "--lsb-per-g", help="Counts per g (e.g. 16384); "
                                                              "without it counts stay counts."),
    gyro: bool = typer.Option(False, "--gyro", help="Also calibrate the gyro channels of a raw log."),
    gyro_lsb_per_rps: float = typer.Option(None, "--gyro-lsb-per-rps",
                                           help="Gyro counts per rad/s (counts logs)."),
    g_local: float = typer.Option(None, "--g-local", help="Local gravity, m/s^2 (else header, "
                                                          "else 9.80665 with a warning)."),
    schedule: Path = typer.Option(None, "--schedule", help="Schedule CSV of a raw log (pos_id, "
                                                           "pitch_deg, heading_deg or face); "
                                                           "default <stem>.schedule.csv if present."),
    k_thr: float = typer.Option(None, "--k-thr", help="Static-detector threshold multiplier "
                                                      "(default: sweep 2..10)."),
    threshold: float = typer.Option(None, "--threshold",
                                    help="Absolute detector threshold on the summed moving "
                                         "variance, (m/s^2)^2 (counts^2 in counts mode)."),
    t_init: float = typer.Option(10.0, "--t-init", help="Initial rest used by the detector, s."),
    window: float = typer.Option(1.0, "--window", help="Moving-variance window, s."),
    min_duration: float = typer.Option(1.5, "--min-duration", help="Shortest static run, s."),
    robust: bool = typer.Option(False, "--robust", help="soft-L1 loss in the LM (f_scale = 3 x "
                                                        "the robust residual scale of a plain fit)."),
    max_generations: int = typer.Option(1000, "--max-generations",
                                        help="Metaheuristic generation budget."),
    seed: SeedOpt = 0,
    out: OutDirOpt = None,
    as_json: JsonOpt = False,
    quiet: QuietOpt = False,
    read: ReadOptions = None,
):
    """Calibrate a triaxial accelerometer (and gyro) from static records or a raw log."""
    import numpy as np

    from inertialab.io import save_model
    from inertialab.workflows import triaxial as wf

    config = wf.Config(method=method, objective=objective, seed=seed,
                       max_generations=max_generations, robust=robust,
                       gyro_lsb_per_rps=gyro_lsb_per_rps)
    ulower = None if unit is None else unit.lower()
    out_dir = prepare_out_dir(out) if out is not None else None
    inputs = [file]
    with collect_warnings(quiet=quiet or as_json) as warns, \
            progress_bar("triaxial fit", quiet=quiet or as_json) as bar:
        rec = wf.read(file, options=read, unit=ulower, g_local=g_local)
        sched = None
        if wf.is_raw_log(rec):
            sched, sp = _read_schedule(file, schedule)
            if sp is not None:
                inputs.append(sp)
        session = wf.prepare(rec, lsb_per_g=lsb_per_g, schedule=sched, k_thr=k_thr,
                             threshold=threshold, t_init_s=t_init, window_s=window,
                             min_duration_s=min_duration, header_check=ulower is None, gyro=gyro)
        batch = wf.fit(session, config) if wf.is_batch(session) else None
        bar.update(0.4, 1.0, "records ready")
    if batch is not None:
        _report_batch(batch, file, out_dir, as_json, warns)
        return
    with collect_warnings(quiet=quiet or as_json) as warns2, \
            progress_bar("triaxial fit", quiet=quiet or as_json) as bar:
        run = wf.fit(session, config)
        bar.update(1.0, 1.0, "done")
    warns = list(warns) + [w for w in warns2 if w not in warns]
    fit, data = run.fit, run.data
    m, obj = fit.method, config.objective.strip().lower()
    payload = wf.result_payload(run)
    payload["seed"] = seed
    units_ = wf.result_units(run)
    gsuf = session.gyro_suffix
    settings = {"method": m, "objective": obj, "unit": ulower, "lsb_per_g": lsb_per_g,
                "gyro": gyro, "g_local": data.g, "seed": seed, "k_thr": k_thr,
                "threshold": threshold, "t_init_s": t_init, "window_s": window,
                "min_duration_s": min_duration, "robust": robust,
                "max_generations": max_generations}
    if out_dir is not None:
        from inertialab.report.figures.triaxial import (
            convergence_figure,
            norm_error_figure,
            sphere_figure,
        )

        save_model(run.model, out_dir / "model.json", units=units_,
                   training_data_sha256=rec.sha256)
        atomic_write_text(out_dir / "result.json",
                          json.dumps(to_jsonable(payload), indent=2, allow_nan=False) + "\n")
        from inertialab.sensors.triaxial import correct

        cor = correct(fit.x, data.a)
        figs = [sphere_figure(data.a, cor, data.g,
                              title=f"{file.name}: measured vs corrected ({m}, {obj})"),
                norm_error_figure({f"{m}-{obj}": np.linalg.norm(cor, axis=1) - data.g})]
        if fit.history is not None:
            figs.append(convergence_figure({m: [fit.history]}))
        write_figures(figs, out_dir)
    if as_json:
        emit_json("triaxial fit", payload, inputs=inputs, settings=settings,
                  units=units_, warnings_=warns)
        return
    rows = []
    for n in payload["params"]:
        rows.append([n, payload["params"][n], (payload["stderr"] or {}).get(n)])
    if fit.phi is not None:
        for i, n in enumerate(("phi_x", "phi_y", "phi_z")):
            rows.append([n + " (rad)", float(fit.phi[i]), (payload["stderr"] or {}).get(n)])
    print_table(["parameter", "value", "std. error"], rows,
                title=f"triaxial fit: {m}, objective {obj}, {fit.n_records} records"
                      + (f" ({data.intervals.count} static intervals)" if data.intervals else ""))
    print("calibrated = correction_matrix @ (raw - offset)   [m/s^2]")
    for row in payload["correction_matrix"]:
        print("  [" + "  ".join(f"{v:+.9g}" for v in row) + "]")
    print("offset = [" + ", ".join(f"{v:.9g}" for v in payload["offset"]) + f"] {data.raw_unit}")
    print(f"residual RMS = {fit.residual_rms:.4g}, iterations = {fit.iterations}, "
          f"nfev = {fit.nfev}")
    if run.gyro_fit is not None:
        gf = run.gyro_fit
        print("gyro: rate = M_g @ (raw - bias)   [rad/s]")
        for row in gf.matrix:
            print("  [" + "  ".join(f"{v:+.9g}" for v in row) + "]")
        print("bias = [" + ", ".join(f"{v:.6g}" for v in gf.bias) + f"] {gsuf}; "
              f"direction residual RMS = {gf.residual_rms:.3g} rad over {gf.n_pairs} motions")
    if out_dir is not None:
        print(f"written: {out_dir}")


def triaxial_apply(
    model_file: Path = typer.Argument(..., help="model.json from 'triaxial fit --out'."),
    file: Path = typer.Argument(..., help="Raw log or static-record file in the model's raw unit."),
    out: Path = typer.Option(..., "--out", help="Output record file (.csv or .parquet); a "
                                                "sidecar .meta.json is written beside it."),
    unit: str = typer.Option(None, "--unit", help="Unit of suffix-less ax/ay/az (mps2 | g | lsb)."),
    as_json: JsonOpt = False,
    quiet: QuietOpt = False,
    read: ReadOptions = None,
):
    """Apply a triaxial calibration: calibrated = correction_matrix @ (raw - offset)."""
    from inertialab.io import load_model, write_record
    from inertialab.workflows import triaxial as wf

    if out.exists() and out.is_dir():
        raise InputError("--out must be a file for this command", path=out)
    ulower = None if unit is None else unit.lower()
    with collect_warnings(quiet=quiet or as_json) as warns:
        model = load_model(model_file, expected_type="triaxial-calibration")
        rec = wf.read(file, options=read, unit=ulower)
        cal = wf.apply(model, rec, model_path=model_file)
        write_record(cal.data, out, cal.meta)
    cols = [rec.find(b) for b in ("ax", "ay", "az")]
    gyro_done = wf.gyro_applied(model, rec)
    summary = {"output": str(out), "rows": int(len(cal.data)), "accelerometer_columns": cols,
               "gyro_calibrated": gyro_done, "raw_unit": model.raw_unit}
    if as_json:
        emit_json("triaxial apply", summary, inputs=[model_file, file],
                  settings={"unit": ulower}, units={}, warnings_=warns)
        return
    print(f"written: {out} ({len(cal.data)} rows, calibrated to m/s^2"
          + (" and rad/s" if gyro_done else "") + ")")


def simulate_triaxial(
    out: Path = typer.Option(..., "--out", help="Record file (.csv or .parquet)."),
    scenario: str = typer.Option("turntable62", "--scenario",
                                 help="sphere1000-clean | sphere100-clean | sphere1000-noisy | "
                                      "turntable62 | turntable62-mount | turntable62-realistic | "
                                      "sixface | rawlog62 | rawlog62-gyro | rawlog62-counts | line5000"),
    seed: int = typer.Option(0, "--seed", help="Random seed."),
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


def register(app: typer.Typer, groups: dict) -> None:
    triaxial, calibrate, simulate = groups["triaxial"], groups["calibrate"], groups["simulate"]
    fit_cmd = _flag_errors(reading_options(triaxial_fit))
    apply_cmd = _flag_errors(reading_options(triaxial_apply))
    triaxial.command("fit")(fit_cmd)
    triaxial.command("apply")(apply_cmd)
    calibrate.command("triaxial", hidden=True)(fit_cmd)
    calibrate.command("apply", hidden=True)(apply_cmd)
    simulate.command("triaxial-poses")(_flag_errors(simulate_triaxial))


def _report_batch(batch, file, out_dir, as_json, warns):
    """Output of a multi-unit (production-line) file: yield and per-unit table."""
    import numpy as np

    t = batch.table
    payload = {"method": "lm-batch", "objective": "scalar", "n_units": int(len(t)),
               "yield_fraction": batch.yield_fraction, "rmse_limit": batch.rmse_limit,
               "rmse_median": float(np.median(t["rmse_mps2"])),
               "rmse_p95": float(np.percentile(t["rmse_mps2"], 95)),
               "converged_fraction": float(t["converged"].mean()), "wall_s": batch.wall_s,
               "failed_units": t.loc[~t["pass"], "unit_id"].tolist()[:100]}
    if out_dir is not None:
        atomic_write_text(out_dir / "units.csv", t.to_csv(index=False, lineterminator="\n"))
        atomic_write_text(out_dir / "result.json",
                          json.dumps(to_jsonable(payload), indent=2) + "\n")
    if as_json:
        emit_json("triaxial fit", payload, inputs=[file], settings={"batch": True},
                  units={"rmse_limit": "m/s^2", "rmse_median": "m/s^2", "rmse_p95": "m/s^2",
                         "wall_s": "s"}, warnings_=warns)
        return
    print(f"{payload['n_units']} units: yield {100 * batch.yield_fraction:.1f} % "
          f"(RMSE <= {batch.rmse_limit} m/s^2 and datasheet ranges); RMSE median "
          f"{payload['rmse_median']:.4f}, p95 {payload['rmse_p95']:.4f} m/s^2; "
          f"solver {batch.wall_s:.2f} s")
    if out_dir is not None:
        print(f"written: {out_dir}")
