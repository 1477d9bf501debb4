"""The triaxial study's commands as one call each (spec 002; docs/triaxial.md,
docs/ferraris.md): a :class:`~inertialab.config.Config` of settings and
``run_*(record, config) -> result`` whose result knows ``to_json()``, ``settings``,
``units``, ``artifacts()`` (the model and the files beside it) and ``summary_rows()``.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

from inertialab.config import Config, seed_setting, setting
from inertialab.errors import InputError
from inertialab.result import ResultBase

if TYPE_CHECKING:  # the study's floors load when a command runs, not for --help
    import numpy as np

    from inertialab.workflows import triaxial as wf

__all__ = ["ApplyConfig", "ExportConfig", "FerrarisConfig", "FitConfig", "run_apply", "run_export",
           "run_ferraris", "run_fit", "run_fit_file"]

def _matrix_lines(title: str, rows) -> list[str]:
    return [title] + ["  [" + "  ".join(f"{v:+.9g}" for v in row) + "]" for row in rows]


# ---------------------------------------------------------------------------- fit

@dataclass(frozen=True)
class FitConfig(Config):
    """Settings of ``triaxial fit``."""

    method: str = setting("lm", help="lm | acs | cs | pso | six-position | ellipsoid, a comma "
                                     "list of them, or all: several methods write the "
                                     "per-method parameter and error tables (with an output "
                                     "directory).")
    objective: str | None = setting(None, help="norm (J_H, field mode; default) | norm2 (J_H2) "
                                               "| scalar (S9, needs references) | scalar12 "
                                               "(S12, with mount rotation). lm, acs, cs, pso "
                                               "only.",
                                    choices=("norm", "norm2", "scalar", "scalar12"))
    unit: str | None = setting(None, help="Unit of suffix-less ax/ay/az: mps2 | g | lsb "
                                          "(overrides suffixes and header).")
    lsb_per_g: float | None = setting(None, help="Counts per g (e.g. 16384); without it counts "
                                                 "stay counts.", lo=1e-9, hi=1e12)
    gyro: bool = setting(False, help="Also calibrate the gyro channels of a raw log.")
    gyro_lsb_per_rps: float | None = setting(None, help="Gyro counts per rad/s (counts logs).",
                                             lo=1e-9, hi=1e12)
    g_local: float | None = setting(None, help="Local gravity (else header, else 9.80665 with "
                                               "a warning).", unit="m/s^2", lo=1.0, hi=100.0)
    schedule: str | None = setting(None, help="Schedule CSV of a raw log (pos_id, pitch_deg, "
                                              "heading_deg or face); default "
                                              "<stem>.schedule.csv if present.")
    k_thr: float | None = setting(None, help="Static-detector threshold multiplier (default: "
                                             "sweep 2..10).", lo=1e-6, hi=1e6)
    threshold: float | None = setting(None, help="Absolute detector threshold on the summed "
                                                 "moving variance, (m/s^2)^2 (counts^2 in "
                                                 "counts mode).", lo=0.0, hi=1e30)
    t_init: float = setting(10.0, help="Initial rest used by the detector.", unit="s",
                            lo=0.0, hi=1e6)
    window: float = setting(1.0, help="Moving-variance window.", unit="s", lo=1e-6, hi=1e6)
    min_duration: float = setting(1.5, help="Shortest static run.", unit="s", lo=0.0, hi=1e6)
    robust: bool = setting(False, help="soft-L1 loss in the LM (f_scale = 3 x the robust "
                                       "residual scale of a plain fit).")
    max_generations: int | None = setting(None, help="Metaheuristic generation budget (acs, "
                                                     "cs, pso; default 1000).", lo=1, hi=1_000_000)
    placement_deg: float | None = setting(None, help="six-position: standard deviation of a "
                                                     "hand-placed face's tilt (default 2).",
                                          unit="deg", lo=0.0, hi=45.0)
    bias_limit: float | None = setting(None, help="Largest plausible |accelerometer bias| "
                                                  "(default 0.5 g).", unit="m/s^2", lo=0.0,
                                       hi=1e6)
    norm_tol: float | None = setting(None, help="Largest plausible | |a| - g | of a calibrated "
                                                "pose (default 0.02 g).", unit="m/s^2", lo=0.0,
                                     hi=1e6)
    force: bool = setting(False, help="Write a non-identifiable or implausible calibration "
                                      "anyway, flagged (apply then needs force too).")
    seed: int = seed_setting("Random seed (same seed, same numbers).")

    def fit_config(self, method: str) -> wf.Config:
        from inertialab.calib.triaxial_checks import Limits
        from inertialab.workflows import triaxial as wf

        return wf.Config(method=method, objective=self.objective, seed=self.seed,
                         max_generations=self.max_generations, robust=self.robust,
                         placement_deg=self.placement_deg,
                         gyro_lsb_per_rps=self.gyro_lsb_per_rps, force=self.force,
                         limits=Limits(bias=self.bias_limit, norm_tol=self.norm_tol))


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


def _method_files(tables: dict, skipped: dict, name: str) -> dict:
    """params.csv/.md, pose_errors.csv, method_errors.csv (file name -> text)."""
    from inertialab.calib.triaxial_compare import markdown

    files = {fname: tables[key].to_csv(index=False, float_format="%.17g")
             for key, fname in (("params", "params.csv"), ("poses", "pose_errors.csv"),
                                ("summary", "method_errors.csv"))}
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
    files["params.md"] = "\n".join(parts)
    return files


@dataclass
class FitResult(ResultBase):
    """``triaxial fit`` of one unit: the run (:class:`CalibrationRun`), the per-method
    tables when several methods were fitted, the effective settings."""

    run: object
    settings: dict
    name: str
    seed: int
    tables: dict | None = None
    skipped: dict | None = None
    gyro_unit: str | None = None
    sha256: str | None = None

    @property
    def units(self) -> dict:
        from inertialab.workflows import triaxial as wf

        return wf.result_units(self.run)

    def to_json(self) -> dict:
        from inertialab.workflows import triaxial as wf

        payload = wf.result_payload(self.run)
        payload["seed"] = self.seed
        if self.tables is not None:
            payload["methods"] = _methods_payload(self.tables, self.skipped)
        return payload

    def artifacts(self) -> dict:
        files = {} if self.tables is None else _method_files(self.tables, self.skipped,
                                                             self.name)
        return {"models": [("model.json", self.run.model, self.units)], "files": files}

    def corrected(self) -> np.ndarray:
        """The records corrected by the fit (the working unit), for the figures."""

        from inertialab.sensors.triaxial import correct

        return correct(self.run.fit.x, self.run.data.a)

    def norm_error(self) -> np.ndarray:
        """|corrected record| - g per record (the working unit), for the figures."""
        import numpy as np

        return np.linalg.norm(self.corrected(), axis=1) - self.run.data.g

    def summary_rows(self) -> list:
        fit, data, p = self.run.fit, self.run.data, self.to_json()
        rows = [[n, p["params"][n], (p["stderr"] or {}).get(n)] for n in p["params"]]
        if fit.phi is not None:
            rows += [[n + " (rad)", float(fit.phi[i]), (p["stderr"] or {}).get(n)]
                     for i, n in enumerate(("phi_x", "phi_y", "phi_z"))]
        out = [(f"triaxial fit: {fit.method}, objective {self.run.model.objective}, "
                f"{fit.n_records} records"
                + (f" ({data.intervals.count} static intervals)" if data.intervals else ""),
                ["parameter", "value", "std. error"], rows)]
        out += _matrix_lines("calibrated = correction_matrix @ (raw - offset)   [m/s^2]",
                             p["correction_matrix"])
        out.append("offset = [" + ", ".join(f"{v:.9g}" for v in p["offset"])
                   + f"] {data.raw_unit}")
        out.append(f"residual RMS = {fit.residual_rms:.4g}, iterations = {fit.iterations}, "
                   f"nfev = {fit.nfev}")
        q = p["quality"]
        ne = q["norm_error"]
        out.append(f"| |a| - g |: RMSE {ne['rmse_mps2']:.4g}, max {ne['max_abs_mps2']:.4g} "
                   f"m/s^2 over {len(q['per_pose'])} poses")
        if "eq21" in q:
            out.append(f"eq. 21 vector error: RMSE {q['eq21']['rmse_mps2']:.4g}, SD "
                       f"{q['eq21']['sd_mps2']:.4g} m/s^2 ({q['eq21']['frame']} frame)")
        out.append(f"95 % intervals (t, {q['dof']} dof): " + "; ".join(
            f"{k} [{lo:.6g}, {hi:.6g}]" for k, (lo, hi) in q["ci95"].items()))
        gf = self.run.gyro_fit
        if gf is not None:
            out += _matrix_lines("gyro: rate = M_g @ (raw - bias)   [rad/s]", gf.matrix)
            out.append("bias = [" + ", ".join(f"{v:.6g}" for v in gf.bias)
                       + f"] {self.gyro_unit}; direction residual RMS = "
                       f"{gf.residual_rms:.3g} rad over {gf.n_pairs} motions")
        out += [f"FLAGGED: {flag}" for flag in self.run.model.flags]
        if self.tables is not None:
            out += self._methods_rows(fit.method)
        return out

    def _methods_rows(self, primary: str) -> list:
        t = self.tables
        wide = t["params"].pivot(index="parameter", columns="method", values="value")
        wide = wide.reindex(index=list(dict.fromkeys(t["params"]["parameter"])),
                            columns=list(dict.fromkeys(t["params"]["method"])))
        summ = t["summary"]
        cols = [c for c in summ.columns if c.endswith("rmse_mps2") or c.endswith("sd_mps2")]
        return [(f"parameters per method (model.json holds {primary})",
                 ["parameter", *wide.columns],
                 [[p, *row] for p, row in zip(wide.index, wide.to_numpy().tolist())]),
                ("errors per method (m/s^2)", ["method", *cols],
                 summ[["method", *cols]].to_numpy().tolist())] + \
            [f"left out {k}: {v}" for k, v in (self.skipped or {}).items()]


@dataclass
class BatchResult(ResultBase):
    """``triaxial fit`` of a multi-unit (production-line) file: yield and per-unit table."""

    batch: object
    settings: dict = field(default_factory=lambda: {"batch": True})
    units = {"rmse_limit": "m/s^2", "rmse_median": "m/s^2", "rmse_p95": "m/s^2",
             "wall_s": "s"}

    def to_json(self) -> dict:
        import numpy as np

        t, b = self.batch.table, self.batch
        return {"method": "lm-batch", "objective": "scalar", "n_units": int(len(t)),
                "yield_fraction": b.yield_fraction, "rmse_limit": b.rmse_limit,
                "rmse_median": float(np.median(t["rmse_mps2"])),
                "rmse_p95": float(np.percentile(t["rmse_mps2"], 95)),
                "converged_fraction": float(t["converged"].mean()), "wall_s": b.wall_s,
                "failed_units": t.loc[~t["pass"], "unit_id"].tolist()[:100]}

    def artifacts(self) -> dict:
        return {"files": {"units.csv": self.batch.table.to_csv(index=False,
                                                               lineterminator="\n")}}

    def summary_rows(self) -> list:
        p, b = self.to_json(), self.batch
        return [f"{p['n_units']} units: yield {100 * b.yield_fraction:.1f} % (RMSE <= "
                f"{b.rmse_limit} m/s^2 and datasheet ranges); RMSE median "
                f"{p['rmse_median']:.4f}, p95 {p['rmse_p95']:.4f} m/s^2; solver "
                f"{b.wall_s:.2f} s"]


def run_fit(record, config: FitConfig, *, schedule=None, name: str = "", progress=None):
    """Calibrate a triaxial accelerometer (and gyro) from static records or a raw log
    (``schedule``: the pose schedule frame of a raw log, or None)."""
    from inertialab.workflows import triaxial as wf

    c = config.validate()
    methods = wf.methods_from(c.method)
    unit = None if c.unit is None else c.unit.lower()
    session = wf.prepare(record, lsb_per_g=c.lsb_per_g, schedule=schedule, k_thr=c.k_thr,
                         threshold=c.threshold, t_init_s=c.t_init, window_s=c.window,
                         min_duration_s=c.min_duration, header_check=unit is None,
                         gyro=c.gyro)
    fc = c.fit_config(methods[0])
    if wf.is_batch(session) and len(methods) == 1:
        return BatchResult(wf.fit(session, fc))
    if progress is not None:
        progress.update(0.4, 1.0, "records ready")
    runs = skipped = tables = None
    try:
        if len(methods) > 1:
            runs, skipped = wf.fit_methods(session, fc, methods)
            run = next(iter(runs.values()))
            tables = _method_tables(runs)
        else:
            run = wf.fit(session, fc)
    except InputError as exc:  # say what was left out before the fit: one line, whole
        left = "; ".join(f"{len(rows)} {why} record(s) left out" for why, rows in
                         getattr(session.data, "dropped", ()) if len(rows))
        if not left:
            raise
        raise type(exc)(f"{exc} ({left})") from None
    settings = {"method": run.fit.method if runs is None else methods,
                "objective": run.model.objective, "unit": unit, "lsb_per_g": c.lsb_per_g,
                "gyro": c.gyro, "g_local": run.data.g, "seed": c.seed, "k_thr": c.k_thr,
                "threshold": c.threshold, "t_init_s": c.t_init, "window_s": c.window,
                "min_duration_s": c.min_duration, "robust": c.robust,
                "max_generations": c.max_generations, "placement_deg": c.placement_deg,
                "bias_limit_mps2": c.bias_limit, "norm_tol_mps2": c.norm_tol,
                "force": c.force}
    return FitResult(run=run, settings=settings, name=name, seed=c.seed, tables=tables,
                     skipped=skipped, gyro_unit=session.gyro_suffix, sha256=record.sha256)


def run_fit_file(file, config: FitConfig, *, options=None, progress=None):
    """:func:`run_fit` on the file at ``file`` (read with the reading ``options``); a raw
    log takes its pose schedule from ``config.schedule`` or ``<stem>.schedule.csv`` when
    present. The result's ``inputs`` name the file and the schedule read."""
    from inertialab.io.sidecar import read_schedule, schedule_path
    from inertialab.workflows import triaxial as wf

    unit = None if config.unit is None else config.unit.lower()
    rec = wf.read(file, options=options, unit=unit, g_local=config.g_local)
    schedule, inputs = None, [file]
    if wf.is_raw_log(rec):
        sp = config.schedule if config.schedule is not None else schedule_path(file)
        if config.schedule is not None or Path(sp).exists():
            schedule = read_schedule(sp)  # the text front door: regular file, size, encoding
            inputs.append(sp)
    res = run_fit(rec, config, schedule=schedule, name=Path(file).name, progress=progress)
    res.with_inputs(inputs)
    if options is not None and options.reusable():  # kept in the model file for apply
        res.settings["reading"] = options.reusable()
    return res


# ----------------------------------------------------------------------- ferraris

@dataclass(frozen=True)
class FerrarisConfig(Config):
    """Settings of ``triaxial ferraris``."""

    sections: str | None = setting(None, help="imucal section list (JSON {\"x_p\": {\"start\": "
                                              "i, \"end\": j}, ..., \"z_rot\": ...}); default: "
                                              "detected from the accelerometer and the gyro.")
    rotation_deg: float = setting(360.0, help="Angle of every turn (the sense is detected).",
                                  unit="deg", lo=1.0, hi=3600.0)
    placement_deg: float = setting(2.0, help="Standard deviation of a face's hand-placement "
                                             "tilt.", unit="deg", lo=0.0, hi=45.0)
    no_g_sensitivity: bool = setting(False, help="Do not estimate the gyro's g-sensitivity.")
    g_local: float | None = setting(None, help="Local gravity (else header, else 9.80665 with "
                                               "a warning).", unit="m/s^2", lo=1.0, hi=100.0)
    unit: str | None = setting(None, help="Unit of suffix-less ax/ay/az (mps2 | g | lsb).")
    bias_limit: float | None = setting(None, help="Largest plausible |accelerometer bias|.",
                                       unit="m/s^2", lo=0.0, hi=1e6)
    force: bool = setting(False, help="Write an implausible calibration anyway, flagged.")


@dataclass
class FerrarisResult(ResultBase):
    """``triaxial ferraris``: the run (:class:`~inertialab.workflows.ferraris.FerrarisRun`)."""

    run: object
    session: object
    settings: dict
    name: str = ""
    sha256: str | None = None

    @property
    def units(self) -> dict:
        from inertialab.workflows import ferraris as wfr

        return wfr.result_units(self.run)

    def to_json(self) -> dict:
        from inertialab.workflows import ferraris as wfr

        return wfr.result_payload(self.run)

    def artifacts(self) -> dict:
        import json

        return {"models": [("model.json", self.run.model, self.units)],
                "files": {"sections.json": json.dumps(self.to_json()["sections"], indent=1)
                          + "\n"}}

    def summary_rows(self) -> list:
        p, s = self.to_json(), self.session
        how = "detected" if s.detection is not None else f"from {self.settings['sections']}"
        out = [f"triaxial ferraris: {self.name}, sections {how}, {s.fs:g} Hz, g = {s.g:g}",
               ("faces", ["face", "|a| - g (m/s^2)", "tilt (deg)"],
                [[n, f"{d['norm_error_mps2']:+.2e}", f"{d['tilt_deg']:.2f}"]
                 for n, d in p["faces"].items()])]
        for n, d in p["turns"].items():
            sense = "counterclockwise" if d["sense"] > 0 else "clockwise"
            out.append(f"{n}: {sense} seen from above, axis ("
                       + ", ".join(f"{v:+.3f}" for v in d["axis"]) + ")")
        out += _matrix_lines("accelerometer: a = correction_matrix @ (raw - offset)   [m/s^2]",
                             p["correction_matrix"])
        out += _matrix_lines("gyro: rate = M_g @ (raw - offset - g_sensitivity @ a)   [rad/s]",
                             p["gyro"]["correction_matrix"])
        return out + [f"FLAGGED: {flag}" for flag in self.run.model.flags]


def run_ferraris(record, config: FerrarisConfig, *, name: str = "", progress=None):
    """Accelerometer (12 parameters) and gyro (scale, misalignment, bias, g-sensitivity)
    from six static faces and a turn about each axis."""
    from inertialab.calib.triaxial_checks import Limits
    from inertialab.workflows import ferraris as wfr

    c = config.validate()
    session = wfr.prepare(record, sections=c.sections, g_local=c.g_local)
    if progress is not None:
        progress.update(0.5, 1.0, "sections ready")
    run = wfr.fit(session, wfr.Config(rotation_deg=c.rotation_deg, placement_deg=c.placement_deg,
                                      g_sensitivity=not c.no_g_sensitivity, force=c.force,
                                      limits=Limits(bias=c.bias_limit)))
    settings = {"sections": c.sections, "rotation_deg": c.rotation_deg,
                "placement_deg": c.placement_deg, "g_sensitivity": not c.no_g_sensitivity,
                "g_local": session.g, "unit": c.unit, "bias_limit_mps2": c.bias_limit,
                "force": c.force}
    return FerrarisResult(run=run, session=session, settings=settings, name=name,
                          sha256=record.sha256)


# -------------------------------------------------------------------------- apply

@dataclass(frozen=True)
class ApplyConfig(Config):
    """Settings of ``triaxial apply``."""

    unit: str | None = setting(None, help="Unit of suffix-less ax/ay/az (mps2 | g | lsb).")
    force: bool = setting(False, help="Apply a flagged calibration anyway.")


@dataclass
class ApplyResult(ResultBase):
    """``triaxial apply``: the calibrated record (``data``, ``meta``) and its summary."""

    data: object
    meta: dict
    summary: dict
    settings: dict
    units = {}

    def to_json(self) -> dict:
        return dict(self.summary)

    def artifacts(self) -> dict:
        out = self.summary["output"]
        return {"records": [] if out is None else [(out, self.data, self.meta)]}

    def summary_rows(self) -> list:
        s = self.summary
        return [f"written: {s['output']} ({s['rows']} rows, calibrated to m/s^2"
                + (" and rad/s" if s["gyro_calibrated"] else "") + ")"]


def _trained_settings(model_path) -> dict:
    """The settings a model file was written with (``{}`` without a file or settings)."""
    if model_path is None:
        return {}
    from inertialab.io.modelfile import read_envelope

    settings = read_envelope(model_path).get("settings")
    return settings if isinstance(settings, dict) else {}


def run_apply(model, path, config: ApplyConfig, *, options=None, model_path=None,
              output=None) -> ApplyResult:
    """Apply a triaxial calibration to the record at ``path``:
    calibrated = correction_matrix @ (raw - offset) (and the gyro block). The file is
    read with the reading options and unit the model was fitted with (stored in the
    model file at ``model_path`` by ``fit``; a model file without them, as older ones,
    adds nothing), each one the user gives in ``options`` or ``config`` winning."""
    from inertialab.io.mapping import ReadOptions
    from inertialab.workflows import triaxial as wf

    c = config.validate()
    trained = _trained_settings(model_path)
    options = (options or ReadOptions()).over(trained.get("reading"))
    unit = c.unit if c.unit is not None else trained.get("unit")
    unit = None if unit is None else str(unit).lower()
    rec = wf.read(path, options=options, unit=unit)
    cal = wf.apply(model, rec, model_path=model_path, force=c.force)
    summary = {"output": None if output is None else str(output), "rows": int(len(cal.data)),
               "accelerometer_columns": [rec.find(b) for b in ("ax", "ay", "az")],
               "gyro_calibrated": wf.gyro_applied(model, rec), "raw_unit": model.raw_unit}
    return ApplyResult(data=cal.data, meta=cal.meta, summary=summary,
                       settings={"unit": unit, "force": c.force,
                                 "reading": options.reusable()})


# ------------------------------------------------------------------------- export

@dataclass(frozen=True)
class ExportConfig(Config):
    """Settings of ``triaxial export`` (the target is its own argument)."""

    drop_g_sensitivity: bool = setting(False, help="imu_tk: export a gyro with a "
                                                   "g-sensitivity without it.")
    force: bool = setting(False, help="Export a flagged calibration anyway.")


@dataclass
class ExportResult(ResultBase):
    """``triaxial export``: the files written for another tool."""

    written: list
    settings: dict
    units = {}

    def to_json(self) -> dict:
        return {"written": self.written, "format": self.settings["to"]}

    def artifacts(self) -> dict:
        return {}

    def summary_rows(self) -> list:
        return ["written: " + ", ".join(self.written)]


def run_export(model, to: str, out, config: ExportConfig) -> ExportResult:
    """Write a triaxial calibration at ``out`` for the tool of target ``to`` (one of the
    registered calibration exporters, :data:`inertialab.io.exporters.EXPORTERS`)."""
    from inertialab.io.exporters import export_calibration, get

    c = config.validate()
    fmt = get("calibration", to).target
    written = export_calibration(model, fmt, out, force=c.force,
                                 drop_g_sensitivity=c.drop_g_sensitivity)
    return ExportResult(written=written, settings={"to": fmt, **c.to_dict()})
