"""Report section and figures of the storage-drift study (spec 004).

Figures: fit and residuals, forecast with its 95 % interval beside the holdout and the
simulated truth, residual autocorrelation with its bounds, and the per-unit
re-calibration schedule. Each figure function takes the plain dict of
:meth:`inertialab.calib.drift.SeriesResult.figure_data` (or a list of
schedule rows), so the CLI and the demo draw the same pictures.
"""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt
import numpy as np

from inertialab.io.names import safe_slug
from inertialab.report.section import Figure, Section, Table
from inertialab.studies.base import StudyResult

_LABEL = {"bias": "bias", "sf": "scale factor"}
_UNIT = {"ug": "µg", "ppm": "ppm"}


def _ylabel(d):
    return f"{_LABEL.get(d['quantity'], d['quantity'])} ({_UNIT.get(d['unit'], d['unit'])})"


def fit_figure(d: dict, name: str | None = None) -> Figure:
    """In-sample series, one-step NAR fit and residuals."""
    fig, (ax, ax2) = plt.subplots(2, 1, figsize=(7.5, 5.2), sharex=True,
                                  gridspec_kw={"height_ratios": [2.2, 1]})
    day, v = np.asarray(d["day"]), np.asarray(d["values"], dtype=float)
    ins = day <= d["origin_day"]
    obs = np.asarray(d["observed"]) & ins
    imp = np.asarray(d["imputed"]) & ins
    ax.plot(day[obs], v[obs], ".", ms=4, color="0.3", label="measured")
    if imp.any():
        ax.plot(day[imp], v[imp], "x", ms=4, color="tab:orange", label="imputed")
    if d.get("truth") is not None:
        t = np.asarray(d["truth"], dtype=float)
        ax.plot(day[ins], t[ins], "-", lw=1, color="tab:green", alpha=0.7, label="latent truth")
    fd, fv = np.asarray(d["fitted_day"]), np.asarray(d["fitted"], dtype=float)
    ax.plot(fd, fv, "-", lw=1.2, color="tab:blue", label="NAR one-step (open loop)")
    ax.set_ylabel(_ylabel(d))
    ax.legend(fontsize=8, loc="best")
    ax.set_title(f"unit {d['unit_id']}: {_LABEL.get(d['quantity'])} fit")
    idx = np.searchsorted(day, fd)
    res = v[idx] - fv
    ax2.axhline(0, color="0.5", lw=0.8)
    ax2.plot(fd, res, ".-", ms=3, lw=0.6, color="tab:blue")
    ax2.set_ylabel("residual")
    ax2.set_xlabel("programme day")
    return Figure(fig, f"One-step NAR fit and residuals, {_LABEL.get(d['quantity'])} of "
                       f"unit {d['unit_id']}.", name or f"fit_{d['quantity']}_{safe_slug(d['unit_id'])}")


def forecast_figure(d: dict, name: str | None = None) -> Figure:
    """Closed-loop forecast with 95 % interval, holdout values and truth."""
    fig, ax = plt.subplots(figsize=(7.5, 4.0))
    day, v = np.asarray(d["day"]), np.asarray(d["values"], dtype=float)
    f = d["forecast"]
    lo_day = d["origin_day"] - 30
    show = (day >= lo_day) & (day <= d["origin_day"]) & np.asarray(d["observed"])
    ax.plot(day[show], v[show], ".", ms=4, color="0.3", label="in-sample")
    fday = np.asarray(f["day"])
    ax.fill_between(fday, f["lo95"], f["hi95"], color="tab:blue", alpha=0.2,
                    label="95 % interval")
    ax.plot(fday, f["value"], "-", color="tab:blue", lw=1.5, label="NAR forecast")
    h = d.get("holdout")
    if h:
        ax.plot(h["day"], h["actual"], "o", ms=4, mfc="none", color="k", label="holdout")
        if h.get("truth") is not None:
            ax.plot(h["day"], h["truth"], "-", color="tab:green", lw=1, alpha=0.7,
                    label="latent truth")
    ax.axvline(d["origin_day"] + 0.5, color="0.6", ls=":", lw=1)
    tol = d.get("tolerance")
    if tol:
        for s in (-1, 1):
            ax.axhline(d["y_cal"] + s * tol, color="tab:red", ls="--", lw=0.8)
    if d.get("recalibration_day") is not None:
        ax.axvline(d["recalibration_day"], color="tab:red", lw=1, alpha=0.6,
                   label="re-calibration day")
    ax.set_xlabel("programme day")
    ax.set_ylabel(_ylabel(d))
    ax.legend(fontsize=8, loc="best")
    return Figure(fig, f"20-step closed-loop forecast of the {_LABEL.get(d['quantity'])} of unit "
                       f"{d['unit_id']} with its 95 % bootstrap interval; dashed: the tolerance "
                       "band around the value at the origin.",
                  name or f"forecast_{d['quantity']}_{safe_slug(d['unit_id'])}")


def acf_figure(d: dict, name: str | None = None) -> Figure:
    """Autocorrelation of the one-step residuals with ±1.96/sqrt(Q) bounds."""
    fig, ax = plt.subplots(figsize=(6.0, 3.0))
    acf = np.asarray(d["acf"], dtype=float)
    k = np.arange(1, acf.size + 1)
    ax.vlines(k, 0, acf, color="tab:blue")
    ax.plot(k, acf, "o", ms=3, color="tab:blue")
    if d.get("bound") is not None:
        ax.axhline(d["bound"], color="tab:red", ls="--", lw=0.8)
        ax.axhline(-d["bound"], color="tab:red", ls="--", lw=0.8)
    ax.axhline(0, color="0.5", lw=0.8)
    ax.set_xlabel("lag k (days)")
    ax.set_ylabel("r_k")
    return Figure(fig, f"Residual autocorrelation ({_LABEL.get(d['quantity'])}, unit "
                       f"{d['unit_id']}) with the 95 % bounds (Yue, Li and Sun, NAR modelling of "
                       "quartz-accelerometer storage drift).",
                  name or f"acf_{d['quantity']}_{safe_slug(d['unit_id'])}")


def error_curve_figure(curves: dict, *, unit_id: str, quantity: str, unit: str,
                       n_origins: int | None = None, name: str | None = None) -> Figure:
    """Forecast error per step: mean |e_k| over origins for each method (the seed's
    Figs. 6/8, the per-step curve of Yue, Li and Sun's storage-drift study)."""
    fig, ax = plt.subplots(figsize=(6.5, 3.6))
    for m, v in curves.items():
        arr = np.array([np.nan if x is None else x for x in v], dtype=float)
        k = np.arange(1, arr.size + 1)
        style = {"lw": 2.0, "color": "tab:blue"} if m == "nar" else {"lw": 1.0, "alpha": 0.8}
        ax.plot(k, arr, ".-", label=m, **style)
    ax.set_xlabel("forecast step k")
    ax.set_ylabel(f"mean |error| ({_UNIT.get(unit, unit)})")
    ax.legend(fontsize=7, ncol=2)
    over = f" over {n_origins} origins" if n_origins else ""
    return Figure(fig, f"Forecast error per step{over}, {_LABEL.get(quantity, quantity)} of unit "
                       f"{unit_id}: NAR and baselines.",
                  name or f"error_curve_{quantity}_{safe_slug(unit_id)}")


def schedule_figure(rows: list[dict], name: str = "schedule") -> Figure:
    """Per-unit re-calibration schedule: origin to the recommended day (or horizon end)."""
    units = sorted({r["unit_id"] for r in rows})
    fig, ax = plt.subplots(figsize=(7.0, 0.35 * len(units) + 1.4))
    off = {"bias": -0.15, "sf": 0.15}
    col = {"bias": "tab:blue", "sf": "tab:orange"}
    seen = set()
    for r in rows:
        y = units.index(r["unit_id"]) + off.get(r["quantity"], 0)
        end = r["recalibration_day"] if r["recalibration_day"] is not None else r["horizon_end"]
        lab = None if r["quantity"] in seen else _LABEL.get(r["quantity"])
        seen.add(r["quantity"])
        ax.plot([r["origin_day"], end], [y, y], "-", lw=4, color=col.get(r["quantity"]),
                alpha=0.8, label=lab)
        ax.plot(end, y, ">" if r["recalibration_day"] is None else "|", ms=8,
                color=col.get(r["quantity"]))
    ax.set_yticks(range(len(units)), units)
    ax.set_xlabel("programme day (bar ends at the re-calibration day; > = none within horizon)")
    ax.legend(fontsize=8, loc="best")
    return Figure(fig, "Re-calibration schedule: 10 % quantile of the first passage of the "
                       "bootstrap paths out of the tolerance band.", name)


def section(result: StudyResult) -> Section:
    """The demo's storage-drift section."""
    figs = []
    for d in result.data.get("example", {}).values():
        figs.extend([fit_figure(d), forecast_figure(d), acf_figure(d)])
    if result.data.get("schedule"):
        figs.append(schedule_figure(result.data["schedule"]))
    tables = []
    pp = result.tables.get("paper_preset", {})
    if pp:
        names = sorted({n for q in pp.values() for n in q["median_forecast_rmse"]})
        rows = [[n] + [pp[q]["median_forecast_rmse"].get(n) for q in pp] for n in names]
        tables.append(Table(
            title="Median 20-day forecast RMSE over units (µg / ppm), paper preset",
            columns=["method"] + [f"{q} ({pp[q]['unit_working']})" for q in pp], rows=rows,
            note="NAR (Yue, Li and Sun) and the baselines from the same origin; lower "
                 "is better."))
        tables.append(Table(
            title="Batch figures", columns=["figure"] + list(pp),
            rows=[["CV order (per unit)"] + [" ".join(map(str, pp[q]["orders"])) for q in pp],
                  ["whiteness pass rate"] + [pp[q]["whiteness_pass_rate"] for q in pp],
                  ["95 % coverage (holdout)"] + [pp[q]["coverage95"] for q in pp],
                  ["share exceeding before schedule"] + [pp[q]["recal_exceeded_share"]
                                                         for q in pp]]))
    return Section(key="drift", title=result.title, paragraphs=list(result.text), tables=tables,
                   figures=figs, results=dict(result.tables), settings=dict(result.settings))
