"""Study ``drift`` (spec 004): the seed's 100-day protocol on the virtual storage lab.

The ``paper`` preset (§6, A8: 100 days, in-sample days 0-79, 20-day forecast) with the
baselines, interval coverage and re-calibration on the ``nav`` preset (A13, §9), the
quick/full settings and the module-level :data:`STUDY` the demo discovers.
"""

from __future__ import annotations

import time
import warnings
from dataclasses import dataclass, replace

import numpy as np

from inertialab.calib.drift import DEFAULT_BASELINES, QUANTITIES
from inertialab.progress import NullProgress
from inertialab.studies.base import Headline, Study, StudyResult, settings_dict
from inertialab.workflows.drift import DriftFit, FitConfig, fit_drift

__all__ = ["STUDY", "FullSettings", "QuickSettings", "run_demo", "summarise"]


@dataclass(frozen=True)
class QuickSettings:
    """Demo (quick): ``paper`` preset, 6 units x 100 days, in-sample days 0-79, R = 4,
    cheap baselines only; ``nav`` coverage on 6 units."""

    seed: int = 0
    n_units: int = 6
    n_days: int = 100
    origin_day: int = 79
    restarts: int = 4
    n_paths: int = 100
    nav_units: int = 6
    baselines: tuple = ("persistence", "window_mean", "ar_ls", "poly_trend",
                        "exp_saturation", "kernel_nar")


@dataclass(frozen=True)
class FullSettings:
    """Demo (full): 12 units, R = 10, B = 200, all baselines except ARIMA (slow; in the
    benchmark), ``nav`` coverage on 12 units."""

    seed: int = 0
    n_units: int = 12
    n_days: int = 100
    origin_day: int = 79
    restarts: int = 10
    n_paths: int = 200
    nav_units: int = 12
    baselines: tuple = DEFAULT_BASELINES


def _median(xs):
    xs = [x for x in xs if x is not None and np.isfinite(x)]
    return float(np.median(xs)) if xs else None


def summarise(fit: DriftFit) -> dict:
    """Batch figures in the seed's units (g, mA/g) and ours (µg, ppm)."""
    out = {}
    for q in QUANTITIES:
        rs = [r for _, qn, r in fit.iter() if qn == q]
        if not rs:
            continue
        fit_ae = [r.series.to_native(r.fit["max_ae"]).item() for r in rs]
        fc_ae = [r.series.to_native(r.holdout["metrics"]["max_ae"]).item()
                 for r in rs if r.holdout]
        orders = [r.order for r in rs]
        cov = [c for r in rs if r.holdout for c in r.holdout["covered"]]
        rmse = {"nar": _median([r.holdout["metrics"]["rmse"] for r in rs if r.holdout])}
        for b in fit.settings.baselines:
            rmse[b] = _median([r.baselines.get(b, {}).get("rmse") for r in rs])
        exc = [r.exceeded_before_schedule for r in rs if r.exceeded_before_schedule is not None]
        out[q] = {
            "unit_working": QUANTITIES[q], "unit_native": "g" if q == "bias" else "mA/g",
            "orders": orders, "order_mode": int(np.bincount(orders).argmax()),
            "median_fit_max_ae_native": _median(fit_ae),
            "median_forecast_max_ae_native": _median(fc_ae),
            "median_fit_max_ae": _median([r.fit["max_ae"] for r in rs]),
            "median_forecast_rmse": rmse,
            "median_skill_vs_persistence": _median([r.skill_vs_persistence for r in rs]),
            "coverage95": float(np.mean(cov)) if cov else None,
            "whiteness_pass_rate": float(np.mean([bool(r.whiteness["passed"]) for r in rs])),
            "recal_exceeded_share": float(np.mean(exc)) if exc else None,
            "recal_days": {r.unit_id: r.recalibration_day for r in rs},
        }
    return out


def run_demo(settings, progress=None) -> StudyResult:
    """The ``drift`` study of ``inertialab demo``: the seed's 100-day protocol on the
    ``paper`` preset (§6, A8) and interval coverage on ``nav`` (A13)."""
    from inertialab.sim.drift import simulate_storage_batch

    progress = progress or NullProgress()
    t0 = time.perf_counter()
    batch = simulate_storage_batch(settings.n_units, settings.n_days, "paper",
                                   rng=np.random.SeedSequence(settings.seed))
    ds = FitConfig(restarts=settings.restarts, n_paths=settings.n_paths,
                   baselines=tuple(settings.baselines), seed=settings.seed)

    class _P:
        def update(self, done, total, note=""):
            progress.update(0.7 * done / max(total, 1), 1.0, note)

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        fit = fit_drift(batch.frame, meta=batch.meta, settings=ds,
                        origin_day=settings.origin_day, progress=_P())
        nav = simulate_storage_batch(settings.nav_units, settings.n_days, "nav",
                                     rng=np.random.SeedSequence(settings.seed))
        nav_fit = fit_drift(nav.frame, meta=nav.meta,
                            settings=replace(ds, preset="strict", baselines=("persistence",)),
                            origin_day=settings.origin_day)
    progress.update(1.0, 1.0, "done")
    summ = summarise(fit)
    nav_cov = []
    for _, _, r in nav_fit.iter():
        if r.holdout:
            ok = ~np.asarray(r.holdout.get("outlier_true", [False] * len(r.holdout["covered"])))
            nav_cov.extend(np.asarray(r.holdout["covered"])[ok].tolist())
    nav_coverage = float(np.mean(nav_cov)) if nav_cov else None
    nav_exc = [r.exceeded_before_schedule for _, _, r in nav_fit.iter()
               if r.exceeded_before_schedule is not None]
    nav_exceeded = float(np.mean(nav_exc)) if nav_exc else None
    b, s = summ.get("bias", {}), summ.get("sf", {})
    headline = [
        Headline("CV order, bias (mode over units)", b.get("order_mode"), 2, "lags"),
        Headline("CV order, scale factor (mode)", s.get("order_mode"), 3, "lags"),
        Headline("bias fit MaxAE (median)", b.get("median_fit_max_ae_native"), 2e-4, "g"),
        Headline("bias 20-day forecast MaxAE (median)", b.get("median_forecast_max_ae_native"),
                 2e-4, "g"),
        Headline("SF fit MaxAE (median)", s.get("median_fit_max_ae_native"), 1e-4, "mA/g"),
        Headline("SF 20-day forecast MaxAE (median)", s.get("median_forecast_max_ae_native"),
                 1e-4, "mA/g"),
        Headline("bias skill vs persistence (median)", b.get("median_skill_vs_persistence"),
                 None, "1"),
        Headline("95 % interval coverage, nav preset (target 0.85-0.99)", nav_coverage, None,
                 "fraction"),
        Headline("nav units leaving tolerance before their re-calibration day (target <= 0.1)",
                 nav_exceeded, None, "fraction"),
    ]
    # figure data: the first unit
    uid = next(iter(fit.results))
    fig_data = {q: r.figure_data() for q, r in fit.results[uid].items()}
    # the schedule is shown for the nav preset: with the paper preset's 50 µg / 20 ppm
    # day-to-day scatter the ±50 band is left at once by most paths
    schedule = [{"unit_id": u, "quantity": q, "recalibration_day": r.recalibration_day,
                 "origin_day": r.origin_day, "horizon_end": r.forecast["day"][-1],
                 "exceeded_before_schedule": r.exceeded_before_schedule}
                for u, q, r in nav_fit.iter()]

    tables = {"paper_preset": summ, "nav_coverage95": nav_coverage,
              "nav_exceeded_before_schedule": nav_exceeded,
              "nav_recalibration_days": {f"{u}/{q}": r.recalibration_day
                                         for u, q, r in nav_fit.iter()},
              "units": fit.to_dict()["units"]}
    text = [
        f"{settings.n_units} simulated units (preset paper, seed {settings.seed}) tested daily "
        f"for {settings.n_days} days with missing days and outliers; NAR models (order by "
        f"kernel CV, S = 10, R = {settings.restarts}, LM with early stopping) fitted on days "
        f"0-{settings.origin_day} and forecast 20 days, beside persistence, AR and trend "
        "baselines. Bias in µg and scale factor in ppm of each unit's mean K1; the seed's "
        "error levels are compared in g and mA/g.",
        "On this preset the NAR is not expected to beat AR or persistence (spec 004): the "
        "day-to-day scatter dominates. Re-calibration days are the 10 % quantile of the "
        "first passage of the bootstrap paths out of ±50 µg / ±50 ppm around the value at "
        "the origin; with the paper preset's 50 µg turn-on scatter most units leave that "
        "band at once, so the schedule figure shows the nav preset (strict: median of the "
        "5 best members, block split).",
    ]
    return StudyResult(
        name="drift", title="Storage drift: NAR forecasting of bias and scale factor",
        settings=settings_dict(settings), headline=headline, tables=tables,
        data={"example": fig_data, "schedule": schedule}, text=text,
        wall_s=time.perf_counter() - t0)


STUDY = Study("drift", "Storage drift: NAR forecasting of bias and scale factor",
              quick=QuickSettings(), full=FullSettings(), run=run_demo)
