"""``inertialab drift fit|evaluate|apply|forecast`` and ``inertialab simulate
storage-drift`` (spec 004). Each command is one call to
:mod:`inertialab.workflows.drift_run` through the runner (:mod:`inertialab.cli.runner`):
its options come from the workflow's ``Config``.

No ``from __future__ import annotations`` here: typer must see the option annotations
as objects through the decorators.
"""

from pathlib import Path

import typer

from inertialab.cli.common import emit_json
from inertialab.cli.options import JsonOpt, SeedOpt, reading_options
from inertialab.cli.runner import config_command
from inertialab.errors import InputError
from inertialab.io.mapping import ReadOptions
from inertialab.workflows import drift_run as wf


def _fit_figures(res):
    """The figures of ``drift fit --out``: per unit and quantity the fit, forecast, ACF
    and error curve; one re-calibration schedule."""
    from inertialab.io.names import safe_slug
    from inertialab.report.figures.drift import (
        acf_figure,
        error_curve_figure,
        fit_figure,
        forecast_figure,
        schedule_figure,
    )

    taken, slugs, figs = {"schedule"}, {}, []  # file names from unit ids: safe slugs only
    for u, q, r in res.fit.iter():
        s = slugs.setdefault(u, safe_slug(u, taken=taken))
        d = r.figure_data()
        figs += [fit_figure(d, f"fit_{q}_{s}"), forecast_figure(d, f"forecast_{q}_{s}"),
                 acf_figure(d, f"acf_{q}_{s}")]
        curve = r.error_curve()
        if curve:
            figs.append(error_curve_figure(curve, unit_id=u, quantity=q, unit=r.unit,
                                           name=f"error_curve_{q}_{s}"))
    figs.append(schedule_figure([
        {"unit_id": u, "quantity": q, "recalibration_day": r.recalibration_day,
         "origin_day": r.origin_day, "horizon_end": r.forecast["day"][-1]}
        for u, q, r in res.fit.iter()]))
    return figs


def _evaluate_figures(res):
    from inertialab.io.names import safe_slug
    from inertialab.report.figures.drift import error_curve_figure

    taken: set = set()
    figs = []
    for u, d in res.per_unit.items():
        s = safe_slug(u, taken=taken)
        for q, r in d.items():
            figs.append(error_curve_figure(r.step_mae, unit_id=u, quantity=q,
                                           unit=wf.UNITS[q], n_origins=len(r.origins),
                                           name=f"error_curve_{q}_{s}"))
    return figs


def _read(file, read):
    from inertialab.io import read_record

    return read_record(file, "storage_drift", options=read)


@reading_options
@config_command(wf.FitConfig)
def drift_fit(file: Path = typer.Argument(..., help="storage_drift record (CSV or Parquet)."),
              *, config, run, read: ReadOptions):
    """Fit NAR models per unit and quantity, forecast, and schedule re-calibration."""
    run.execute("drift fit", lambda bar: wf.run_fit(_read(file, read), config, progress=bar),
                inputs=[file], figures=_fit_figures)


@reading_options
@config_command(wf.EvaluateConfig)
def drift_evaluate(file: Path = typer.Argument(..., help="storage_drift record (CSV or "
                                                         "Parquet)."),
                   *, config, run, read: ReadOptions):
    """Rolling-origin evaluation: refit at origins FIRST, FIRST+STEP, ..., N-K and
    compare NAR with the baselines (per-origin RMSE, win rates, Wilcoxon, per-step
    error curve; spec 004 §5)."""
    run.execute("drift evaluate",
                lambda bar: wf.run_evaluate(_read(file, read), config, progress=bar),
                inputs=[file], figures=_evaluate_figures)


@reading_options
@config_command(wf.Config, out="file")
def drift_apply(model: Path = typer.Argument(..., help="model.json written by 'drift fit "
                                                       "--out'."),
                file: Path = typer.Argument(..., help="Later storage_drift record (same units; "
                                                      "a 'day' column or dates; optional "
                                                      "output_ma and a_ref_g columns)."),
                *, config, run, read: ReadOptions):
    """Compensate a later record with the forecast bias and scale factor: residuals
    with and without the forecast, and a = I/k - b for an output current (spec 004 §9)."""
    from inertialab.io import write_record
    from inertialab.workflows.registries import load_model

    out, run.out = run.out, None  # one record, not a directory
    if out is not None and out.exists() and not out.is_file():
        raise InputError("--out must be a regular file for this command", path=out)

    def produce(bar):
        res = wf.run_apply(load_model(model, expected_type="storage-drift"), _read(file, read))
        if out is not None:
            write_record(res.frame, out, {"source": "drift apply", "model": str(model),
                                          "record": str(file)})
        res.written = None if out is None else str(out)
        return res

    env = run.execute("drift apply", produce, inputs=[model, file])
    if out is not None and not run.as_json:
        print(f"written: {out}")
    return env


@config_command(wf.Config, out=None)
def drift_forecast(model: Path = typer.Argument(..., help="model.json written by 'drift fit "
                                                          "--out'."),
                   horizon: int = typer.Option(None, "--horizon", help="Steps K, 1 to 1000 "
                                                                       "(default: the fit's)."),
                   *, config, run):
    """Forecast again from a saved storage-drift model."""
    from inertialab.workflows.registries import load_model

    if horizon is not None:
        wf.check_horizon(horizon)  # before any work
    run.execute("drift forecast", lambda bar: wf.run_forecast(
        load_model(model, expected_type="storage-drift"), horizon), inputs=[model])


def simulate_storage(
    preset: str = typer.Option("paper", "--preset", help="paper | nav"),
    units: int = typer.Option(12, "--units", help="Number of accelerometers."),
    days: int = typer.Option(120, "--days", help="Programme length in days."),
    seed: SeedOpt = 0,
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
                                             "units": units, "days": days, "preset": preset},
                  settings={"preset": preset, "units": units, "days": days, "seed": seed,
                            "outliers": not no_outliers, "missing_prob": missing_prob,
                            "skip_weekends": skip_weekends},
                  units={"days": "day"})
        return
    print(f"written: {out} ({len(batch.frame)} tests of {units} units, preset {preset})")


def register(app: typer.Typer, groups: dict) -> None:
    drift, simulate = groups["drift"], groups["simulate"]
    drift.command("fit")(drift_fit)
    drift.command("evaluate")(drift_evaluate)
    drift.command("apply")(drift_apply)
    drift.command("forecast")(drift_forecast)
    simulate.command("storage-drift")(simulate_storage)
