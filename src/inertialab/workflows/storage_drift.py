"""Storage-drift study (spec 004): daily grid, per-unit NAR fits and forecasts, baselines,
rolling-origin evaluation and re-calibration scheduling.

Pipeline for a record of the ``storage_drift`` kind (one row per test of one unit):

1. :func:`to_daily_grid` (§2.2): programme day d = floor((t - t0)/1 day), invalid rows
   dropped, same-day repeats averaged (``n_rep``, ``rep_sd``), exact duplicate tests
   dropped with a warning and the same (unit, time) twice with different values an
   :class:`~inertialab.errors.InputError`; gaps of at most ``max_gap`` steps filled by
   linear interpolation and flagged ``imputed``; longer gaps split segments; optional
   Hampel screen; weekly (or other regular) programmes resampled to their native step.
   Bias is worked in µg, scale factor in ppm of the unit's mean K1 (CONTRACTS "drift").
2. :func:`fit_series` per unit and quantity: NAR (order by kernel CV, R restarts,
   closed-loop forecast with 95 % bootstrap intervals), the baselines of §4, holdout
   metrics when the record extends past the origin (§5; scored on observed, non-imputed
   days only), skill vs persistence, whiteness, and the re-calibration day (§9): for a
   tolerance Δ around the value at the origin, the first-passage step of every
   simulated path, its 10 % quantile, as a programme day (``None``: none within horizon);
   CUSUM alarms on the one-step residuals flag shocks and steps (§9).
3. :func:`fit_drift` does 1-2 for a whole record and returns a :class:`DriftFit` with a
   :class:`DriftModel` (model-file type ``storage-drift``) that forecasts again later.
4. :func:`evaluate_rolling_origin` (§5): refit at origins T = first, first+step, ..., N-K;
   mean/median/max metrics, win rates and a paired Wilcoxon test of per-origin RMSE.

Random streams: ``SeedSequence(seed).spawn(n_units)`` over units in sorted ``unit_id``
order, then each unit's stream ``spawn(2)`` for (bias, sf); each is the NAR's seed.
"""

from __future__ import annotations

import time
import warnings
from dataclasses import asdict, dataclass, field, replace

import numpy as np
import pandas as pd

from inertialab.errors import DataQualityWarning, InputError
from inertialab.learn.forecast_baselines import make_baseline
from inertialab.learn.nar import NARForecaster
from inertialab.units import convert, split_suffix
from inertialab.workflows.base import Headline, NullProgress, Study, StudyResult, settings_dict

__all__ = [
    "QUANTITIES",
    "STUDY",
    "DailySeries",
    "DriftFit",
    "DriftModel",
    "DriftSettings",
    "FullSettings",
    "QuickSettings",
    "RollingResult",
    "SeriesResult",
    "evaluate_rolling_origin",
    "fit_drift",
    "fit_series",
    "cusum_alarms",
    "recalibration",
    "run_demo",
    "to_daily_grid",
]

#: quantity -> working unit (CONTRACTS.md "drift": bias µg, scale factor ppm)
QUANTITIES = {"bias": "ug", "sf": "ppm"}

DEFAULT_BASELINES = ("persistence", "window_mean", "ar_ls", "ar_aic", "poly_trend",
                     "exp_saturation", "exp_ar1", "kernel_nar")


# ==================================================================================
# daily grid (spec 004 §2.2)
# ==================================================================================

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


def _find(frame: pd.DataFrame, base: str) -> str | None:
    for c in frame.columns:
        b, suf = split_suffix(c)
        if b == base and suf is not None:
            return c
    return None


def _bias_ug(frame, col, meta, path, k1_col):
    _, suf = split_suffix(col)
    x = frame[col].to_numpy(dtype=float)
    if suf in ("ma",):
        if k1_col is not None and split_suffix(k1_col)[1] == "ma_per_g":
            k1 = frame[k1_col].to_numpy(dtype=float)
        else:
            nom = meta.get("k1_nominal_ma_per_g")
            if isinstance(nom, dict):
                k1 = frame["unit_id"].map(nom).to_numpy(dtype=float)
            elif nom is not None:
                k1 = np.full(x.size, float(nom))
            else:
                raise InputError("a bias in mA needs K1: an sf_ma_per_g column or "
                                 "'k1_nominal_ma_per_g' in the sidecar", path=path, column=col)
        return x / k1 * 1e6
    return np.asarray(convert(x, suf, "ug"), dtype=float)


def _sf_values(frame, col, meta, path):
    """Scale factor as ppm relative to k_ref per unit; returns (ppm array, k_ref per unit)."""
    _, suf = split_suffix(col)
    x = frame[col].to_numpy(dtype=float)
    units = frame["unit_id"].to_numpy()
    kref: dict[str, float] = {}
    if suf in ("ppm", "pct"):
        ppm = np.asarray(convert(x, suf, "ppm"), dtype=float)
        ref = meta.get("k_ref") or meta.get("k1_nominal_ma_per_g")
        for u in np.unique(units):
            kref[str(u)] = float(ref[u]) if isinstance(ref, dict) and u in ref else \
                (float(ref) if isinstance(ref, (int, float)) else float("nan"))
        return ppm, kref
    ppm = np.empty_like(x)
    for u in np.unique(units):
        m = units == u
        ref = meta.get("k_ref")
        k = float(ref[u]) if isinstance(ref, dict) and u in ref else float(np.mean(x[m]))
        if k == 0:
            raise InputError(f"unit {u}: mean scale factor is zero", path=path, column=col)
        kref[str(u)] = k
        ppm[m] = 1e6 * (x[m] - k) / k
    return ppm, kref


def _programme_days(frame: pd.DataFrame, meta: dict, path) -> np.ndarray:
    if "day" in frame.columns:
        return frame["day"].to_numpy(dtype=float)
    tcol = "timestamp" if "timestamp" in frame.columns else "date"
    ts = pd.to_datetime(frame[tcol], utc=True)
    t0 = meta.get("t0")
    t0 = pd.Timestamp(t0, tz="UTC") if t0 is not None and pd.Timestamp(t0).tzinfo is None \
        else (pd.Timestamp(t0) if t0 is not None else ts.min())
    return np.floor((ts - t0).dt.total_seconds().to_numpy() / 86400.0)


def _check_duplicates(frame: pd.DataFrame, value_cols: list[str], path):
    """Same (unit, time) twice: identical -> dropped with a warning; different -> InputError."""
    key = "timestamp" if "timestamp" in frame.columns else ("date" if "date" in frame.columns
                                                             else "day")
    cols = ["unit_id", key]
    dup = frame.duplicated(cols, keep=False)
    if not dup.any():
        return frame
    keep = np.ones(len(frame), dtype=bool)
    for _, grp in frame[dup].groupby(cols, sort=False):
        idx = grp.index.to_numpy()
        vals = frame.loc[idx, value_cols].to_numpy(dtype=float)
        same = np.all(np.isclose(vals, vals[0], rtol=0, atol=0, equal_nan=True))
        if not same:
            rows = [int(i) + 1 for i in idx[:2]]
            raise InputError(
                f"unit {grp['unit_id'].iloc[0]}: {key} {grp[key].iloc[0]} appears twice with "
                f"different values (rows {rows[0]} and {rows[1]} after sorting by unit and "
                f"date); repeats on one day need distinct timestamps", path=path)
        keep[idx[1:]] = False
    warnings.warn(f"{path}: {int((~keep).sum())} exact duplicate test(s) dropped",
                  DataQualityWarning, stacklevel=3)
    return frame[keep]


def _hampel(values, observed, segment, half=3, k=5.0):
    """Spec 004 §2.2 item 5: |y_d - median(y_{d-3..d+3})| > 5 * 1.4826 MAD over the segment."""
    flag = np.zeros(values.size, dtype=bool)
    for s in np.unique(segment[segment >= 0]):
        idx = np.flatnonzero((segment == s) & observed)
        if idx.size < 2 * half + 1:
            continue
        y = values[idx]
        dev = np.empty(idx.size)
        for j, i in enumerate(idx):
            win = (idx >= i - half) & (idx <= i + half)
            dev[j] = y[j] - np.median(y[win])
        sig = 1.4826 * np.median(np.abs(dev - np.median(dev)))
        if sig > 0:
            flag[idx[np.abs(dev) > k * sig]] = True
    return flag


def to_daily_grid(frame: pd.DataFrame, *, quantity: str, meta: dict | None = None,
                  max_gap: int = 3, hampel: bool = False, path="<frame>") -> dict[str, DailySeries]:
    """Regularise a storage record to one series per unit on its grid (spec 004 §2.2).

    Parameters
    ----------
    frame : DataFrame
        Validated ``storage_drift`` record (``read_record(path, "storage_drift").data``).
    quantity : {"bias", "sf"}
    meta : dict, optional
        Sidecar (``t0``, ``k_ref``, ``k1_nominal_ma_per_g``).
    max_gap : int, default=3
        Longest run of missing steps filled by linear interpolation (weekends).
    hampel : bool, default=False
        Apply the Hampel outlier screen (off by default, spec §2.2 item 5).

    Returns
    -------
    dict unit_id -> :class:`DailySeries`, in sorted unit order.
    """
    meta = dict(meta or {})
    if quantity not in QUANTITIES:
        raise InputError(f"quantity must be 'bias' or 'sf', got {quantity!r}")
    col = _find(frame, quantity)
    if col is None:
        raise InputError(f"record has no {quantity} column (e.g. "
                         f"{'bias_mg' if quantity == 'bias' else 'sf_ma_per_g'})", path=path)
    df = frame.copy()
    if "valid" in df.columns:
        df = df[df["valid"].fillna(True).astype(bool)]
    df = df[np.isfinite(df[col].to_numpy(dtype=float))]
    if len(df) == 0:
        raise InputError(f"no valid {quantity} values", path=path, column=col)
    df = _check_duplicates(df.reset_index(drop=True), [col], path)
    if quantity == "bias":
        vals = _bias_ug(df, col, meta, path, _find(df, "sf"))
        kref = {}
    else:
        vals, kref = _sf_values(df, col, meta, path)
    tcol = _find(df, f"true_{quantity}")
    truth = None
    if tcol is not None:
        if quantity == "bias":
            truth = _bias_ug(df, tcol, meta, path, _find(df, "sf"))
        else:
            tv = df[tcol].to_numpy(dtype=float)
            truth = np.array([1e6 * (v - kref[str(u)]) / kref[str(u)]
                              for v, u in zip(tv, df["unit_id"])]) \
                if split_suffix(tcol)[1] not in ("ppm", "pct") else convert(tv, split_suffix(tcol)[1], "ppm")
    outl = df["is_outlier_true"].to_numpy(dtype=bool) if "is_outlier_true" in df.columns else None
    days = _programme_days(df, meta, path)
    work = pd.DataFrame({"unit_id": df["unit_id"].astype(str).to_numpy(), "day": days,
                         "v": vals})
    if truth is not None:
        work["truth"] = truth
    if outl is not None:
        work["outl"] = outl
    out: dict[str, DailySeries] = {}
    for uid in sorted(work["unit_id"].unique()):
        u = work[work["unit_id"] == uid].sort_values("day", kind="stable")
        d = u["day"].to_numpy()
        ud = np.unique(d)
        step = 1
        if ud.size > 2:
            step = max(1, int(round(float(np.median(np.diff(ud))))))
        gi = np.round((d - ud[0]) / step).astype(int)
        n = int(gi.max()) + 1
        g = u.assign(gi=gi).groupby("gi")
        mean = g["v"].mean()
        cnt = g["v"].count()
        sd = g["v"].std(ddof=1)
        values = np.full(n, np.nan)
        values[mean.index.to_numpy()] = mean.to_numpy()
        n_rep = np.zeros(n, dtype=int)
        n_rep[cnt.index.to_numpy()] = cnt.to_numpy()
        rep_sd = np.full(n, np.nan)
        rep_sd[sd.index.to_numpy()] = sd.to_numpy()
        observed = n_rep > 0
        tr = None
        if truth is not None:
            tr = np.full(n, np.nan)
            tm = g["truth"].mean()
            tr[tm.index.to_numpy()] = tm.to_numpy()
        ot = None
        if outl is not None:
            ot = np.zeros(n, dtype=bool)
            om = g["outl"].max()
            ot[om.index.to_numpy()] = om.to_numpy().astype(bool)
        screened = np.zeros(n, dtype=bool)
        if hampel:
            seg0 = np.where(observed, 0, -1)
            screened = _hampel(values, observed, seg0)
            observed = observed & ~screened
            values = np.where(observed, values, np.nan)
        values, imputed, segment = _fill_gaps(values, observed, int(max_gap))
        out[uid] = DailySeries(
            unit_id=uid, quantity=quantity, unit=QUANTITIES[quantity],
            day=(ud[0] + step * np.arange(n)).astype(int), values=values, observed=observed,
            imputed=imputed, n_rep=n_rep, rep_sd=rep_sd, segment=segment, screened=screened,
            truth=tr, outlier_true=ot, step_days=step,
            k_ref=kref.get(uid) if quantity == "sf" else None)
    return out


def _fill_gaps(values, observed, max_gap):
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


# ==================================================================================
# per-series fit and forecast
# ==================================================================================

@dataclass(frozen=True)
class DriftSettings:
    """Settings of :func:`fit_drift` / :func:`fit_series` (spec 004 defaults).

    horizon K = 20 steps; order None = kernel CV with H = 6; hidden S = 10; restarts
    R = 10; preset "paper" (best member, random split) or "strict" (median, block split);
    n_paths B = 200; max_gap 3; Hampel screen off; tolerances 50 µg and 50 ppm
    (CONTRACTS.md "drift"); re-calibration at the 10 % quantile of the first passage.
    """

    horizon: int = 20
    order: int | None = None
    H: int = 6
    hidden: int = 10
    restarts: int = 10
    preset: str = "paper"
    combine: str | None = None
    split: str | None = None
    n_paths: int = 200
    max_gap: int = 3
    hampel: bool = False
    baselines: tuple = DEFAULT_BASELINES
    tol_bias_ug: float = 50.0
    tol_sf_ppm: float = 50.0
    recal_quantile: float = 0.1
    seed: int = 0

    def tolerance(self, quantity: str) -> float:
        return float(self.tol_bias_ug if quantity == "bias" else self.tol_sf_ppm)


def _metrics(e) -> dict | None:
    e = np.asarray(e, dtype=float)
    if e.size == 0:
        return None
    return {"max_ae": float(np.max(np.abs(e))), "mae": float(np.mean(np.abs(e))),
            "me": float(np.mean(e)), "rmse": float(np.sqrt(np.mean(e * e))),
            "mse": float(np.mean(e * e)), "n": int(e.size)}


def recalibration(paths: np.ndarray, y_cal: float, tol: float, *, quantile: float = 0.1):
    """First-passage re-calibration step (spec 004 §9).

    t* = min{k : |path_k - y_cal| > tol} per path (inf when never within the horizon);
    returns ``(k, t_star)`` with ``k`` the ``quantile`` of t* (an int step, or None when
    that quantile lies beyond the horizon) and the per-path t* array.
    """
    paths = np.atleast_2d(np.asarray(paths, dtype=float))
    out = np.abs(paths - y_cal) > tol
    any_ = out.any(axis=1)
    t_star = np.where(any_, np.argmax(out, axis=1) + 1, np.inf).astype(float)
    q = float(np.quantile(t_star, quantile, method="inverted_cdf"))
    return (None if not np.isfinite(q) else int(q)), t_star


def cusum_alarms(resid, *, k: float = 0.5, h: float = 5.0) -> np.ndarray:
    """Two-sided tabular CUSUM on robustly standardised one-step residuals (spec 004 §9).

    z = (e - median e) / (1.4826 MAD e); S+ = max(0, S+ + z - k), S- = max(0, S- - z - k);
    an alarm is raised where either exceeds ``h`` and both sums restart from 0.
    Returns the indices (into ``resid``) of the alarms. Defaults k = 0.5, h = 5
    (in-control average run length of the two-sided scheme ≈ 465 samples).
    """
    e = np.asarray(resid, dtype=float)
    if e.size == 0:
        return np.zeros(0, dtype=int)
    med = float(np.median(e))
    sig = 1.4826 * float(np.median(np.abs(e - med)))
    if not sig > 0:
        return np.zeros(0, dtype=int)
    z = (e - med) / sig
    sp = sm = 0.0
    out = []
    for i, v in enumerate(z):
        sp = max(0.0, sp + v - k)
        sm = max(0.0, sm - v - k)
        if sp > h or sm > h:
            out.append(i)
            sp = sm = 0.0
    return np.asarray(out, dtype=int)


@dataclass
class SeriesResult:
    """Fit and forecast of one unit's quantity (JSON keys of the CLI, issue 8 item 5)."""

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

    def to_dict(self) -> dict:
        return {
            "unit": self.unit, "origin_day": self.origin_day, "step_days": self.step_days,
            "order": self.order, "cv_scores": self.cv_scores, "fit": self.fit,
            "forecast": self.forecast, "holdout": self.holdout, "baselines": self.baselines,
            "whiteness": self.whiteness, "recalibration_day": self.recalibration_day,
            "recalibration_reason": self.recalibration_reason,
            "skill_vs_persistence": self.skill_vs_persistence, "accepted": self.accepted,
            "y_cal": self.y_cal, "tolerance": self.tolerance, "k_ref": self.k_ref,
            "anomaly_days": self.anomaly_days,
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


def fit_series(series: DailySeries, settings: DriftSettings = DriftSettings(), *,
               origin_day: int | None = None, rng=None) -> SeriesResult:
    """NAR fit, forecast, baselines, holdout metrics and re-calibration for one series.

    In-sample = grid steps up to the origin (the last observed step on or before
    ``origin_day``; default the last observed step). Steps after it, up to the horizon,
    are the holdout, scored on observed, non-imputed, non-screened steps only.
    """
    K = int(settings.horizon)
    if K < 1:
        raise InputError(f"horizon must be >= 1, got {settings.horizon}")
    T = _origin_index(series, origin_day)
    y = series.values[: T + 1]
    usable = series.usable[: T + 1]
    seg = series.segment[: T + 1]
    # use only the last segment when an earlier one is separated by a long gap? No:
    # the NAR skips samples touching gaps; all segments contribute (spec §2.2 item 4).
    del seg
    nar = NARForecaster(order=settings.order, H=settings.H, hidden=settings.hidden,
                        restarts=settings.restarts, preset=settings.preset,
                        combine=settings.combine, split=settings.split,
                        n_paths=settings.n_paths, rng=rng)
    nar.fit(y, usable=usable)
    fc = nar.forecast(K)
    paths = nar.forecast_paths(K)
    fdays = series.day[T] + series.step_days * np.arange(1, K + 1)
    y_cal = float(y[-1])
    tol = settings.tolerance(series.quantity)
    k_rec, _ = recalibration(paths, y_cal, tol, quantile=settings.recal_quantile)
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
                   "step": steps.tolist(), "metrics": _metrics(e),
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
    for name in settings.baselines:
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                bf = make_baseline(name).fit(y, usable=usable).forecast(K)
        except (InputError, ValueError, np.linalg.LinAlgError) as exc:
            base_out[name] = {"error": str(exc)}
            continue
        entry = {"value": bf.values.tolist()}
        if score.size:
            m = _metrics(series.values[score] - bf.values[steps - 1])
            entry.update({"rmse": m["rmse"], "max_ae": m["max_ae"], "mae": m["mae"]})
            if name == "persistence":
                pers_rmse = m["rmse"]
        base_out[name] = entry
    if holdout is not None and pers_rmse:
        skill = float(1.0 - holdout["metrics"]["rmse"] / pers_rmse)
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


# ==================================================================================
# a whole record
# ==================================================================================

class DriftModel:
    """All units' NAR models of one record, able to forecast again (model type ``storage-drift``).

    ``entries[unit_id][quantity]`` holds the fitted :class:`NARForecaster` and the
    origin day, grid step, working unit (µg / ppm), k_ref, the calibrated value and
    the tolerance.
    """

    MODEL_TYPE = "storage-drift"

    def __init__(self, entries: dict | None = None, settings: dict | None = None):
        self.entries = entries or {}
        self.settings = settings or {}

    def forecast(self, horizon: int | None = None) -> dict:
        """Forecast every unit and quantity ``horizon`` steps past its origin.

        Returns ``{unit_id: {quantity: {"unit", "forecast": {"day", "value", "lo95",
        "hi95"}, "recalibration_day", "recalibration_reason"}}}``.
        """
        K = int(horizon or self.settings.get("horizon", 20))
        if K < 1:
            raise InputError(f"horizon must be >= 1, got {horizon}")
        q = float(self.settings.get("recal_quantile", 0.1))
        out: dict = {}
        for uid, qs in self.entries.items():
            out[uid] = {}
            for qn, e in qs.items():
                nar: NARForecaster = e["nar"]
                fc = nar.forecast(K)
                paths = nar.forecast_paths(K)
                k_rec, _ = recalibration(paths, e["y_cal"], e["tolerance"], quantile=q)
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
        try:
            ent = {}
            for uid, qs in d["entries"].items():
                ent[uid] = {}
                for qn, e in qs.items():
                    if qn not in QUANTITIES:
                        raise InputError(f"storage-drift model: unknown quantity {qn!r}")
                    x = dict(e)
                    x["nar"] = NARForecaster.from_dict(e["nar"])
                    for key in ("origin_day", "step_days"):
                        x[key] = int(x[key])
                    for key in ("y_cal", "tolerance"):
                        x[key] = float(x[key])
                    ent[uid][qn] = x
            return cls(ent, dict(d.get("settings", {})))
        except (KeyError, TypeError, AttributeError) as exc:
            raise InputError(f"storage-drift model: bad payload ({exc})") from None


@dataclass
class DriftFit:
    """Result of :func:`fit_drift`: ``results[unit_id][quantity]`` -> :class:`SeriesResult`."""

    results: dict
    model: DriftModel
    settings: DriftSettings
    wall_s: float = 0.0

    def iter(self):
        for uid, qs in self.results.items():
            for qn, r in qs.items():
                yield uid, qn, r

    def to_dict(self) -> dict:
        return {"units": {uid: {qn: r.to_dict() for qn, r in qs.items()}
                          for uid, qs in self.results.items()}}


def fit_drift(frame: pd.DataFrame, *, meta: dict | None = None,
              settings: DriftSettings = DriftSettings(), quantities=("bias", "sf"),
              origin_day: int | None = None, path="<frame>", progress=None) -> DriftFit:
    """Fit and forecast every unit and quantity of a storage record.

    Parameters
    ----------
    frame : validated ``storage_drift`` record (``Record.data``)
    meta : sidecar (``t0``, ``k_ref``, ``tol_bias_ug``/``tol_sf_ppm`` if the settings
        keep the defaults, see CONTRACTS.md "drift")
    settings : :class:`DriftSettings`
    quantities : which of "bias", "sf" (a quantity absent from the record is skipped
        when both are asked for)
    origin_day : last in-sample programme day (default: the last test)
    """
    progress = progress or NullProgress()
    meta = dict(meta or {})
    t0 = time.perf_counter()
    qs = [q for q in quantities if q in QUANTITIES]
    if not qs:
        raise InputError(f"quantities must be bias and/or sf, got {quantities!r}")
    present = [q for q in qs if _find(frame, q) is not None]
    if not present:
        raise InputError(f"record has none of the columns {', '.join(qs)}", path=path)
    if len(qs) == 1 and not present:
        raise InputError(f"record has no {qs[0]} column", path=path)
    grids = {q: to_daily_grid(frame, quantity=q, meta=meta, max_gap=settings.max_gap,
                              hampel=settings.hampel, path=path) for q in present}
    units = sorted(set().union(*[set(g) for g in grids.values()]))
    ss = np.random.SeedSequence(int(settings.seed))
    children = dict(zip(units, ss.spawn(len(units))))
    results: dict = {}
    entries: dict = {}
    total = len(units) * len(present)
    done = 0
    for uid in units:
        qseeds = dict(zip(("bias", "sf"), children[uid].spawn(2)))
        results[uid] = {}
        entries[uid] = {}
        for q in present:
            if uid not in grids[q]:
                continue
            s = grids[q][uid]
            finite = np.isfinite(s.values)
            if finite.sum() and np.ptp(s.values[finite]) == 0:
                warnings.warn(f"unit {uid}: {q} is constant; its forecast is persistence",
                              DataQualityWarning, stacklevel=2)
            r = fit_series(s, settings, origin_day=origin_day, rng=qseeds[q])
            results[uid][q] = r
            entries[uid][q] = {"nar": r.model, "origin_day": r.origin_day,
                               "step_days": r.step_days, "unit": r.unit, "k_ref": r.k_ref,
                               "y_cal": r.y_cal, "tolerance": r.tolerance}
            done += 1
            progress.update(done, total, f"{uid} {q}")
    model = DriftModel(entries, {"horizon": settings.horizon,
                                 "recal_quantile": settings.recal_quantile,
                                 "seed": settings.seed, "preset": settings.preset})
    return DriftFit(results, model, settings, time.perf_counter() - t0)


# ==================================================================================
# rolling origin (spec 004 §5)
# ==================================================================================

@dataclass(frozen=True)
class RollingResult:
    """Rolling-origin evaluation of one series.

    Attributes
    ----------
    origins : grid indices of the origins
    rmse : method -> per-origin 20-step RMSE (NaN where no scoring day)
    max_ae : method -> per-origin MaxAE
    summary : method -> {"mean", "median", "max"} of RMSE
    win_rate : baseline -> share of origins where NAR's RMSE is lower
    wilcoxon_p : baseline -> paired Wilcoxon signed-rank p-value on per-origin RMSE
    orders : NAR order per origin
    """

    origins: tuple
    rmse: dict
    max_ae: dict
    summary: dict
    win_rate: dict
    wilcoxon_p: dict
    orders: tuple

    def to_dict(self) -> dict:
        return asdict(self)


def evaluate_rolling_origin(series: DailySeries, settings: DriftSettings = DriftSettings(), *,
                            first: int = 50, step: int = 5, rng=0,
                            refit_order: bool = True) -> RollingResult:
    """Refit NAR and the baselines at origins first, first+step, ..., N-K (spec 004 §5).

    ``refit_order=False`` keeps the order chosen at the first origin.
    """
    from scipy.stats import wilcoxon

    K = int(settings.horizon)
    N = series.values.size
    origins = [T for T in range(int(first), N - K + 1, int(step))]
    if not origins:
        raise InputError(f"series of {N} steps too short for origins from {first} with K = {K}")
    seeds = np.random.SeedSequence(int(rng) if not isinstance(rng, np.random.SeedSequence)
                                   else 0).spawn(len(origins))
    names = ["nar", *settings.baselines]
    rm = {n: [] for n in names}
    mx = {n: [] for n in names}
    orders = []
    order = settings.order
    for T, sd in zip(origins, seeds):
        st = replace(settings, order=order)
        r = fit_series(series, st, origin_day=int(series.day[T - 1]), rng=sd)
        if not refit_order and order is None:
            order = r.order
        orders.append(r.order)
        hm = r.holdout["metrics"] if r.holdout else None
        rm["nar"].append(hm["rmse"] if hm else np.nan)
        mx["nar"].append(hm["max_ae"] if hm else np.nan)
        for b in settings.baselines:
            e = r.baselines.get(b, {})
            rm[b].append(e.get("rmse", np.nan))
            mx[b].append(e.get("max_ae", np.nan))
    summary, win, wp = {}, {}, {}
    a = np.asarray(rm["nar"], dtype=float)
    for n in names:
        v = np.asarray(rm[n], dtype=float)
        f = v[np.isfinite(v)]
        summary[n] = {"mean": float(np.mean(f)) if f.size else None,
                      "median": float(np.median(f)) if f.size else None,
                      "max": float(np.max(f)) if f.size else None}
        if n == "nar":
            continue
        ok = np.isfinite(a) & np.isfinite(v)
        win[n] = float(np.mean(a[ok] < v[ok])) if ok.any() else None
        d = a[ok] - v[ok]
        if ok.sum() >= 2 and np.any(d != 0):
            wp[n] = float(wilcoxon(a[ok], v[ok]).pvalue)
        else:
            wp[n] = None
    return RollingResult(tuple(origins), {k: list(map(float, v)) for k, v in rm.items()},
                         {k: list(map(float, v)) for k, v in mx.items()}, summary, win, wp,
                         tuple(orders))


# ==================================================================================
# demo study
# ==================================================================================

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
    from inertialab.sim.storage_drift import simulate_storage_batch

    progress = progress or NullProgress()
    t0 = time.perf_counter()
    batch = simulate_storage_batch(settings.n_units, settings.n_days, "paper",
                                   rng=np.random.SeedSequence(settings.seed))
    ds = DriftSettings(restarts=settings.restarts, n_paths=settings.n_paths,
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
        Headline("CV order, bias (mode over units)", b.get("order_mode"), 2, ""),
        Headline("CV order, scale factor (mode)", s.get("order_mode"), 3, ""),
        Headline("bias fit MaxAE (median)", b.get("median_fit_max_ae_native"), 2e-4, "g"),
        Headline("bias 20-day forecast MaxAE (median)", b.get("median_forecast_max_ae_native"),
                 2e-4, "g"),
        Headline("SF fit MaxAE (median)", s.get("median_fit_max_ae_native"), 1e-4, "mA/g"),
        Headline("SF 20-day forecast MaxAE (median)", s.get("median_forecast_max_ae_native"),
                 1e-4, "mA/g"),
        Headline("bias skill vs persistence (median)", b.get("median_skill_vs_persistence"),
                 None, ""),
        Headline("95 % interval coverage, nav preset (A13: 0.85-0.99)", nav_coverage, None, ""),
        Headline("nav units leaving tolerance before their re-calibration day (target <= 0.1)",
                 nav_exceeded, None, ""),
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
        "On this preset the NAR is not expected to beat AR or persistence (spec A8): the "
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
