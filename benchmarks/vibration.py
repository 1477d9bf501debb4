"""Benchmark ``vibration``: spec 001 checks 11-16 and the seed's targets T1-T5.

Runs the default virtual lab (spec 001 §6: fs 200 Hz, P1 = P3 = 1800 s, 1-500 Hz sweep at
1 oct/min plus a 5-s dwell, 500 Hz fixed run, 5 g, preset "mid") for seeds 0-4 through
the default pipeline (level 6, spread 1.2, goal 1e-4, centres "max_error") and reports
every number the checks and targets name. Check 16's time budget (full pipeline on both
default records <= 60 s on 2 cores) is measured once, from writing and reading the CSV
records to the last figure input (whole-record CWT scalogram included).
"""

from __future__ import annotations

import math
import tempfile
import time
import warnings
from pathlib import Path

import numpy as np

SEEDS = (0, 1, 2, 3, 4)
TERMS = ("Q", "N", "B", "K", "R")


def _v(row, k):
    return float(row[k]["value"])


def _ratio(a, b):
    return a / b if (b and math.isfinite(a) and math.isfinite(b) and b != 0) else float("nan")


def _max_finite(*values) -> float:
    """Largest finite value (nan when none): an undefined ratio does not hide the others."""
    finite = [v for v in values if math.isfinite(v)]
    return max(finite) if finite else float("nan")


def _per_seed(seed: int) -> dict:
    from inertialab.studies.vibration import simulate_pair
    from inertialab.workflows.vibration import FitConfig, analyse

    sweep, fixed = simulate_pair(seed)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        res = analyse(sweep, fixed, FitConfig(views=False))
    ph, dec, comp = (res.tables[k] for k in ("phases", "decomposition", "compensation"))
    L = res.level
    out = {"seed": seed, "level_rule": res.level_selection.level,
           "delta_j": {str(j): d for j, d in res.level_selection.delta.items()}}
    # check 13 / T1: per-phase ratios of the fixed run (WLS)
    out["phase_ratio_P2_P1"] = {k: _ratio(_v(ph["fixed/P2"], k), _v(ph["fixed/P1"], k))
                                for k in TERMS}
    out["phase_ratio_P3_P1"] = {k: _ratio(_v(ph["fixed/P3"], k), _v(ph["fixed/P1"], k))
                                for k in TERMS}
    out["phase_ratio_P2_P1_sweep"] = {k: _ratio(_v(ph["sweep/P2"], k), _v(ph["sweep/P1"], k))
                                      for k in TERMS}
    # check 14 / T2: Table-2 analogue ("ols"), both records
    for rec in ("sweep", "fixed"):
        raw = dec[f"{rec}/raw"]
        out[f"t2_{rec}_A_over_raw"] = {k: _ratio(_v(dec[f"{rec}/A{L}"], k), _v(raw, k))
                                       for k in TERMS}
        out[f"t2_{rec}_D_over_raw"] = {k: _ratio(_v(dec[f"{rec}/x-A{L}"], k), _v(raw, k))
                                       for k in TERMS}
        # K read as significant (not an upper bound, absent or unobservable) in raw, A_L
        out[f"t2_{rec}_K_significant"] = {
            name: not ({"upper_bound", "absent", "not_observable"} & set(row["K"]["flags"]))
            for name, row in (("raw", raw), (f"A{L}", dec[f"{rec}/A{L}"]))}
        out[f"t2_{rec}_K_ci"] = {"raw": list(raw["K"]["ci"]),
                                 f"A{L}": list(dec[f"{rec}/A{L}"]["K"]["ci"])}
    # check 15 / T5: Table-3 analogue ("wls", tau >= 2^(L+1) tau0 for A_L rows)
    out["t3_rbf_over_A"] = {k: _ratio(_v(comp["rbf"], k), _v(comp[f"A{L}"], k)) for k in TERMS}
    out["t3_poly_over_A"] = {k: _ratio(_v(comp["poly"], k), _v(comp[f"A{L}"], k)) for k in TERMS}
    out["t3_A_over_raw"] = {k: _ratio(_v(comp[f"A{L}"], k), _v(comp["raw"], k)) for k in TERMS}
    out["t3_rbf_over_poly"] = {k: _ratio(_v(comp["rbf"], k), _v(comp["poly"], k))
                               for k in TERMS}
    out["tables"] = res.tables
    out["residual"] = res.metrics["residual"]
    out["delta_b"] = {"rbf": res.residual_bias_dph["rbf"], "poly": res.residual_bias_dph["poly"],
                      f"A{L}": res.metrics["residual"][f"A{L}"]["delta_b"]}
    out["fit"] = res.fit
    return out


def _timing() -> dict:
    """Check 16: write both default records, read them back, full pipeline with views."""
    from inertialab.io import write_record
    from inertialab.sim.fog_vibration import simulate
    from inertialab.workflows.vibration import FitConfig, analyse, load_run

    with tempfile.TemporaryDirectory() as d:
        paths = {}
        for ex in ("sweep", "fixed"):
            r = simulate(ex, 0)
            paths[ex] = Path(d) / f"{ex}.csv"
            write_record(r.record, paths[ex], r.meta)
        c0, w0 = time.process_time(), time.perf_counter()
        sweep, fixed = load_run(paths["sweep"]), load_run(paths["fixed"])
        c1, w1 = time.process_time(), time.perf_counter()
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            res = analyse(sweep, fixed, FitConfig(views=True))
        c2, w2 = time.process_time(), time.perf_counter()
    return {"read_cpu_s": c1 - c0, "read_wall_s": w1 - w0, "pipeline_cpu_s": c2 - c1,
            "pipeline_wall_s": w2 - w1, "total_cpu_s": c2 - c0, "total_wall_s": w2 - w0,
            "n_samples": {"sweep": sweep.n, "fixed": fixed.n}, "level": res.level,
            "budget_s": 60.0, "includes": "CSV read + validation of both records, phases, "
                                          "Welch, whole-record CWT scalogram, EMD window, "
                                          "db4 J=10, level rule, 18 OADEV + noise-term fits, "
                                          "targets, RBF + polynomial, held-out refits, "
                                          "compensation, metrics"}


def run(quick: bool = False) -> dict:
    seeds = SEEDS[:2] if quick else SEEDS
    per = [_per_seed(s) for s in seeds]
    timing = _timing()
    def med(xs):
        a = np.asarray([np.nan if v is None else v for v in xs], dtype=float)
        return float(np.nanmedian(a)) if np.isfinite(a).any() else float("nan")

    def allk(key, k):
        return [p[key][k] for p in per]

    levels = [p["level_rule"] for p in per]
    checks = {
        "11_auto_level": {
            "levels": levels, "n_six": sum(1 for v in levels if v == 6),
            "pass": sum(1 for v in levels if v == 6) >= min(4, len(per)) and
            all(5 <= v <= 7 for v in levels)},
        "12_rbf_goal": {
            "rbf_mse": [p["fit"]["rbf"]["train_mse"] for p in per],
            "rbf_over_poly_train_rmse": [p["fit"]["rbf"]["train_rmse"] /
                                         p["fit"]["poly"]["train_rmse"] for p in per],
            "heldout_rmse_rbf": [p["fit"]["rbf"]["heldout_rmse"] for p in per],
            "heldout_rmse_poly": [p["fit"]["poly"]["heldout_rmse"] for p in per],
            "truth_rmse_rbf": [p["fit"]["rbf"]["truth_rmse"] for p in per],
            "truth_rmse_poly": [p["fit"]["poly"]["truth_rmse"] for p in per],
            "neurons": [p["fit"]["rbf"]["neurons"] for p in per]},
        "13_phases": {
            "Q_P2_P1": allk("phase_ratio_P2_P1", "Q"), "N_P2_P1": allk("phase_ratio_P2_P1", "N"),
            "B_P2_P1": allk("phase_ratio_P2_P1", "B"), "Q_P3_P1": allk("phase_ratio_P3_P1", "Q"),
            "N_P3_P1": allk("phase_ratio_P3_P1", "N"), "B_P3_P1": allk("phase_ratio_P3_P1", "B")},
        "14_table2_ols": {rec: {
            "QN_A_over_raw": [max(p[f"t2_{rec}_A_over_raw"]["Q"], p[f"t2_{rec}_A_over_raw"]["N"])
                              for p in per],
            "K_A_over_raw": [p[f"t2_{rec}_A_over_raw"]["K"] for p in per],
            # the K ratio is read only where both fits report K as significant: the ratio
            # of two upper bounds says nothing about K (a term the data cannot
            # support is flagged, not compared)
            "K_both_significant": [all(p[f"t2_{rec}_K_significant"].values()) for p in per],
            "K_ci": [p[f"t2_{rec}_K_ci"] for p in per],
            "Q_D_over_raw": [p[f"t2_{rec}_D_over_raw"]["Q"] for p in per],
            "N_D_over_raw": [p[f"t2_{rec}_D_over_raw"]["N"] for p in per],
            "BK_D_over_raw": [_max_finite(p[f"t2_{rec}_D_over_raw"]["B"],
                                          p[f"t2_{rec}_D_over_raw"]["K"]) for p in per],
            # seeds where the raw record's B is reported absent (an upper bound): the B
            # ratio is undefined there and the check reads K alone
            "B_raw_absent": sum(1 for p in per
                                if not math.isfinite(p[f"t2_{rec}_D_over_raw"]["B"]))}
            for rec in ("sweep", "fixed")},
        "15_table3_wls": {
            "K_rbf_over_A": allk("t3_rbf_over_A", "K"), "R_rbf_over_A": allk("t3_rbf_over_A", "R"),
            "abs_delta_b_rbf": [abs(p["delta_b"]["rbf"]) for p in per],
            "abs_delta_b_poly": [abs(p["delta_b"]["poly"]) for p in per]},
    }
    c13 = checks["13_phases"]
    c13["pass"] = (all(v >= 1.2 for v in c13["Q_P2_P1"]) and all(v >= 1.2 for v in c13["N_P2_P1"])
                   and all(v >= 1.5 for v in c13["B_P2_P1"])
                   and all(abs(v - 1) <= 0.05 for v in c13["Q_P3_P1"] + c13["N_P3_P1"])
                   and all(1 / 1.6 <= v <= 1.6 for v in c13["B_P3_P1"]))
    for c in checks["14_table2_ols"].values():
        c["pass"] = {
            "QN_A_le_0.1": all(v <= 0.1 for v in c["QN_A_over_raw"]),
            "K_A_within_30pct": (all(abs(v - 1) <= 0.3 for v, sig in
                                     zip(c["K_A_over_raw"], c["K_both_significant"]) if sig)
                                 if any(c["K_both_significant"]) else None),
            "QN_D_within_10pct": all(abs(v - 1) <= 0.1 for v in c["Q_D_over_raw"] +
                                     c["N_D_over_raw"]),
            "BK_D_le_0.2": all(v <= 0.2 for v in c["BK_D_over_raw"])}
    c15 = checks["15_table3_wls"]
    c15["median_abs_delta_b"] = {"rbf": med(c15["abs_delta_b_rbf"]),
                                 "poly": med(c15["abs_delta_b_poly"])}
    c15["pass"] = (all(v <= 0.5 for v in c15["K_rbf_over_A"]) and
                   all(v <= 0.5 for v in c15["R_rbf_over_A"]) and
                   c15["median_abs_delta_b"]["rbf"] < c15["median_abs_delta_b"]["poly"])
    c12 = checks["12_rbf_goal"]
    c12["pass"] = (all(v <= 1e-4 for v in c12["rbf_mse"]) and
                   all(v <= 1 / 20 for v in c12["rbf_over_poly_train_rmse"]))
    checks["16_time_budget"] = {**timing, "pass": timing["total_wall_s"] <= 60.0}
    # targets T1-T5 (medians over seeds)
    targets = {
        "T1": {"P2_over_P1_median": {k: med(allk("phase_ratio_P2_P1", k)) for k in TERMS},
               "P3_over_P1_median": {k: med(allk("phase_ratio_P3_P1", k)) for k in TERMS},
               "sweep_P2_over_P1_median": {k: med(allk("phase_ratio_P2_P1_sweep", k))
                                           for k in TERMS}},
        "T2": {rec: {"A_over_raw_median": {k: med(allk(f"t2_{rec}_A_over_raw", k))
                                           for k in TERMS},
                     "D_over_raw_median": {k: med(allk(f"t2_{rec}_D_over_raw", k))
                                           for k in TERMS}} for rec in ("sweep", "fixed")},
        "T3": {"heldout_rmse_median": {"rbf": med(c12["heldout_rmse_rbf"]),
                                       "poly": med(c12["heldout_rmse_poly"])},
               "truth_rmse_median": {"rbf": med(c12["truth_rmse_rbf"]),
                                     "poly": med(c12["truth_rmse_poly"])},
               "train_rmse_median": {"rbf": med([p["fit"]["rbf"]["train_rmse"] for p in per]),
                                     "poly": med([p["fit"]["poly"]["train_rmse"] for p in per])}},
        "T4": {"delta_b_median": {k: med([p["delta_b"][k] for p in per]) for k in per[0]["delta_b"]},
               "edge_on_median": {k: med([p["residual"][k]["edge_on"] for p in per])
                                  for k in per[0]["residual"]},
               "edge_off_median": {k: med([p["residual"][k]["edge_off"] for p in per])
                                   for k in per[0]["residual"]},
               "p2_stability_10s_median": {k: med([p["residual"][k]["stability_10s"]["P2"]
                                                   for p in per]) for k in per[0]["residual"]}},
        "T5": {"A_over_raw_median": {k: med(allk("t3_A_over_raw", k)) for k in TERMS},
               "rbf_over_A_median": {k: med(allk("t3_rbf_over_A", k)) for k in TERMS},
               "poly_over_A_median": {k: med(allk("t3_poly_over_A", k)) for k in TERMS},
               "rbf_over_poly_median": {k: med(allk("t3_rbf_over_poly", k)) for k in TERMS}},
    }
    for p in per:
        p.pop("tables")
    return {"seeds": list(seeds), "settings": {
        "virtual_lab": "spec 001 §6 defaults (fs 200 Hz, P1 = P3 = 1800 s, sweep 1-500 Hz at "
                       "1 oct/min + 5 s dwell, fixed 500 Hz for 1800 s, 5 g, preset mid)",
        "pipeline": "level 6, db4 J = 10, spread 1.2, goal 1e-4, centres max_error; phases and "
                    "Table 3 WLS, Table 2 OLS"},
        "checks": checks, "targets": targets, "per_seed": per}


def _fmt(x, nd=3):
    if x is None or (isinstance(x, float) and not math.isfinite(x)):
        return "n/a"
    if isinstance(x, float):
        return f"{x:.{nd}g}"
    return str(x)


def _lst(xs, nd=3):
    return ", ".join(_fmt(float(v), nd) for v in xs)


def _k_note(cc) -> str:
    """What check 14's K part read: the seeds where K is significant in both the raw
    record and A_L, and the intervals where it is not."""
    sig = cc.get("K_both_significant")
    if sig is None or all(sig):
        return ""
    n_not = sum(1 for v in sig if not v)
    his = [f"{_fmt(ci['raw'][1])}/{_fmt(max(v[1] for k, v in ci.items() if k != 'raw'))}"
           for ci, s in zip(cc["K_ci"], sig) if not s]
    return (f"; K is not significant in the raw record or A6 on {n_not} of {len(sig)} seeds "
            f"(upper bounds raw/A6 {', '.join(his)} deg/h/sqrt(h)): its ratio there compares "
            "two upper bounds and is not read")


def _row(d):
    return " / ".join(f"{k} {_fmt(d[k])}" for k in TERMS)


def markdown(result: dict) -> str:
    c = result["checks"]
    t = result["targets"]
    seeds = result["seeds"]
    ok = lambda b: ("cannot be read" if b is None  # noqa: E731
                    else "holds" if b else "**does not hold**")
    c14 = c["14_table2_ols"]
    lines = [
        "## Spec 001: FOG under vibration (db4 multiscale separation, RBF compensation)",
        "",
        f"Virtual lab, seeds {seeds}: {result['settings']['virtual_lab']}. Pipeline: "
        f"{result['settings']['pipeline']}. The seed's numeric tables are missing (images), so "
        "its targets are qualitative; ratios are ours/ours.",
        "",
        "| check | spec 001 §7 | ours (per seed) | verdict |",
        "|---|---|---|---|",
        f"| 11 | auto level L* = 6 in >= 4 of 5 seeds, always 5-7 | "
        f"{_lst(c['11_auto_level']['levels'])} | {ok(c['11_auto_level']['pass'])} |",
        f"| 12 | RBF MSE <= 1e-4, train RMSE <= 1/20 of the polynomial's | MSE "
        f"{_lst(c['12_rbf_goal']['rbf_mse'])}; ratio {_lst(c['12_rbf_goal']['rbf_over_poly_train_rmse'])}"
        f" ({_lst(c['12_rbf_goal']['neurons'])} neurons) | {ok(c['12_rbf_goal']['pass'])} (by "
        "construction) |",
        f"| 12 (info) | held-out RMSE (odd bins train, even test), deg/h | RBF "
        f"{_lst(c['12_rbf_goal']['heldout_rmse_rbf'])}; poly {_lst(c['12_rbf_goal']['heldout_rmse_poly'])}"
        " | reported, not gated |",
        f"| 12 (info) | RMSE against the simulated b_v(f), deg/h | RBF "
        f"{_lst(c['12_rbf_goal']['truth_rmse_rbf'])}; poly {_lst(c['12_rbf_goal']['truth_rmse_poly'])}"
        " | reported |",
        f"| 13 | E2 Q, N P2/P1 >= 1.2, B >= 1.5; P3/P1 Q, N within 5 %, B within x1.6 | Q "
        f"{_lst(c['13_phases']['Q_P2_P1'])}; N {_lst(c['13_phases']['N_P2_P1'])}; B "
        f"{_lst(c['13_phases']['B_P2_P1'])}; P3/P1 Q {_lst(c['13_phases']['Q_P3_P1'])}, N "
        f"{_lst(c['13_phases']['N_P3_P1'])}, B {_lst(c['13_phases']['B_P3_P1'])} | "
        f"{ok(c['13_phases']['pass'])} |",
    ]
    for rec in ("sweep", "fixed"):
        cc = c14[rec]
        p = cc["pass"]
        lines.append(
            f"| 14 ({rec}) | OLS: Q, N of A6 <= 0.1 raw; K of A6 within 30 %; Q, N of x-A6 within "
            f"10 %; B, K of x-A6 <= 0.2 raw | QN(A6)/raw {_lst(cc['QN_A_over_raw'])}; K(A6)/raw "
            f"{_lst(cc['K_A_over_raw'])}; Q(x-A6)/raw {_lst(cc['Q_D_over_raw'])}; N "
            f"{_lst(cc['N_D_over_raw'])}; BK(x-A6)/raw {_lst(cc['BK_D_over_raw'])} | "
            + "; ".join(f"{k} {ok(v)}" for k, v in p.items())
            + _k_note(cc)
            + (f"; the raw record's B is reported absent (an upper bound) on "
               f"{cc['B_raw_absent']} of {len(cc['BK_D_over_raw'])} seeds, where B/raw is "
               "undefined and the B, K part reads K alone"
               if cc.get("B_raw_absent") else "") + " |")
    c15 = c["15_table3_wls"]
    lines += [
        f"| 15 | WLS (A6 rows tau >= 2^7 tau0): K, R after RBF <= 0.5 x A6; median abs(Delta_b) RBF "
        f"< poly | K {_lst(c15['K_rbf_over_A'])}; R {_lst(c15['R_rbf_over_A'])}; abs(Delta_b) RBF "
        f"{_lst(c15['abs_delta_b_rbf'])} vs poly {_lst(c15['abs_delta_b_poly'])} (medians "
        f"{_fmt(c15['median_abs_delta_b']['rbf'])} vs {_fmt(c15['median_abs_delta_b']['poly'])} "
        f"deg/h) | {ok(c15['pass'])} |",
    ]
    c16 = c["16_time_budget"]
    lines += [
        f"| 16 | full pipeline on both default records <= 60 s (2 cores) | "
        f"{_fmt(c16['total_wall_s'])} s wall, {_fmt(c16['total_cpu_s'])} s CPU "
        f"(read {_fmt(c16['read_wall_s'])} s, pipeline {_fmt(c16['pipeline_wall_s'])} s; "
        f"{c16['n_samples']['sweep']} + {c16['n_samples']['fixed']} samples) | "
        f"{ok(c16['pass'])} |",
        "",
        "Seed targets (qualitative, spec 001 §5) beside our medians over the seeds:",
        "",
        "| target | paper (seed) | ours | verdict |",
        "|---|---|---|---|",
    ]
    t1 = t["T1"]
    lines.append(
        "| T1 (Table 1) | in P2 all of Q N B K R clearly larger than P1/P3; P1 ~ P3 for Q N B; K, R "
        f"a bit smaller in P3 | P2/P1 {_row(t1['P2_over_P1_median'])}; P3/P1 "
        f"{_row(t1['P3_over_P1_median'])}; sweep P2/P1 {_row(t1['sweep_P2_over_P1_median'])} | Q, N, "
        "B reproduce; K and R of a single P2 phase are erratic (NNLS often puts them at 0 or "
        "lets them absorb the thermal ramp), as the spec's prototype found |")
    t2s, t2f = t["T2"]["sweep"], t["T2"]["fixed"]
    lines.append(
        "| T2 (Table 2) | A6: much smaller Q, N, R; B, K fall only a little. x-A6: Q, N, R ~ "
        f"unchanged, B, K fall strongly | sweep A6/raw {_row(t2s['A_over_raw_median'])}; "
        f"x-A6/raw {_row(t2s['D_over_raw_median'])}; fixed A6/raw {_row(t2f['A_over_raw_median'])}"
        f"; x-A6/raw {_row(t2f['D_over_raw_median'])} | Q, N and the detail signal reproduce; "
        "**does not reproduce**: R does not drop in A6 (R is a long-tau term, the low-pass keeps "
        "it; spec §9) and B does not drop in A6 (it tends to rise: the low-pass signal's OLS fit "
        "moves the white-noise power of short taus into the flat term) |")
    t3 = t["T3"]
    lines.append(
        "| T3 (Fig. 6) | RBF follows the measured bias curve far more closely than the "
        f"4th-order polynomial | train RMSE RBF {_fmt(t3['train_rmse_median']['rbf'])} vs poly "
        f"{_fmt(t3['train_rmse_median']['poly'])} deg/h; held-out {_fmt(t3['heldout_rmse_median']['rbf'])}"
        f" vs {_fmt(t3['heldout_rmse_median']['poly'])}; vs truth {_fmt(t3['truth_rmse_median']['rbf'])}"
        f" vs {_fmt(t3['truth_rmse_median']['poly'])} | reproduces on the training data (the "
        "seed's claim); on held-out bins the margin shrinks"
        + (" and against the true curve the near-interpolating RBF is **worse** than the "
           "polynomial (it fits the noise; spec §8)" if t3["truth_rmse_median"]["rbf"] >
           t3["truth_rmse_median"]["poly"] else "") + " |")
    t4 = t["T4"]
    lines.append(
        "| T4 (Figs. 7-8) | after denoising an offset remains in P2; RBF compensation removes it "
        "except for fluctuations at the on/off edges | Delta_b "
        + ", ".join(f"{k} {_fmt(v)}" for k, v in t4["delta_b_median"].items())
        + " deg/h; edge on " + ", ".join(f"{k} {_fmt(v)}" for k, v in t4["edge_on_median"].items())
        + "; edge off " + ", ".join(f"{k} {_fmt(v)}" for k, v in t4["edge_off_median"].items())
        + f" deg/h | reproduces: the {_fmt(t4['delta_b_median'][next(k for k in t4['delta_b_median'] if k.startswith('A'))])}"
        f" deg/h offset of the denoised signal drops to {_fmt(t4['delta_b_median']['rbf'])} "
        "deg/h (median; what remains is mostly the fixture's thermal drift, which the sweep "
        "targets do not contain); the edges keep excursions of about 10 deg/h |")
    t5 = t["T5"]
    lines.append(
        "| T5 (Table 3) | denoising lowers Q, N markedly; compensation then lowers B, K, R "
        "markedly; RBF clearly lower than polynomial | A6/raw "
        f"{_row(t5['A_over_raw_median'])}; RBF/A6 {_row(t5['rbf_over_A_median'])}; poly/A6 "
        f"{_row(t5['poly_over_A_median'])}; RBF/poly {_row(t5['rbf_over_poly_median'])} | K, R "
        "and the residual bias reproduce (medians); B falls only a little; N of the A6-derived "
        "rows is read on tau >= 2^7 tau0 (physical range) where the low-pass keeps the white "
        "noise, so it does not fall there (with the paper's OLS over all taus it goes to 0) |")
    lines += ["", "Per-seed numbers, tables and settings: `benchmarks/results/vibration.json`."]
    return "\n".join(lines) + "\n"
