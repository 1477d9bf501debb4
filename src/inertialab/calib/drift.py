"""Storage drift of bias and scale factor (spec 004): per-series NAR fit, forecast and
re-calibration, on arrays; the fitted artefact :class:`DriftModel`.

* :class:`DailySeries` — one unit's quantity on its regular grid (spec §2.2), built from a
  record by :func:`inertialab.workflows.drift.prepare`; :func:`fill_gaps` interpolates
  short gaps and numbers the segments.
* :func:`fit_series` — NAR (order by kernel CV, R restarts, closed-loop forecast with
  95 % bootstrap intervals), the baselines of §4, holdout metrics when the series extends
  past the origin (§5; scored on observed, non-imputed days only; every error through
  :mod:`inertialab.metrics`, ME = maximum absolute error as in the glossary), skill vs
  persistence, whiteness, the re-calibration day (§9: first passage of the simulated
  paths out of a tolerance band around the value at the origin, 10 % quantile, as a
  programme day; ``None``: none within horizon) and CUSUM alarms on the one-step
  residuals (§9; :mod:`inertialab.learn.monitoring`).
* :class:`DriftModel` — all units' NAR models of one record (model-file type
  ``storage-drift``), able to forecast again later.

Bias is worked in µg, scale factor in ppm of the unit's reference K1 (docs/drift.md).
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass, field

import numpy as np

from inertialab import metrics
from inertialab.errors import InputError
from inertialab.io.model_schemas import check_own_payload
from inertialab.learn.forecast_baselines import make_baseline
from inertialab.learn.monitoring import cusum_alarms, first_passage
from inertialab.learn.nar import NARForecaster
from inertialab.learn.nar_direct import DirectNARForecaster
from inertialab.limits import MAX_HORIZON, check_horizon

__all__ = ["DEFAULT_BASELINES", "DIRECT", "MAX_HORIZON", "QUANTITIES", "check_horizon", "DailySeries", "DriftModel", "baselines_of",
           "SeriesResult", "error_metrics", "fill_gaps", "fit_series"]

#: quantity -> working unit (bias µg, scale factor ppm; docs/drift.md)
QUANTITIES = {"bias": "ug", "sf": "ppm"}


#: Most grid steps one unit's series may span (about 270 years of days): a day column
#: with one stray value of 1e9 would otherwise allocate a grid of a billion steps.
MAX_GRID_STEPS = 100_000


def check_span(n_steps: int, unit, first_day, last_day, *, path=None) -> int:
    """Refuse a unit whose programme days span more than :data:`MAX_GRID_STEPS` grid
    steps (one line naming the unit and its first and last day), before the grid is
    allocated; returns ``n_steps``."""
    if not 1 <= n_steps <= MAX_GRID_STEPS:
        raise InputError(f"unit {unit}: its days run from {first_day:g} to {last_day:g}, "
                         f"{n_steps} grid steps; a storage programme spans at most "
                         f"{MAX_GRID_STEPS} (is a day value wrong?)", path=path, column="day")
    return n_steps


DEFAULT_BASELINES = ("persistence", "window_mean", "ar_ls", "ar_aic", "poly_trend",
                     "exp_saturation", "exp_ar1", "kernel_nar")



@dataclass
class DailySeries:
    """One unit's quantity on its regular grid (spec 004 §2.2).

    Attributes
    ----------
    unit_id, quantity : which series (``quantity`` is "bias" or "sf")
    unit : "ug" (bias) or "ppm" (scale factor relative to ``k_ref``)
    day : (n,) programme day of each grid step
    values : (n,) value per step; NaN where missing (gap longer than ``max_gap``)
    observed : (n,) a test exists for that step (and survived screening)
    imputed : (n,) filled by linear interpolation
    n_rep, rep_sd : tests averaged into the step and their SD (NaN for one test)
    segment : (n,) segment number, -1 on missing steps
    screened : (n,) flagged by the Hampel screen (treated as missing)
    truth : (n,) latent truth from a simulated record, or None
    outlier_true : (n,) simulated outlier flag, or None
    step_days : grid step in days (1 for daily programmes)
    k_ref : reference scale factor (mA/g) for ppm, None for bias
    """

    unit_id: str
    quantity: str
    unit: str
    day: np.ndarray
    values: np.ndarray
    observed: np.ndarray
    imputed: np.ndarray
    n_rep: np.ndarray
    rep_sd: np.ndarray
    segment: np.ndarray
    screened: np.ndarray
    truth: np.ndarray | None = None
    outlier_true: np.ndarray | None = None
    step_days: int = 1
    k_ref: float | None = None

    @property
    def usable(self) -> np.ndarray:
        """Observed, not imputed, not screened: allowed as CV sample and scoring target."""
        return self.observed & ~self.imputed & np.isfinite(self.values)

    def to_native(self, x):
        """Values in µg / ppm back to g / mA/g (bias / scale factor) for comparison with the seed."""
        x = np.asarray(x, dtype=float)
        if self.quantity == "bias":
            return x * 1e-6
        return x * 1e-6 * (self.k_ref or 1.0)


def fill_gaps(values, observed, max_gap):
    """Linear interpolation over runs of <= max_gap missing steps; segments split at longer gaps."""
    n = values.size
    v = values.copy()
    imputed = np.zeros(n, dtype=bool)
    obs_idx = np.flatnonzero(observed)
    for a, b in zip(obs_idx[:-1], obs_idx[1:]):
        gap = b - a - 1
        if 0 < gap <= max_gap:
            k = np.arange(1, gap + 1)
            v[a + 1: b] = v[a] + (v[b] - v[a]) * k / (gap + 1)
            imputed[a + 1: b] = True
    present = np.isfinite(v)
    segment = np.full(n, -1)
    s = -1
    prev = False
    for i in range(n):
        if present[i]:
            if not prev:
                s += 1
            segment[i] = s
        prev = present[i]
    return v, imputed, segment


def baselines_of(settings) -> tuple:
    """The baselines ``settings`` asks for (None: :data:`DEFAULT_BASELINES`)."""
    return DEFAULT_BASELINES if settings.baselines is None else tuple(settings.baselines)


#: The direct-strategy NAR (one net per step, :mod:`inertialab.learn.nar_direct`) is asked
#: for like a baseline: add this name to the settings' ``baselines`` (spec 004 §3.8 ablation).
DIRECT = "nar_direct"


def _baseline(name: str, nar: NARForecaster, settings, K: int):
    """A baseline forecaster; ``"nar_direct"`` is the direct NAR with the recursive NAR's
    order, hidden size, restarts and preset, seeded from the NAR's stream."""
    if name != DIRECT:
        return make_baseline(name)
    return DirectNARForecaster(horizon=K, order=nar.order_, H=settings.H, hidden=nar.hidden_,
                               restarts=settings.restarts, preset=settings.preset,
                               rng=nar.seed_seq_.spawn(1)[0])


def error_metrics(actual, predicted) -> dict | None:
    """Errors of ``predicted`` against ``actual`` (spec 004 §5, docs/drift.md; same
    units as the inputs): ``me`` = ``max_ae`` = max |e| (ME, the maximum absolute error,
    the forecast MaxAE), ``mae`` = mean |e| (AE), ``mbe`` = mean e (signed, e = predicted - actual),
    ``rmse``, ``mse`` and ``n``; None when there is no sample."""
    if np.size(actual) == 0:
        return None
    s = metrics.error_summary(actual, predicted)
    return {"max_ae": s.me, "mae": s.ae, "me": s.me, "mbe": s.mbe, "rmse": s.rmse,
            "mse": metrics.mse(actual, predicted), "n": s.n}


@dataclass
class SeriesResult:
    """Fit and forecast of one unit's quantity (the JSON keys of ``drift fit --json``)."""

    unit_id: str
    quantity: str
    unit: str
    origin_day: int
    step_days: int
    order: int
    cv_scores: list
    fit: dict
    forecast: dict
    holdout: dict | None
    baselines: dict
    whiteness: dict
    recalibration_day: int | None
    recalibration_reason: str | None
    skill_vs_persistence: float | None
    accepted: bool
    y_cal: float
    tolerance: float
    k_ref: float | None
    model: NARForecaster = field(repr=False)
    series: DailySeries = field(repr=False)
    origin_index: int = 0
    fitted_day: np.ndarray = field(default=None, repr=False)
    fitted: np.ndarray = field(default=None, repr=False)
    exceeded_before_schedule: bool | None = None
    anomaly_days: list = field(default_factory=list)

    @property
    def hidden(self) -> int:
        """Hidden neurons S of the NAR (given, or chosen from the grid by validation)."""
        return int(self.model.hidden_)

    @property
    def hidden_scores(self) -> dict | None:
        """{S: mean validation MSE over the restarts} when a grid was searched (§3.2)."""
        sc = self.model.hidden_scores_
        return None if sc is None else {str(k): v for k, v in sc.items()}

    def figure_data(self) -> dict:
        """Arrays the report's figures need (fit, residuals, forecast, ACF)."""
        srs = self.series
        return {
            "unit_id": self.unit_id, "quantity": self.quantity, "unit": self.unit,
            "day": srs.day, "values": srs.values, "observed": srs.observed,
            "imputed": srs.imputed, "truth": srs.truth, "fitted_day": self.fitted_day,
            "fitted": self.fitted, "forecast": self.forecast, "holdout": self.holdout,
            "acf": self.whiteness["acf"], "bound": self.whiteness["bound"],
            "origin_day": self.origin_day, "y_cal": self.y_cal, "tolerance": self.tolerance,
            "recalibration_day": self.recalibration_day,
        }

    def error_curve(self) -> dict | None:
        """|e_k| per forecast step k = 1..K on the holdout for the NAR and each baseline
        (None on steps with no scored day); None without a holdout (Yue et al., spec 004, Figs. 6/8)."""
        if not self.holdout:
            return None
        K = len(self.forecast["value"])
        k = np.asarray(self.holdout["step"]) - 1
        actual = np.asarray(self.holdout["actual"])
        out = {}
        for name, pred in [("nar", self.forecast["value"])] + [
                (b, e["value"]) for b, e in self.baselines.items() if "value" in e]:
            curve = [None] * K
            for kk, a in zip(k, actual):
                curve[kk] = float(abs(a - pred[kk]))
            out[name] = curve
        return out

    def to_dict(self) -> dict:
        return {
            "unit": self.unit, "origin_day": self.origin_day, "step_days": self.step_days,
            "order": self.order, "cv_scores": self.cv_scores, "fit": self.fit,
            "forecast": self.forecast, "holdout": self.holdout, "baselines": self.baselines,
            "whiteness": self.whiteness, "recalibration_day": self.recalibration_day,
            "recalibration_reason": self.recalibration_reason,
            "skill_vs_persistence": self.skill_vs_persistence, "accepted": self.accepted,
            "y_cal": self.y_cal, "tolerance": self.tolerance, "k_ref": self.k_ref,
            "anomaly_days": self.anomaly_days, "hidden": self.hidden,
            "hidden_scores": self.hidden_scores,
        }


def _origin_index(series: DailySeries, origin_day) -> int:
    fin = np.flatnonzero(np.isfinite(series.values) & (series.observed | series.imputed))
    if origin_day is not None:
        fin = fin[series.day[fin] <= origin_day]
    if fin.size == 0:
        raise InputError(f"unit {series.unit_id}: no {series.quantity} value on or before "
                         f"the origin day {origin_day}")
    # the origin must be an observed day (a forecast starts from a measurement)
    obs = fin[series.observed[fin]]
    return int(obs[-1] if obs.size else fin[-1])


def fit_series(series: DailySeries, settings, *, origin_day: int | None = None,
               rng=None) -> SeriesResult:
    """NAR fit, forecast, baselines, holdout metrics and re-calibration for one series
    (``settings``: :class:`inertialab.workflows.drift.FitConfig`, read by name). In-sample
    = grid steps up to the origin (the last observed step on or before ``origin_day``;
    default the last observed step). Steps after it, up to the horizon, are the holdout,
    scored on observed, non-imputed, non-screened steps only."""
    K = check_horizon(settings.horizon)
    T = _origin_index(series, origin_day)
    y = series.values[: T + 1]
    usable = series.usable[: T + 1]
    seg = series.segment[: T + 1]
    # use only the last segment when an earlier one is separated by a long gap? No:
    # the NAR skips samples touching gaps; all segments contribute (spec §2.2 item 4).
    del seg
    nar = NARForecaster(order=settings.nar_order, H=settings.H, hidden=settings.hidden,
                        hidden_grid=settings.hidden_sizes,
                        restarts=settings.restarts, preset=settings.preset,
                        combine=settings.combine, split=settings.split,
                        n_paths=settings.n_paths, rng=rng)
    nar.fit(y, usable=usable)
    fc = nar.forecast(K)
    paths = nar.forecast_paths(K)
    fdays = series.day[T] + series.step_days * np.arange(1, K + 1)
    y_cal = float(y[-1])
    tol = settings.tolerance(series.quantity)
    k_rec, _ = first_passage(paths, y_cal, tol, quantile=settings.recal_quantile)
    rec_day = None if k_rec is None else int(series.day[T] + series.step_days * k_rec)
    # holdout
    hold = np.arange(T + 1, min(T + 1 + K, series.values.size))
    score = hold[series.usable[hold]] if hold.size else hold
    steps = score - T  # 1-based step of each scored day
    holdout = None
    base_out: dict = {}
    skill = None
    exceeded = None
    pers_rmse = None
    if score.size:
        actual = series.values[score]
        e = actual - fc.values[steps - 1]
        holdout = {"day": series.day[score].tolist(), "actual": actual.tolist(),
                   "step": steps.tolist(), "metrics": error_metrics(actual, fc.values[steps - 1]),
                   "abs_error": np.abs(e).tolist(),
                   "covered": ((actual >= fc.lo95[steps - 1]) &
                               (actual <= fc.hi95[steps - 1])).tolist()}
        if series.truth is not None:
            holdout["truth"] = series.truth[score].tolist()
        if series.outlier_true is not None:
            holdout["outlier_true"] = series.outlier_true[score].tolist()
        out = np.abs(actual - y_cal) > tol
        first = int(steps[np.argmax(out)]) if out.any() else None
        if first is not None:
            exceeded = bool(k_rec is None or first < k_rec)
        else:
            exceeded = False
    for name in baselines_of(settings):
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                bf = _baseline(name, nar, settings, K).fit(y, usable=usable).forecast(K)
        except (InputError, ValueError, np.linalg.LinAlgError) as exc:
            base_out[name] = {"error": str(exc)}
            continue
        entry = {"value": bf.values.tolist()}
        if score.size:
            m = error_metrics(series.values[score], bf.values[steps - 1])
            entry.update({"rmse": m["rmse"], "max_ae": m["max_ae"], "mae": m["mae"]})
            if name == "persistence":
                pers_rmse = m["rmse"]
        base_out[name] = entry
    if holdout is not None and pers_rmse:
        skill = metrics.skill_score(holdout["metrics"]["rmse"], pers_rmse)
    fm = nar.fit_metrics()
    fit = {k: fm["all"][k] for k in ("mse", "rmse", "max_ae")}
    fit["train"] = fm.get("train")
    fit["validation"] = fm.get("validation")
    wh = nar.residual_check()
    sel = nar.order_selection_
    fdays_in = series.day[nar.sample_index_]
    resid = y[nar.sample_index_] - np.asarray(nar.fitted_)
    anomalies = fdays_in[cusum_alarms(resid)].tolist() if not nar.constant_ else []
    return SeriesResult(
        unit_id=series.unit_id, quantity=series.quantity, unit=series.unit,
        origin_day=int(series.day[T]), step_days=series.step_days, order=int(nar.order_),
        cv_scores=[] if sel is None else list(sel.scores), fit=fit,
        forecast={"day": fdays.tolist(), "value": fc.values.tolist(),
                  "lo95": fc.lo95.tolist(), "hi95": fc.hi95.tolist(),
                  "median": fc.median.tolist()},
        holdout=holdout, baselines=base_out,
        whiteness={"passed": None if wh is None else wh.passed,
                   "ljung_box_p": None if wh is None else wh.ljung_box_p,
                   "acf": [] if wh is None else list(wh.acf),
                   "bound": None if wh is None else wh.bound},
        recalibration_day=rec_day,
        recalibration_reason=None if rec_day is not None else "none within horizon",
        skill_vs_persistence=skill, accepted=bool(nar.accepted_), y_cal=y_cal,
        tolerance=tol, k_ref=series.k_ref, model=nar, series=series, origin_index=T,
        fitted_day=series.day[nar.sample_index_], fitted=np.asarray(nar.fitted_),
        exceeded_before_schedule=exceeded, anomaly_days=[int(d) for d in anomalies])


class DriftModel:
    """All units' NAR models of one record, able to forecast again (model type ``storage-drift``).

    ``entries[unit_id][quantity]`` holds the fitted :class:`NARForecaster` and the
    origin day, grid step, working unit (µg / ppm), k_ref, the calibrated value and
    the tolerance.

    Examples
    --------
    One unit's bias (an AR(2) series settling at 1/3 ug) with its NAR: three daily steps
    forecast past day 79; against a calibrated 0 ug, a tolerance of 0.5 ug holds over the
    horizon, one of 0.3 ug is passed on the first day:

    >>> import numpy as np
    >>> from inertialab.learn import NARForecaster
    >>> rng = np.random.default_rng(0)
    >>> y, e = np.zeros(80), rng.normal(0.0, 0.01, 80)
    >>> for k in range(2, 80):
    ...     y[k] = 0.9 * y[k - 1] - 0.2 * y[k - 2] + 0.1 + e[k]
    >>> nar = NARForecaster(order=2, hidden=2, restarts=1, n_paths=20, rng=0).fit(y)
    >>> entry = {"nar": nar, "origin_day": 79, "step_days": 1, "unit": "ug", "k_ref": 1.0,
    ...          "y_cal": 0.0, "tolerance": 0.5}
    >>> out = DriftModel({"u1": {"bias": entry}}, {"horizon": 3}).forecast()["u1"]["bias"]
    >>> out["forecast"]["day"], out["recalibration_day"]
    ([80, 81, 82], None)
    >>> bool(np.allclose(out["forecast"]["value"], 1 / 3, atol=0.03))
    True
    >>> tight = DriftModel({"u1": {"bias": {**entry, "tolerance": 0.3}}}, {"horizon": 3})
    >>> tight.forecast()["u1"]["bias"]["recalibration_day"]
    80
    """

    MODEL_TYPE = "storage-drift"
    #: Payload format of this type (bump when ``to_dict`` changes; old versions keep loading).
    FORMAT_VERSION = 1

    def __init__(self, entries: dict | None = None, settings: dict | None = None):
        self.entries = entries or {}
        self.settings = settings or {}

    @classmethod
    def from_results(cls, results: dict, settings: dict | None = None) -> DriftModel:
        """The model of :func:`fit_series` results ``{unit_id: {quantity: SeriesResult}}``:
        each entry keeps the fitted NAR, its origin day, grid step (days), working unit,
        k_ref, calibrated value and tolerance; ``settings`` (horizon, recal_quantile, ...)
        are stored as given."""
        entries = {uid: {q: {"nar": r.model, "origin_day": r.origin_day,
                             "step_days": r.step_days, "unit": r.unit, "k_ref": r.k_ref,
                             "y_cal": r.y_cal, "tolerance": r.tolerance}
                         for q, r in qs.items()}
                   for uid, qs in results.items()}
        return cls(entries, settings)

    def forecast(self, horizon: int | None = None) -> dict:
        """Forecast every unit and quantity ``horizon`` steps past its origin.

        Returns ``{unit_id: {quantity: {"unit", "forecast": {"day", "value", "lo95",
        "hi95"}, "recalibration_day", "recalibration_reason"}}}``.
        """
        K = check_horizon(self.settings.get("horizon", 20) if horizon is None else horizon)
        q = float(self.settings.get("recal_quantile", 0.1))
        out: dict = {}
        for uid, qs in self.entries.items():
            out[uid] = {}
            for qn, e in qs.items():
                nar: NARForecaster = e["nar"]
                fc = nar.forecast(K)
                paths = nar.forecast_paths(K)
                k_rec, _ = first_passage(paths, e["y_cal"], e["tolerance"], quantile=q)
                day = e["origin_day"] + e["step_days"] * np.arange(1, K + 1)
                rec = None if k_rec is None else int(e["origin_day"] + e["step_days"] * k_rec)
                out[uid][qn] = {
                    "unit": e["unit"], "order": int(nar.order_),
                    "forecast": {"day": day.tolist(), "value": fc.values.tolist(),
                                 "lo95": fc.lo95.tolist(), "hi95": fc.hi95.tolist()},
                    "recalibration_day": rec,
                    "recalibration_reason": None if rec is not None else "none within horizon",
                }
        return out

    def to_dict(self) -> dict:
        ent = {}
        for uid, qs in self.entries.items():
            ent[uid] = {}
            for qn, e in qs.items():
                d = {k: v for k, v in e.items() if k != "nar"}
                d["nar"] = e["nar"].to_dict()
                ent[uid][qn] = d
        return {"settings": self.settings, "entries": ent}

    @classmethod
    def from_dict(cls, d: dict) -> DriftModel:
        """Rebuild from :meth:`to_dict`, validating every field:
        types, finiteness and ranges, and a one-step forecast of every entry; anything
        else is an :class:`InputError`."""
        check_own_payload(cls.MODEL_TYPE, d)  # types, shapes, ranges: one line naming the key
        try:
            settings = d.get("settings", {})
            if not isinstance(settings, dict):
                raise InputError("settings must be an object")
            settings = dict(settings)
            if "horizon" in settings:
                settings["horizon"] = check_horizon(settings["horizon"])
            if settings.get("t0") is not None:
                import datetime as _dt

                _dt.datetime.fromisoformat(str(settings["t0"]))
            q = float(settings.get("recal_quantile", 0.1))
            if not 0.0 <= q <= 1.0:
                raise InputError(f"recal_quantile must lie in [0, 1], got {q}")
            if not isinstance(d["entries"], dict):
                raise InputError("entries must be an object")
            ent = {}
            for uid, qs in d["entries"].items():
                ent[uid] = {}
                if not isinstance(qs, dict):
                    raise InputError(f"entry {uid!r} must be an object")
                for qn, e in qs.items():
                    if qn not in QUANTITIES:
                        raise InputError(f"storage-drift model: unknown quantity {qn!r}")
                    x = dict(e)
                    x["nar"] = NARForecaster.from_dict(e["nar"])
                    for key in ("origin_day", "step_days"):
                        v = float(x[key])
                        if not (np.isfinite(v) and v == int(v) and abs(v) <= 1e7):
                            raise InputError(f"{uid}/{qn}: {key} must be a whole number of "
                                             "days (|value| <= 1e7)")
                        x[key] = int(v)
                    if x["step_days"] < 1:
                        raise InputError(f"{uid}/{qn}: step_days must be >= 1")
                    for key in ("y_cal", "tolerance"):
                        x[key] = float(x[key])
                        if not np.isfinite(x[key]):
                            raise InputError(f"{uid}/{qn}: {key} must be finite")
                    if not x["tolerance"] > 0:
                        raise InputError(f"{uid}/{qn}: tolerance must be positive")
                    if x.get("k_ref") is not None:
                        x["k_ref"] = float(x["k_ref"])
                        if not (np.isfinite(x["k_ref"]) and x["k_ref"] > 0):
                            raise InputError(f"{uid}/{qn}: k_ref must be positive")
                    if x.get("unit", QUANTITIES[qn]) != QUANTITIES[qn]:
                        raise InputError(f"{uid}/{qn}: unit must be {QUANTITIES[qn]!r}")
                    with warnings.catch_warnings():
                        warnings.simplefilter("ignore")
                        check = x["nar"].forecast(1)
                    if not np.all(np.isfinite([check.values, check.lo95, check.hi95])):
                        raise InputError(f"{uid}/{qn}: the network gives a non-finite forecast")
                    ent[uid][qn] = x
            return cls(ent, settings)
        except InputError as exc:
            raise InputError(f"storage-drift model: bad payload ({exc})") from None
        except (KeyError, TypeError, AttributeError, ValueError, IndexError,
                OverflowError) as exc:
            raise InputError(f"storage-drift model: bad payload ({type(exc).__name__}: "
                             f"{exc})") from None
