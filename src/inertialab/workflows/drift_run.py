"""The drift study's commands as one call each: a :class:`~inertialab.config.Config` of
settings (validated, with the bounds and help the command line shows) and
``run_*(record, config) -> result``; each result knows ``to_json()``, ``settings``,
``units``, ``artifacts()`` and ``summary_rows()`` (spec 004; docs/drift.md).
"""

from __future__ import annotations

from dataclasses import dataclass

from inertialab.config import Config, seed_setting, setting
from inertialab.errors import InputError
from inertialab.limits import MAX_HORIZON, check_horizon
from inertialab.result import ResultBase

__all__ = ["Config", "EvaluateConfig", "FitConfig", "UNITS", "check_horizon", "run_apply", "run_evaluate", "run_fit",
           "run_forecast"]

#: Units of the numeric keys of the drift commands' JSON.
UNITS = {"bias": "ug", "sf": "ppm", "day": "day", "order": "1", "cv_scores": "1",
         "ljung_box_p": "1", "recalibration_day": "day", "tolerance": "ug (bias) | ppm (sf)",
         "k_ref": "mA/g", "skill_vs_persistence": "1"}
#: The forecast horizon check (1 .. 1000 grid steps), for callers that check first.
_QUANTITIES = {"both": ("bias", "sf"), "bias": ("bias",), "sf": ("sf",)}


def _order(o: str):
    o = str(o).strip().lower()
    if o == "auto":
        return None
    try:
        p = int(o)
    except ValueError:
        raise InputError(f"argument 'order' must be 'auto' or a positive integer, got "
                         f"'{o}'") from None
    if p < 1:
        raise InputError(f"argument 'order' must be >= 1, got {p}")
    return p


def _hidden_grid(text):
    if text is None:
        return None
    try:
        sizes = tuple(int(v) for v in str(text).replace(" ", "").split(",") if v)
    except ValueError:
        raise InputError(f"argument 'hidden_grid' must be comma-separated integers, got "
                         f"'{text}'") from None
    if not sizes or min(sizes) < 1 or max(sizes) > 200:
        raise InputError(f"argument 'hidden_grid' sizes must be from 1 to 200, got '{text}'")
    return sizes


@dataclass(frozen=True)
class _Common(Config):
    quantity: str = setting("both", help="bias | sf | both", choices=tuple(_QUANTITIES))
    horizon: int = setting(20, help="Forecast horizon K in grid steps (1 to 1000).",
                           lo=1, hi=MAX_HORIZON)
    order: str = setting("auto", help="auto (kernel CV, H = 6) or N.")
    restarts: int = setting(10, help="Training restarts R.", lo=1, hi=1000)
    hidden: int = setting(10, help="Hidden neurons S (the paper's 10).", lo=1, hi=200)
    hidden_grid: str | None = setting(None, help="Choose S by validation from sizes, e.g. "
                                                 "2,4,6,8,10 (replaces the single size).")
    preset: str = setting("paper", help="paper (best member, random split) | strict "
                                        "(median of the best half, block split)",
                          choices=("paper", "strict"))


@dataclass(frozen=True)
class FitConfig(_Common):
    """Settings of ``drift fit``."""

    origin_day: int | None = setting(None, help="Last in-sample programme day (default: the "
                                                "last test); later days are scored as holdout.",
                                     lo=-10**7, hi=10**7)
    tol_bias_ug: float | None = setting(None, help="Bias tolerance (default: sidecar, else 50).",
                                        unit="ug", lo=1e-9, hi=1e9)
    tol_sf_ppm: float | None = setting(None, help="Scale-factor tolerance (default: sidecar, "
                                                  "else 50).", unit="ppm", lo=1e-9, hi=1e9)
    max_gap: int = setting(3, help="Longest gap (steps) interpolated.", lo=0, hi=36_500)
    hampel: bool = setting(False, help="Hampel outlier screen (spec 004).")
    arima: bool = setting(False, help="Add the ARIMA-by-AIC baseline (slow).")
    seed: int = seed_setting("Seed of the restarts and bootstrap paths.")


@dataclass(frozen=True)
class EvaluateConfig(_Common):
    """Settings of ``drift evaluate`` (rolling origin, spec 004 §5)."""

    unit_id: list[str] | None = setting(None, help="Only this unit_id (repeatable).")
    first: int = setting(50, help="First origin (grid steps).", lo=1, hi=10**6)
    step: int = setting(5, help="Steps between origins.", lo=1, hi=10**6)
    direct: bool = setting(False, help="Add the direct strategy (one net per step; K x R "
                                       "fits per origin).")
    max_gap: int = setting(3, help="Longest gap (steps) interpolated.", lo=0, hi=36_500)
    seed: int = seed_setting("Seed of the restarts.")


def _unit_payload(r) -> dict:
    """The per-unit, per-quantity JSON of ``drift fit`` (docs/drift.md)."""
    base = {n: {"rmse": e.get("rmse"), "max_ae": e.get("max_ae")} if "error" not in e
            else {"rmse": None, "max_ae": None, "error": e["error"]}
            for n, e in r.baselines.items()}
    return {
        "unit": r.unit, "order": r.order, "cv_scores": r.cv_scores,
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
        "tolerance": r.tolerance, "origin_day": r.origin_day, "accepted": r.accepted,
        "anomaly_days": r.anomaly_days, "hidden": r.hidden, "hidden_scores": r.hidden_scores,
    }


@dataclass
class FitResult(ResultBase):
    """``drift fit``: the fit (:class:`inertialab.workflows.drift.DriftFit`) and the
    effective settings (tolerances from the sidecar resolved)."""

    fit: object
    settings: dict
    sha256: str | None = None
    units = UNITS

    def to_json(self) -> dict:
        # "per_unit" (not "units": that envelope key maps numeric keys to their units)
        return {"per_unit": {uid: {q: _unit_payload(r) for q, r in qsr.items()}
                             for uid, qsr in self.fit.results.items()}}

    def artifacts(self) -> dict:
        return {"models": [("model.json", self.fit.model, {"bias": "ug", "sf": "ppm"})]}

    def summary_rows(self) -> list:
        rows = []
        for u, q, r in self.fit.iter():
            h = r.holdout["metrics"]["rmse"] if r.holdout else None
            rows.append([u, q, r.unit, r.order, r.fit["rmse"], r.fit["max_ae"], h,
                         r.forecast["value"][-1], r.recalibration_day or "none in horizon"])
        return [("drift fit (NAR per unit; bias µg, scale factor ppm)",
                 ["unit", "quantity", "unit of measure", "order", "fit RMSE", "fit MaxAE",
                  "holdout RMSE", f"forecast day {self.fit.settings.horizon}", "re-calibrate"],
                 rows)]


def run_fit(record, config: FitConfig, *, progress=None) -> FitResult:
    """Fit NAR models per unit and quantity, forecast, and schedule re-calibration."""
    from inertialab.workflows import drift as wf

    c = config.validate()
    p, grid = _order(c.order), _hidden_grid(c.hidden_grid)
    tb = c.tol_bias_ug if c.tol_bias_ug is not None else float(record.meta.get("tol_bias_ug", 50.0))
    ts = c.tol_sf_ppm if c.tol_sf_ppm is not None else float(record.meta.get("tol_sf_ppm", 50.0))
    base = wf.DEFAULT_BASELINES + (("arima",) if c.arima else ())
    settings = wf.DriftSettings(horizon=c.horizon, order=p, restarts=c.restarts,
                                hidden=c.hidden, hidden_grid=grid, preset=c.preset,
                                max_gap=c.max_gap, hampel=c.hampel, baselines=base,
                                tol_bias_ug=tb, tol_sf_ppm=ts, seed=c.seed)
    fit = wf.fit(record, settings, quantities=_QUANTITIES[c.quantity],
                 origin_day=c.origin_day, progress=progress)
    sett = {**c.to_dict(), "hidden_grid": None if grid is None else list(grid),
            "tol_bias_ug": tb, "tol_sf_ppm": ts}
    return FitResult(fit=fit, settings=sett, sha256=record.sha256)


@dataclass
class EvaluateResult(ResultBase):
    """``drift evaluate``: per unit and quantity the rolling-origin comparison."""

    per_unit: dict
    settings: dict
    units = UNITS

    def to_json(self) -> dict:
        return {"per_unit": {u: {q: r.to_dict() for q, r in d.items()}
                             for u, d in self.per_unit.items()}}

    def artifacts(self) -> dict:
        return {}

    def summary_rows(self) -> list:
        rows = []
        for u, d in self.per_unit.items():
            for q, r in d.items():
                sm = r.summary
                rows.append([u, q, len(r.origins), sm["nar"]["median"],
                             sm["persistence"]["median"], sm["ar_ls"]["median"],
                             r.win_rate.get("persistence"), r.wilcoxon_p.get("persistence"),
                             r.win_rate.get("ar_ls"), sm.get("nar_direct", {}).get("median")])
        return [("drift evaluate (rolling origin; bias µg, scale factor ppm)",
                 ["unit", "quantity", "origins", "NAR median RMSE", "persistence", "AR(p)",
                  "NAR win vs persistence", "Wilcoxon p", "NAR win vs AR", "direct NAR"],
                 rows)]


def run_evaluate(record, config: EvaluateConfig, *, progress=None) -> EvaluateResult:
    """Rolling-origin evaluation: refit at origins FIRST, FIRST+STEP, ..., N-K and compare
    NAR with the baselines (spec 004 §5)."""
    from inertialab.workflows import drift as wf

    c = config.validate()
    p, grid = _order(c.order), _hidden_grid(c.hidden_grid)
    base = ("persistence", "window_mean", "ar_ls", "ar_aic", "poly_trend", "kernel_nar")
    base += (("nar_direct",) if c.direct else ())
    settings = wf.DriftSettings(horizon=c.horizon, order=p, restarts=c.restarts,
                                hidden=c.hidden, hidden_grid=grid, preset=c.preset,
                                max_gap=c.max_gap, baselines=base, seed=c.seed)
    res = wf.evaluate(record, settings, quantities=_QUANTITIES[c.quantity], first=c.first,
                      step=c.step, units=c.unit_id or None, progress=progress)
    sett = {k: v for k, v in c.to_dict().items() if k not in ("unit_id", "max_gap")}
    sett.update({"hidden_grid": None if grid is None else list(grid), "baselines": list(base)})
    return EvaluateResult(per_unit=res, settings=sett)


@dataclass
class ApplyResult(ResultBase):
    """``drift apply``: the compensated frame and the residual summary."""

    frame: object
    summary: dict
    settings: dict
    units = UNITS

    written: str | None = None
    meta: dict | None = None

    def to_json(self) -> dict:
        return {"summary": self.summary, "rows": len(self.frame), "written": self.written}

    def artifacts(self) -> dict:
        return {"records": [] if self.written is None else
                [(self.written, self.frame, self.meta)]}

    def summary_rows(self) -> list:
        rows = [[u, q, v["unit"], v["n"], v["rmse_uncompensated"], v["rmse_compensated"]]
                for u, d in self.summary.items() for q, v in d.items()]
        return [("drift apply (residual after compensation; bias µg, SF ppm)",
                 ["unit", "quantity", "unit of measure", "tests", "RMSE without forecast",
                  "RMSE with forecast"], rows)] + (
            [] if self.written is None else [f"written: {self.written}"])


def run_apply(model, record, *, out=None, model_path=None) -> ApplyResult:
    """Compensate a later record with the forecast bias and scale factor (spec 004 §9);
    ``out``: where the compensated record is to be written (with its sidecar)."""
    from inertialab.workflows import drift as wf

    frame, summary = wf.apply(model, record)
    return ApplyResult(frame=frame, summary=summary, settings={},
                       written=None if out is None else str(out),
                       meta={"source": "drift apply", "model": str(model_path),
                             "record": str(record.path)})


@dataclass
class ForecastResult(ResultBase):
    """``drift forecast``: forecasts again from a saved model."""

    per_unit: dict
    settings: dict
    units = UNITS

    def to_json(self) -> dict:
        return {"per_unit": self.per_unit}

    def artifacts(self) -> dict:
        return {}

    def summary_rows(self) -> list:
        rows = []
        for u, qs in self.per_unit.items():
            for q, e in qs.items():
                f = e["forecast"]
                rows.append([u, q, e["unit"], f["day"][0], f["value"][0], f["day"][-1],
                             f["value"][-1], f["lo95"][-1], f["hi95"][-1],
                             e["recalibration_day"] or "none in horizon"])
        return [("drift forecast", ["unit", "quantity", "unit of measure", "first day",
                                    "first value", "last day", "last value", "lo95", "hi95",
                                    "re-calibrate"], rows)]


def run_forecast(model, horizon: int | None = None) -> ForecastResult:
    """Forecast every unit and quantity of a saved model ``horizon`` steps (default: the
    fit's)."""
    from inertialab.workflows import drift as wf

    if horizon is not None:
        check_horizon(horizon)
    return ForecastResult(per_unit=wf.forecast(model, horizon),
                          settings={"horizon": horizon, "seed": model.settings.get("seed")})
