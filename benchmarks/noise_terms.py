"""Noise-term coverage benchmark (issue 14 item 3): MEMS presets, 10-h records.

For each preset of :mod:`inertialab.sim.mems_presets` and each seed: simulate a 10-h
log, compute the octave overlapping Allan deviation, fit the terms by every method asked
for, and compare with the preset's truth. Reported per preset, method and term: the
coverage of the 95 % interval (truth inside ``ci``; a non-significant term's interval is
``[0, upper]``), the median |relative error| and the median relative error (bias), the
share of seeds where the term was reported significant, and the textbook B
``min(sigma)/0.6643`` beside the IEEE B. Targets (issue 14): coverage of N, B, K within
90-98 %, median |error| N <= 2 %, B <= 10 %, K <= 15 %.

Counts: the issue asks for >= 200 seeds per preset. One 10-h record costs ~3 s (100 Hz)
to ~30 s (1 kHz) of one core to simulate and analyse, so the full count takes hours;
``run(seeds=...)`` takes any count, and the stored result says which were run.

Usage: ``python -m benchmarks noise_terms`` (default counts below) or from Python
``run(seeds={"consumer-100hz": 200}, methods=("wls",))``.
"""

from __future__ import annotations

import time

import numpy as np

#: seeds per preset for the default (full) and quick runs
SEEDS = {"consumer-100hz": 40, "industrial-400hz": 20, "consumer-1khz": 8,
         "accel-200hz": 20}
QUICK = {"consumer-100hz": 3, "accel-200hz": 2}
METHODS = ("wls", "ols", "slope", "gmwm")
#: GMWM costs ~10 s per fit (16 candidate models): run on the first seeds only
GMWM_SEEDS = 5
TERMS = ("N", "B", "K", "R", "Q")


def _one(preset, seed, hours, methods, gmwm_seeds):
    from inertialab.noise.allan import oadev
    from inertialab.noise.terms import fit_noise_terms
    from inertialab.sim import mems_presets as MP

    run = MP.simulate(preset, hours=hours, seed=seed)
    r = oadev(run.y, rate_hz=run.rate_hz, taus="octave")
    out = {"seed": seed, "truth": {k: run.truth[k]["value"] for k in TERMS}, "fits": {}}
    for method in methods:
        if method == "gmwm" and seed >= gmwm_seeds:
            continue
        t0 = time.process_time()
        t = fit_noise_terms(r, unit=run.unit, kind=run.kind, method=method,
                            n_boot=50 if method == "gmwm" else 200, seed=seed)
        cpu = time.process_time() - t0
        f = {k: {"value": getattr(t, k).value, "ci": list(getattr(t, k).ci),
                 "flags": list(getattr(t, k).flags)} for k in TERMS}
        f["cpu_s"] = cpu
        if t.b_textbook:
            f["b_textbook"] = t.b_textbook["value"]
        if t.gmwm:
            f["model"] = t.gmwm["model"]
        out["fits"][method] = f
    return out


def _summary(rows, method):
    s = {}
    for k in TERMS:
        vals, cov, sig = [], [], []
        for row in rows:
            f = row["fits"].get(method)
            if f is None:
                continue
            tv, e = row["truth"][k], f[k]
            lo, hi = e["ci"]
            cov.append(bool(np.isfinite(lo) and lo <= tv <= hi))
            sig.append(not ({"upper_bound", "not_observable", "absent"} & set(e["flags"])))
            if tv > 0 and np.isfinite(e["value"]):
                vals.append(e["value"] / tv - 1)
        if not cov:
            continue
        v = np.array(vals) if vals else np.array([np.nan])
        s[k] = {"n": len(cov), "coverage": float(np.mean(cov)),
                "median_abs_err": float(np.nanmedian(np.abs(v))),
                "median_err": float(np.nanmedian(v)), "significant": float(np.mean(sig))}
    tb = [row["fits"][method]["b_textbook"] / row["truth"]["B"] - 1 for row in rows
          if method in row["fits"] and "b_textbook" in row["fits"][method]]
    if tb:
        s["B_textbook_median_err"] = float(np.median(tb))
    cpu = [row["fits"][method]["cpu_s"] for row in rows if method in row["fits"]]
    s["cpu_s_median"] = float(np.median(cpu)) if cpu else float("nan")
    return s


def run(quick: bool = False, *, seeds: dict | None = None, hours: float = 10.0,
        methods=METHODS, gmwm_seeds: int = GMWM_SEEDS) -> dict:
    counts = seeds or (QUICK if quick else SEEDS)
    if quick:
        hours = min(hours, 2.0)
    out = {"hours": hours, "seeds": dict(counts), "methods": list(methods),
           "gmwm_seeds": gmwm_seeds, "confidence": 0.95, "presets": {}}
    for preset, n in counts.items():
        t0 = time.perf_counter()
        rows = [_one(preset, s, hours, methods, gmwm_seeds) for s in range(n)]
        out["presets"][preset] = {
            "rows": rows, "wall_s": time.perf_counter() - t0,
            "summary": {m: _summary(rows, m) for m in methods}}
    return out


def markdown(result: dict) -> str:
    lines = ["## Noise terms on MEMS presets (issue 14)", "",
             f"{result['hours']:g}-h records of `sim.mems_presets`; seeds per preset "
             f"{result['seeds']}; GMWM on the first {result['gmwm_seeds']} seeds; 95 % "
             "intervals. Targets: coverage of N, B, K 90-98 %, median |error| N <= 2 %, "
             "B <= 10 %, K <= 15 %.", "",
             "| preset | method | term | n | coverage | median abs err | median err | "
             "significant |", "|---|---|---|---|---|---|---|---|"]
    for preset, p in result["presets"].items():
        for m, s in p["summary"].items():
            for k in TERMS:
                if k not in s:
                    continue
                e = s[k]
                lines.append(f"| {preset} | {m} | {k} | {e['n']} | {100 * e['coverage']:.0f} % "
                             f"| {100 * e['median_abs_err']:.1f} % | "
                             f"{100 * e['median_err']:+.1f} % | "
                             f"{100 * e['significant']:.0f} % |")
            if "B_textbook_median_err" in s:
                lines.append(f"| {preset} | {m} | B textbook min/0.664 | | | | "
                             f"{100 * s['B_textbook_median_err']:+.1f} % | |")
    lines.append("")
    return "\n".join(lines)


def octave_correlation(n: int = 2**15, reps: int = 300, seed: int = 0) -> dict:
    """The one-octave correlation of log OADEV^2 per noise type that the bootstrap copula
    of :mod:`inertialab.noise.terms` uses (``OCTAVE_RHO``): white, flicker (Kasdin) and
    random-walk rate, ``n`` samples, ``reps`` records, m = 1..1024. Measured (seed 0):
    adjacent-octave correlations 0.44-0.59 (white), 0.55-0.72 (flicker), 0.74-0.89 (RW)."""
    from inertialab.noise.allan import oadev
    from inertialab.sensors.gyro import kasdin_flicker

    rng = np.random.default_rng(seed)
    out = {}
    for kind in ("white", "flicker", "rw"):
        rows = []
        for _ in range(reps):
            e = rng.standard_normal(n)
            y = e if kind == "white" else (kasdin_flicker(e) if kind == "flicker"
                                           else np.cumsum(e))
            r = oadev(y, rate_hz=1.0, taus=[2**k for k in range(11)], alpha=0)
            rows.append(np.log(r.dev**2))
        c = np.corrcoef(np.array(rows).T)
        out[kind] = {"adjacent": [float(v) for v in np.diag(c, 1)],
                     "lag2": [float(v) for v in np.diag(c, 2)]}
    return out
