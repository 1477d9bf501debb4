"""Spec 000 §8.2 reproduction: IAFSA-SCM-ANFIS against ANN, FIS, ANFIS, SCM-ANFIS and the
polynomial baselines on the virtual lab's thermal tumble.

Paper preset, lot seed 0: unit 0 trains, unit 1 is the transfer unit; run seeds 0, 1, 2
(median reported); splits ``random`` and ``interp_T``. The realistic preset is run with
one seed for comparison. BLAS runs single-threaded inside the workflow (spec 000
§8.2.5). Times are wall seconds and process CPU seconds of this process.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

PAPER_MG = {"ann": 0.138, "fis": 0.101, "anfis": 0.034, "iafsa-scm-anfis": 0.004}
LABELS = {"ann": "ANN", "fis": "FIS", "anfis": "ANFIS (grid)", "scm-anfis": "SCM-ANFIS",
          "iafsa-scm-anfis": "IAFSA-SCM-ANFIS", "poly-sep": "POLY-SEP", "poly-2d": "POLY-2D"}


def _one(preset: str, seed: int, split: str, cfg_kw: dict) -> dict:
    from inertialab.studies.thermal import virtual_lab_run

    return virtual_lab_run(preset, seed, split, cfg_kw)


def _median(runs: list[dict], model: str, key: str = "rmse_ug") -> float:
    return float(np.median([r["models"][model][key] for r in runs]))


def _checks(runs: list[dict]) -> dict:
    """Spec 000 §8.2 acceptance checks on the paper-preset runs (medians over seeds)."""
    out = {}
    for split in ("random", "interp_T"):
        rs = [r for r in runs if r["split"] == split and r["preset"] == "paper"]
        if not rs:
            continue
        med = {m: _median(rs, m) for m in rs[0]["models"]}
        out[split] = {
            "median_rmse_ug": med,
            "iafsa_le_1.05_scm": med["iafsa-scm-anfis"] <= 1.05 * med["scm-anfis"],
            "scm_le_fis": med["scm-anfis"] <= med["fis"],
            "iafsa_lt_anfis": med["iafsa-scm-anfis"] < med["anfis"],
            "iafsa_lt_ann": med["iafsa-scm-anfis"] < med["ann"],
            "seed_order_ann_fis_gt_anfis_gt_iafsa": bool(
                min(med["ann"], med["fis"]) > med["anfis"] > med["iafsa-scm-anfis"]),
            "search_never_worse": all(r["search"]["fun"] <= r["search"]["f_default"] for r in rs),
            "tenfold_reduction": {m: bool(float(np.median([r["raw_rms_ug"] for r in rs]))
                                          >= 10 * med[m]) for m in med},
        }
    rnd = [r for r in runs if r["split"] == "random" and r["preset"] == "paper"]
    if rnd:
        floor = float(np.median([r["noise_floor_ug"] for r in rnd]))
        bound = max(10.0, 2.5 * floor)
        out["rmse_bound"] = {"bound_ug": bound, "noise_floor_ug": floor,
                             "iafsa_rmse_ug": _median(rnd, "iafsa-scm-anfis"),
                             "holds": _median(rnd, "iafsa-scm-anfis") <= bound}
        tr = [r["transfer"]["comp_max_drift_ug"] for r in rnd]
        raw = [r["transfer"]["raw_max_drift_ug"] for r in rnd]
        out["transfer"] = {"raw_max_ug_median": float(np.median(raw)),
                           "comp_max_ug_median": float(np.median(tr)),
                           "holds": float(np.median(raw)) >= 3000 and float(np.median(tr)) <= 30}
        s_wall = [r["search"]["wall_s"] for r in runs if r["preset"] == "paper"]
        f_wall = [r["fit_wall_s"] for r in runs if r["preset"] == "paper"]
        f_cpu = [r["fit_cpu_s"] for r in runs if r["preset"] == "paper"]
        out["time"] = {"search_wall_s_max": max(s_wall), "fit_wall_s_max": max(f_wall),
                       "fit_cpu_s_max": max(f_cpu),
                       "search_le_180": max(s_wall) <= 180,
                       "one_split_one_seed_le_300": max(f_wall) <= 300}
    return out


def run(quick: bool = False) -> dict:
    from inertialab.workflows.thermal import FitConfig

    if quick:
        seeds, splits = (0,), ("random",)
        cfg_kw = {"fish": 6, "generations": 6, "search_epochs": 10, "epochs": 60}
    else:
        seeds, splits = (0, 1, 2), ("random", "interp_T")
        cfg_kw = {}
    runs = []
    for split in splits:
        for seed in seeds:
            runs.append(_one("paper", seed, split, cfg_kw))
    realistic = [_one("realistic", 0, "random", cfg_kw)]
    defaults = replace(FitConfig(), **cfg_kw)
    return {"settings": {"lot_seed": 0, "train_unit": 0, "transfer_unit": 1, "run_seeds": list(seeds),
                         "transfer_seed": "run seed + 1000", "splits": list(splits),
                         "fish": defaults.fish, "generations": defaults.generations,
                         "search_epochs": defaults.search_epochs, "epochs": defaults.epochs,
                         "ann_max_epochs": defaults.ann_max_epochs, "quick": quick,
                         "fish_table": defaults.fish_table()},
            "runs": runs, "realistic": realistic, "checks": _checks(runs)}


def _fmt(v, nd=1):
    return "–" if v is None else f"{v:.{nd}f}"


def markdown(result: dict) -> str:
    st = result["settings"]
    runs = result["runs"]
    ch = result["checks"]
    lines = ["## Thermal drift compensation (spec 000, IAFSA-SCM-ANFIS)", ""]
    lines.append(
        f"Virtual lab, paper preset, lot seed {st['lot_seed']}: unit {st['train_unit']} trains, "
        f"unit {st['transfer_unit']} is compensated with its model; run seeds {st['run_seeds']} "
        f"(medians), IAFSA {st['fish']} fish x {st['generations']} generations, "
        f"{st['search_epochs']}-epoch objective, {st['epochs']} final epochs.")
    if st.get("fish_table"):
        lines.append("Fish-swarm parameters (the paper's Table 1, spec 000 §3.5 values): "
                     + ", ".join(f"{k} {v:g}" for k, v in st["fish_table"].items()) + ".")
    lines.append("")
    splits = [s for s in st["splits"] if s in ch]
    head = "| model | paper RMSE (µg) | " + " | ".join(f"ours, {s} (µg)" for s in splits)
    head += " | MAXE ppm (random) | rules |"
    lines += [head, "|---" * (4 + len(splits)) + "|"]
    for m in runs[0]["models"]:
        paper = PAPER_MG.get(m)
        cells = [LABELS.get(m, m), "–" if paper is None else f"{paper * 1e3:.0f}"]
        cells += [_fmt(ch[s]["median_rmse_ug"][m]) for s in splits]
        rnd = [r for r in runs if r["split"] == "random"]
        cells.append(_fmt(_median(rnd, m, "maxe_ppm")) if rnd else "–")
        rules = rnd[0]["models"][m]["rules"] if rnd else None
        cells.append("–" if rules is None else str(rules))
        lines.append("| " + " | ".join(cells) + " |")
    per_seed = "; ".join(
        f"{r['split']} seed {r['run_seed']}: {r['models']['iafsa-scm-anfis']['rmse_ug']:.1f} µg, "
        f"{r['search']['n_rules']} rules, {r['search']['nfev']} evaluations, transfer "
        f"{r['transfer']['comp_max_drift_ug']:.0f} µg" for r in runs)
    lines += ["", f"IAFSA-SCM-ANFIS per run ({per_seed}). A search that settles on many narrow "
              "rules (near R_max = 40) can fit the validation set points and still miss "
              "intermediate temperatures and the second unit; the medians hide such a run, "
              "the list above does not."]
    raw = float(np.median([r["raw_rms_ug"] for r in runs if r["split"] == "random"]))
    lines += ["", f"Raw (uncompensated) RMS drift on the random test set: {raw:.0f} µg."]
    lines.append("")
    lines.append("Checks of spec 000 §8.2:")
    lines.append("")
    for s in splits:
        c = ch[s]
        lines.append(
            f"- {s}: IAFSA <= 1.05 x SCM-ANFIS {_yes(c['iafsa_le_1.05_scm'])}, SCM-ANFIS <= FIS "
            f"{_yes(c['scm_le_fis'])}, IAFSA < ANFIS {_yes(c['iafsa_lt_anfis'])}, IAFSA < ANN "
            f"{_yes(c['iafsa_lt_ann'])}; the paper's order ANN, FIS > ANFIS > IAFSA-SCM-ANFIS "
            f"{_yes(c['seed_order_ann_fis_gt_anfis_gt_iafsa'])}; search never worse than the "
            f"default start {_yes(c['search_never_worse'])}; >= 10x reduction of the raw drift: "
            + ", ".join(f"{LABELS[m]} {_yes(v)}" for m, v in c["tenfold_reduction"].items()) + ".")
    if "rmse_bound" in ch:
        b = ch["rmse_bound"]
        lines.append(f"- IAFSA-SCM-ANFIS RMSE {b['iafsa_rmse_ug']:.1f} µg <= max(10, 2.5 x noise "
                     f"floor {b['noise_floor_ug']:.1f}) = {b['bound_ug']:.1f} µg "
                     f"{_yes(b['holds'])} (paper: 4 µg).")
        t = ch["transfer"]
        lines.append(f"- Transfer to unit 1: raw max drift {t['raw_max_ug_median'] / 1e3:.2f} mg -> "
                     f"compensated {t['comp_max_ug_median']:.1f} µg (bound 30 µg) {_yes(t['holds'])}"
                     f" (paper: 7.21 mg -> 9.3 µg).")
        tm = ch["time"]
        lines.append(f"- Time: longest IAFSA search {tm['search_wall_s_max']:.0f} s wall (budget 180 s) "
                     f"{_yes(tm['search_le_180'])}; longest complete fit of the 7 models, one split, "
                     f"one seed {tm['fit_wall_s_max']:.0f} s wall / {tm['fit_cpu_s_max']:.0f} s CPU "
                     f"(budget 300 s) {_yes(tm['one_split_one_seed_le_300'])}. The machine is shared; "
                     "CPU time is the steadier figure.")
    if result.get("realistic"):
        r = result["realistic"][0]
        lines += ["", "Realistic preset (one seed, random split; report only): " + ", ".join(
            f"{LABELS[m]} {v['rmse_ug']:.1f} µg" for m, v in r["models"].items())
            + f"; transfer max drift {r['transfer']['raw_max_drift_ug'] / 1e3:.2f} mg -> "
              f"{r['transfer']['comp_max_drift_ug']:.1f} µg."]
    lines += ["", "Limits (spec 000 §8.3): the paper's µg-level figures assume every "
              "temperature-dependent term is a function of (T, a_i) only; the realistic preset's "
              "drifting misalignment (1 µrad/°C) and 15 % unit-to-unit spread leave an error a "
              "two-input model cannot learn, and its transfer does not approach the paper's 9.3 µg. "
              "Split ratio, fish parameters and ANN structure of the paper are unknown: the "
              "ordering, not the exact numbers, is the reproduction target. The paper's claim of "
              "1 µg-level stability does not follow from its own 4 µg test RMSE and 9.3 µg "
              "transfer drift."]
    return "\n".join(lines) + "\n"


def _yes(b) -> str:
    return "**holds**" if b else "**does not hold**"
