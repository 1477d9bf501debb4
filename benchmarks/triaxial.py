"""Benchmark ``triaxial``: spec 002 §7.2 reproductions on the virtual lab.

* ACS vs CS: generations to J <= 1e-10 over 30 seeds (0..29, common initial populations)
  on ``sphere100-clean`` and ``sphere1000-clean`` with objective S9 (§3.9 protocol),
  paired one-sided Wilcoxon signed-rank test; the noisy 1000-point set with the LM optimum
  as target; PSO (standard, N = 10, constant w = 0.729 / c = 1.49) failure rates.
* LM timing for 1000 records (S9 and norm), median over repetitions.
* ``line5000``: vectorised batch GN time, agreement with per-unit scipy LM, yield.
* ``turntable62-realistic``: eq.-21 RMSE/SD of ACS-S12, LM-S12, LM-S9, LM-norm and the
  six-position "laboratory" baseline, beside the paper's 0.1103/0.0643 -> 0.0826/0.0487.
* ``sixface``: classic 6- and 12-parameter six-position vs LM-S9 (E3).
"""

from __future__ import annotations

import os
import time

import numpy as np
from scipy.stats import wilcoxon

from inertialab.metrics import vector_error
from inertialab.optim.base import Target
from inertialab.optim.cuckoo import adaptive_cuckoo_search, cuckoo_search
from inertialab.optim.pso import pso
from inertialab.regress.nlls import levenberg_marquardt
from inertialab.sensors import triaxial as tx
from inertialab.sim import triaxial_poses as tp
from inertialab.workflows import triaxial as fc

PAPER = {"acs_vs_cs_100_pct": -22.0, "acs_vs_cs_1000_pct": -16.0, "cs_100": 636, "acs_100": 496,
         "cs_1000": 750, "acs_1000": 630, "rmse_lab": 0.1103, "rmse_acs": 0.0826,
         "sd_lab": 0.0643, "sd_acs": 0.0487}


def _stats(gens):
    ok = np.array([g for g in gens if g is not None], dtype=float)
    if ok.size == 0:
        return {"mean": None, "sd": None, "median": None, "iqr": None, "min": None, "max": None,
                "failures": len(gens)}
    q1, q3 = np.percentile(ok, [25, 75])
    return {"mean": float(ok.mean()), "sd": float(ok.std(ddof=1)) if ok.size > 1 else None,
            "median": float(np.median(ok)), "iqr": float(q3 - q1), "min": float(ok.min()),
            "max": float(ok.max()), "failures": int(len(gens) - ok.size)}


def _race(a, ref, x_true, seeds, *, J_star=0.0, methods=("cs", "acs", "pso"), pso_kw=None):
    f = lambda X: tx.objective_many(X, a, objective="scalar", ref=ref)  # noqa: E731
    box = tx.search_box("scalar")
    fns = {"cs": cuckoo_search, "acs": adaptive_cuckoo_search, "pso": pso}
    out = {m: {"generations": [], "nfev": [], "wall_s": [], "x_err": []} for m in methods}
    for s in seeds:
        for m in methods:
            kw = dict(pso_kw or {}) if m == "pso" else {}
            t0 = time.perf_counter()
            r = fns[m](f, box, rng=s, vectorized=True, target=Target(J_star), **kw)
            wall = time.perf_counter() - t0
            err = float(np.max(np.abs(r.x - x_true)))
            fail = (not r.success) or (J_star == 0.0 and err > 1e-3)
            out[m]["generations"].append(None if fail else int(r.converged_at))
            out[m]["nfev"].append(int(r.nfev))
            out[m]["wall_s"].append(wall)
            out[m]["x_err"].append(err)
    summary = {}
    for m, d in out.items():
        summary[m] = {**_stats(d["generations"]), "mean_wall_s": float(np.mean(d["wall_s"])),
                      "max_x_err": float(np.max(d["x_err"])), "generations": d["generations"],
                      "mean_nfev": float(np.mean(d["nfev"]))}
    if "cs" in out and "acs" in out:
        pairs = [(c, a_) for c, a_ in zip(out["cs"]["generations"], out["acs"]["generations"])
                 if c is not None and a_ is not None]
        if len(pairs) >= 5:
            c, a_ = np.array(pairs, dtype=float).T
            p = float(wilcoxon(a_, c, alternative="less").pvalue)
            summary["acs_vs_cs"] = {"reduction_pct": float(100 * (1 - a_.mean() / c.mean())),
                                    "wilcoxon_p_one_sided": p, "pairs": len(pairs)}
    return summary


def _ablation(seeds):
    """ACS parts (spec 002 §7.2, informative): omega1 only, delta only, and the textbook mask."""
    a, ref, xt = _sphere("sphere100-clean")
    f = lambda X: tx.objective_many(X, a, objective="scalar", ref=ref)  # noqa: E731
    box = tx.search_box("scalar")
    configs = {
        "CS": (cuckoo_search, {}),
        "ACS (omega1 and delta)": (adaptive_cuckoo_search, {}),
        "ACS omega1 only (delta_min = 1)": (adaptive_cuckoo_search, {"delta_min": 1.0}),
        "ACS delta only (omega_min = 1)": (adaptive_cuckoo_search, {"omega_min": 1.0}),
        "CS textbook mask, Pa = 0.25": (cuckoo_search, {"mask": "textbook"}),
        "CS textbook mask, Pa = 0.1": (cuckoo_search, {"mask": "textbook", "pa": 0.1}),
    }
    out = {}
    for name, (fn, kw) in configs.items():
        gens = []
        for s in seeds:
            r = fn(f, box, rng=s, vectorized=True, target=Target(0.0), **kw)
            ok = r.success and np.max(np.abs(r.x - xt)) <= 1e-3
            gens.append(int(r.converged_at) if ok else None)
        out[name] = _stats(gens)
    return out


def _sphere(name, seed=0):
    rec = tp.simulate_static(name, seed=seed)
    sd = fc.static_data_from_frame(rec.data, rec.meta)
    return sd.a, sd.ref, rec.truth["x"]


def _lm_timing(reps):
    a, ref, _ = _sphere("sphere1000-noisy", 0)
    out = {}
    for obj in ("scalar", "norm"):
        walls, nfev = [], 0
        for _ in range(reps):
            t0 = time.perf_counter()
            res = levenberg_marquardt(lambda x, obj=obj: tx.residuals(x, a, objective=obj, ref=ref), tx.X0,
                                      jac=lambda x, obj=obj: tx.jacobian(x, a, objective=obj, ref=ref))
            walls.append(time.perf_counter() - t0)
            nfev = res.nfev
        out[obj] = {"median_ms": 1e3 * float(np.median(walls)), "nfev": int(nfev), "reps": reps}
    return out


def _batch(n_units, check_every):
    rec = tp.simulate_line(n_units, seed=0)
    sd = fc.static_data_from_frame(rec.data, rec.meta)
    t0 = time.process_time()
    b = fc.calibrate_batch(sd)
    cpu = time.process_time() - t0
    A = sd.a.reshape(n_units, 18, 3)
    R = sd.ref.reshape(n_units, 18, 3)
    diffs = []
    for u in range(0, n_units, check_every):
        res = levenberg_marquardt(lambda x, u=u: tx.residuals(x, A[u], objective="scalar", ref=R[u]),
                                  tx.X0, jac=lambda x, u=u: tx.jacobian(x, A[u], objective="scalar",
                                                                      ref=R[u]))
        diffs.append(float(np.max(np.abs(res.x - b.X[u]))))
    rmse = b.table["rmse_mps2"].to_numpy()
    return {"units": n_units, "wall_s": b.wall_s, "cpu_s": cpu, "checked_units": len(diffs),
            "max_abs_diff_vs_scipy_lm": float(np.max(diffs)),
            "yield_fraction": b.yield_fraction, "rmse_median_mps2": float(np.median(rmse)),
            "rmse_p95_mps2": float(np.percentile(rmse, 95)),
            "max_abs_param_error": float(np.max(np.abs(b.X - rec.truth["X"]))),
            "converged_fraction": float(b.table["converged"].mean())}


def _stream(n_units: int, chunk: int = 10_000, solver_chunk: int = 2048) -> dict:
    """Fleet streaming: ``n_units`` made ``chunk`` at a time by the line
    simulator and calibrated by :func:`iter_calibrate_batch`; peak traced memory (numpy
    allocations, tracemalloc) and CPU. The peak is set by the chunks, not by the fleet."""
    import tracemalloc

    from inertialab.calib.triaxial_batch import iter_calibrate_batch

    def chunks():
        for i in range(0, n_units, chunk):
            k = min(chunk, n_units - i)
            rec = tp.simulate_line(k, seed=1000 + i)
            sd = fc.static_data_from_frame(rec.data, rec.meta)
            yield np.arange(i, i + k), sd.a.reshape(k, 18, 3), sd.ref.reshape(k, 18, 3)

    tracemalloc.start()
    t0 = time.process_time()
    n = passed = 0
    for table in iter_calibrate_batch(chunks(), chunk_units=solver_chunk):
        n += len(table)
        passed += int(table["pass"].sum())
    cpu = time.process_time() - t0
    peak = tracemalloc.get_traced_memory()[1]
    tracemalloc.stop()
    return {"units": n, "input_chunk": chunk, "solver_chunk": solver_chunk,
            "peak_traced_mb": peak / 1e6, "cpu_s_incl_simulation": cpu,
            "yield_fraction": passed / n}


def _turntable(seeds, max_generations):
    """Eq.-21 RMSE/SD of every method against the same sensor-frame truth,
    and, for the record, in each fit's own frame (S12 against references turned by its own
    fitted phi, the others against unturned references: the unfair scoring of before)."""
    from inertialab.studies.triaxial import _eq21, eq21_sensor_frame, sensor_frame_truth

    rows = {k: {"rmse": [], "sd": [], "rmse_own": [], "sd_own": [], "x_err": []} for k in
            ("ACS-S12", "LM-S12", "LM-S9", "LM-norm", "lab six-position (12 par.)",
             "lab six-position (6 par.)")}
    for s in seeds:
        rec = tp.simulate("turntable62-realistic", seed=s)
        sd = fc.static_data_from_frame(rec.data, rec.meta)
        truth = sensor_frame_truth(rec)
        fits = {
            "ACS-S12": fc.calibrate(sd.a, ref=sd.ref, method="acs", objective="scalar12", g=sd.g,
                                    rng=s, max_generations=max_generations),
            "LM-S12": fc.calibrate(sd.a, ref=sd.ref, objective="scalar12", g=sd.g),
            "LM-S9": fc.calibrate(sd.a, ref=sd.ref, objective="scalar", g=sd.g),
            "LM-norm": fc.calibrate(sd.a, objective="norm", g=sd.g),
            "lab six-position (12 par.)": fc.calibrate(sd.a, ref=sd.ref, refine_faces=False,
                                                       method="six-position", g=sd.g),
        }
        six = fits["lab six-position (12 par.)"]
        x6 = np.array(six.extra["x_6param"])
        for k, f in fits.items():
            ve = eq21_sensor_frame(f, sd.a, truth)
            own = _eq21(f, sd.a, sd.ref, f.phi)
            for key, v in (("rmse", ve.rmse), ("sd", ve.sd), ("rmse_own", own.rmse),
                           ("sd_own", own.sd)):
                rows[k][key].append(v)
            rows[k]["x_err"].append(float(np.max(np.abs(f.x - rec.truth["x"]))))
        ve6 = vector_error(truth, tx.correct(x6, sd.a))
        own6 = vector_error(sd.ref, tx.correct(x6, sd.a))
        for key, v in (("rmse", ve6.rmse), ("sd", ve6.sd), ("rmse_own", own6.rmse),
                       ("sd_own", own6.sd)):
            rows["lab six-position (6 par.)"][key].append(v)
        rows["lab six-position (6 par.)"]["x_err"].append(float(np.max(np.abs(x6 - rec.truth["x"]))))
    return {k: {"rmse_mean": float(np.mean(v["rmse"])), "rmse_sd": float(np.std(v["rmse"], ddof=1))
                if len(v["rmse"]) > 1 else None, "sd_mean": float(np.mean(v["sd"])),
                "rmse_own_frame_mean": float(np.mean(v["rmse_own"])),
                "sd_own_frame_mean": float(np.mean(v["sd_own"])),
                "max_param_error_mean": float(np.mean(v["x_err"])), "seeds": list(seeds),
                "scoring": "sensor-frame truth"} for k, v in rows.items()}


def _sixface(seeds):
    out = {k: [] for k in ("six-position 6 par.", "six-position 12 par.", "LM-S9")}
    for s in seeds:
        rec = tp.simulate("sixface", seed=s)
        sd = fc.static_data_from_frame(rec.data, rec.meta)
        six = fc.calibrate(sd.a, ref=sd.ref, refine_faces=False, method="six-position", g=sd.g)
        s9 = fc.calibrate(sd.a, ref=sd.ref, objective="scalar", g=sd.g)
        xt = rec.truth["x"]
        out["six-position 6 par."].append(float(np.max(np.abs(np.array(six.extra["x_6param"]) - xt))))
        out["six-position 12 par."].append(float(np.max(np.abs(six.x - xt))))
        out["LM-S9"].append(float(np.max(np.abs(s9.x - xt))))
    return {k: {"mean_max_param_error": float(np.mean(v)), "sd": float(np.std(v, ddof=1))}
            for k, v in out.items()}


def run(quick: bool = False) -> dict:
    n_seeds = 5 if quick else 30
    seeds = list(range(n_seeds))
    t_all = time.perf_counter()
    res = {"settings": {"seeds": seeds, "objective": "S9", "pop_size": 25, "max_generations": 1000,
                        "target": "J <= J* + 1e-10 + 1e-6 J*", "dataset_seed": 0,
                        "blas_threads_env": {k: os.environ.get(k) for k in
                                             ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS",
                                              "MKL_NUM_THREADS")}},
           "paper": PAPER}
    a, ref, xt = _sphere("sphere100-clean")
    res["sphere100"] = _race(a, ref, xt, seeds)
    a, ref, xt = _sphere("sphere1000-clean")
    res["sphere1000"] = _race(a, ref, xt, seeds)
    a, ref, xt = _sphere("sphere1000-noisy")
    J_star = fc.calibrate(a, ref=ref, objective="scalar").J
    res["sphere1000_noisy"] = _race(a, ref, xt, seeds, J_star=J_star, methods=("cs", "acs"))
    res["sphere1000_noisy"]["J_star"] = J_star
    a, ref, xt = _sphere("sphere100-clean")
    res["pso_sensitivity"] = {
        "N10": _race(a, ref, xt, seeds, methods=("pso",), pso_kw={"pop_size": 10})["pso"],
        "constant_w0.729_c1.49": _race(a, ref, xt, seeds, methods=("pso",),
                                       pso_kw={"w": 0.729, "c1": 1.49, "c2": 1.49})["pso"],
    }
    res["ablation_sphere100"] = _ablation(range(3 if quick else 10))
    res["lm_timing_1000"] = _lm_timing(5 if quick else 21)
    res["batch_line5000"] = _batch(500 if quick else 5000, 25 if quick else 50)
    res["batch_stream"] = _stream(20_000 if quick else 200_000)
    res["turntable62_realistic"] = _turntable(range(3 if quick else 10), 1000)
    res["turntable_remeasured"] = None
    res["sixface"] = _sixface(range(5 if quick else 30))
    res["wall_s"] = time.perf_counter() - t_all
    return res


def _f(v, fmt=".1f"):
    return "–" if v is None else format(v, fmt)


def markdown(r: dict) -> str:
    s = r["settings"]
    L = ["## Study 002 — triaxial accelerometer calibration (CS/ACS/PSO, LM, batch)", ""]
    L.append(f"Virtual MPU6050-A (spec §6.1); objective S9, N = 25, T_max = 1000, target "
             f"J <= J* + 1e-10 + 1e-6·J*; {len(s['seeds'])} seeds with common initial "
             "populations (spec §3.9). Generation = Lévy + abandonment phase for CS/ACS "
             "(2N evaluations), N evaluations for PSO.")
    L.append("")
    L.append("| data set | CS mean gen. | ACS mean gen. | ACS vs CS | Wilcoxon p (one-sided) | "
             "PSO mean gen. (failures) | paper |")
    L.append("|---|---|---|---|---|---|---|")
    for key, label, paper in (("sphere100", "sphere100-clean", "CS ≈ 636 → ACS ≈ 496 (−22 %)"),
                              ("sphere1000", "sphere1000-clean", "CS ≈ 750 → ACS ≈ 630 (−16 %)"),
                              ("sphere1000_noisy", "sphere1000-noisy (target: LM optimum)", "–")):
        d = r[key]
        cmp_ = d.get("acs_vs_cs", {})
        p = d.get("pso")
        pso_txt = "not run" if p is None else f"{_f(p['mean'])} ({p['failures']})"
        L.append(f"| {label} | {_f(d['cs']['mean'])} ± {_f(d['cs']['sd'])} "
                 f"({d['cs']['failures']} fail) | {_f(d['acs']['mean'])} ± {_f(d['acs']['sd'])} "
                 f"({d['acs']['failures']} fail) | {_f(-cmp_.get('reduction_pct', float('nan')))} % "
                 f"| {_f(cmp_.get('wilcoxon_p_one_sided'), '.2g')} | {pso_txt} | {paper} |")
    L.append("")
    red100 = r["sphere100"].get("acs_vs_cs", {}).get("reduction_pct")
    red1000 = r["sphere1000"].get("acs_vs_cs", {}).get("reduction_pct")
    ok = (red100 is not None and red1000 is not None and red100 >= 10 and red1000 >= 10
          and r["sphere100"]["acs_vs_cs"]["wilcoxon_p_one_sided"] < 0.01
          and r["sphere1000"]["acs_vs_cs"]["wilcoxon_p_one_sided"] < 0.01)
    L.append(f"**ACS speed-up {'reproduces' if ok else 'does not reproduce at the spec threshold'}** "
             f"(spec pass: >= 10 % at both sizes with p < 0.01): ours {_f(red100)} % / "
             f"{_f(red1000)} % fewer generations, paper 22 % / 16 %. Our absolute generation "
             "counts are lower than the paper's derived ones (its Table 7 is an image; ACS's "
             "constants are this project's reconstruction, spec §3.4).")
    L.append("")
    L.append(f"Accuracy at convergence: max ‖x̂ − x_true‖∞ over all seeds CS "
             f"{max(r['sphere100']['cs']['max_x_err'], r['sphere1000']['cs']['max_x_err']):.1e}, ACS "
             f"{max(r['sphere100']['acs']['max_x_err'], r['sphere1000']['acs']['max_x_err']):.1e} "
             "(spec ≤ 1e-4, prototype ≤ 8e-6).")
    if "ablation_sphere100" in r:
        ab = r["ablation_sphere100"]
        L.append("")
        L.append("Ablation on sphere100-clean (informative; spec prototype: most of the gain from "
                 "ω1, δ alone ≈ 3 %, textbook mask with Pa = 0.1 slower than 0.25): " + "; ".join(
                     f"{k}: {_f(v['mean'])} ({v['failures']} fail)" for k, v in ab.items()) + ".")
    L.append("")
    ps = r["pso_sensitivity"]
    L.append(f"**PSO** (standard, w 0.9→0.4, c = 2): {r['sphere100']['pso']['failures']} / "
             f"{len(s['seeds'])} failures on sphere100, {r['sphere1000']['pso']['failures']} on "
             f"sphere1000, mean {_f(r['sphere100']['pso']['mean'])} generations. The paper's "
             "'PSO trapped in a local optimum' does **not** reproduce with this standard PSO. "
             f"Sensitivity: N = 10 → {ps['N10']['failures']} failures (mean "
             f"{_f(ps['N10']['mean'])}); constant w = 0.729, c = 1.49 → "
             f"{ps['constant_w0.729_c1.49']['failures']} failures (mean "
             f"{_f(ps['constant_w0.729_c1.49']['mean'])}).")
    L.append("")
    lm = r["lm_timing_1000"]
    L.append(f"**LM, 1000 records** (scipy `least_squares`, analytic Jacobian): S9 "
             f"{lm['scalar']['median_ms']:.1f} ms ({lm['scalar']['nfev']} evaluations), norm "
             f"{lm['norm']['median_ms']:.1f} ms ({lm['norm']['nfev']} evaluations), median of "
             f"{lm['scalar']['reps']}; spec limit 50 ms. A metaheuristic needs ~10^4 evaluations.")
    L.append("")
    b = r["batch_line5000"]
    L.append(f"**Batch line{b['units']}** (vectorised LM-damped Gauss–Newton, S9, fixture rig18): "
             f"{b['wall_s']:.2f} s wall ({b['cpu_s']:.2f} s CPU; spec ≤ 5 s), max |difference| to "
             f"per-unit scipy LM {b['max_abs_diff_vs_scipy_lm']:.1e} over {b['checked_units']} "
             f"checked units (spec 1e-8); RMSE median {b['rmse_median_mps2']:.4f}, p95 "
             f"{b['rmse_p95_mps2']:.4f} m/s² (spec prototype 0.023/0.027); yield "
             f"{100 * b['yield_fraction']:.1f} % at RMSE ≤ 0.04 m/s² and datasheet ranges.")
    if "batch_stream" in r:
        st = r["batch_stream"]
        L.append("")
        L.append(f"**Fleet streaming** ({st['units']} units made and calibrated "
                 f"{st['input_chunk']} at a time, solver chunks of {st['solver_chunk']}): peak "
                 f"traced memory {st['peak_traced_mb']:.0f} MB, independent of the fleet size "
                 f"(1e6 units stream in the same), CPU {st['cpu_s_incl_simulation']:.1f} s "
                 f"including the simulation; yield {100 * st['yield_fraction']:.1f} %.")
    L.append("")
    L.append("**Turntable, 62 positions, realistic** (mount rotation, 16-bit quantisation, "
             "quadratic mismatch; mean over data seeds), eq.-21 vector error of every method "
             "against the same truth, the true gravity vectors in the sensor frame:")
    L.append("")
    L.append("| method | RMSE (m/s²) | SD (m/s²) | own-frame RMSE (m/s²) | max parameter error | paper |")
    L.append("|---|---|---|---|---|---|")
    tt = r["turntable62_realistic"]
    for k, v in tt.items():
        paper = {"ACS-S12": "0.0826 / 0.0487", "lab six-position (12 par.)":
                 "laboratory: 0.1103 / 0.0643"}.get(k, "")
        own = v.get("rmse_own_frame_mean")
        L.append(f"| {k} | {v['rmse_mean']:.4f} | {v['sd_mean']:.4f} | "
                 f"{'–' if own is None else format(own, '.4f')} | "
                 f"{v['max_param_error_mean']:.4f} | {paper} |")
    L.append("")
    lab, acs = tt["lab six-position (12 par.)"], tt["ACS-S12"]
    fair = 100 * (1 - acs["rmse_mean"] / lab["rmse_mean"])
    line = (f"Relative improvement lab → ACS-S12, scored in the same sensor frame: RMSE "
            f"{fair:.0f} % (paper 25 %), SD {100 * (1 - acs['sd_mean'] / lab['sd_mean']):.0f} % "
            "(paper 24 %).")
    if lab.get("rmse_own_frame_mean") is not None:
        unfair = 100 * (1 - acs["rmse_own_frame_mean"] / lab["rmse_own_frame_mean"])
        line += (f" Scoring each fit in its own frame (S12 against references turned by its own "
                 f"fitted φ̂, the others against unturned references), as this page did "
                 f"before, gives {unfair:.0f} %: it charges the non-S12 methods with the mount "
                 "rotation itself.")
    L.append(line + " Our absolute errors are smaller than the paper's because the virtual "
             "rig's reference error (0.05°) and noise are those of spec §6.2, not of the "
             "authors' turntable.")
    if r.get("turntable_remeasured"):
        L.append("")
        L.append(f"(The turntable rows were re-measured alone, {r['turntable_remeasured']}.)")
    L.append("")
    sf = r["sixface"]
    L.append("**Six faces** (0.5° hand-placement error), mean max |x̂ − x_true|: " + ", ".join(
        f"{k} {v['mean_max_param_error']:.4f}" for k, v in sf.items())
        + ". The 6-parameter form cannot see θ (its error is −θ_true).")
    return "\n".join(L) + "\n"


def remeasure_turntable() -> None:
    """Re-measure only the turntable rows of the stored result (10 seeds, as the full run)
    and re-render docs/results.md: ``python -c 'import benchmarks.triaxial as b;
    b.remeasure_turntable()'``."""
    import datetime
    import json

    from benchmarks.__main__ import DOC, RESULTS, render

    path = RESULTS / "triaxial.json"
    data = json.loads(path.read_text())
    t0 = time.perf_counter()
    data["result"]["turntable62_realistic"] = _turntable(range(10), 1000)
    wall = time.perf_counter() - t0
    day = datetime.datetime.now(datetime.UTC).strftime("%Y-%m-%d")
    data["result"]["turntable_remeasured"] = (
        f"by benchmarks.triaxial.remeasure_turntable() in {wall:.0f} s on {day}")
    path.write_text(json.dumps(data, indent=1) + "\n")
    DOC.write_text(render())
