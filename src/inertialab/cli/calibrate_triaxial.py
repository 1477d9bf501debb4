"""``inertialab calibrate triaxial``, ``inertialab calibrate apply`` and
``inertialab simulate triaxial-poses`` (spec 002). Thin: parse, call
:mod:`inertialab.workflows.field_calibration`, print or write."""

from __future__ import annotations

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
from inertialab.errors import InputError

_METHODS = ("lm", "acs", "cs", "pso", "six-position", "ellipsoid")
_OBJECTIVES = ("norm", "norm2", "scalar", "scalar12")
_UNITS = ("mps2", "g", "mg", "lsb")


def _columns_of(path: Path) -> list[str]:
    """Column names of a CSV (after ``#`` header lines) or Parquet file, lower-case."""
    if not path.exists():
        raise InputError("no such file", path=path)
    if path.suffix.lower() in (".parquet", ".pq"):
        try:
            import pyarrow.parquet as pq

            return [c.lower() for c in pq.read_schema(path).names]
        except ImportError:
            raise InputError("reading Parquet needs pyarrow", path=path) from None
    try:
        with open(path, encoding="utf-8") as fh:
            for line in fh:
                if line.lstrip().startswith("#") or not line.strip():
                    continue
                return [c.strip().lower() for c in line.strip().split(",")]
    except UnicodeDecodeError:
        raise InputError("not UTF-8 text; save the file as UTF-8 CSV", path=path) from None
    raise InputError("no header line", path=path)


def _is_raw_log(path: Path) -> bool:
    return "t_s" in _columns_of(path)


def _acc_cols(record):
    cols = [record.find(b) for b in ("ax", "ay", "az")]
    if any(c is None for c in cols):
        raise InputError("missing accelerometer columns ax, ay, az (with a unit suffix)",
                         path=record.path)
    return cols


def _gyro_cols(record):
    cols = [record.find(b) for b in ("gx", "gy", "gz")]
    if any(c is None for c in cols):
        return None
    return cols


def _suffix(col: str) -> str:
    from inertialab.units import split_suffix

    return split_suffix(col)[1]


def _payload(run, fit, data) -> dict:
    m = run.model
    d = m.to_dict()
    out = {
        "method": d["method"], "objective": d["objective"], "params": d["params"],
        "stderr": d["stderr"], "correction_matrix": d["correction_matrix"],
        "offset": d["offset"], "residual_rms": d["residual_rms"], "iterations": d["iterations"],
        "nfev": d["nfev"], "n_records": d["n_records"], "static_intervals": d["static_intervals"],
        "raw_unit": d["raw_unit"], "g_local": d["g_local"], "phi": d["phi"],
        "J": fit.J, "J_final": fit.J, "x": fit.x.tolist(),
        "x_names": list(d["params"]), "converged": fit.converged, "cond": fit.cond,
        "cov": None if fit.cov is None else fit.cov.tolist(),
        "counts_mode": bool(data.counts), "wall_s": fit.wall_s,
    }
    if data.intervals is not None:
        out["detection"] = {"k_thr": data.k_thr, "threshold": data.intervals.threshold,
                            "counts_per_k_thr": None if data.sweep_counts is None else
                            {f"{k:g}": v for k, v in data.sweep_counts.items()},
                            "t_start_s": data.intervals.t_start.tolist(),
                            "t_end_s": data.intervals.t_end.tolist()}
    if fit.extra:
        out["extra"] = fit.extra
    if d["gyro"] is not None:
        out["gyro"] = d["gyro"]
    return out


def _units(data, has_gyro: bool, gyro_unit: str | None) -> dict:
    work = "lsb" if data.counts else "m/s^2"
    u = {"params.bx": work, "params.by": work, "params.bz": work,
         "params.kx": "lsb per m/s^2" if data.counts else "1",
         "params.ky": "lsb per m/s^2" if data.counts else "1",
         "params.kz": "lsb per m/s^2" if data.counts else "1",
         "params.theta_yz": "rad", "params.theta_zy": "rad", "params.theta_zx": "rad",
         "phi": "rad", "correction_matrix": f"m/s^2 per {data.raw_unit}",
         "offset": data.raw_unit, "residual_rms": work, "J": f"({work})^2",
         "g_local": "m/s^2", "wall_s": "s"}
    if has_gyro:
        u.update({"gyro.correction_matrix": f"rad/s per {gyro_unit}", "gyro.offset": gyro_unit,
                  "gyro.residual_rms": "rad"})
    return u


def register(app: typer.Typer, groups: dict) -> None:
    calibrate, simulate = groups["calibrate"], groups["simulate"]

    @calibrate.command("triaxial")
    def calibrate_triaxial(
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
                                        help="Absolute detector threshold on the summed moving variance, (m/s^2)^2 (counts^2 in counts mode)."),
        t_init: float = typer.Option(10.0, "--t-init", help="Initial rest used by the detector, s."),
        window: float = typer.Option(1.0, "--window", help="Moving-variance window, s."),
        min_duration: float = typer.Option(1.5, "--min-duration", help="Shortest static run, s."),
        robust: bool = typer.Option(False, "--robust", help="soft-L1 loss in the LM (f_scale = 3 x "
                                                            "the robust residual scale of a plain fit)."),
        max_generations: int = typer.Option(1000, "--max-generations",
                                            help="Metaheuristic generation budget."),
        seed: int = typer.Option(0, "--seed", help="Seed of the metaheuristics."),
        out: Path = typer.Option(None, "--out", help="Directory for model.json, result.json and figures."),
        as_json: bool = typer.Option(False, "--json", help="Print the result as JSON."),
        quiet: bool = typer.Option(False, "--quiet", help="No progress or warnings on stderr."),
    ):
        """Calibrate a triaxial accelerometer (and gyro) from static records or a raw log."""
        import numpy as np
        import pandas as pd

        from inertialab.io import read_record, save_model
        from inertialab.io.sidecar import schedule_path
        from inertialab.workflows import field_calibration as fc

        m = method.strip().lower()
        if m not in _METHODS:
            raise InputError(f"--method must be one of {', '.join(_METHODS)}, got '{method}'")
        obj = objective.strip().lower()
        if obj not in _OBJECTIVES:
            raise InputError(f"--objective must be one of {', '.join(_OBJECTIVES)}, got '{objective}'")
        if unit is not None and unit.lower() not in _UNITS:
            raise InputError(f"--unit must be one of {', '.join(_UNITS)}, got '{unit}'")
        ulower = None if unit is None else unit.lower()
        out_dir = prepare_out_dir(out) if out is not None else None
        raw_log = _is_raw_log(file)
        if gyro and not raw_log:
            raise InputError("--gyro needs a raw log (t_s column): static records carry no motion",
                             path=file)
        inputs = [file]
        batch = None
        with collect_warnings(quiet=quiet or as_json) as warns, \
                progress_bar("calibrate triaxial", quiet=quiet or as_json) as bar:
            unit_arg = None if ulower is None else {"ax": ulower, "ay": ulower, "az": ulower}
            rec = read_record(file, "triaxial_raw" if raw_log else "triaxial_static",
                              unit=unit_arg, g_local=g_local)
            meta = dict(rec.meta)
            cols = _acc_cols(rec)
            suffix = _suffix(cols[0])
            robust_kw = {}
            if raw_log:
                sched = None
                sp = schedule if schedule is not None else schedule_path(file)
                if schedule is not None or Path(sp).exists():
                    if not Path(sp).exists():
                        raise InputError("no such schedule file", path=sp)
                    sched = pd.read_csv(sp, comment="#", skipinitialspace=True)
                    sched.columns = [c.strip().lower() for c in sched.columns]
                    inputs.append(sp)
                t = rec.column("t_s")
                data = fc.raw_log_data(
                    t, rec.data[cols].to_numpy(dtype=float), meta, suffix=suffix,
                    lsb_per_g=lsb_per_g, schedule=sched, k_thr=k_thr, threshold=threshold,
                    window_s=window, t_init_s=t_init, min_duration_s=min_duration, path=file,
                    header_check=ulower is None)
            else:
                data = fc.static_data_from_frame(rec.data, meta, lsb_per_g=lsb_per_g, path=file,
                                                 header_check=ulower is None)
                t = None
                if data.unit_id is not None and len(set(data.unit_id)) > 1:
                    if m != "lm" or obj != "scalar":
                        raise InputError(f"{len(set(data.unit_id))} units in one file: the batch "
                                         "solver runs --method lm --objective scalar (S9) only",
                                         path=file)
                    batch = fc.calibrate_batch(data)
            bar.update(0.4, 1.0, "records ready")
        if batch is not None:
            _report_batch(batch, file, out_dir, as_json, warns, rec.sha256)
            return
        with collect_warnings(quiet=quiet or as_json) as warns2, \
                progress_bar("calibrate triaxial", quiet=quiet or as_json) as bar:
            if robust:
                robust_kw = {"loss": "soft_l1", "f_scale": None}
            gyro_raw = gsuf = None
            if gyro:
                gcols = _gyro_cols(rec)
                if gcols is None:
                    raise InputError("--gyro given but the log has no gx, gy, gz columns", path=file)
                gyro_raw = rec.data[gcols].to_numpy(dtype=float)
                gsuf = _suffix(gcols[0])
            run = fc.calibrate_record_data(
                data, method=m, objective=obj, rng=seed, gyro_raw=gyro_raw, t=t,
                gyro_suffix=gsuf, gyro_lsb_per_rps=gyro_lsb_per_rps, meta=meta,
                max_generations=max_generations, **robust_kw)
            bar.update(1.0, 1.0, "done")
        warns = list(warns) + [w for w in warns2 if w not in warns]
        fit = run.fit
        payload = _payload(run, fit, data)
        payload["seed"] = seed
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
            from inertialab.sensors.triaxial import correct

            save_model(run.model, out_dir / "model.json", units=_units(data, gyro, gsuf),
                       training_data_sha256=rec.sha256)
            atomic_write_text(out_dir / "result.json",
                              json.dumps(_clean(payload), indent=2, allow_nan=False) + "\n")
            cor = correct(fit.x, data.a)
            figs = [sphere_figure(data.a, cor, data.g,
                                  title=f"{file.name}: measured vs corrected ({m}, {obj})"),
                    norm_error_figure({f"{m}-{obj}": np.linalg.norm(cor, axis=1) - data.g})]
            if fit.history is not None:
                figs.append(convergence_figure({m: [fit.history]}))
            write_figures(figs, out_dir)
        if as_json:
            emit_json("calibrate triaxial", payload, inputs=inputs, settings=settings,
                      units=_units(data, gyro, gsuf), warnings_=warns)
            return
        names = list(payload["params"])
        rows = []
        for n in names:
            se = (payload["stderr"] or {}).get(n)
            rows.append([n, payload["params"][n], se])
        if fit.phi is not None:
            for i, n in enumerate(("phi_x", "phi_y", "phi_z")):
                se = (payload["stderr"] or {}).get(n)
                rows.append([n + " (rad)", float(fit.phi[i]), se])
        print_table(["parameter", "value", "std. error"], rows,
                    title=f"calibrate triaxial: {m}, objective {obj}, {fit.n_records} records"
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

    @calibrate.command("apply")
    def calibrate_apply(
        model_file: Path = typer.Argument(..., help="model.json from 'calibrate triaxial --out'."),
        file: Path = typer.Argument(..., help="Raw log or static-record file in the model's raw unit."),
        out: Path = typer.Option(..., "--out", help="Output record file (.csv or .parquet)."),
        unit: str = typer.Option(None, "--unit", help="Unit of suffix-less ax/ay/az (mps2 | g | lsb)."),
        as_json: bool = typer.Option(False, "--json", help="Print a summary as JSON."),
        quiet: bool = typer.Option(False, "--quiet", help="No warnings on stderr."),
    ):
        """Apply a triaxial calibration: calibrated = correction_matrix @ (raw - offset)."""
        from inertialab.io import load_model, read_record, write_record

        if out.exists() and out.is_dir():
            raise InputError("--out must be a file for this command", path=out)
        ulower = None if unit is None else unit.lower()
        with collect_warnings(quiet=quiet or as_json) as warns:
            model = load_model(model_file, expected_type="triaxial-calibration")
            raw_log = _is_raw_log(file)
            unit_arg = None if ulower is None else {"ax": ulower, "ay": ulower, "az": ulower}
            rec = read_record(file, "triaxial_raw" if raw_log else "triaxial_static", unit=unit_arg)
            cols = _acc_cols(rec)
            suffix = _suffix(cols[0])
            if suffix != model.raw_unit:
                raise InputError(f"the file's accelerometer unit is '{suffix}', the calibration "
                                 f"expects '{model.raw_unit}'", path=file, column=cols[0])
            df = rec.data.copy()
            cal = model.apply(df[cols].to_numpy(dtype=float))
            pos = df.columns.get_loc(cols[0])
            df = df.drop(columns=cols)
            for i, c in enumerate(("ax_mps2", "ay_mps2", "az_mps2")):
                df.insert(pos + i, c, cal[:, i])
            gcols = _gyro_cols(rec)
            gyro_done = False
            if gcols is not None and model.gyro is not None:
                gs = _suffix(gcols[0])
                if gs != model.gyro.get("raw_unit"):
                    raise InputError(f"the file's gyro unit is '{gs}', the calibration expects "
                                     f"'{model.gyro.get('raw_unit')}'", path=file, column=gcols[0])
                gcal = model.apply_gyro(df[gcols].to_numpy(dtype=float))
                gpos = df.columns.get_loc(gcols[0])
                df = df.drop(columns=gcols)
                for i, c in enumerate(("gx_rps", "gy_rps", "gz_rps")):
                    df.insert(gpos + i, c, gcal[:, i])
                gyro_done = True
            meta = dict(rec.meta)
            meta.update(units="mps2", calibrated_with=str(model_file), source_record=str(file))
            for k in ("lsb_per_g", "lsb_offset", "gyro_lsb_per_rps"):
                meta.pop(k, None)
            write_record(df, out, meta)
        summary = {"output": str(out), "rows": int(len(df)), "accelerometer_columns": cols,
                   "gyro_calibrated": gyro_done, "raw_unit": model.raw_unit}
        if as_json:
            emit_json("calibrate apply", summary, inputs=[model_file, file],
                      settings={"unit": ulower}, units={}, warnings_=warns)
            return
        print(f"written: {out} ({len(df)} rows, calibrated to m/s^2"
              + (" and rad/s" if gyro_done else "") + ")")

    @simulate.command("triaxial-poses")
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
        as_json: bool = typer.Option(False, "--json", help="Print a summary as JSON."),
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
                   "kind": rec.kind, "seed": seed, "true_params": meta.get("true_params"),
                   **opts}
        if as_json:
            emit_json("simulate triaxial-poses", summary, settings={"scenario": scenario,
                                                                     "seed": seed,
                                                                     "g_local": g_local},
                      units={"true_params": "m/s^2 (b), 1 (k), rad (theta)"})
            return
        print("written: " + ", ".join(written))


def _report_batch(batch, file, out_dir, as_json, warns, sha):
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
        from inertialab.cli.common import atomic_write_text as _w

        _w(out_dir / "units.csv", t.to_csv(index=False, lineterminator="\n"))
        _w(out_dir / "result.json", json.dumps(_clean(payload), indent=2) + "\n")
    if as_json:
        emit_json("calibrate triaxial", payload, inputs=[file], settings={"batch": True},
                  units={"rmse_limit": "m/s^2", "rmse_median": "m/s^2", "rmse_p95": "m/s^2",
                         "wall_s": "s"}, warnings_=warns)
        return
    print(f"{payload['n_units']} units: yield {100 * batch.yield_fraction:.1f} % "
          f"(RMSE <= {batch.rmse_limit} m/s^2 and datasheet ranges); RMSE median "
          f"{payload['rmse_median']:.4f}, p95 {payload['rmse_p95']:.4f} m/s^2; "
          f"solver {batch.wall_s:.2f} s")
    if out_dir is not None:
        print(f"written: {out_dir}")


def _clean(obj):
    import math

    import numpy as np

    if isinstance(obj, dict):
        return {str(k): _clean(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [_clean(v) for v in obj]
    if isinstance(obj, np.ndarray):
        return _clean(obj.tolist())
    if isinstance(obj, (np.floating, float)):
        f = float(obj)
        return f if math.isfinite(f) else None
    if isinstance(obj, np.integer):
        return int(obj)
    if isinstance(obj, np.bool_):
        return bool(obj)
    return obj
