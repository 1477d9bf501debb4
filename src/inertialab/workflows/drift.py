"""Workflow ``drift`` (spec 004): storage records to per-unit NAR forecasts.

Thin, one verb set over :mod:`inertialab.calib.drift`:

* :func:`prepare` / :func:`to_daily_grid` (§2.2) — a ``storage_drift`` record to one
  :class:`~inertialab.calib.drift.DailySeries` per unit and quantity: programme day
  d = floor((t - t0)/1 day), invalid rows dropped, same-day repeats averaged (``n_rep``,
  ``rep_sd``), exact duplicate tests dropped with a warning and the same (unit, time)
  twice with different values an :class:`~inertialab.errors.InputError`; gaps of at most
  ``max_gap`` steps filled by linear interpolation and flagged ``imputed``; longer gaps
  split segments; optional Hampel screen; weekly (or other regular) programmes resampled
  to their native step. Bias in µg, scale factor in ppm of the unit's mean K1.
* :func:`fit` / :func:`fit_drift` — every unit and quantity of a record fitted and
  forecast (:func:`~inertialab.calib.drift.fit_series`), returning a :class:`DriftFit`
  with a :class:`~inertialab.calib.drift.DriftModel`.
* :func:`forecast` — a saved model forecast again.
* the commands ``drift fit|evaluate|forecast|apply``, one call each: a
  :class:`~inertialab.config.Config` of settings per command (:class:`FitConfig`,
  :class:`EvaluateConfig`) and ``run_*(record, config) -> result`` whose result
  (:class:`inertialab.result.Result`) knows ``to_json()``, ``settings``, ``units``,
  ``artifacts()`` and ``summary_rows()``.

The estimators (:mod:`inertialab.calib.drift`, scipy) and pandas are imported inside the
functions that use them, so that ``drift fit --help`` starts light; their names
re-exported here (``DEFAULT_BASELINES``, ``DriftModel`` ...) load on first use.
:class:`FitConfig` and :class:`EvaluateConfig` are the settings of the commands, of the
verbs and of the estimator (:func:`~inertialab.calib.drift.fit_series` reads them by
the flags' names); ``DriftSettings`` is the deprecated name of the former estimator
class.

Random streams: ``SeedSequence(seed).spawn(n_units)`` over units in sorted ``unit_id``
order, then each unit's stream ``spawn(2)`` for (bias, sf); each is the NAR's seed.
"""

from __future__ import annotations

import time
import warnings
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING

import numpy as np

from inertialab.config import Config as _Settings
from inertialab.config import seed_setting, setting
from inertialab.errors import DataQualityWarning, InputError
from inertialab.learn.monitoring import hampel_flags
from inertialab.limits import MAX_HORIZON, check_horizon
from inertialab.progress import NullProgress
from inertialab.result import ResultBase
from inertialab.units import convert, split_suffix

if TYPE_CHECKING:
    import pandas as pd

    from inertialab.calib.drift import (
        DEFAULT_BASELINES,
        QUANTITIES,
        DailySeries,
        DriftModel,
    )

__all__ = ["DEFAULT_BASELINES", "MAX_HORIZON", "QUANTITIES", "UNITS", "DriftFit", "DriftSettings",
           "EvaluateConfig", "FitConfig", "ForecastConfig", "apply", "check_horizon", "evaluate", "fit",
           "fit_drift", "forecast", "prepare", "run_apply", "run_evaluate", "run_fit",
           "run_forecast", "to_daily_grid"]

#: Names of :mod:`inertialab.calib.drift` re-exported for callers of the workflow, loaded
#: on first use.
_CALIB = ("DEFAULT_BASELINES", "QUANTITIES", "DailySeries", "DriftModel", "check_span", "fill_gaps", "fit_series")


def __getattr__(name: str):
    """The estimator floor's names (:data:`_CALIB`) on first use."""
    if name in _CALIB:
        from inertialab.calib import drift

        return getattr(drift, name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def _find(frame: pd.DataFrame, base: str) -> str | None:
    for c in frame.columns:
        b, suf = split_suffix(c)
        if b == base and suf is not None:
            return c
    return None


def _load_ohm(frame, meta, path, col) -> np.ndarray:
    """Load resistor per row, ohm: a ``load_ohm`` column, else the sidecar's ``load_ohm``
    (a number or ``{unit_id: number}``); needed to read a scale factor in V/g (spec 004 §1)."""
    import pandas as pd

    if "load_ohm" in frame.columns:
        r = pd.to_numeric(frame["load_ohm"], errors="coerce").to_numpy(dtype=float)
    else:
        ref = meta.get("load_ohm")
        if isinstance(ref, dict):
            r = frame["unit_id"].astype(str).map(
                lambda u: ref.get(u, float("nan"))).to_numpy(dtype=float)
        elif isinstance(ref, (int, float)) and not isinstance(ref, bool):
            r = np.full(len(frame), float(ref))
        else:
            raise InputError("a scale factor in V/g needs the load resistor: a load_ohm "
                             "column or 'load_ohm' in the sidecar (k[mA/g] = 1000 k[V/g] / "
                             "R[ohm], spec 004)", path=path, column=col)
    bad = ~(np.isfinite(r) & (r > 0))
    if bad.any():
        rows = (np.flatnonzero(bad)[:5] + 1).tolist()
        raise InputError("load_ohm must be a positive number of ohms for every test of a "
                         "scale factor in V/g", path=path, column="load_ohm",
                         row=rows[0] if len(rows) == 1 else rows)
    return r


def _sf_ma_per_g(frame, col, meta, path) -> np.ndarray:
    """A scale-factor column in mA/g: V/g through the load resistor (k[mA/g] =
    1000 k[V/g] / R[ohm], spec 004), mA/g as it is."""
    x = frame[col].to_numpy(dtype=float)
    if split_suffix(col)[1] == "v_per_g":
        return 1000.0 * x / _load_ohm(frame, meta, path, col)
    return x


def _bias_ug(frame, col, meta, path, k1_col):
    _, suf = split_suffix(col)
    x = frame[col].to_numpy(dtype=float)
    if suf in ("ma",):
        if k1_col is not None and split_suffix(k1_col)[1] in ("ma_per_g", "v_per_g"):
            k1 = _sf_ma_per_g(frame, k1_col, meta, path)
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
    """Scale factor as ppm relative to k_ref per unit; returns (ppm array, k_ref per unit
    in mA/g; a V/g column is converted with the load resistor first)."""
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
    x = _sf_ma_per_g(frame, col, meta, path)  # k_ref and ppm relative to mA/g (spec §1)
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
    import pandas as pd

    if "day" in frame.columns:
        return frame["day"].to_numpy(dtype=float)
    tcol = "timestamp" if "timestamp" in frame.columns else "date"
    ts = pd.to_datetime(frame[tcol], utc=True)
    t0 = meta.get("t0")
    t0 = pd.Timestamp(t0, tz="UTC") if t0 is not None and pd.Timestamp(t0).tzinfo is None \
        else (pd.Timestamp(t0) if t0 is not None else ts.min())
    return np.floor((ts - t0).dt.total_seconds().to_numpy() / 86400.0)


def _programme_t0(frame: pd.DataFrame, meta: dict) -> str | None:
    """The programme start t0 (ISO, UTC) of a dated record, for :func:`apply` on a later
    record; None when the record counts days itself."""
    import pandas as pd

    if "day" in frame.columns:
        return None
    if meta.get("t0") is not None:
        t0 = pd.Timestamp(meta["t0"])
        t0 = t0.tz_localize("UTC") if t0.tzinfo is None else t0.tz_convert("UTC")
    else:
        tcol = "timestamp" if "timestamp" in frame.columns else "date"
        t0 = pd.to_datetime(frame[tcol], utc=True).min()
    return t0.isoformat()


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




def _truth(df, quantity: str, meta: dict, path, kref: dict):
    """The virtual lab's true values of ``quantity`` in the working unit (µg, ppm), or
    None for a real record."""
    tcol = _find(df, f"true_{quantity}")
    if tcol is None:
        return None
    if quantity == "bias":
        return _bias_ug(df, tcol, meta, path, _find(df, "sf"))
    suf = split_suffix(tcol)[1]
    tv = _sf_ma_per_g(df, tcol, meta, path) if suf == "v_per_g" else df[tcol].to_numpy(dtype=float)
    if suf in ("ppm", "pct"):
        return convert(tv, suf, "ppm")
    return np.array([1e6 * (v - kref[str(u)]) / kref[str(u)] for v, u in zip(tv, df["unit_id"])])


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
    import pandas as pd

    from inertialab.calib.drift import QUANTITIES, DailySeries, check_span, fill_gaps

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
    truth = _truth(df, quantity, meta, path, kref)
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
        span = (float(ud[-1]) - float(ud[0])) / step + 1  # checked before the grid
        check_span(int(min(span, 2**62)), uid, float(ud[0]), float(ud[-1]), path=path)
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
            screened = hampel_flags(values, observed, seg0)
            observed = observed & ~screened
            values = np.where(observed, values, np.nan)
        values, imputed, segment = fill_gaps(values, observed, int(max_gap))
        out[uid] = DailySeries(
            unit_id=uid, quantity=quantity, unit=QUANTITIES[quantity],
            day=(ud[0] + step * np.arange(n)).astype(int), values=values, observed=observed,
            imputed=imputed, n_rep=n_rep, rep_sd=rep_sd, segment=segment, screened=screened,
            truth=tr, outlier_true=ot, step_days=step,
            k_ref=kref.get(uid) if quantity == "sf" else None)
    return out


@dataclass
class DriftFit:
    """Result of :func:`fit_drift`: ``results[unit_id][quantity]`` -> :class:`SeriesResult`."""

    results: dict
    model: DriftModel
    settings: FitConfig
    wall_s: float = 0.0

    def iter(self):
        for uid, qs in self.results.items():
            for qn, r in qs.items():
                yield uid, qn, r

    def to_dict(self) -> dict:
        return {"units": {uid: {qn: r.to_dict() for qn, r in qs.items()}
                          for uid, qs in self.results.items()}}


def fit_drift(frame: pd.DataFrame, *, meta: dict | None = None,
              settings: FitConfig | None = None, quantities=("bias", "sf"),
              origin_day: int | None = None, path="<frame>", progress=None) -> DriftFit:
    """Fit and forecast every unit and quantity of a storage record.

    Parameters
    ----------
    frame : validated ``storage_drift`` record (``Record.data``)
    meta : sidecar (``t0``, ``k_ref``, ``tol_bias_ug``/``tol_sf_ppm`` if the settings
        keep the defaults, see docs/drift.md)
    settings : :class:`FitConfig` (default: spec 004's)
    quantities : which of "bias", "sf" (a quantity absent from the record is skipped
        when both are asked for)
    origin_day : last in-sample programme day (default: the last test)
    """
    from inertialab.calib.drift import QUANTITIES, DriftModel, fit_series

    settings = (settings or FitConfig()).validate()
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
    total = len(units) * len(present)
    done = 0
    for uid in units:
        qseeds = dict(zip(("bias", "sf"), children[uid].spawn(2)))
        results[uid] = {}
        for q in present:
            if uid not in grids[q]:
                continue
            s = grids[q][uid]
            finite = np.isfinite(s.values)
            if finite.sum() and np.ptp(s.values[finite]) == 0:
                warnings.warn(f"unit {uid}: {q} is constant; its forecast is persistence",
                              DataQualityWarning, stacklevel=2)
            try:
                results[uid][q] = fit_series(s, settings, origin_day=origin_day,
                                             rng=qseeds[q])
            except InputError as exc:  # a series the model cannot take: name it
                if exc.path is not None:
                    raise
                raise InputError(f"unit {uid}, {q}: {exc}", path=path) from exc
            done += 1
            progress.update(done, total, f"{uid} {q}")
    model = DriftModel.from_results(results, {"horizon": settings.horizon,
                                              "recal_quantile": settings.recal_quantile,
                                              "seed": settings.seed, "preset": settings.preset,
                                              "t0": _programme_t0(frame, meta)})
    return DriftFit(results, model, settings, time.perf_counter() - t0)


def prepare(record, *, settings: FitConfig | None = None,
            quantities=("bias", "sf")) -> dict:
    """The grids of a validated ``storage_drift`` record: ``{quantity: {unit_id:
    DailySeries}}`` for each asked quantity the record holds (:func:`to_daily_grid`)."""
    from inertialab.calib.drift import QUANTITIES

    settings = settings or FitConfig()
    frame = record.data
    present = [q for q in quantities if q in QUANTITIES and _find(frame, q) is not None]
    return {q: to_daily_grid(frame, quantity=q, meta=record.meta, max_gap=settings.max_gap,
                             hampel=settings.hampel, path=record.path) for q in present}


def fit(record, settings: FitConfig | None = None, *, quantities=("bias", "sf"),
        origin_day: int | None = None, progress=None) -> DriftFit:
    """:func:`fit_drift` on a validated ``storage_drift`` record."""
    return fit_drift(record.data, meta=record.meta, settings=settings, quantities=quantities,
                     origin_day=origin_day, path=record.path, progress=progress)


def forecast(model: DriftModel, horizon: int | None = None) -> dict:
    """Forecast every unit and quantity of a saved model ``horizon`` steps past its origin
    (:meth:`~inertialab.calib.drift.DriftModel.forecast`)."""
    return model.forecast(horizon)


def evaluate(record, settings: FitConfig | None = None, *, quantities=("bias", "sf"),
             first: int = 50, step: int = 5, units=None, progress=None) -> dict:
    """Rolling-origin evaluation (spec 004 §5) of every (or the named) unit and quantity of
    a record: ``{unit_id: {quantity: RollingResult}}``. Each series gets its own seed,
    spawned like :func:`fit_drift`'s (sorted units, then bias, sf)."""
    from inertialab.calib.drift_eval import evaluate_rolling_origin

    settings = (settings or EvaluateConfig()).validate()
    progress = progress or NullProgress()
    check_horizon(settings.horizon)
    if int(first) < 10 or int(step) < 1:
        raise InputError(f"argument 'first' must be >= 10 and 'step' >= 1, got {first}, {step}")
    grids = prepare(record, settings=settings, quantities=quantities)
    if not grids:
        raise InputError(f"record has none of the columns {', '.join(quantities)}",
                         path=record.path)
    all_units = sorted(set().union(*[set(g) for g in grids.values()]))
    if units is not None:
        missing = [u for u in units if u not in all_units]
        if missing:
            raise InputError(f"no unit(s) {', '.join(missing)} in the record", path=record.path)
    chosen = all_units if units is None else [u for u in all_units if u in set(units)]
    children = dict(zip(all_units, np.random.SeedSequence(int(settings.seed)).spawn(
        len(all_units))))
    out: dict = {}
    total, done = len(chosen) * len(grids), 0
    for uid in chosen:
        qseeds = dict(zip(("bias", "sf"), children[uid].spawn(2)))
        out[uid] = {}
        for q, g in grids.items():
            if uid in g:
                out[uid][q] = evaluate_rolling_origin(g[uid], settings, first=first, step=step,
                                                      rng=int(qseeds[q].generate_state(1)[0]))
            done += 1
            progress.update(done, total, f"{uid} {q}")
    return out


# ---------------------------------------------------------------------------- apply

#: Output columns of :func:`apply` (units in the names, docs/records.md).
APPLY_STATUS = {0: "forecast used", 1: "on or before the origin: calibrated value used"}


def apply(model: DriftModel, record) -> tuple[pd.DataFrame, dict]:
    """Compensate a later record with the model's forecasts (spec 004 §9 "Compensation").

    For every test of a unit the model holds, the forecast bias b̂ (µg) and scale factor
    k̂ = k_ref (1 + 1e-6 ppm̂) (mA/g) of its programme day (step k = (day - origin) /
    step; on or before the origin the calibrated value at the origin, status 1) give

    * ``bias_residual_ug`` = measured bias - b̂ beside ``bias_residual_uncomp_ug`` =
      measured - calibrated value (what is left without the forecast), and the same for
      the scale factor in ppm of k_ref (``sf_residual_ppm``, ``sf_residual_uncomp_ppm``),
      where the record measured them;
    * ``a_g`` = I / k̂ - b̂ (g) for an output current column ``output_ma`` (mA), and
      ``a_error_ug`` = a_g - ``a_ref_g`` when the known input is given.

    Programme days come from a ``day`` column, else from dates with the sidecar's ``t0``
    or the fitting record's start kept in the model. Returns the output frame and a
    summary ``{unit_id: {quantity: {"rmse_compensated", "rmse_uncompensated", "n"}}}``
    (RMSE through :mod:`inertialab.metrics`).
    """
    import pandas as pd

    from inertialab import metrics

    frame, meta, path = record.data.copy(), dict(record.meta), record.path
    if "day" not in frame.columns:
        t0 = meta.get("t0", model.settings.get("t0"))
        if t0 is None:
            raise InputError("the later record needs programme days: a 'day' column, or "
                             "dates with 't0' in the sidecar (the model keeps no start)",
                             path=path)
        meta["t0"] = t0
    frame["unit_id"] = frame["unit_id"].astype(str)
    unknown = sorted(set(frame["unit_id"]) - set(model.entries))
    if unknown:
        raise InputError(f"unit(s) {', '.join(unknown[:5])} are not in the model "
                         f"(it holds {', '.join(sorted(model.entries)[:5])})", path=path,
                         column="unit_id")
    days = _programme_days(frame, meta, path)
    out = pd.DataFrame({"unit_id": frame["unit_id"].to_numpy(), "day": days.astype(int)})
    status = np.zeros(len(frame), dtype=int)
    hat = {"bias": np.full(len(frame), np.nan), "sf": np.full(len(frame), np.nan)}
    kref = np.full(len(frame), np.nan)
    steps = np.zeros(len(frame), dtype=int)
    for uid, qs in model.entries.items():
        rows = np.flatnonzero(out["unit_id"].to_numpy() == uid)
        if rows.size == 0:
            continue
        for q, e in qs.items():
            k = np.floor((days[rows] - e["origin_day"]) / e["step_days"]).astype(int)
            kmax = int(k.max())
            vals = np.empty(rows.size)
            before = k < 1
            vals[before] = e["y_cal"]
            if kmax >= 1:
                check_horizon(kmax)
                fc = e["nar"].forecast(kmax, intervals=False).values
                vals[~before] = fc[k[~before] - 1]
            hat[q][rows] = vals
            status[rows] = np.maximum(status[rows], before.astype(int))
            steps[rows] = np.maximum(k, 0)
            if q == "sf":
                kref[rows] = e["k_ref"] if e.get("k_ref") is not None else np.nan
    out["forecast_step"] = steps
    out["bias_hat_ug"] = hat["bias"]
    out["sf_hat_ppm"] = hat["sf"]
    out["sf_hat_ma_per_g"] = kref * (1.0 + 1e-6 * hat["sf"])
    summary: dict = {}
    for q, unit in (("bias", "ug"), ("sf", "ppm")):
        col = _find(frame, q)
        if col is None:
            continue
        if q == "bias":
            meas = _bias_ug(frame, col, meta, path, _find(frame, "sf"))
        elif split_suffix(col)[1] in ("ppm", "pct"):
            meas = np.asarray(convert(frame[col].to_numpy(dtype=float),
                                      split_suffix(col)[1], "ppm"), dtype=float)
        else:
            meas = 1e6 * (_sf_ma_per_g(frame, col, meta, path) - kref) / kref
        ycal = np.array([model.entries[u].get(q, {}).get("y_cal", np.nan)
                         for u in out["unit_id"]])
        out[f"{q}_residual_{unit}"] = meas - hat[q]
        out[f"{q}_residual_uncomp_{unit}"] = meas - ycal
        for uid in out["unit_id"].unique():
            m = (out["unit_id"].to_numpy() == uid) & np.isfinite(meas) & np.isfinite(hat[q]) \
                & (status == 0)
            if m.any():
                summary.setdefault(uid, {})[q] = {
                    "rmse_compensated": metrics.rmse(meas[m], hat[q][m]),
                    "rmse_uncompensated": metrics.rmse(meas[m], ycal[m]), "n": int(m.sum()),
                    "unit": unit}
    if "output_ma" in frame.columns:
        _output_current(frame, out, hat["bias"], path)
    out["status"] = status
    return out, summary


def _output_current(frame, out, bias_hat, path) -> None:
    """``a_g`` = I / k̂ - b̂ for the output current ``output_ma`` (and ``a_error_ug``
    against ``a_ref_g``), added to ``out``."""
    import pandas as pd

    hat = {"bias": bias_hat}
    missing = sorted({u for u, b, k in zip(out["unit_id"], hat["bias"],
                                           out["sf_hat_ma_per_g"])
                      if not (np.isfinite(b) and np.isfinite(k))})
    if missing:
        raise InputError(f"output_ma needs both a bias and a scale-factor model (with "
                         f"k_ref); unit(s) {', '.join(missing[:5])} lack one", path=path,
                         column="output_ma")
    i_ma = pd.to_numeric(frame["output_ma"], errors="coerce").to_numpy(dtype=float)
    if not np.all(np.isfinite(i_ma)):
        rows = (np.flatnonzero(~np.isfinite(i_ma))[:5] + 1).tolist()
        raise InputError("output_ma must be a finite number of mA", path=path,
                         column="output_ma", row=rows[0] if len(rows) == 1 else rows)
    a = i_ma / out["sf_hat_ma_per_g"].to_numpy() - 1e-6 * hat["bias"]
    out["a_g"] = a
    if "a_ref_g" in frame.columns:
        out["a_error_ug"] = 1e6 * (a - pd.to_numeric(frame["a_ref_g"], errors="coerce")
                                   .to_numpy(dtype=float))


#: Units of the numeric keys of the drift commands' JSON.
UNITS = {"bias": "ug", "sf": "ppm", "day": "day", "order": "1", "cv_scores": "1",
         "ljung_box_p": "1", "recalibration_day": "day", "tolerance": "ug (bias) | ppm (sf)",
         "k_ref": "mA/g", "skill_vs_persistence": "1"}
#: The forecast horizon check (1 .. 1000 grid steps), for callers that check first.
_QUANTITIES = {"both": ("bias", "sf"), "bias": ("bias",), "sf": ("sf",)}
#: The baselines ``drift evaluate`` compares NAR with (``direct`` adds the direct NAR).
EVALUATED_BASELINES = ("persistence", "window_mean", "ar_ls", "ar_aic", "poly_trend",
                       "kernel_nar")


def _order(o):
    """The NAR order of ``order``: None for ``auto`` (or None), else an integer 1..1000."""
    from inertialab.learn.nar import MAX_ORDER

    if o is None:
        return None
    o = str(o).strip().lower()
    if o == "auto":
        return None
    try:
        p = int(o)
    except ValueError:
        raise InputError(f"argument 'order' must be 'auto' or a positive integer, got "
                         f"'{o}'") from None
    if not 1 <= p <= MAX_ORDER:
        raise InputError(f"argument 'order' must be from 1 to {MAX_ORDER}, got {p}")
    return p


def _hidden_grid(text):
    """The hidden sizes of ``hidden_grid`` (a comma text or a tuple), or None."""
    if text is None:
        return None
    if isinstance(text, (tuple, list)):
        text = ",".join(str(v) for v in text)
    try:
        sizes = tuple(int(v) for v in str(text).replace(" ", "").split(",") if v)
    except ValueError:
        raise InputError(f"argument 'hidden_grid' must be comma-separated integers, got "
                         f"'{text}'") from None
    if not sizes or min(sizes) < 1 or max(sizes) > 200:
        raise InputError(f"argument 'hidden_grid' sizes must be from 1 to 200, got '{text}'")
    return sizes


#: Fields that ``settings`` does not write as declared: the estimator's fixed choices
#: (library only) and, for ``drift evaluate``, the baselines written as the run chose them.
NOT_WRITTEN = ("H", "combine", "split", "n_paths", "recal_quantile", "baselines")


@dataclass(frozen=True)
class _Common(_Settings):
    """The settings both commands share, which the estimator
    (:func:`~inertialab.calib.drift.fit_series`) reads by these names; spec 004 defaults:
    horizon K = 20 steps; ``order`` ``auto`` = kernel CV with H = 6 (spec §3.1 [R-2];
    passed explicitly, so the study does not follow the NAR learner's generic
    ``H="auto"`` default for long series, :func:`inertialab.learn.nar.auto_lag_bound`);
    hidden S = 10 (or chosen from ``hidden_grid`` by validation, §3.2); restarts R = 10;
    preset ``paper`` (best member, random split) or ``strict`` (median, block split).
    Library only: ``H``; ``combine`` and ``split`` (None: the preset's); ``n_paths`` B =
    200 bootstrap paths; ``recal_quantile`` 0.1 (re-calibration at the 10 % quantile of
    the first passage); ``baselines`` (None: :data:`~inertialab.calib.drift.DEFAULT_BASELINES`;
    ``nar_direct`` adds the direct NAR)."""

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
    H: int = setting(6, help="Largest order of the kernel CV.", lo=1, hi=1000, cli=False)
    combine: str | None = setting(None, help="Member combination (default: the preset's).",
                                  cli=False)
    split: str | None = setting(None, help="Validation split (default: the preset's).",
                                cli=False)
    n_paths: int = setting(200, help="Bootstrap forecast paths.", lo=1, hi=100_000, cli=False)
    recal_quantile: float = setting(0.1, help="Quantile of the first passage, in (0, 1].",
                                    lo=0.0, hi=1.0, cli=False)
    baselines: tuple | None = setting(None, help="Baselines (default: calib's).", cli=False)

    @property
    def nar_order(self) -> int | None:
        """``order`` as the NAR takes it: None (kernel CV) or an integer."""
        return _order(self.order)

    @property
    def hidden_sizes(self) -> tuple | None:
        """``hidden_grid`` as a tuple of sizes, or None."""
        return _hidden_grid(self.hidden_grid)

    def tolerance(self, quantity: str) -> float:
        """The re-calibration tolerance of ``quantity`` (µg or ppm; 50 when unset)."""
        v = self.tol_bias_ug if quantity == "bias" else self.tol_sf_ppm
        return 50.0 if v is None else float(v)

    def validate(self):
        """The declared bounds and choices, ``order``, ``hidden_grid`` and the open lower
        bound of ``recal_quantile``; one :class:`InputError` naming the argument."""
        super().validate()
        _order(self.order)
        _hidden_grid(self.hidden_grid)
        if not self.recal_quantile > 0:
            raise InputError(f"argument 'recal_quantile' must be in (0, 1], got "
                             f"{self.recal_quantile}")
        return self

    def written(self, *drop) -> dict:
        """The settings as ``settings`` writes them before the run fills in what it
        decided: every field but :data:`NOT_WRITTEN` and ``drop``."""
        return {k: v for k, v in self.to_dict().items() if k not in NOT_WRITTEN + drop}


@dataclass(frozen=True)
class FitConfig(_Common):
    """Settings of ``drift fit`` and of :func:`fit` / :func:`fit_drift` (one class: each
    field's name is its JSON key in ``settings`` and its flag with ``-``). Tolerances
    None: the sidecar's ``tol_bias_ug``/``tol_sf_ppm``, else 50 µg and 50 ppm
    (docs/drift.md); max_gap 3 steps interpolated; Hampel screen off."""

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
    """Settings of ``drift evaluate`` (rolling origin, spec 004 §5) and of
    :func:`evaluate`; the tolerances (50 µg, 50 ppm) and the Hampel screen (off) are
    library only."""

    unit_id: list[str] | None = setting(None, help="Only this unit_id (repeatable).")
    first: int = setting(50, help="First origin (grid steps).", lo=1, hi=10**6)
    step: int = setting(5, help="Steps between origins.", lo=1, hi=10**6)
    direct: bool = setting(False, help="Add the direct strategy (one net per step; K x R "
                                       "fits per origin).")
    max_gap: int = setting(3, help="Longest gap (steps) interpolated.", lo=0, hi=36_500)
    seed: int = seed_setting("Seed of the restarts.")
    tol_bias_ug: float | None = setting(None, help="Bias tolerance.", unit="ug", lo=1e-9,
                                        hi=1e9, cli=False)
    tol_sf_ppm: float | None = setting(None, help="Scale-factor tolerance.", unit="ppm",
                                       lo=1e-9, hi=1e9, cli=False)
    hampel: bool = setting(False, help="Hampel outlier screen.", cli=False)


def DriftSettings(**settings) -> FitConfig:
    """Deprecated: :class:`FitConfig` (the estimator's settings have the commands' names;
    ``order`` None is ``auto``), for one release."""
    warnings.warn("DriftSettings is deprecated: use inertialab.workflows.drift.FitConfig",
                  DeprecationWarning, stacklevel=2)
    return FitConfig(**settings).validate()


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
    from inertialab.calib.drift import DEFAULT_BASELINES

    c = config.validate()
    grid = c.hidden_sizes
    tb = c.tol_bias_ug if c.tol_bias_ug is not None else float(record.meta.get("tol_bias_ug", 50.0))
    ts = c.tol_sf_ppm if c.tol_sf_ppm is not None else float(record.meta.get("tol_sf_ppm", 50.0))
    base = (c.baselines or DEFAULT_BASELINES) + (("arima",) if c.arima else ())
    c = replace(c, baselines=base, tol_bias_ug=tb, tol_sf_ppm=ts)
    drift_fit = fit(record, c, quantities=_QUANTITIES[c.quantity], origin_day=c.origin_day,
                    progress=progress)
    sett = c.written() | {"hidden_grid": None if grid is None else list(grid)}
    return FitResult(fit=drift_fit, settings=sett, sha256=record.sha256)


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
    c = config.validate()
    grid = c.hidden_sizes
    base = c.baselines or EVALUATED_BASELINES
    base += (("nar_direct",) if c.direct else ())
    c = replace(c, baselines=base)
    res = evaluate(record, c, quantities=_QUANTITIES[c.quantity], first=c.first,
                   step=c.step, units=c.unit_id or None, progress=progress)
    sett = c.written("unit_id", "max_gap", "tol_bias_ug", "tol_sf_ppm", "hampel")
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
    frame, summary = apply(model, record)
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


@dataclass(frozen=True)
class ForecastConfig(_Settings):
    """Settings of ``drift forecast`` and of :func:`run_forecast`: ``horizon``, the steps K
    past the model's origin (1 to :data:`MAX_HORIZON`; None: the horizon the model was
    fitted with)."""

    horizon: int | None = setting(None, help="Steps K, 1 to 1000 (default: the fit's).")

    def validate(self):
        """``horizon`` None or an integer 1..:data:`MAX_HORIZON`; one :class:`InputError`
        naming it."""
        super().validate()
        if self.horizon is not None:
            check_horizon(self.horizon)
        return self


def run_forecast(model, config: ForecastConfig | None = None) -> ForecastResult:
    """Forecast every unit and quantity of a saved model ``config.horizon`` steps (None:
    the fit's). A bare horizon (an int) in place of ``config`` still works for one
    release, with a :class:`DeprecationWarning`."""
    if not isinstance(config, ForecastConfig):
        if config is not None:
            import warnings

            warnings.warn("run_forecast(model, horizon) is deprecated: pass "
                          "ForecastConfig(horizon=...)", DeprecationWarning, stacklevel=2)
        config = ForecastConfig(horizon=config)
    config.validate()
    return ForecastResult(per_unit=forecast(model, config.horizon),
                          settings=config.to_dict() | {"seed": model.settings.get("seed")})
