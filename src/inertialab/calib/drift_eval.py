"""Rolling-origin evaluation of the storage-drift forecasts (spec 004 §5), on a
:class:`~inertialab.calib.drift.DailySeries`: refit NAR and the baselines at origins
T = first, first + step, ..., N - K; mean/median/max metrics, win rates and a paired
Wilcoxon signed-rank test of per-origin RMSE.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass, replace

import numpy as np

from inertialab.calib.drift import DailySeries, baselines_of, fit_series
from inertialab.errors import InputError

__all__ = ["RollingResult", "evaluate_rolling_origin"]


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
    step_mae : method -> mean |e_k| over origins for steps k = 1..K (None where no origin
        scored step k): the forecast-error curve per step (the seed's Figs. 6/8)
    step_n : number of origins scored at each step
    """

    origins: tuple
    rmse: dict
    max_ae: dict
    summary: dict
    win_rate: dict
    wilcoxon_p: dict
    orders: tuple
    step_mae: dict = None
    step_n: tuple = ()

    def to_dict(self) -> dict:
        return asdict(self)


def evaluate_rolling_origin(series: DailySeries, settings, *,
                            first: int = 50, step: int = 5, rng=0,
                            refit_order: bool = True) -> RollingResult:
    """Refit NAR and the baselines at origins first, first+step, ..., N-K (spec 004 §5).

    ``settings``: as :func:`~inertialab.calib.drift.fit_series` reads them (the
    workflow's ``EvaluateConfig``). ``refit_order=False`` keeps the order chosen at the
    first origin.
    """
    from scipy.stats import wilcoxon

    K = int(settings.horizon)
    N = series.values.size
    origins = [T for T in range(int(first), N - K + 1, int(step))]
    if not origins:
        raise InputError(f"series of {N} steps too short for origins from {first} with K = {K}")
    seeds = np.random.SeedSequence(int(rng) if not isinstance(rng, np.random.SeedSequence)
                                   else 0).spawn(len(origins))
    names = ["nar", *baselines_of(settings)]
    rm = {n: [] for n in names}
    mx = {n: [] for n in names}
    abs_sum = {n: np.zeros(K) for n in names}
    abs_cnt = {n: np.zeros(K, dtype=int) for n in names}
    orders = []
    order = settings.nar_order
    for T, sd in zip(origins, seeds):
        st = replace(settings, order=order)
        r = fit_series(series, st, origin_day=int(series.day[T - 1]), rng=sd)
        if not refit_order and order is None:
            order = r.order
        orders.append(r.order)
        hm = r.holdout["metrics"] if r.holdout else None
        rm["nar"].append(hm["rmse"] if hm else np.nan)
        mx["nar"].append(hm["max_ae"] if hm else np.nan)
        if r.holdout:
            k = np.asarray(r.holdout["step"]) - 1
            actual = np.asarray(r.holdout["actual"])
            np.add.at(abs_sum["nar"], k, np.asarray(r.holdout["abs_error"]))
            np.add.at(abs_cnt["nar"], k, 1)
        for b in baselines_of(settings):
            e = r.baselines.get(b, {})
            rm[b].append(e.get("rmse", np.nan))
            mx[b].append(e.get("max_ae", np.nan))
            if r.holdout and "value" in e:
                np.add.at(abs_sum[b], k, np.abs(actual - np.asarray(e["value"])[k]))
                np.add.at(abs_cnt[b], k, 1)
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
    curve = {n: [float(a / c) if c else None for a, c in zip(abs_sum[n], abs_cnt[n])]
             for n in names}
    return RollingResult(tuple(origins), {k: list(map(float, v)) for k, v in rm.items()},
                         {k: list(map(float, v)) for k, v in mx.items()}, summary, win, wp,
                         tuple(orders), curve, tuple(int(c) for c in abs_cnt["nar"]))
