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
    reading_options,
)
from inertialab.errors import InputError
from inertialab.io.mapping import ReadOptions
from inertialab.jsonable import to_jsonable


def _read_schedule(file: Path, schedule: Path | None):
    """The pose schedule of a raw log: ``--schedule`` or ``<stem>.schedule.csv`` if present."""
    from inertialab.io.sidecar import read_schedule, schedule_path

    sp = schedule if schedule is not None else schedule_path(file)
    if schedule is None and not Path(sp).exists():
        return None, None
    return read_schedule(sp), sp  # the text front door: regular file, size, encoding


def triaxial_fit(
    file: Path = typer.Argument(..., help="Static-record CSV (one row per pose) or raw log "
                                          "(t_s, ax, ay, az [, gx, gy, gz]); told apart by columns."),
    method: str = typer.Option("lm", "--method", help="lm | acs | cs | pso | six-position | "
                                                      "ellipsoid, a comma list of them, or all: "
                                                      "several methods write the per-method "
                                                      "parameter and error tables (--out)."),
    objective: str = typer.Option(None, "--objective",
                                  help="norm (J_H, field mode; default) | norm2 (J_H2) | scalar "
                                       "(S9, needs references) | scalar12 (S12, with mount "
                                       "rotation). lm, acs, cs, pso only."),
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
    max_generations: int = typer.Option(None, "--max-generations",
                                        help="Metaheuristic generation budget (acs, cs, pso; "
                                             "default 1000)."),
    placement_deg: float = typer.Option(None, "--placement-deg",
                                        help="six-position: standard deviation of a hand-placed "
                                             "face's tilt, deg (default 2)."),
    bias_limit: float = typer.Option(None, "--bias-limit",
                                     help="Largest plausible |accelerometer bias|, m/s^2 "
                                          "(default 0.5 g)."),
    norm_tol: float = typer.Option(None, "--norm-tol",
                                   help="Largest plausible | |a| - g | of a calibrated pose, "
                                        "m/s^2 (default 0.02 g)."),
    force: bool = typer.Option(False, "--force",
                               help="Write a non-identifiable or implausible calibration "
                                    "anyway, flagged (apply then needs --force too)."),
    seed: SeedOpt = 0,
    out: OutDirOpt = None,
    as_json: JsonOpt = False,
    quiet: QuietOpt = False,
    read: ReadOptions = None,
):
    """Calibrate a triaxial accelerometer (and gyro) from static records or a raw log."""
    import numpy as np

    from inertialab.calib.triaxial_checks import Limits
    from inertialab.io import save_model
    from inertialab.workflows import triaxial as wf

    methods = wf.methods_from(method)
    config = wf.Config(method=methods[0], objective=objective, seed=seed,
                       max_generations=max_generations, robust=robust,
                       placement_deg=placement_deg,
                       gyro_lsb_per_rps=gyro_lsb_per_rps, force=force,
                       limits=Limits(bias=bias_limit, norm_tol=norm_tol))
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
        batch = wf.fit(session, config) if wf.is_batch(session) and len(methods) == 1 else None
        bar.update(0.4, 1.0, "records ready")
    if batch is not None:
        _report_batch(batch, file, out_dir, as_json, warns)
        return
    runs = skipped = None
    with collect_warnings(quiet=quiet or as_json) as warns2, \
            progress_bar("triaxial fit", quiet=quiet or as_json) as bar:
        if len(methods) > 1:
            runs, skipped = wf.fit_methods(session, config, methods)
            run = next(iter(runs.values()))
        else:
            run = wf.fit(session, config)
        bar.update(1.0, 1.0, "done")
    warns = list(warns) + [w for w in warns2 if w not in warns]
    fit, data = run.fit, run.data
    m, obj = fit.method, run.model.objective
    payload = wf.result_payload(run)
    payload["seed"] = seed
    tables = None
    if runs is not None:
        tables = _method_tables(runs)
        payload["methods"] = _methods_payload(tables, skipped)
    units_ = wf.result_units(run)
    gsuf = session.gyro_suffix
    settings = {"method": m if runs is None else methods, "objective": obj, "unit": ulower, "lsb_per_g": lsb_per_g,
                "gyro": gyro, "g_local": data.g, "seed": seed, "k_thr": k_thr,
                "threshold": threshold, "t_init_s": t_init, "window_s": window,
                "min_duration_s": min_duration, "robust": robust,
                "max_generations": max_generations, "placement_deg": placement_deg,
                "bias_limit_mps2": bias_limit,
                "norm_tol_mps2": norm_tol, "force": force}
    if out_dir is not None:
        from inertialab.report.figures.triaxial import (
            convergence_figure,
            coverage_figure,
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
                norm_error_figure({f"{m}-{obj}": np.linalg.norm(cor, axis=1) - data.g}),
                coverage_figure(cor, title=f"{file.name}: pose coverage")]
        if fit.history is not None:
            figs.append(convergence_figure({m: [fit.history]}))
        if tables is not None:
            figs.append(_write_method_tables(tables, skipped, out_dir, file.name))
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
    q = payload["quality"]
    ne = q["norm_error"]
    print(f"| |a| - g |: RMSE {ne['rmse_mps2']:.4g}, max {ne['max_abs_mps2']:.4g} m/s^2 over "
          f"{len(q['per_pose'])} poses")
    if "eq21" in q:
        print(f"eq. 21 vector error: RMSE {q['eq21']['rmse_mps2']:.4g}, SD {q['eq21']['sd_mps2']:.4g}"
              f" m/s^2 ({q['eq21']['frame']} frame)")
    print(f"95 % intervals (t, {q['dof']} dof): " + "; ".join(
        f"{k} [{lo:.6g}, {hi:.6g}]" for k, (lo, hi) in q["ci95"].items()))
    if run.gyro_fit is not None:
        gf = run.gyro_fit
        print("gyro: rate = M_g @ (raw - bias)   [rad/s]")
        for row in gf.matrix:
            print("  [" + "  ".join(f"{v:+.9g}" for v in row) + "]")
        print("bias = [" + ", ".join(f"{v:.6g}" for v in gf.bias) + f"] {gsuf}; "
              f"direction residual RMS = {gf.residual_rms:.3g} rad over {gf.n_pairs} motions")
    for flag in run.model.flags:
        print(f"FLAGGED: {flag}")
    if tables is not None:
        _print_methods(tables, skipped, m)
    if out_dir is not None:
        print(f"written: {out_dir}")


def _method_tables(runs: dict) -> dict:
    from inertialab.calib import triaxial_compare as tc

    poses = tc.pose_error_table(runs)
    return {"params": tc.parameter_table(runs), "poses": poses,
            "summary": tc.error_summary(poses)}


def _methods_payload(tables: dict, skipped: dict) -> dict:
    out = {}
    for name, grp in tables["params"].groupby("method", sort=False):
        out[name] = {"objective": grp["objective"].iloc[0],
                     "params": dict(zip(grp["parameter"], grp["value"])),
                     "stderr": dict(zip(grp["parameter"], grp["stderr"])),
                     "ci95": {p: [lo, hi] for p, lo, hi in
                              zip(grp["parameter"], grp["ci95_low"], grp["ci95_high"])}}
    for row in tables["summary"].to_dict("records"):
        out[row.pop("method")]["errors"] = row
    return {"fitted": out, "skipped": dict(skipped)}


def _write_method_tables(tables: dict, skipped: dict, out_dir: Path, name: str):
    """params.csv/.md, pose_errors.csv, method_errors.csv; returns the Fig. 8 figure."""
    from inertialab.calib.triaxial_compare import markdown
    from inertialab.report.figures.triaxial import method_errors_figure

    for key, fname in (("params", "params.csv"), ("poses", "pose_errors.csv"),
                       ("summary", "method_errors.csv")):
        atomic_write_text(out_dir / fname, tables[key].to_csv(index=False, float_format="%.17g"))
    parts = [f"# Calibration parameters per method: {name}\n",
             "Value, standard error and 95 % t-interval of every parameter (spec 002 "
             "Tables 3-6, 8-9, 11-12 from these data). b in the working unit, k "
             "dimensionless (counts per m/s^2 in counts mode), angles in rad.\n"]
    for method, grp in tables["params"].groupby("method", sort=False):
        parts.append(f"## {method} (objective {grp['objective'].iloc[0]})\n")
        parts.append(markdown(grp[["parameter", "value", "stderr", "ci95_low", "ci95_high",
                                   "unit"]]))
    parts.append("## Errors per method (m/s^2)\n")
    parts.append(markdown(tables["summary"]))
    if skipped:
        parts.append("## Methods left out\n")
        parts.extend(f"- {k}: {v}\n" for k, v in skipped.items())
    atomic_write_text(out_dir / "params.md", "\n".join(parts))
    return method_errors_figure(tables["poses"], title=f"{name}: error per pose and method")


def _print_methods(tables: dict, skipped: dict, primary: str) -> None:
    wide = tables["params"].pivot(index="parameter", columns="method", values="value")
    wide = wide.reindex(index=list(dict.fromkeys(tables["params"]["parameter"])),
                        columns=list(dict.fromkeys(tables["params"]["method"])))
    print_table(["parameter", *wide.columns], [[p, *row] for p, row in
                                                zip(wide.index, wide.to_numpy().tolist())],
                title=f"parameters per method (model.json holds {primary})")
    summ = tables["summary"]
    cols = [c for c in summ.columns if c.endswith("rmse_mps2") or c.endswith("sd_mps2")]
    print_table(["method", *cols], summ[["method", *cols]].to_numpy().tolist(),
                title="errors per method (m/s^2)")
    for k, v in skipped.items():
        print(f"left out {k}: {v}")


def triaxial_apply(
    model_file: Path = typer.Argument(..., help="model.json from 'triaxial fit --out'."),
    file: Path = typer.Argument(..., help="Raw log or static-record file in the model's raw unit."),
    out: Path = typer.Option(..., "--out", help="Output record file (.csv or .parquet); a "
                                                "sidecar .meta.json is written beside it."),
    unit: str = typer.Option(None, "--unit", help="Unit of suffix-less ax/ay/az (mps2 | g | lsb)."),
    force: bool = typer.Option(False, "--force", help="Apply a flagged calibration anyway."),
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
        cal = wf.apply(model, rec, model_path=model_file, force=force)
        write_record(cal.data, out, cal.meta)
    cols = [rec.find(b) for b in ("ax", "ay", "az")]
    gyro_done = wf.gyro_applied(model, rec)
    summary = {"output": str(out), "rows": int(len(cal.data)), "accelerometer_columns": cols,
               "gyro_calibrated": gyro_done, "raw_unit": model.raw_unit}
    if as_json:
        emit_json("triaxial apply", summary, inputs=[model_file, file],
                  settings={"unit": ulower, "force": force}, units={}, warnings_=warns)
        return
    print(f"written: {out} ({len(cal.data)} rows, calibrated to m/s^2"
          + (" and rad/s" if gyro_done else "") + ")")


def triaxial_ferraris(
    file: Path = typer.Argument(..., help="Raw log of a Ferraris session: t_s, ax ay az, gx gy gz "
                                          "(six static faces, then one turn about each axis)."),
    sections: Path = typer.Option(None, "--sections",
                                  help="imucal section list (JSON {\"x_p\": {\"start\": i, "
                                       "\"end\": j}, ..., \"z_rot\": ...}); default: detected "
                                       "from the accelerometer and the gyro."),
    rotation_deg: float = typer.Option(360.0, "--rotation-deg",
                                       help="Angle of every turn, deg (the sense is detected)."),
    placement_deg: float = typer.Option(2.0, "--placement-deg",
                                        help="Standard deviation of a face's hand-placement "
                                             "tilt, deg."),
    no_g_sensitivity: bool = typer.Option(False, "--no-g-sensitivity",
                                          help="Do not estimate the gyro's g-sensitivity."),
    g_local: float = typer.Option(None, "--g-local", help="Local gravity, m/s^2 (else header, "
                                                          "else 9.80665 with a warning)."),
    unit: str = typer.Option(None, "--unit", help="Unit of suffix-less ax/ay/az (mps2 | g | lsb)."),
    bias_limit: float = typer.Option(None, "--bias-limit",
                                     help="Largest plausible |accelerometer bias|, m/s^2."),
    force: bool = typer.Option(False, "--force", help="Write an implausible calibration "
                                                      "anyway, flagged."),
    out: OutDirOpt = None,
    as_json: JsonOpt = False,
    quiet: QuietOpt = False,
    read: ReadOptions = None,
):
    """Ferraris protocol: accelerometer (12 parameters) and gyro (scale, misalignment, bias,
    g-sensitivity) from six static faces and a turn about each axis."""
    from inertialab.calib.triaxial_checks import Limits
    from inertialab.io import save_model
    from inertialab.workflows import ferraris as wf
    from inertialab.workflows import triaxial as wt

    out_dir = prepare_out_dir(out) if out is not None else None
    config = wf.Config(rotation_deg=rotation_deg, placement_deg=placement_deg,
                       g_sensitivity=not no_g_sensitivity, force=force,
                       limits=Limits(bias=bias_limit))
    inputs = [file] + ([sections] if sections is not None else [])
    with collect_warnings(quiet=quiet or as_json) as warns, \
            progress_bar("triaxial ferraris", quiet=quiet or as_json) as bar:
        rec = wt.read(file, options=read, unit=unit, g_local=g_local)
        session = wf.prepare(rec, sections=sections, g_local=g_local)
        bar.update(0.5, 1.0, "sections ready")
        run = wf.fit(session, config)
        bar.update(1.0, 1.0, "done")
    payload = wf.result_payload(run)
    units_ = wf.result_units(run)
    settings = {"sections": None if sections is None else str(sections),
                "rotation_deg": rotation_deg, "placement_deg": placement_deg,
                "g_sensitivity": not no_g_sensitivity, "g_local": session.g, "unit": unit,
                "bias_limit_mps2": bias_limit, "force": force}
    if out_dir is not None:
        from inertialab.report.figures.triaxial import sections_figure

        save_model(run.model, out_dir / "model.json", units=units_,
                   training_data_sha256=rec.sha256)
        atomic_write_text(out_dir / "result.json",
                          json.dumps(to_jsonable(payload), indent=2, allow_nan=False) + "\n")
        atomic_write_text(out_dir / "sections.json",
                          json.dumps(payload["sections"], indent=1) + "\n")
        write_figures([sections_figure(session.t, session.acc, session.gyro, session.sections,
                                       detection=session.detection,
                                       title=f"{file.name}: Ferraris sections")], out_dir)
    if as_json:
        emit_json("triaxial ferraris", payload, inputs=inputs, settings=settings, units=units_,
                  warnings_=warns)
        return
    how = "detected" if session.detection is not None else f"from {sections}"
    print(f"triaxial ferraris: {file.name}, sections {how}, {session.fs:g} Hz, g = {session.g:g}")
    rows = [[name, f"{d['norm_error_mps2']:+.2e}", f"{d['tilt_deg']:.2f}"]
            for name, d in payload["faces"].items()]
    print_table(["face", "|a| - g (m/s^2)", "tilt (deg)"], rows, title="faces")
    for name, d in payload["turns"].items():
        sense = "counterclockwise" if d["sense"] > 0 else "clockwise"
        print(f"{name}: {sense} seen from above, axis ("
              + ", ".join(f"{v:+.3f}" for v in d["axis"]) + ")")
    print("accelerometer: a = correction_matrix @ (raw - offset)   [m/s^2]")
    for row in payload["correction_matrix"]:
        print("  [" + "  ".join(f"{v:+.9g}" for v in row) + "]")
    print("gyro: rate = M_g @ (raw - offset - g_sensitivity @ a)   [rad/s]")
    for row in payload["gyro"]["correction_matrix"]:
        print("  [" + "  ".join(f"{v:+.9g}" for v in row) + "]")
    for flag in run.model.flags:
        print(f"FLAGGED: {flag}")
    if out_dir is not None:
        print(f"written: {out_dir}")



def triaxial_export(
    model_file: Path = typer.Argument(..., help="model.json from 'triaxial fit' or 'triaxial "
                                                "ferraris'."),
    to: str = typer.Option(..., "--to", help="imucal (JSON, format 2.0.0) | imu_tk (.calib text, "
                                             "one per triad) | kalibr (scale-misalignment YAML)"),
    out: Path = typer.Option(..., "--out", help="Output file (imu_tk: the stem of "
                                                "<stem>_acc.calib and <stem>_gyro.calib)."),
    drop_g_sensitivity: bool = typer.Option(False, "--drop-g-sensitivity",
                                            help="imu_tk: export a gyro with a g-sensitivity "
                                                 "without it."),
    force: bool = typer.Option(False, "--force", help="Export a flagged calibration anyway."),
    as_json: JsonOpt = False,
):
    """Export a triaxial calibration for imucal, imu_tk or Kalibr."""
    from inertialab.io import load_model
    from inertialab.io.exporters import imu_tk, imucal, kalibr_intrinsics

    model = load_model(model_file, expected_type="triaxial-calibration")
    fmt = to.strip().lower().replace("-", "_")
    if fmt == "imucal":
        imucal.write_imucal(model, out, force=force)
        written = [str(out)]
    elif fmt == "imu_tk":
        stem = str(out)[:-6] if str(out).endswith(".calib") else str(out)
        written = imu_tk.write_imu_tk(model, stem, drop_g_sensitivity=drop_g_sensitivity,
                                      force=force)
    elif fmt == "kalibr":
        kalibr_intrinsics.write_kalibr(model, out, force=force)
        written = [str(out)]
    else:
        raise InputError(f"--to must be imucal, imu_tk or kalibr, got '{to}'")
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


def simulate_ferraris(
    out: Path = typer.Option(..., "--out", help="Record file (.csv or .parquet); the true "
                                                "sections go to <stem>.sections.json."),
    seed: int = typer.Option(0, "--seed", help="Random seed."),
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
