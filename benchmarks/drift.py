"""Spec 004 reproduction: kernel-CV order (A1), NAR benefit on S1 (A6), no spurious
benefit on a linear AR(2) (A7), paper-scale error levels (A8), interval coverage (A13),
plus rolling-origin skill and the re-calibration schedule on the virtual lab.

``run(quick)`` returns JSON-ready numbers with their seeds and settings; ``markdown``
writes the docs/results.md section with the seed paper's figures beside ours.
"""

from __future__ import annotations

import sys
import time
import warnings

import numpy as np

from inertialab.calib.drift import DEFAULT_BASELINES
from inertialab.calib.drift_eval import evaluate_rolling_origin
from inertialab.learn.forecast_baselines import ARLeastSquares, Persistence
from inertialab.learn.nar import SPEC_H, NARForecaster
from inertialab.learn.order_cv import select_order_cv
from inertialab.sim.drift import benchmark_process, mackey_glass, simulate_storage_batch
from inertialab.studies.drift import summarise
from inertialab.workflows.drift import FitConfig, fit_drift, to_daily_grid


def _a1(n_seeds):
    out = {}
    for name, p in (("S1", 2), ("S2", 3)):
        orders = [select_order_cv(benchmark_process(name, 100, s)).order for s in range(n_seeds)]
        out[name] = {"true_order": p, "hits": int(sum(o == p for o in orders)),
                     "seeds": n_seeds, "share": float(np.mean(np.asarray(orders) == p)),
                     "histogram": np.bincount(orders, minlength=7)[1:].tolist()}
    return out


def _nar_vs_linear(proc, n_seeds, split):
    r_nar, r_ar, r_p, o_nar, o_ar = [], [], [], [], []
    for s in range(n_seeds):
        y = benchmark_process(proc, 120, s)
        yi, yh = y[:100], y[100:]
        m = NARForecaster(H=SPEC_H, restarts=10, preset="strict", split=split, rng=s).fit(yi)
        f = m.forecast(20, intervals=False).values
        ar = ARLeastSquares(order=m.order_).fit(yi)
        r_nar.append(np.sqrt(np.mean((f - yh) ** 2)))
        r_ar.append(np.sqrt(np.mean((ar.forecast(20).values - yh) ** 2)))
        r_p.append(np.sqrt(np.mean((Persistence().fit(yi).forecast(20).values - yh) ** 2)))
        lags = np.column_stack([y[100 - k:120 - k] for k in range(1, m.order_ + 1)])
        o_nar.append(np.sqrt(np.mean((m.one_step(lags) - yh) ** 2)))
        o_ar.append(np.sqrt(np.mean((ar.one_step(lags) - yh) ** 2)))
    med = lambda v: float(np.median(v))  # noqa: E731
    return {"process": proc, "seeds": n_seeds, "split": split, "restarts": 10,
            "combine": "median", "median_rmse20": {"nar": med(r_nar), "ar": med(r_ar),
                                                   "persistence": med(r_p)},
            "ratio_vs_ar": med(r_nar) / med(r_ar), "ratio_vs_persistence": med(r_nar) / med(r_p),
            "median_rmse1": {"nar": med(o_nar), "ar": med(o_ar)},
            "ratio_one_step_vs_ar": med(o_nar) / med(o_ar)}


#: NAR settings compared on Mackey-Glass: the spec 004 study's lag bound
#: H = 6 (§3.1 [R-2]) and the learner's generic default H = "auto" (largest bound the
#: spec's m >= 10 H rule allows, :func:`inertialab.learn.nar.auto_lag_bound`); both with
#: S = 10, R = 10, preset paper, order by kernel CV.
MG_NARS = {"nar_spec_H6": {"H": SPEC_H}, "nar_auto_H": {}}


def _mackey_glass(n_origins, n_train=500, horizon=20, step=20):
    """NAR vs AR(6) and persistence on Mackey-Glass (tau = 17, sampled each time unit from
    t = 118): at origins T = 500, 520, ... every model is refitted on the 500 values before
    T and forecasts 20 steps closed loop; RMSE pooled over origins and steps. Also the
    kernel-CV criterion CV(p), p = 1..40, at the first origin (why H = 6 fails)."""
    x = mackey_glass(n_train + step * (n_origins - 1) + horizon)
    origins = [n_train + step * j for j in range(n_origins)]
    errs = {k: [] for k in (*MG_NARS, "ar6", "persistence")}
    orders = {k: [] for k in MG_NARS}
    bounds = {k: [] for k in MG_NARS}
    cpu = {k: 0.0 for k in MG_NARS}
    for T in origins:
        train, truth = x[T - n_train:T], x[T:T + horizon]
        for name, kw in MG_NARS.items():
            c0 = time.process_time()
            m = NARForecaster(rng=T, **kw).fit(train)
            errs[name].append(m.forecast(horizon, intervals=False).values - truth)
            cpu[name] += time.process_time() - c0
            orders[name].append(int(m.order_))
            bounds[name].append(int(m.order_selection_.H))
            print(f"   mackey-glass T={T} {name}: p={m.order_} "
                  f"rmse={np.sqrt(np.mean(errs[name][-1] ** 2)):.4f} "
                  f"cpu={time.process_time() - c0:.0f}s", file=sys.stderr, flush=True)
        errs["ar6"].append(ARLeastSquares(order=6).fit(train).forecast(horizon).values - truth)
        errs["persistence"].append(Persistence().fit(train).forecast(horizon).values - truth)
    cv = select_order_cv(x[origins[0] - n_train:origins[0]], H=40)
    rmse = {k: float(np.sqrt(np.mean(np.square(v)))) for k, v in errs.items()}
    per_origin = {k: [float(np.sqrt(np.mean(np.square(e)))) for e in v] for k, v in errs.items()}
    step_curve = {k: np.sqrt(np.mean(np.square(v), axis=0)).tolist() for k, v in errs.items()}
    return {"series": "Mackey-Glass tau = 17, dt = 0.1 RK4, sampled each time unit, t >= 118",
            "n_train": n_train, "horizon": horizon, "origins": origins,
            "rmse": rmse, "rmse_per_origin": per_origin, "rmse_per_step": step_curve,
            "orders": orders, "lag_bounds": bounds,
            "cpu_s_per_fit": {k: v / n_origins for k, v in cpu.items()},
            "ratio_vs_ar6": {k: rmse[k] / rmse["ar6"] for k in MG_NARS},
            "ratio_vs_persistence": {k: rmse[k] / rmse["persistence"] for k in MG_NARS},
            "settings": {k: {"hidden": 10, "restarts": 10, "preset": "paper",
                             "H": v.get("H", "auto")} for k, v in MG_NARS.items()},
            "kernel_cv_first_origin": {"H": cv.H, "order": cv.order,
                                       "scores": [float(v) for v in cv.scores]},
            "targets": {"vs_ar6": 0.5, "vs_persistence": 0.25}}


def restart_spread(order, origins=(500, 520, 540, 560, 580), n_train=500, horizon=20):
    """Diagnostic (not part of ``run``): 20-step closed-loop RMSE of each of the R = 10
    restarts of a NAR with a fixed ``order`` on Mackey-Glass, and each restart's best
    one-step validation MSE (normalised units), per origin. Shows whether a bad NAR
    forecast is one unlucky initialisation or every restart.
    ``python -c "from benchmarks.drift import restart_spread as r; print(r(5))"``."""
    from inertialab.learn.mlp_lm import forward

    x = mackey_glass(max(origins) + horizon)
    out = {}
    for T in origins:
        train, truth = x[T - n_train:T], x[T:T + horizon]
        m = NARForecaster(order=order, rng=T).fit(train)
        rm, vm = [], []
        for mem in m.members_:
            state, f = m._to_unit(train[-order:])[::-1], []
            for _ in range(horizon):
                v = float(forward(mem.theta, state[None, :], m.hidden_)[0])
                f.append(v)
                state = np.r_[v, state[:-1]]
            rm.append(float(np.sqrt(np.mean((m._from_unit(np.array(f)) - truth) ** 2))))
            vm.append(mem.val_mse)
        out[T] = {"rmse20": rm, "val_mse": vm}
    return out


def _a8(n_units, arima_units):
    batch = simulate_storage_batch(n_units, 100, "paper", rng=np.random.SeedSequence(0))
    st = FitConfig(preset="paper", baselines=DEFAULT_BASELINES, seed=0)
    fit = fit_drift(batch.frame, meta=batch.meta, settings=st, origin_day=79)
    summ = summarise(fit)
    res = {"units": n_units, "preset": "paper", "seed": "SeedSequence(0).spawn(n_units)",
           "in_sample_days": "0-79", "horizon": 20, "restarts": 10, "combine": "best",
           "split": "random", "summary": summ}
    if arima_units:
        sub = batch.frame[batch.frame["unit_id"].isin(sorted(batch.frame["unit_id"].unique())
                                                      [:arima_units])]
        fa = fit_drift(sub, meta=batch.meta, origin_day=79,
                       settings=FitConfig(restarts=10, baselines=("persistence", "ar_ls",
                                                                      "arima"), seed=0))
        med = {}
        for q in ("bias", "sf"):
            rs = [r for _, qq, r in fa.iter() if qq == q and r.holdout]
            med[q] = {n: float(np.median([r.baselines[n]["rmse"] for r in rs
                                          if "rmse" in r.baselines.get(n, {})]))
                      for n in ("persistence", "ar_ls", "arima")}
            med[q]["nar"] = float(np.median([r.holdout["metrics"]["rmse"] for r in rs]))
        res["arima_subset"] = {"units": arima_units, "median_rmse": med}
    # rolling origin on the first two units' bias and scale factor
    ro = {}
    for q in ("bias", "sf"):
        grid = to_daily_grid(batch.frame, quantity=q, meta=batch.meta)
        for uid in sorted(grid)[:2]:
            rr = evaluate_rolling_origin(grid[uid], FitConfig(
                restarts=10, baselines=("persistence", "ar_ls", "exp_ar1")), first=50, step=5,
                rng=0)
            ro[f"{uid}/{q}"] = {"origins": list(rr.origins), "summary": rr.summary,
                                "win_rate": rr.win_rate, "wilcoxon_p": rr.wilcoxon_p}
    res["rolling_origin"] = ro
    return res


def _a13(n_units):
    batch = simulate_storage_batch(n_units, 100, "nav", rng=np.random.SeedSequence(0))
    st = FitConfig(preset="strict", baselines=("persistence",), seed=0)
    fit = fit_drift(batch.frame, meta=batch.meta, settings=st, origin_day=79)
    cov, cov_truth, exc, rec_len = [], [], [], []
    for _, _, r in fit.iter():
        if not r.holdout:
            continue
        c = np.asarray(r.holdout["covered"])
        ok = ~np.asarray(r.holdout.get("outlier_true", [False] * c.size))
        cov.extend(c[ok].tolist())
        steps = np.asarray(r.holdout["step"]) - 1
        t = np.asarray(r.holdout["truth"])
        lo, hi = np.asarray(r.forecast["lo95"])[steps], np.asarray(r.forecast["hi95"])[steps]
        cov_truth.extend(((t >= lo) & (t <= hi)).tolist())
        if r.exceeded_before_schedule is not None:
            exc.append(r.exceeded_before_schedule)
        rec_len.append((r.recalibration_day - r.origin_day) if r.recalibration_day is not None
                       else None)
    none_share = float(np.mean([x is None for x in rec_len]))
    lens = [x for x in rec_len if x is not None]
    return {"units": n_units, "preset": "nav", "nar_preset": "strict", "seed": 0,
            "coverage_observed": float(np.mean(cov)), "pairs": len(cov),
            "coverage_truth": float(np.mean(cov_truth)),
            "recal_exceeded_share": float(np.mean(exc)) if exc else None,
            "recal_mean_interval_days": float(np.mean(lens)) if lens else None,
            "recal_none_within_horizon_share": none_share,
            "tolerances": {"bias_ug": 50, "sf_ppm": 50}}


def run(quick: bool = False) -> dict:
    t0 = time.perf_counter()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        out = {"quick": quick}
        out["A1"] = _a1(30 if quick else 100)
        n = 10 if quick else 50
        out["A6"] = {"block": _nar_vs_linear("S1", n, "block")}
        if not quick:
            out["A6"]["random"] = _nar_vs_linear("S1", n, "random")
        out["A7"] = _nar_vs_linear("AR2", n, "block")
        out["A8"] = _a8(6 if quick else 20, 0 if quick else 4)
        out["A13"] = _a13(6 if quick else 20)
        out["mackey_glass"] = _mackey_glass(2 if quick else 6)
    out["wall_s"] = time.perf_counter() - t0
    return out


def _f(x, fmt=".3g"):
    return "–" if x is None else format(x, fmt)


def markdown(r: dict) -> str:
    a1, a6, a7, a8, a13 = r["A1"], r["A6"], r["A7"], r["A8"], r["A13"]
    sb, ss = a8["summary"]["bias"], a8["summary"]["sf"]
    L = ["## Storage drift: NAR forecasting (spec 004)", ""]
    L.append("Seed: Yue, Li & Sun (2016), one quartz accelerometer tested daily for 100 days; "
             "kernel-CV order, MATLAB narnet trained open loop with trainlm, 20-day closed-loop "
             "forecast. Ours: the same method on the virtual lab (`paper` preset, "
             f"{a8['units']} units, "
             "in-sample days 0-79) and on benchmark processes of known order.")
    L.append("")
    L.append("| figure | seed paper | ours | check |")
    L.append("|---|---|---|---|")
    L.append(f"| CV order, bias | p = 2 | per-unit orders {sb['orders']} (mode {sb['order_mode']}) "
             "| not reproduced: on the paper preset the criterion mostly picks p = 1 |")
    L.append(f"| CV order, scale factor | p = 3 | {ss['orders']} (mode {ss['order_mode']}) | "
             "not reproduced (see above) |")
    L.append(f"| bias fit MaxAE (median over units) | ≈ 2e-4 (g) | {_f(sb['median_fit_max_ae_native'])} g "
             "| A8: in [1e-4, 3e-4] |")
    L.append(f"| bias 20-day forecast MaxAE | ≈ 2e-4 (g) | {_f(sb['median_forecast_max_ae_native'])} g "
             "| A8: in [1e-4, 3e-4] |")
    L.append(f"| SF fit MaxAE | ≈ 1e-4 (mA/g) | {_f(ss['median_fit_max_ae_native'])} mA/g "
             "| A8: in [0.5e-4, 1.5e-4] |")
    L.append(f"| SF 20-day forecast MaxAE | ≈ 1e-4 (mA/g) | "
             f"{_f(ss['median_forecast_max_ae_native'])} mA/g | A8: in [0.5e-4, 1.5e-4] |")
    L.append("")
    L.append("The seed gives no units; g and mA/g are the spec's reading [R-8]. The A8 bands "
             "test that we are at the seed's scale, not below it.")
    L.append("")
    L.append("**Does the NAR beat simpler forecasts?** Median 20-day RMSE over units "
             "(paper preset; bias µg, scale factor ppm):")
    L.append("")
    names = list(sb["median_forecast_rmse"])
    L.append("| method | bias | scale factor |")
    L.append("|---|---|---|")
    for n in names:
        L.append(f"| {n} | {_f(sb['median_forecast_rmse'].get(n))} | "
                 f"{_f(ss['median_forecast_rmse'].get(n))} |")
    L.append("")
    L.append(f"Median skill vs persistence: bias {_f(sb['median_skill_vs_persistence'], '+.2f')}, "
             f"scale factor {_f(ss['median_skill_vs_persistence'], '+.2f')}. On this preset the "
             "day-to-day scatter dominates and the NAR does not beat AR or persistence "
             "consistently (spec A8 expects no benefit; report only).")
    if "arima_subset" in a8:
        m = a8["arima_subset"]["median_rmse"]
        L.append("")
        L.append(f"ARIMA by AIC (first {a8['arima_subset']['units']} units only; the 24-model "
                 "grid is slow): median RMSE bias " + ", ".join(
                     f"{k} {_f(v)}" for k, v in m["bias"].items()) + "; scale factor " +
                 ", ".join(f"{k} {_f(v)}" for k, v in m["sf"].items()) + ".")
    if a8.get("rolling_origin"):
        L.append("")
        L.append("Rolling origin (T = 50, 55, ..., 80; refit at each origin): NAR win rate and "
                 "paired Wilcoxon p vs persistence / AR(p̂):")
        L.append("")
        L.append("| series | origins | win vs persistence | p | win vs AR | p |")
        L.append("|---|---|---|---|---|---|")
        for k, v in a8["rolling_origin"].items():
            L.append(f"| {k} | {len(v['origins'])} | {_f(v['win_rate'].get('persistence'), '.2f')} | "
                     f"{_f(v['wilcoxon_p'].get('persistence'), '.2f')} | "
                     f"{_f(v['win_rate'].get('ar_ls'), '.2f')} | "
                     f"{_f(v['wilcoxon_p'].get('ar_ls'), '.2f')} |")
    L.append("")
    L.append("**Benchmarks of known order** (spec §7.3, §8):")
    L.append("")
    L.append("| check | criterion | ours |")
    L.append("|---|---|---|")
    L.append(f"| A1 S1 NLAR(2): p̂ = 2 | ≥ 85 % | {a1['S1']['hits']}/{a1['S1']['seeds']} "
             f"(histogram p = 1..6: {a1['S1']['histogram']}) |")
    L.append(f"| A1 S2 NAR(3): p̂ = 3 | ≥ 70 % | {a1['S2']['hits']}/{a1['S2']['seeds']} "
             f"({a1['S2']['histogram']}) |")
    for split, v in a6.items():
        L.append(f"| A6 S1, NAR / AR(p̂) 20-step RMSE ({split} split) | ≤ 0.8 | "
                 f"{_f(v['ratio_vs_ar'])} |")
        L.append(f"| A6 S1, NAR / persistence ({split} split) | ≤ 0.8 | "
                 f"{_f(v['ratio_vs_persistence'])} |")
    L.append(f"| A7 linear AR(2), NAR / AR 20-step | ≤ 1.1 | {_f(a7['ratio_vs_ar'])} |")
    L.append(f"| A7 linear AR(2), NAR / AR one-step | ≤ 1.1 | {_f(a7['ratio_one_step_vs_ar'])} |")
    L.append(f"| A13 nav, 95 % interval coverage of observed holdout | 0.85-0.99 | "
             f"{_f(a13['coverage_observed'])} ({a13['pairs']} pairs; vs latent truth "
             f"{_f(a13['coverage_truth'])}) |")
    L.append(f"| §9 nav units leaving ±50 µg/ppm before their re-calibration day | ≤ 0.10 | "
             f"{_f(a13['recal_exceeded_share'])} (mean interval "
             f"{_f(a13['recal_mean_interval_days'])} days; none within horizon: "
             f"{_f(a13['recal_none_within_horizon_share'], '.2f')}) |")
    if "mackey_glass" in r:
        mg = r["mackey_glass"]
        L.append("")
        L.append(f"**The NAR as a learner**: {mg['series']}; "
                 f"{mg['n_train']} training values before each of {len(mg['origins'])} origins "
                 f"(T = {mg['origins'][0]}, {mg['origins'][1]}, ...), refit at each, "
                 f"{mg['horizon']}-step closed-loop forecast; RMSE pooled over origins and "
                 "steps. Target: NAR ≤ 0.5 × AR(6) and ≤ 0.25 × persistence.")
        L.append("")
        L.append("| model | lag bound H | orders chosen | 20-step RMSE | / AR(6) | / persistence "
                 "| CPU s per fit |")
        L.append("|---|---|---|---|---|---|---|")
        for k in MG_NARS:
            L.append(f"| {k} | {sorted(set(mg['lag_bounds'][k]))} | "
                     f"{sorted(set(mg['orders'][k]))} | {_f(mg['rmse'][k])} | "
                     f"{_f(mg['ratio_vs_ar6'][k], '.2g')} | "
                     f"{_f(mg['ratio_vs_persistence'][k], '.2g')} | "
                     f"{_f(mg['cpu_s_per_fit'][k], '.1f')} |")
        L.append(f"| AR(6) least squares | – | 6 | {_f(mg['rmse']['ar6'])} | 1 | "
                 f"{_f(mg['rmse']['ar6'] / mg['rmse']['persistence'], '.3f')} | – |")
        L.append(f"| persistence | – | – | {_f(mg['rmse']['persistence'])} | – | 1 | – |")
        cv = mg.get("kernel_cv_first_origin")
        L.append("")
        if cv:
            sc = cv["scores"]
            L.append(f"Why H = 6 fails: the kernel-CV criterion at T = {mg['origins'][0]} has a "
                     f"local minimum at p = 5 (CV {sc[4]:.4f}, rising to {max(sc[5:9]):.4f} "
                     f"by p = 9) and its global minimum over 1..{cv['H']} at p = {cv['order']} "
                     f"(CV {sc[cv['order'] - 1]:.4f}), beyond the 17-unit delay. The spec's "
                     "bound H = 6 [R-2] stops the search at the local minimum; five "
                     "consecutive samples of this smooth delay system do not fix its "
                     "state, so every restart's closed loop drifts although its one-step "
                     "validation error is tiny. The learner's generic default H = \"auto\" "
                     "takes the largest bound the spec's own rule m >= 10 H allows (40 "
                     "here); the spec 004 study keeps H = 6.")
    return "\n".join(L) + "\n"
