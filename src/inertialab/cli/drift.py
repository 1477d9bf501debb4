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
from inertialab.cli.options import JsonOpt, OutDirOpt, OutFileOpt, QuietOpt, reading_options
from inertialab.errors import InputError
from inertialab.io.mapping import ReadOptions
from inertialab.io.names import safe_slug

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


def _hidden_grid(text):
    if text is None:
        return None
    try:
        sizes = tuple(int(v) for v in str(text).replace(" ", "").split(",") if v)
    except ValueError:
        raise InputError(f"--hidden-grid must be comma-separated integers, got '{text}'") from None
    if not sizes or min(sizes) < 1 or max(sizes) > 200:
        raise InputError(f"--hidden-grid sizes must be from 1 to 200, got '{text}'")
    return sizes


def _unit_payload(r) -> dict:
    """The per-unit, per-quantity JSON of ``drift fit`` (docs/drift.md)."""
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
        "hidden": r.hidden,
        "hidden_scores": r.hidden_scores,
    }


def register(app: typer.Typer, groups: dict) -> None:
    drift, simulate = groups["drift"], groups["simulate"]

    @drift.command("fit")
    @reading_options
    def drift_fit(
        file: Path = typer.Argument(..., help="storage_drift record (CSV or Parquet)."),
        quantity: str = typer.Option("both", "--quantity", help="bias | sf | both"),
        horizon: int = typer.Option(20, "--horizon", help="Forecast horizon K in grid steps "
                                                          "(1 to 1000)."),
        order: str = typer.Option("auto", "--order", help="auto (kernel CV, H = 6) or N."),
        restarts: int = typer.Option(10, "--restarts", help="Training restarts R."),
        hidden: int = typer.Option(10, "--hidden", help="Hidden neurons S (spec default 10)."),
        hidden_grid: str = typer.Option(None, "--hidden-grid",
                                        help="Choose S by validation from sizes, e.g. "
                                             "2,4,6,8,10 (overrides --hidden)."),
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
        wf.check_horizon(horizon)
        grid = _hidden_grid(hidden_grid)
        if not 1 <= hidden <= 200:
            raise InputError(f"--hidden must be from 1 to 200, got {hidden}")
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
                                        hidden=hidden, hidden_grid=grid,
                                        preset=preset, max_gap=max_gap, hampel=hampel,
                                        baselines=base, tol_bias_ug=tb, tol_sf_ppm=ts,
                                        seed=seed)
            with progress_bar("drift fit", quiet=quiet or as_json) as bar:
                fit = wf.fit(rec, settings, quantities=qs, origin_day=origin_day, progress=bar)
        # "per_unit" (not "units": that envelope key maps numeric keys to their units)
        payload = {"per_unit": {uid: {q: _unit_payload(r) for q, r in qsr.items()}
                                for uid, qsr in fit.results.items()}}
        sett = {"quantity": quantity, "horizon": horizon, "order": order, "restarts": restarts,
                "hidden": hidden, "hidden_grid": None if grid is None else list(grid),
                "preset": preset, "origin_day": origin_day, "tol_bias_ug": tb,
                "tol_sf_ppm": ts, "max_gap": max_gap, "hampel": hampel, "arima": arima,
                "seed": seed}
        if out_dir is not None:
            from inertialab.report.figures.drift import (
                acf_figure,
                error_curve_figure,
                fit_figure,
                forecast_figure,
                schedule_figure,
            )

            save_model(fit.model, out_dir / "model.json", units={"bias": "ug", "sf": "ppm"},
                       training_data_sha256=rec.sha256, settings=sett)
            atomic_write_text(out_dir / "result.json", json.dumps(
                json_ready({"settings": sett, **payload}), indent=2, allow_nan=False) + "\n")
            # file names from unit ids only as safe, collision-free slugs
            taken = {"schedule"}
            slugs: dict = {}
            figs = []
            for u, q, r in fit.iter():
                s = slugs.setdefault(u, safe_slug(u, taken=taken))
                d = r.figure_data()
                figs.extend([fit_figure(d, f"fit_{q}_{s}"), forecast_figure(d, f"forecast_{q}_{s}"),
                             acf_figure(d, f"acf_{q}_{s}")])
                curve = r.error_curve()
                if curve:
                    figs.append(error_curve_figure(curve, unit_id=u, quantity=q, unit=r.unit,
                                                   name=f"error_curve_{q}_{s}"))
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

    @drift.command("evaluate")
    @reading_options
    def drift_evaluate(
        file: Path = typer.Argument(..., help="storage_drift record (CSV or Parquet)."),
        quantity: str = typer.Option("both", "--quantity", help="bias | sf | both"),
        unit_id: list[str] = typer.Option(None, "--unit-id",
                                          help="Only this unit_id (repeatable)."),
        first: int = typer.Option(50, "--first", help="First origin (grid steps)."),
        step: int = typer.Option(5, "--step", help="Steps between origins."),
        horizon: int = typer.Option(20, "--horizon", help="Forecast horizon K (1 to 1000)."),
        order: str = typer.Option("auto", "--order", help="auto (kernel CV, H = 6) or N."),
        restarts: int = typer.Option(10, "--restarts", help="Training restarts R."),
        hidden: int = typer.Option(10, "--hidden", help="Hidden neurons S."),
        hidden_grid: str = typer.Option(None, "--hidden-grid",
                                        help="Choose S by validation from sizes, e.g. 2,4,6,8,10."),
        preset: str = typer.Option("paper", "--preset", help="paper | strict"),
        direct: bool = typer.Option(False, "--direct",
                                    help="Add the direct strategy (one net per step; K x R "
                                         "fits per origin)."),
        max_gap: int = typer.Option(3, "--max-gap", help="Longest gap (steps) interpolated."),
        seed: int = typer.Option(0, "--seed", help="Seed of the restarts."),
        out: OutDirOpt = None,
        as_json: JsonOpt = False,
        quiet: QuietOpt = False,
        *,
        read: ReadOptions,
    ):
        """Rolling-origin evaluation: refit at origins FIRST, FIRST+STEP, ..., N-K and
        compare NAR with the baselines (per-origin RMSE, win rates, Wilcoxon, per-step
        error curve; spec 004 §5)."""
        from inertialab.io import read_record
        from inertialab.workflows import drift as wf

        qs = _quantities(quantity)
        p = _order(order)
        wf.check_horizon(horizon)
        grid = _hidden_grid(hidden_grid)
        if restarts < 1 or not 1 <= hidden <= 200:
            raise InputError("--restarts must be >= 1 and --hidden from 1 to 200")
        if preset not in ("paper", "strict"):
            raise InputError(f"--preset must be paper or strict, got '{preset}'")
        base = ("persistence", "window_mean", "ar_ls", "ar_aic", "poly_trend", "kernel_nar")
        base += (("nar_direct",) if direct else ())
        settings = wf.DriftSettings(horizon=horizon, order=p, restarts=restarts, hidden=hidden,
                                    hidden_grid=grid, preset=preset, max_gap=max_gap,
                                    baselines=base, seed=seed)
        with collect_warnings(quiet=quiet or as_json) as warns:
            rec = read_record(file, "storage_drift", options=read)
            with progress_bar("drift evaluate", quiet=quiet or as_json) as bar:
                res = wf.evaluate(rec, settings, quantities=qs, first=first, step=step,
                                  units=unit_id or None, progress=bar)
        payload = {"per_unit": {u: {q: r.to_dict() for q, r in d.items()}
                                for u, d in res.items()}}
        sett = {"quantity": quantity, "first": first, "step": step, "horizon": horizon,
                "order": order, "restarts": restarts, "hidden": hidden,
                "hidden_grid": None if grid is None else list(grid), "preset": preset,
                "direct": direct, "baselines": list(base), "seed": seed}
        if out is not None:
            from inertialab.report.figures.drift import error_curve_figure

            out_dir = prepare_out_dir(out)
            atomic_write_text(out_dir / "result.json", json.dumps(
                json_ready({"settings": sett, **payload}), indent=2, allow_nan=False) + "\n")
            taken: set = set()
            figs = []
            for u, d in res.items():
                s = safe_slug(u, taken=taken)
                for q, r in d.items():
                    figs.append(error_curve_figure(r.step_mae, unit_id=u, quantity=q,
                                                   unit=wf.QUANTITIES[q],
                                                   n_origins=len(r.origins),
                                                   name=f"error_curve_{q}_{s}"))
            write_figures(figs, out_dir)
        if as_json:
            emit_json("drift evaluate", payload, inputs=[file], settings=sett, units=_UNITS,
                      warnings_=warns)
            return
        rows = []
        for u, d in res.items():
            for q, r in d.items():
                sm = r.summary
                rows.append([u, q, len(r.origins), sm["nar"]["median"],
                             sm["persistence"]["median"], sm["ar_ls"]["median"],
                             r.win_rate.get("persistence"), r.wilcoxon_p.get("persistence"),
                             r.win_rate.get("ar_ls"), sm.get("nar_direct", {}).get("median")])
        print_table(["unit", "quantity", "origins", "NAR median RMSE", "persistence",
                     "AR(p)", "NAR win vs persistence", "Wilcoxon p", "NAR win vs AR",
                     "direct NAR"], rows,
                    title="drift evaluate (rolling origin; bias µg, scale factor ppm)")
        if out is not None:
            print(f"written: {out}")

    @drift.command("apply")
    @reading_options
    def drift_apply(
        model: Path = typer.Argument(..., help="model.json written by 'drift fit --out'."),
        file: Path = typer.Argument(..., help="Later storage_drift record (same units; a "
                                              "'day' column or dates; optional output_ma and "
                                              "a_ref_g columns)."),
        out: OutFileOpt = None,
        as_json: JsonOpt = False,
        quiet: QuietOpt = False,
        *,
        read: ReadOptions,
    ):
        """Compensate a later record with the forecast bias and scale factor: residuals
        with and without the forecast, and a = I/k - b for an output current (spec 004 §9)."""
        from inertialab.io import read_record, write_record
        from inertialab.workflows.drift import apply
        from inertialab.workflows.registries import load_model

        with collect_warnings(quiet=quiet or as_json) as warns:
            m = load_model(model, expected_type="storage-drift")
            rec = read_record(file, "storage_drift", options=read)
            frame, summary = apply(m, rec)
        if out is not None:
            if out.exists() and not out.is_file():
                raise InputError("--out must be a regular file for this command", path=out)
            write_record(frame, out, {"source": "drift apply", "model": str(model),
                                      "record": str(file)})
        if as_json:
            emit_json("drift apply", {"summary": summary, "rows": len(frame),
                                      "written": None if out is None else str(out)},
                      inputs=[model, file], settings={}, units=_UNITS, warnings_=warns)
            return
        rows = [[u, q, v["unit"], v["n"], v["rmse_uncompensated"], v["rmse_compensated"]]
                for u, d in summary.items() for q, v in d.items()]
        print_table(["unit", "quantity", "unit of measure", "tests", "RMSE without forecast",
                     "RMSE with forecast"], rows,
                    title="drift apply (residual after compensation; bias µg, SF ppm)")
        if out is not None:
            print(f"written: {out}")

    @drift.command("forecast")
    def drift_forecast(
        model: Path = typer.Argument(..., help="model.json written by 'drift fit --out'."),
        horizon: int = typer.Option(None, "--horizon", help="Steps K, 1 to 1000 (default: "
                                                            "the fit's)."),
        as_json: JsonOpt = False,
        quiet: QuietOpt = False,
    ):
        """Forecast again from a saved storage-drift model."""
        from inertialab.workflows.drift import check_horizon, forecast
        from inertialab.workflows.registries import load_model

        if horizon is not None:
            check_horizon(horizon)
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
        from inertialab.sim.drift import simulate_storage_batch

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
