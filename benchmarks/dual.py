"""Spec 003 reproduction: dual accelerometers on a dividing head, g^2 model, LS and EBR.

Monte Carlo checks AC-6 to AC-11 of spec 003 §7.1 on the virtual lab (M = 1000 runs,
run m with seed 20240603 + m; ``--quick``: 100), the paper's Tables 1-3 mirrored with our
numbers (the paper's own values were images and are lost from the seed), and the
paper's findings of §5 marked reproduced, reproduced with a prior, or not reproducible.
"""

from __future__ import annotations

import time
import warnings

import numpy as np

from inertialab.sensors.dual_meter import COEF_NAMES
from inertialab.studies.dual import monte_carlo

SEED = 20240603
IDX = {n: i for i, n in enumerate(COEF_NAMES)}
SCALE = {"KA0": "ug", "KB0": "ug", "kA1": "ppm", "kB1": "ppm", "eta": "urad",
         "KA2": "ug/g^2", "KB2": "ug/g^2", "KAx": "ug/g^2", "KBx": "ug/g^2"}


def _rms(e):
    return np.sqrt(np.mean(np.asarray(e) ** 2, axis=0))


def _per_coef(v):
    return {n: float(v[IDX[n]]) for n in COEF_NAMES}


def run(quick: bool = False) -> dict:
    M = 100 if quick else 1000
    Ms = max(M // 5, 20)
    t0 = time.process_time()
    all_m = ("single-ls", "ls", "ebr", "ridge-hkb", "ridge-gcv")
    mc = {}
    mc["h1"] = monte_carlo(M, seed=SEED, h=1.0, methods=all_m, cross_fit=True)
    mc["h0"] = monte_carlo(M, seed=SEED, h=0.0, methods=("single-ls", "ls", "ebr"))
    mc["h2.5"] = monte_carlo(M, seed=SEED, h=2.5, methods=("single-ls", "ls", "ebr"))
    mc["cert"] = monte_carlo(M, seed=SEED, h=1.0, prior="certificate", methods=("ls", "ebr"))
    mc["none"] = monte_carlo(M, seed=SEED, h=1.0, prior="none", methods=("ls", "ebr"))
    two = {h: monte_carlo(M, seed=SEED, h=h, methods=("ls",), two_orientation=True)
           for h in (1.0, 2.5)}
    s3 = monte_carlo(Ms, seed=SEED, h=1.0, scenario="S3", methods=("ls", "ebr"))
    s4 = {n: monte_carlo(Ms, seed=SEED, h=1.0, n_positions=n, methods=("ls", "ebr"))
          for n in (8, 12, 20, 36)}
    cpu = time.process_time() - t0

    res = {"settings": {"n_runs": M, "n_runs_small": Ms, "seed": SEED, "seeds": f"{SEED}+m",
                        "scenario": "S1 (table 6.1 unit drawn with tau, H = 6 historical runs)",
                        "ebr_rule": "E1", "quick": quick},
           "cpu_s": cpu}
    # Tables 1 and 2: RMS error and mean reported SD per method (h = 1, historical prior)
    h1 = mc["h1"]
    tab = {}
    for m in all_m:
        sd = np.where(np.isfinite(h1[m]["sd"]), h1[m]["sd"], np.nan)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", RuntimeWarning)  # all-NaN columns: not estimable
            mean_sd = np.nanmean(sd, axis=0)
        tab[m] = {"rms_err": _per_coef(_rms(h1[m]["err"])),
                  "mean_sd": _per_coef(mean_sd),
                  "bias": _per_coef(np.mean(h1[m]["err"], axis=0)),
                  "R_median_ug": float(np.median(h1[m]["R"]) * 1e6),
                  "R_val_median_ug": float(np.median(h1[m]["R_val"]) * 1e6),
                  "total_mse": float(np.sum(_rms(h1[m]["err"]) ** 2))}
    tab["prior only"] = {"rms_err": _per_coef(_rms(h1["prior_err"]))}
    res["table_h1"] = tab
    res["combos"] = {"names": h1["combo_names"],
                     "ls_rms": _rms(h1["ls"]["combo_err"]).tolist(),
                     "ebr_rms": _rms(h1["ebr"]["combo_err"]).tolist(),
                     "ebr_sandwich_sd_mean": np.mean(h1["ebr"]["combo_sd"], 0).tolist(),
                     "ebr_mc_sd": np.std(h1["ebr"]["combo_err"], 0).tolist()}
    # head-error sweep
    res["sweep"] = {h: {"single_KA2": float(_rms(mc[k]["single-ls"]["err"])[IDX["KA2"]]),
                        "single_KB2": float(_rms(mc[k]["single-ls"]["err"])[IDX["KB2"]]),
                        "ebr_KA2": float(_rms(mc[k]["ebr"]["err"])[IDX["KA2"]]),
                        "ebr_KB2": float(_rms(mc[k]["ebr"]["err"])[IDX["KB2"]]),
                        "single_R_median_ug": float(np.median(mc[k]["single-ls"]["R"]) * 1e6),
                        "dual_R_median_ug": float(np.median(mc[k]["ls"]["R"]) * 1e6)}
                    for h, k in (("0", "h0"), ("1", "h1"), ("2.5", "h2.5"))}
    ch = {}
    # AC-6
    tot_e, tot_l = tab["ebr"]["total_mse"], tab["ls"]["total_mse"]
    ident = {n: (tab["ebr"]["rms_err"][n], tab["ls"]["rms_err"][n]) for n in ("kA1", "kB1", "eta")}
    k2 = {n: (tab["ebr"]["rms_err"][n], tab["prior only"]["rms_err"][n]) for n in ("KA2", "KB2")}
    e25 = res["sweep"]["2.5"]
    e0 = res["sweep"]["0"]
    ch["AC-6"] = {
        "mse_ratio": tot_e / tot_l, "mse_ratio_ok": tot_e < 0.01 * tot_l,
        "identifiable_ratio": {n: a / b for n, (a, b) in ident.items()},
        "identifiable_ok": all(a <= 1.05 * b for a, b in ident.values()),
        "k2_vs_prior_ratio": {n: a / b for n, (a, b) in k2.items()},
        "k2_vs_prior_ok": all(a < 0.9 * b for a, b in k2.values()),
        "h2.5_ebr_over_single_KA2": e25["ebr_KA2"] / e25["single_KA2"],
        "h2.5_ok": e25["ebr_KA2"] < 0.5 * e25["single_KA2"],
        "ebr_K2_change_h0_to_h2.5": e25["ebr_KA2"] / e0["ebr_KA2"] - 1,
        "single_K2_growth_h0_to_h2.5": e25["single_KA2"] / e0["single_KA2"],
        "sweep_ok": abs(e25["ebr_KA2"] / e0["ebr_KA2"] - 1) < 0.1
        and e25["single_KA2"] > 3 * e0["single_KA2"]}
    ch["AC-6"]["pass"] = all(v for k, v in ch["AC-6"].items() if k.endswith("_ok"))
    # AC-7
    none, cert = mc["none"], mc["cert"]
    dk2 = np.abs(none["ebr"]["err"][:, [IDX["KA2"], IDX["KB2"]]]
                 - none["ls"]["err"][:, [IDX["KA2"], IDX["KB2"]]])
    est = cert["ebr"]["err"] + cert["truth"]
    inside = np.mean((np.abs(est[:, IDX["KA2"]]) < 9.4e-5) & (np.abs(est[:, IDX["KB2"]]) < 2.5e-5))
    ce = {n: (float(_rms(cert["ebr"]["err"])[IDX[n]]), float(_rms(cert["truth"])[IDX[n]]))
          for n in ("KA2", "KB2")}
    ch["AC-7"] = {"max_abs_ebr_minus_minnorm_K2": float(dk2.max()), "paper_prior_ok": bool(dk2.max() < 1e-8),
                  "certificate_inside_fraction": float(inside), "inside_ok": bool(inside >= 0.99),
                  "certificate_rms_vs_prior_centre": ce,
                  "certificate_rms_ok": all(a < b for a, b in ce.values()),
                  "paper_faithful_ebr_K2_rms": {n: float(_rms(none["ebr"]["err"])[IDX[n]])
                                                for n in ("KA2", "KB2")},
                  "paper_faithful_inside_fraction": float(np.mean(
                      (np.abs((none["ebr"]["err"] + none["truth"])[:, IDX["KA2"]]) < 9.4e-5)
                      & (np.abs((none["ebr"]["err"] + none["truth"])[:, IDX["KB2"]]) < 2.5e-5)))}
    ch["AC-7"]["pass"] = ch["AC-7"]["paper_prior_ok"] and ch["AC-7"]["inside_ok"] and ch["AC-7"]["certificate_rms_ok"]
    # AC-8
    ratios = (np.array(res["combos"]["ebr_sandwich_sd_mean"]) / np.array(res["combos"]["ebr_mc_sd"]))
    names = res["combos"]["names"]
    sel = [names.index(n) for n in ("KA2+KBx", "KB2-KAx", "KA0+KA2")]
    cover = {n: float(np.mean(np.abs(h1["ebr"]["err"][:, IDX[n]]) < 1.96 * h1["ebr"]["sd"][:, IDX[n]]))
             for n in ("KA2", "KB2")}
    ch["AC-8"] = {"sandwich_over_mc_sd": {names[i]: float(ratios[i]) for i in sel},
                  "sandwich_ok": bool(np.all(np.abs(ratios[sel] - 1) <= 0.15)),
                  "posterior_95_coverage": cover,
                  "coverage_ok": all(0.90 <= c <= 0.99 for c in cover.values())}
    ch["AC-8"]["pass"] = ch["AC-8"]["sandwich_ok"] and ch["AC-8"]["coverage_ok"]
    # AC-9
    m25 = mc["h2.5"]
    ratio = m25["single-ls"]["R"] / m25["ls"]["R"]
    rr = h1["ebr"]["R"] / h1["ls"]["R"]
    ch["AC-9"] = {"frac_single_gt_5x_dual_h2.5": float(np.mean(ratio > 5)),
                  "min_ratio": float(ratio.min()), "median_ratio": float(np.median(ratio)),
                  "ebr_over_ls_R_min": float(rr.min()), "ebr_over_ls_R_max": float(rr.max()),
                  "R_val_median_ug": {m: tab[m]["R_val_median_ug"] for m in all_m},
                  "frac_ebr_Rval_below_ls": float(np.mean(h1["ebr"]["R_val"] < h1["ls"]["R_val"]))}
    ch["AC-9"]["pass"] = bool(np.mean(ratio > 5) >= 0.95 and rr.min() >= 1 - 1e-9 and rr.max() <= 1.05)
    # AC-10
    frac = {}
    for n in ("kA1", "kB1", "eta"):
        d = np.abs(h1["ebr"]["err"][:, IDX[n]] - h1["ls"]["err"][:, IDX[n]])
        frac[n] = float(np.mean(d < 0.5 * h1["ls"]["sd"][:, IDX[n]]))
    ch["AC-10"] = {"frac_within_half_sd": frac, "pass": all(v >= 0.99 for v in frac.values())}
    # AC-11
    t_rms = {str(h): dict(zip(("KA2", "KB2", "KAx", "KBx"),
                              _rms(two[h]["two_orientation_err"]).tolist())) for h in two}
    ch["AC-11"] = {"rms_err": t_rms,
                   "pass": all(v < 2e-6 for d in t_rms.values() for v in d.values())}
    res["checks"] = ch
    res["s3_model_error"] = {m: {n: float(_rms(s3[m]["err"])[IDX[n]]) for n in ("kA1", "KA2", "KB2")}
                             for m in ("ls", "ebr")}
    res["s4_positions"] = {str(n): {"ls_kA1_rms": float(_rms(v["ls"]["err"])[IDX["kA1"]]),
                                    "ebr_KA2_rms": float(_rms(v["ebr"]["err"])[IDX["KA2"]]),
                                    "ls_R_median_ug": float(np.median(v["ls"]["R"]) * 1e6)}
                           for n, v in s4.items()}
    res["lambda_median"] = float(np.median(h1["lambda"]))
    return res


def _u(x, n):
    return f"{x * 1e6:.3g}"


def markdown(result: dict) -> str:
    st = result["settings"]
    tab = result["table_h1"]
    ch = result["checks"]
    L = ["## Dual accelerometers on a dividing head (spec 003, g^2 model, EBR)", ""]
    L.append(f"Virtual lab scenario {st['scenario']}, {st['n_runs']} Monte Carlo runs "
             f"(seeds {st['seeds']}, m = 0..{st['n_runs'] - 1}), head-error scale h = 1 unless "
             "stated, EBR rule E1. The paper's Tables 1-3 were images and are lost from the "
             "seed: only its qualitative claims can stand beside our numbers.")
    L += ["", "### Table 1/2 mirror: RMS error and mean reported SD (h = 1, historical prior)", ""]
    cols = ["single-ls", "ls", "ebr", "ridge-hkb", "ridge-gcv", "prior only"]
    L.append("| coefficient (unit) | " + " | ".join(cols) + " |")
    L.append("|---" * (len(cols) + 1) + "|")
    for n in COEF_NAMES:
        cells = []
        for m in cols:
            e = tab[m]["rms_err"][n]
            sd = tab[m].get("mean_sd", {}).get(n)
            s = f"{e * 1e6:.3g}"
            if m != "prior only":
                s += " (sd n/e)" if sd is None or sd != sd else f" (sd {sd * 1e6:.3g})"
            cells.append(s)
        L.append(f"| {n} ({SCALE[n]}) | " + " | ".join(cells) + " |")
    L.append("| R median (µg) | " + " | ".join(
        f"{tab[m]['R_median_ug']:.3g}" if m in tab and "R_median_ug" in tab[m] else "–" for m in cols) + " |")
    L.append("| R_val median (µg) | " + " | ".join(
        f"{tab[m]['R_val_median_ug']:.3g}" if m in tab and "R_val_median_ug" in tab[m] else "–" for m in cols) + " |")
    L += ["", "n/e: not estimable (LS reports no SD for K0, K2, Kx: rank 7 of 9). SDs: LS "
          "harmonic, EBR posterior, ridge sandwich.", ""]
    L += ["### Head-error sweep (RMS error of K2, µg/g²; median residual R, µg)", "",
          "| h | single-LS KA2 | single-LS KB2 | EBR KA2 | EBR KB2 | single R | dual R |",
          "|---|---|---|---|---|---|---|"]
    for h, v in result["sweep"].items():
        L.append(f"| {h} | {_u(v['single_KA2'], 0)} | {_u(v['single_KB2'], 0)} | "
                 f"{_u(v['ebr_KA2'], 0)} | {_u(v['ebr_KB2'], 0)} | {v['single_R_median_ug']:.3g} | "
                 f"{v['dual_R_median_ug']:.3g} |")
    L += ["", "### Table 3 mirror (real test)", "",
          "No real records are available; the virtual run above stands in. The paper's claim "
          "that LS and EBR agree on K0, k1 and eta holds for k1 and eta (AC-10); for K0 it "
          "holds only with an informative prior (K0 is in the null-space coupling).", ""]
    L += ["### Acceptance checks (spec 003 §7.1)", "", "| check | result | numbers |",
          "|---|---|---|"]
    a6 = ch["AC-6"]
    L.append(f"| AC-6 | {'pass' if a6['pass'] else 'FAIL'} | MSE(EBR)/MSE(min-norm) = "
             f"{a6['mse_ratio']:.3g}; kA1/kB1/eta RMS ratio EBR/LS = "
             + ", ".join(f"{v:.3f}" for v in a6["identifiable_ratio"].values())
             + "; K2 RMS EBR/prior-only = " + ", ".join(f"{v:.2f}" for v in a6["k2_vs_prior_ratio"].values())
             + f"; h=2.5 EBR/single KA2 = {a6['h2.5_ebr_over_single_KA2']:.2f}; EBR K2 change "
             f"h 0->2.5 {a6['ebr_K2_change_h0_to_h2.5'] * 100:+.1f} %, single-LS growth "
             f"{a6['single_K2_growth_h0_to_h2.5']:.1f}x |")
    a7 = ch["AC-7"]
    L.append(f"| AC-7 | {'pass' if a7['pass'] else 'FAIL'} | paper prior: max |EBR K2 - min-norm K2| = "
             f"{a7['max_abs_ebr_minus_minnorm_K2']:.2g}; certificate prior: inside limits "
             f"{a7['certificate_inside_fraction'] * 100:.1f} %, K2 RMS "
             + ", ".join(f"{n} {a * 1e6:.3g} vs centre {b * 1e6:.3g}" for n, (a, b) in
                         a7["certificate_rms_vs_prior_centre"].items()) + " µg/g² |")
    a8 = ch["AC-8"]
    L.append(f"| AC-8 | {'pass' if a8['pass'] else 'FAIL'} | sandwich/MC SD "
             + ", ".join(f"{k} {v:.2f}" for k, v in a8["sandwich_over_mc_sd"].items())
             + "; posterior 95 % coverage " + ", ".join(f"{k} {v:.3f}" for k, v in a8["posterior_95_coverage"].items()) + " |")
    a9 = ch["AC-9"]
    L.append(f"| AC-9 | {'pass' if a9['pass'] else 'FAIL'} | h=2.5: single R > 5 dual R in "
             f"{a9['frac_single_gt_5x_dual_h2.5'] * 100:.1f} % (min ratio {a9['min_ratio']:.2f}, median "
             f"{a9['median_ratio']:.2f}); R_EBR/R_LS in [{a9['ebr_over_ls_R_min']:.6f}, "
             f"{a9['ebr_over_ls_R_max']:.4f}]; R_val(EBR) < R_val(LS) in "
             f"{a9['frac_ebr_Rval_below_ls'] * 100:.0f} % of runs |")
    a10 = ch["AC-10"]
    L.append(f"| AC-10 | {'pass' if a10['pass'] else 'FAIL'} | |EBR-LS| < 0.5 SD in "
             + ", ".join(f"{k} {v * 100:.1f} %" for k, v in a10["frac_within_half_sd"].items()) + " |")
    a11 = ch["AC-11"]
    L.append(f"| AC-11 | {'pass' if a11['pass'] else 'FAIL'} | two-orientation LS K2/Kx RMS "
             + "; ".join(f"h={h}: " + ", ".join(f"{k} {v * 1e6:.2f}" for k, v in d.items())
                         for h, d in a11["rms_err"].items()) + " µg/g² |")
    L += ["", "### The paper's findings (§5)", "",
          "| # | finding | status here |", "|---|---|---|"]
    sw = result["sweep"]
    L.append(f"| 1 | single-meter LS has the largest residual and lowest accuracy | reproduced "
             f"once the head error matters: at h = 1 single-LS KA2 RMS {_u(sw['1']['single_KA2'], 0)} "
             f"vs EBR {_u(sw['1']['ebr_KA2'], 0)} µg/g²; at h = 0 single-LS is the *most* accurate "
             f"({_u(sw['0']['single_KA2'], 0)} µg/g²), so the claim depends on the head error |")
    L.append("| 2 | dual LS removes the angle error but cannot separate Kx from K2 | reproduced "
             "exactly: rank 7 of 9, null directions (KA0, KA2, KBx) and (KB0, KB2, KAx); "
             "min-norm K2 errors ~1e-4 |")
    L.append("| 3 | EBR has a smaller residual than dual LS, higher accuracy, and gives K2 | "
             "residual part not reproducible (in-sample R_EBR >= R_LS by construction; "
             f"out of sample R_val(EBR) < R_val(LS) in {a9['frac_ebr_Rval_below_ls'] * 100:.0f} % of runs); "
             "accuracy and K2 reproduced only with an informative (historical) prior |")
    L.append("| 4 | LS and EBR agree on K0, k1, eta | reproduced for k1 and eta (AC-10); K0 "
             "agrees only with an informative prior |")
    L.append(f"| 5 | EBR K2 inside the certificate limits | reproduced with the certificate prior "
             f"({a7['certificate_inside_fraction'] * 100:.0f} % of runs); with the paper's zero "
             f"prior only {a7['paper_faithful_inside_fraction'] * 100:.0f} % (KA2 ~ K0 + K2 ~ 5e-4) |")
    L += ["", "Extra: S3 model error (K3 = 5e-6, DMM INL) RMS: " + "; ".join(
        f"{m}: " + ", ".join(f"{n} {v * 1e6:.3g}" for n, v in d.items())
        for m, d in result["s3_model_error"].items()) + " (ppm / µg/g²). S4 positions: " + "; ".join(
        f"N={n}: LS kA1 {v['ls_kA1_rms'] * 1e6:.3g} ppm, EBR KA2 {v['ebr_KA2_rms'] * 1e6:.3g} µg/g²"
        for n, v in result["s4_positions"].items()) + "."]
    return "\n".join(L) + "\n"
