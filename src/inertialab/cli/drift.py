"""``inertialab drift fit``, ``inertialab drift forecast`` and ``inertialab simulate
storage-drift`` (spec 004). Thin: parse, call :mod:`inertialab.workflows.drift`, print or
write.

No ``from __future__ import annotations`` here: the shared options are ``Annotated``
aliases that typer must see as objects through :func:`~inertialab.cli.options.reading_options`.
"""

import json
import sys
from pathlib import Path

import typer

from inertialab.cli.common import (
    atomic_write_text,
    collect_warnings,
    emit_json,
    json_ready,
    prepare_out_dir,
    print_table,
    progress_bar,
    write_figures,
)
from inertialab.cli.options import JsonOpt, OutDirOpt, QuietOpt, reading_options
from inertialab.errors import InputError
from inertialab.io.mapping import ReadOptions

_UNITS = {"bias": "ug", "sf": "ppm", "day": "day", "order": "1", "cv_scores": "1",
          "ljung_box_p": "1", "recalibration_day": "day", "tolerance": "ug (bias) | ppm (sf)",
          "k_ref": "mA/g", "skill_vs_persistence": "1"}


def _quantities(q: str) -> tuple:
    q = q.strip().lower()
    if q == "both":
        return ("bias", "sf")
    if q in ("bias", "sf"):
        return (q,)
    raise InputError(f"--quantity must be bias, sf or both, got '{q}'")


def _order(o: str):
    o = o.strip().lower()
    if o == "auto":
        return None
    try:
        p = int(o)
    except ValueError:
        raise InputError(f"--order must be 'auto' or a positive integer, got '{o}'") from None
    if p < 1:
        raise InputError(f"--order must be >= 1, got {p}")
    return p


def _unit_payload(r) -> dict:
    """The per-unit, per-quantity JSON of issue 8 item 5 (plus a few extras)."""
    base = {n: {"rmse": e.get("rmse"), "max_ae": e.get("max_ae")} if "error" not in e
            else {"rmse": None, "max_ae": None, "error": e["error"]}
            for n, e in r.baselines.items()}
    return {
        "unit": r.unit,
        "order": r.order,
        "cv_scores": r.cv_scores,
        "fit": {k: r.fit[k] for k in ("mse", "rmse", "max_ae")},
        "forecast": {k: r.forecast[k] for k in ("day", "value", "lo95", "hi95")},
        "holdout": None if r.holdout is None else {
            "day": r.holdout["day"], "actual": r.holdout["actual"],
            **{k: r.holdout["metrics"][k] for k in ("max_ae", "mae", "me", "mbe", "rmse")}},
        "baselines": base,
        "skill_vs_persistence": r.skill_vs_persistence,
        "whiteness": {"passed": r.whiteness["passed"],
                      "ljung_box_p": r.whiteness["ljung_box_p"]},
        "recalibration_day": r.recalibration_day,
        "recalibration_reason": r.recalibration_reason,
        "tolerance": r.tolerance,
        "origin_day": r.origin_day,
        "accepted": r.accepted,
        "anomaly_days": r.anomaly_days,
    }


def register(app: typer.Typer, groups: dict) -> None:
    drift, simulate = groups["drift"], groups["simulate"]

    @drift.command("fit")
    @reading_options
    def drift_fit(
        file: Path = typer.Argument(..., help="storage_drift record (CSV or Parquet)."),
        quantity: str = typer.Option("both", "--quantity", help="bias | sf | both"),
        horizon: int = typer.Option(20, "--horizon", help="Forecast horizon K in grid steps."),
        order: str = typer.Option("auto", "--order", help="auto (kernel CV, H = 6) or N."),
        restarts: int = typer.Option(10, "--restarts", help="Training restarts R."),
        preset: str = typer.Option("paper", "--preset",
                                   help="paper (best member, random split) | strict "
                                        "(median of the best half, block split)"),
        origin_day: int = typer.Option(None, "--origin-day",
                                       help="Last in-sample programme day (default: the last "
                                            "test); later days are scored as holdout."),
        tol_bias_ug: float = typer.Option(None, "--tol-bias-ug",
                                          help="Bias tolerance, µg (default: sidecar, else 50)."),
        tol_sf_ppm: float = typer.Option(None, "--tol-sf-ppm",
                                         help="Scale-factor tolerance, ppm (default: sidecar, "
                                              "else 50)."),
        max_gap: int = typer.Option(3, "--max-gap", help="Longest gap (steps) interpolated."),
        hampel: bool = typer.Option(False, "--hampel", help="Hampel outlier screen (§2.2)."),
        arima: bool = typer.Option(False, "--arima", help="Add the ARIMA-by-AIC baseline (slow)."),
        seed: int = typer.Option(0, "--seed", help="Seed of the restarts and bootstrap paths."),
        out: OutDirOpt = None,
        as_json: JsonOpt = False,
        quiet: QuietOpt = False,
        *,
        read: ReadOptions,
    ):
        """Fit NAR models per unit and quantity, forecast, and schedule re-calibration."""
        from inertialab.io import read_record, save_model
        from inertialab.workflows import drift as wf

        qs = _quantities(quantity)
        p = _order(order)
        if horizon < 1:
            raise InputError(f"--horizon must be >= 1, got {horizon}")
        if restarts < 1:
            raise InputError(f"--restarts must be >= 1, got {restarts}")
        if preset not in ("paper", "strict"):
            raise InputError(f"--preset must be paper or strict, got '{preset}'")
        out_dir = prepare_out_dir(out) if out is not None else None
        with collect_warnings(quiet=quiet or as_json) as warns:
            rec = read_record(file, "storage_drift", options=read)
            tb = tol_bias_ug if tol_bias_ug is not None else float(rec.meta.get("tol_bias_ug", 50.0))
            ts = tol_sf_ppm if tol_sf_ppm is not None else float(rec.meta.get("tol_sf_ppm", 50.0))
            base = wf.DEFAULT_BASELINES + (("arima",) if arima else ())
            settings = wf.DriftSettings(horizon=horizon, order=p, restarts=restarts,
                                        preset=preset, max_gap=max_gap, hampel=hampel,
                                        baselines=base, tol_bias_ug=tb, tol_sf_ppm=ts,
                                        seed=seed)
            with progress_bar("drift fit", quiet=quiet or as_json) as bar:
                fit = wf.fit(rec, settings, quantities=qs, origin_day=origin_day, progress=bar)
        # "per_unit" (not "units": that envelope key maps numeric keys to their units)
        payload = {"per_unit": {uid: {q: _unit_payload(r) for q, r in qsr.items()}
                                for uid, qsr in fit.results.items()}}
        sett = {"quantity": quantity, "horizon": horizon, "order": order, "restarts": restarts,
                "preset": preset, "origin_day": origin_day, "tol_bias_ug": tb,
                "tol_sf_ppm": ts, "max_gap": max_gap, "hampel": hampel, "arima": arima,
                "seed": seed}
        if out_dir is not None:
            from inertialab.report.figures.drift import (
                acf_figure,
                fit_figure,
                forecast_figure,
                schedule_figure,
            )

            save_model(fit.model, out_dir / "model.json", units={"bias": "ug", "sf": "ppm"},
                       training_data_sha256=rec.sha256, settings=sett)
            atomic_write_text(out_dir / "result.json", json.dumps(
                json_ready({"settings": sett, **payload}), indent=2, allow_nan=False) + "\n")
            figs = []
            for _, _, r in fit.iter():
                d = r.figure_data()
                figs.extend([fit_figure(d), forecast_figure(d), acf_figure(d)])
            figs.append(schedule_figure([
                {"unit_id": u, "quantity": q, "recalibration_day": r.recalibration_day,
                 "origin_day": r.origin_day, "horizon_end": r.forecast["day"][-1]}
                for u, q, r in fit.iter()]))
            write_figures(figs, out_dir)
        if as_json:
            emit_json("drift fit", payload, inputs=[file], settings=sett, units=_UNITS,
                      warnings_=warns)
            return
        rows = []
        for u, q, r in fit.iter():
            h = r.holdout["metrics"]["rmse"] if r.holdout else None
            rows.append([u, q, r.unit, r.order, r.fit["rmse"], r.fit["max_ae"], h,
                         r.forecast["value"][-1], r.recalibration_day or "none in horizon"])
        print_table(["unit", "quantity", "unit of measure", "order", "fit RMSE", "fit MaxAE",
                     "holdout RMSE", f"forecast day {fit.settings.horizon}", "re-calibrate"],
                    rows, title="drift fit (NAR per unit; bias µg, scale factor ppm)")
        if out_dir is not None:
            print(f"written: {out_dir}")
        sys.stdout.flush()

    @drift.command("forecast")
    def drift_forecast(
        model: Path = typer.Argument(..., help="model.json written by 'drift fit --out'."),
        horizon: int = typer.Option(None, "--horizon", help="Steps K (default: the fit's)."),
        as_json: JsonOpt = False,
        quiet: QuietOpt = False,
    ):
        """Forecast again from a saved storage-drift model."""
        from inertialab.io import load_model
        from inertialab.workflows.drift import forecast

        if horizon is not None and horizon < 1:
            raise InputError(f"--horizon must be >= 1, got {horizon}")
        with collect_warnings(quiet=quiet or as_json) as warns:
            m = load_model(model, expected_type="storage-drift")
            res = forecast(m, horizon)
        if as_json:
            emit_json("drift forecast", {"per_unit": res}, inputs=[model],
                      settings={"horizon": horizon, "seed": m.settings.get("seed")},
                      units=_UNITS, warnings_=warns)
            return
        rows = []
        for u, qs in res.items():
            for q, e in qs.items():
                f = e["forecast"]
                rows.append([u, q, e["unit"], f["day"][0], f["value"][0], f["day"][-1],
                             f["value"][-1], f["lo95"][-1], f["hi95"][-1],
                             e["recalibration_day"] or "none in horizon"])
        print_table(["unit", "quantity", "unit of measure", "first day", "first value",
                     "last day", "last value", "lo95", "hi95", "re-calibrate"], rows,
                    title="drift forecast")

    @simulate.command("storage-drift")
    def simulate_storage(
        preset: str = typer.Option("paper", "--preset", help="paper | nav"),
        units: int = typer.Option(12, "--units", help="Number of accelerometers."),
        days: int = typer.Option(120, "--days", help="Programme length in days."),
        seed: int = typer.Option(0, "--seed", help="Seed (units spawned from it)."),
        no_outliers: bool = typer.Option(False, "--no-outliers", help="No ±8σ outliers."),
        missing_prob: float = typer.Option(None, "--missing-prob",
                                           help="Probability a day is missing (default 0.05)."),
        skip_weekends: bool = typer.Option(False, "--skip-weekends",
                                           help="No tests on Saturdays and Sundays."),
        out: Path = typer.Option(..., "--out", help="Record file (.csv or .parquet); the "
                                                    "sidecar is written beside it."),
        as_json: JsonOpt = False,
    ):
        """Simulate a storage programme (spec 004 §7) with ground-truth columns."""
        from inertialab.io import write_record
        from inertialab.sim.storage_drift import simulate_storage_batch

        if missing_prob is not None and not 0.0 <= missing_prob < 1.0:
            raise InputError(f"--missing-prob must lie in [0, 1), got {missing_prob}")
        batch = simulate_storage_batch(units, days, preset, rng=seed, outliers=not no_outliers,
                                       missing_prob=missing_prob, skip_weekends=skip_weekends)
        if out.exists() and out.is_dir():
            raise InputError("--out must be a file for this command", path=out)
        write_record(batch.frame, out, batch.meta)  # data and sidecar, each atomically
        if as_json:
            emit_json("simulate storage-drift", {"path": str(out), "rows": len(batch.frame),
                                                 "units": units, "days": days,
                                                 "preset": preset},
                      settings={"preset": preset, "units": units, "days": days, "seed": seed,
                                "outliers": not no_outliers, "missing_prob": missing_prob,
                                "skip_weekends": skip_weekends},
                      units={"days": "day"})
            return
        print(f"written: {out} ({len(batch.frame)} tests of {units} units, preset {preset})")
