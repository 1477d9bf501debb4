"""Predicted drift against observed drift on the MEMS presets and the real logs.

For each preset of :mod:`inertialab.sim.mems_presets` and seed ``s``: simulate two
independent logs of the same sensor (seeds ``s`` and ``s + 10000``), fit the noise terms
on the first (default WLS, spectral lines included, as ``allan --imu``), predict the
error integrated over each horizon after a 10-s bias window
(:mod:`inertialab.noise.terms.drift_prediction`), and integrate the second log the same way
over non-overlapping windows. Reported per preset and horizon, over the seeds:
observed/predicted RMS (median and 10-90 % spread of the per-seed ratios, and the ratio
of the pooled RMS) and the coverage of the 95 % band (pooled windows); the same for the
Kalibr / imu_utils reading. On the real ADIS16405 logs (``--real``): fit on the first
half, check on the second, per axis.

Each preset seed also checks the predicted RMS's 95 % interval
(:func:`inertialab.noise.terms.drift_prediction.predicted_rms_ci`, with the fitted log's
measured non-stationarity (the spread of its segments' own predicted drift,
:func:`inertialab.noise.segments.drift_spread.segment_log_var`) and local misfit, widened
by the observed RMS's own sampling under the predicted model):
its coverage and median high/low per horizon (``rms_ci``). ``--pooled`` pools three
independent logs of a preset (:mod:`inertialab.noise.terms.pooled`) and checks the pooled
interval on a fourth (``--unit-spread``: each log from its own unit of the model, its N, K
and B drawn with that log-sd); ``--real-intervals`` checks it on the shared logs by halves after
the warm-up (and with none cut) and by leave-one-log-out, and records how much the
warm-up cut moves each log's terms; ``--pooled-halves`` pools three of the shared logs'
four halves and checks the fourth.

Commands::

    python -m benchmarks.drift_check --seeds 50 --hours 3 --json benchmarks/results/drift_check.json
    python -m benchmarks.drift_check --real
    python -m benchmarks.drift_check --seeds 40 --hours 3          # with the RMS interval
    python -m benchmarks.drift_check --seeds 40 --first-seed 100000 --preset industrial-400hz
    python -m benchmarks.drift_check --pooled --seeds 20 --hours 2
    python -m benchmarks.drift_check --pooled --seeds 20 --hours 2 --unit-spread 0.15
    python -m benchmarks.drift_check --real-intervals
    python -m benchmarks.drift_check --pooled-halves
    python -m benchmarks.drift_check --pooled-halves-cli wls

Targets: observed/predicted 1.00 +- 0.05 and coverage 93-97 % at every horizon on the
presets; 0.8-1.25 at every horizon and axis on the real logs.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import sys
import time
from pathlib import Path

import numpy as np

HORIZONS = (1.0, 10.0, 60.0, 300.0)
WINDOW = 10.0
PRESETS = ("consumer-100hz", "industrial-400hz", "consumer-1khz", "accel-200hz")


def _fit(y, rate_hz, unit):
    from inertialab.noise.spectral.lines import spectral_lines
    from inertialab.noise.statistics.allan import oadev
    from inertialab.noise.terms.fit import fit_noise_terms

    res = oadev(y, rate_hz=rate_hz, taus="octave")
    terms = fit_noise_terms(res, unit=unit, kind=None, rate_hz=rate_hz,
                            lines=spectral_lines(y, rate_hz))
    return res, terms


def seed_row(preset: str, seed: int, hours: float) -> dict:
    from inertialab.noise.terms.drift_prediction import (
        effective_windows,
        kalibr_components,
        misfit_log_var,
        model_effective_windows,
        observed_error,
        predict,
        predict_terms,
    )
    from inertialab.sim.mems_presets import simulate

    a = simulate(preset, hours=hours, seed=seed)
    b = simulate(preset, hours=hours, seed=seed + 10000)
    res, terms = _fit(a.y, a.rate_hz, a.unit)
    pred = predict_terms(terms, HORIZONS, WINDOW, a.rate_hz)
    kal = predict(kalibr_components(res), HORIZONS, WINDOW, a.rate_hz)
    row = {"seed": seed, "pred": pred.rms.tolist(), "kalibr": kal.rms.tolist(),
           "obs_sq": [], "n": [], "n_eff": [], "in_band": [], "in_kalibr": []}
    extra = _extra(a.y, a.rate_hz, a.unit) + misfit_log_var(res, terms, HORIZONS)
    for i, h in enumerate(HORIZONS):
        e = observed_error(b.y, b.rate_hz, h, WINDOW)
        row["obs_sq"].append(float(np.sum(e * e)))
        row["n"].append(int(e.size))
        row["n_eff"].append(effective_windows(e))
        row["in_band"].append(int(np.sum(np.abs(e) <= pred.band_95[i])))
        row["in_kalibr"].append(int(np.sum(np.abs(e) <= kal.band_95[i])))
    obs = np.sqrt(np.asarray(row["obs_sq"]) / np.maximum(row["n"], 1))
    row["n_model"] = model_effective_windows(pred, row["n"]).tolist()
    row |= _ci_check(pred, terms, extra, row["n_model"], obs)
    return row


def _extra(y, rate_hz, unit):
    """The log-variance the fitted log's measured non-stationarity adds at each horizon
    (as ``allan --imu``: the spread of its segments' own predicted drift,
    :func:`inertialab.noise.segments.drift_spread.segment_log_var`, each segment fitted as
    the log)."""
    from inertialab.noise.segments.drift_spread import segment_log_var

    return segment_log_var(y, rate_hz, lambda seg: _fit(seg, rate_hz, unit), HORIZONS,
                           WINDOW)


def _ci_check(pred, terms, extra, n, obs) -> dict:
    """Whether each observed RMS lies inside the predicted RMS's 95 % interval widened by
    its own sampling over ``n`` windows, and by how much beyond an edge (obs/high or
    low/obs, 1 inside)."""
    from inertialab.noise.terms.drift_prediction import predicted_rms_ci

    ci = predicted_rms_ci(pred, terms, extra_log_var=extra, n_windows=n)
    lo, hi = ci["low"], ci["high"]
    inside = (obs >= lo) & (obs <= hi)
    with np.errstate(divide="ignore", invalid="ignore"):
        edge = np.where(obs > hi, obs / hi, np.where(obs < lo, lo / obs, 1.0))
        # the standardised log ratio: ln(obs^2/pred^2) over the interval's total log-sd
        # (upper-bound terms aside); its variance over seeds is 1 for a calibrated interval
        sd = np.sqrt(sum(np.asarray(v, float) ** 2 for v in ci["log_sd"].values()))
        z = 2.0 * np.log(np.asarray(obs, float) / np.asarray(pred.rms, float)) / sd
    return {"ci_inside": inside.astype(int).tolist(), "ci_edge": edge.tolist(),
            "ci_high_over_low": (hi / np.where(lo > 0, lo, np.nan)).tolist(),
            "ci_z": z.tolist(),
            "ci_log_sd": {k: np.asarray(v, float).tolist() for k, v in ci["log_sd"].items()}}


def summarise(rows) -> dict:
    pred = np.array([r["pred"] for r in rows])
    kal = np.array([r["kalibr"] for r in rows])
    sq = np.array([r["obs_sq"] for r in rows])
    n = np.array([r["n"] for r in rows])
    obs = np.sqrt(sq / n)
    out = {}
    for name, p, inb in (("model", pred, "in_band"), ("kalibr", kal, "in_kalibr")):
        ratio = obs / p
        cover = np.array([r[inb] for r in rows]).sum(axis=0) / n.sum(axis=0)
        pooled = np.sqrt(sq.sum(axis=0) / np.sum(n * p * p, axis=0))
        out[name] = {"ratio_median": np.median(ratio, axis=0).tolist(),
                     "ratio_p10": np.quantile(ratio, 0.1, axis=0).tolist(),
                     "ratio_p90": np.quantile(ratio, 0.9, axis=0).tolist(),
                     "ratio_pooled": pooled.tolist(), "coverage_95": cover.tolist()}
    ins = np.array([r["ci_inside"] for r in rows])
    hl = np.array([r["ci_high_over_low"] for r in rows], dtype=float)
    z = np.array([r["ci_z"] for r in rows], dtype=float)
    out["rms_ci"] = {"coverage": ins.mean(axis=0).tolist(), "cases": int(ins.shape[0]),
                     "z_variance": np.nanvar(z, axis=0).tolist(),
                     "high_over_low_median": np.nanmedian(hl, axis=0).tolist(),
                     "high_over_low_p10": np.nanquantile(hl, 0.1, axis=0).tolist(),
                     "high_over_low_p90": np.nanquantile(hl, 0.9, axis=0).tolist()}
    out["seeds"] = len(rows)
    out["rows"] = [{k: r[k] for k in ("seed", "ci_inside", "ci_z", "ci_log_sd")}
                   for r in rows]
    out["windows_per_seed"] = n[0].tolist()
    return out


def run_presets(seeds: int, hours: float, presets=PRESETS, first_seed: int = 0) -> dict:
    """Per preset, seeds ``first_seed .. first_seed + seeds - 1`` (:func:`seed_row`). A
    seed's first stream is the white noise of every preset, so presets run on one block
    of seeds share their white-noise draws; give each preset its own block
    (``--first-seed``) for independent cases across presets."""
    out = {}
    for p in presets:
        t0 = time.process_time()
        rows = [seed_row(p, s, hours) for s in range(first_seed, first_seed + seeds)]
        out[p] = summarise(rows) | {"cpu_s": time.process_time() - t0}
        print(p, _fmt(out[p]), flush=True)
    return out


def run_real() -> dict:
    from scipy.stats import chi2

    from benchmarks.real_logs import LOGS, RATE_HZ, load_shared
    from inertialab.noise.terms.drift_prediction import (
        check_prediction,
        kalibr_components,
        predict,
        predict_terms,
    )

    out = {}
    for name in LOGS:
        for axis, (y, unit) in load_shared(name).items():
            half = y.size // 2
            res, terms = _fit(y[:half], RATE_HZ, unit)
            pred = predict_terms(terms, HORIZONS, WINDOW, RATE_HZ)
            kal = predict(kalibr_components(res), HORIZONS, WINDOW, RATE_HZ)
            c = check_prediction(pred, y[half:], RATE_HZ)
            ck = check_prediction(kal, y[half:], RATE_HZ)
            # the prediction on the half it was fitted on, and the two halves' own observed
            # drift: where the second half drifts more than 1.25x (or less than 0.8x) the
            # first, a model right on the first half cannot meet the check on the second
            own = check_prediction(pred, y[:half], RATE_HZ)
            halves = c["observed_rms"] / own["observed_rms"]
            # the ratio's own 95 % sampling range under a right model: the RMS of n
            # independent windows (chi-square with n degrees of freedom)
            n_w = np.asarray(c["n_windows"], dtype=float)
            samp = np.sqrt(np.array([chi2.ppf(0.025, n_w), chi2.ppf(0.975, n_w)]) / n_w)
            out[f"{name} {axis}"] = {"ratio": c["ratio"].tolist(),
                                     "coverage_95": c["coverage_95"],
                                     "kalibr_ratio": ck["ratio"].tolist(),
                                     "n_windows": c["n_windows"],
                                     "own_half_ratio": own["ratio"].tolist(),
                                     "second_over_first_observed": halves.tolist(),
                                     "sampling_95": samp.T.tolist()}
            print(name, axis, np.round(c["ratio"], 2), np.round(ck["ratio"], 2),
                  "own half", np.round(own["ratio"], 2), "halves", np.round(halves, 2),
                  "sampling 95 %", np.round(samp.T, 2).tolist(), flush=True)
    return out


def _axis_prediction(y_fit, rate_hz, unit, y_check, *, between=None):
    """Fit ``y_fit``, predict with the RMS interval (as ``allan --imu``: terms, measured
    non-stationarity, local misfit; ``between``: as ``--pool`` of this one log, a map from
    the log's segment spread to the pool's between-log part, which then stands in for the
    spread) and check on ``y_check``: ``(ratio, inside, edge, terms, stationarity)``."""
    from inertialab.noise.segments.stationarity import check_stationarity
    from inertialab.noise.terms.drift_prediction import (
        check_prediction,
        misfit_log_var,
        predict_terms,
    )

    res, terms = _fit(y_fit, rate_hz, unit)
    st = check_stationarity(y_fit, rate_hz)
    pred = predict_terms(terms, HORIZONS, WINDOW, rate_hz)
    own = _extra(y_fit, rate_hz, unit)
    extra = (own if between is None else between(own)) + misfit_log_var(res, terms, HORIZONS)
    c = check_prediction(pred, y_check, rate_hz)
    chk = _ci_check(pred, terms, extra, c["n_effective_model"], c["observed_rms"])
    return c["ratio"], chk, terms, st


def _warmup_span(axes: dict, rate_hz: float) -> dict:
    from inertialab.noise.segments.warmup import log_warmup

    return log_warmup({k: v[0] for k, v in axes.items()}, rate_hz)


def run_real_intervals() -> dict:
    """The RMS interval on the shared logs: fitted on the first half of what follows the
    warm-up and checked on the second (and, for comparison, with no warm-up cut), and
    leave-one-log-out (fitted on one whole log, checked on the other; the between-log part
    from the fitted log's own segments, as ``--pool`` with one log in the fit)."""
    from benchmarks.real_logs import LOGS, RATE_HZ, load_shared
    from inertialab.noise.terms.pooled import next_log_var

    logs = {name: load_shared(name) for name in LOGS}
    out = {"halves": {}, "halves_no_warmup": {}, "leave_one_out": {}, "warmup": {}}
    cut = {}
    for name, axes in logs.items():
        wu = _warmup_span(axes, RATE_HZ)
        out["warmup"][name] = {"span_s": wu["span_s"], "from": wu["from"],
                               "by": {k: v["warmup_s"] for k, v in wu["by"].items()}}
        cut[name] = {k: (y[wu["n_samples"]:], u) for k, (y, u) in axes.items()}
        for axis, (y, unit) in axes.items():  # how much the cut moves the whole-log terms
            t0, t1 = _fit(y, RATE_HZ, unit)[1], _fit(cut[name][axis][0], RATE_HZ, unit)[1]
            out.setdefault("terms_moved", {})[f"{name} {axis}"] = {
                k: [getattr(t0, k).value, getattr(t1, k).value,
                    "upper_bound" in getattr(t1, k).flags] for k in "NBK"}
        for key, src in (("halves", cut[name]), ("halves_no_warmup", axes)):
            for axis, (y, unit) in src.items():
                h = y.size // 2
                r, chk, terms, st = _axis_prediction(y[:h], RATE_HZ, unit, y[h:])
                out[key][f"{name} {axis}"] = {"ratio": r.tolist(), **chk,
                                              "stationarity": st.verdict,
                                              "N": terms.N.value, "B": terms.B.value,
                                              "K": terms.K.value}
                print(key, name, axis, np.round(r, 2), chk["ci_inside"],
                      np.round(chk["ci_edge"], 2), st.verdict, flush=True)
    names = list(LOGS)
    for fit_name in names:
        for chk_name in names:
            if chk_name == fit_name:
                continue
            for axis, (y, unit) in cut[fit_name].items():
                def between(prior):  # drift_between with one log: the floor, times 1 + 1/1
                    return np.array([next_log_var([0.0], [0.0], p) for p in prior])

                r, chk, _, _ = _axis_prediction(y, RATE_HZ, unit, cut[chk_name][axis][0],
                                                between=between)
                out["leave_one_out"][f"{fit_name}->{chk_name} {axis}"] = {
                    "ratio": r.tolist(), **chk}
                print("loo", fit_name, chk_name, axis, np.round(r, 2), chk["ci_inside"],
                      np.round(chk["ci_edge"], 2), flush=True)
    for key in ("halves", "halves_no_warmup", "leave_one_out"):
        ins = np.array([v["ci_inside"] for v in out[key].values()])
        edge = np.array([v["ci_edge"] for v in out[key].values()])
        out[key + "_summary"] = {"inside": int(ins.sum()), "of": int(ins.size),
                                 "worst_edge": float(edge.max()),
                                 "inside_per_horizon": ins.sum(axis=0).tolist()}
        print(key, out[key + "_summary"], flush=True)
    return out


def pooled_check(ys, y_check, fs: float, unit: str) -> dict:
    """Pool the logs ``ys`` (WLS, as ``--pool``: the between-log spread Student's
    prediction interval for the next log, each log's within-log drift spread its floor:
    :func:`inertialab.noise.terms.pooled.next_log_var`), predict with the pooled RMS
    interval and check on ``y_check``: :func:`_ci_check`'s dict."""
    from inertialab.noise.segments.drift_spread import segment_log_var
    from inertialab.noise.segments.stationarity import check_stationarity
    from inertialab.noise.statistics.allan import oadev
    from inertialab.noise.terms.drift_prediction import (
        check_prediction,
        misfit_log_var,
        predict_terms,
    )
    from inertialab.noise.terms.fit import fit_noise_terms
    from inertialab.noise.terms.pooled import pool_curves
    from inertialab.workflows.imu_drift import DriftOptions
    from inertialab.workflows.imu_pool import drift_between

    def fit(y):
        c = oadev(y, rate_hz=fs, taus="octave")
        return c, fit_noise_terms(c, unit=unit, kind=None, rate_hz=fs)

    n = len(ys)
    curves, own = zip(*[fit(y) for y in ys])
    stats = [check_stationarity(y, fs) for y in ys]
    within = [segment_log_var(y, fs, fit, HORIZONS, WINDOW) for y in ys]
    pooled = pool_curves(list(curves), [fs] * n)
    terms = fit_noise_terms(pooled, unit=unit, kind=None, rate_hz=fs)
    opts = DriftOptions(horizons_s=HORIZONS, bias_window_s=WINDOW)
    extra = drift_between(list(own), [fs] * n, stats, opts, within=within)
    extra = extra + misfit_log_var(pooled, terms, HORIZONS)
    pred = predict_terms(terms, HORIZONS, WINDOW, fs)
    c = check_prediction(pred, y_check, fs)
    return _ci_check(pred, terms, extra, c["n_effective_model"], c["observed_rms"]) | {
        "ratio": c["ratio"].tolist()}


def unit_of(preset: str, rng, spread: float):
    """One unit of a sensor model: the preset with its white density, random walk and
    Gauss-Markov amplitudes each times ``exp(spread * e)``, ``e`` standard normal (a
    unit-to-unit log-sd of ``spread``; 0: the preset itself)."""
    import math

    from inertialab.sim.mems_presets import preset as get

    base = get(preset)
    if spread <= 0:
        return base
    e = rng.standard_normal(3)
    return base.with_(n_white=base.n_white * math.exp(spread * e[0]),
                      k_rw=base.k_rw * math.exp(spread * e[1]),
                      gm=tuple((g[0] * math.exp(spread * e[2]), g[1]) for g in base.gm))


def pooled_row(preset: str, seed: int, hours: float, n_logs: int = 3,
               unit_spread: float = 0.0) -> dict:
    """Pool ``n_logs`` independent logs of a preset (:func:`pooled_check`) and check on
    one more log; with ``unit_spread``, each log from its own unit (:func:`unit_of`)."""
    from inertialab.sim.mems_presets import simulate

    rng = np.random.default_rng(seed + 777)
    runs = [simulate(unit_of(preset, rng, unit_spread), hours=hours, seed=seed + 1000 * i)
            for i in range(n_logs + 1)]
    return pooled_check([r.y for r in runs[:n_logs]], runs[-1].y, runs[0].rate_hz,
                        runs[0].unit)


def run_pooled_halves() -> dict:
    """The four halves of the two shared logs (after each log's warm-up) as four logs:
    pool three, check the fourth, per axis. Two halves of one log are not independent
    units: a pool holding a log's other half sees that log's unit, so the figure is
    kinder than three other units would be."""
    from benchmarks.real_logs import LOGS, RATE_HZ, load_shared

    parts = {}
    for name in LOGS:
        axes = load_shared(name)
        n0 = _warmup_span(axes, RATE_HZ)["n_samples"]
        for axis, (y, unit) in axes.items():
            y = y[n0:]
            h = y.size // 2
            parts.setdefault(axis, []).extend([(f"{name} first half", y[:h], unit),
                                               (f"{name} second half", y[h:], unit)])
    out = {}
    for axis, halves in parts.items():
        for j, (label, y_chk, unit) in enumerate(halves):
            rest = [p[1] for i, p in enumerate(halves) if i != j]
            row = pooled_check(rest, y_chk, RATE_HZ, unit)
            out[f"{label} {axis}"] = row
            print("pooled halves", label, axis, np.round(row["ratio"], 2), row["ci_inside"],
                  np.round(row["ci_edge"], 2), np.round(row["ci_high_over_low"], 2), flush=True)
    ins = np.array([v["ci_inside"] for v in out.values()])
    edge = np.array([v["ci_edge"] for v in out.values()])
    hl = np.array([v["ci_high_over_low"] for v in out.values()], dtype=float)
    out["summary"] = {"inside": int(ins.sum()), "of": int(ins.size),
                      "inside_per_horizon": ins.sum(axis=0).tolist(),
                      "worst_edge": float(edge.max()),
                      "high_over_low_median": np.nanmedian(hl, axis=0).tolist()}
    print("pooled halves", out["summary"], flush=True)
    return out


def _half_files(folder: Path) -> list[Path]:
    """The shared logs each cut in two CSV files (``t_s`` and ``{axis}_{unit}`` columns),
    as a user's own files of those halves would be: no warm-up cut here, each file's own
    is found by ``allan --imu``."""
    import pandas as pd

    from benchmarks.real_logs import LOGS, RATE_HZ, load_shared

    out = []
    for name in LOGS:
        axes = load_shared(name)
        n = min(v[0].size for v in axes.values())
        for j, (a, b) in enumerate(((0, n // 2), (n // 2, n))):
            cols = {f"{ax}_{u}": y[a:b] for ax, (y, u) in axes.items()}
            path = folder / f"{name}_half{j + 1}.csv"
            pd.DataFrame({"t_s": np.arange(b - a) / RATE_HZ, **cols}).to_csv(path, index=False)
            out.append(path)
    return out


def run_pooled_halves_cli(method: str = "wls") -> dict:
    """``--pooled-halves`` through the product: the four half files (:func:`_half_files`),
    three pooled by ``inertialab allan --imu A B C --pool --method METHOD --predict-drift
    1,10,60,300 --check-on D --json`` (a subprocess, as a user runs it), per fold and axis
    whether the observed RMS lies inside the interval the check is judged by
    (``rms_ci_with_sampling``), and that interval's high/low."""
    import subprocess
    import tempfile

    h = ",".join(f"{v:g}" for v in HORIZONS)
    out = {}
    with tempfile.TemporaryDirectory() as tmp:
        files = _half_files(Path(tmp))
        for chk in files:
            rest = [str(f) for f in files if f != chk]
            t0 = time.time()
            run = subprocess.run([sys.executable, "-m", "inertialab", "allan", *rest, "--imu",
                                  "--pool", "--method", method, "--predict-drift", h,
                                  "--check-on", str(chk), "--json"],
                                 capture_output=True, text=True, check=True)
            for ax in json.loads(run.stdout)["imu"]["axes"]:
                c = ax["drift_prediction"]["check"]
                ci = c["rms_ci_with_sampling"]
                out[f"{chk.stem} {ax['axis']}"] = {
                    "ratio": c["observed_over_predicted"],
                    "ci_inside": [int(bool(v)) for v in c["inside_rms_ci"]],
                    "ci_high_over_low": [hi / lo if lo else None
                                         for lo, hi in zip(ci["low"], ci["high"])],
                    "model": ax["model_choice"]["chosen"]}
            print("pooled halves (cli)", chk.stem, f"{time.time() - t0:.0f} s",
                  sum(sum(v["ci_inside"]) for k, v in out.items() if k.startswith(chk.stem)),
                  "of 24", flush=True)
    ins = np.array([v["ci_inside"] for v in out.values()])
    hl = np.array([v["ci_high_over_low"] for v in out.values()], dtype=float)
    out["summary"] = {"inside": int(ins.sum()), "of": int(ins.size),
                      "inside_per_horizon": ins.sum(axis=0).tolist(),
                      "high_over_low_median": np.nanmedian(hl, axis=0).tolist(),
                      "high_over_low_p90": np.nanpercentile(hl, 90, axis=0).tolist()}
    print("pooled halves (cli)", out["summary"], flush=True)
    return out


def run_pooled(seeds: int, hours: float, presets=PRESETS, unit_spread: float = 0.0) -> dict:
    out = {}
    for p in presets:
        rows = [pooled_row(p, s, hours, unit_spread=unit_spread) for s in range(seeds)]
        ins = np.array([r["ci_inside"] for r in rows])
        hl = np.array([r["ci_high_over_low"] for r in rows], dtype=float)
        z = np.array([r["ci_z"] for r in rows], dtype=float)
        out[p] = {"seeds": seeds, "unit_spread": unit_spread, "rms_ci": {
            "coverage": ins.mean(axis=0).tolist(), "cases": int(ins.shape[0]),
            "z_variance": np.nanvar(z, axis=0).tolist(),
            "high_over_low_median": np.nanmedian(hl, axis=0).tolist()}}
        print("pooled", p, out[p], flush=True)
    return out


def across_presets(by_preset: dict) -> dict:
    """The RMS interval's coverage over all presets' cases per horizon, and the median,
    least and greatest of the presets' own coverages."""
    cov = np.array([v["rms_ci"]["coverage"] for v in by_preset.values()], dtype=float)
    n = np.array([v["rms_ci"]["cases"] for v in by_preset.values()], dtype=float)
    return {"coverage": (cov * n[:, None]).sum(axis=0) / n.sum(), "cases": int(n.sum()),
            "preset_median": np.median(cov, axis=0), "preset_min": cov.min(axis=0),
            "preset_max": cov.max(axis=0)}


def _fmt(s) -> str:
    m = s["model"]
    return (f"ratio median {np.round(m['ratio_median'], 3)} pooled "
            f"{np.round(m['ratio_pooled'], 3)} coverage {np.round(m['coverage_95'], 3)}; "
            f"RMS interval coverage {np.round(s['rms_ci']['coverage'], 3)} high/low "
            f"{np.round(s['rms_ci']['high_over_low_median'], 2)}; "
            f"kalibr pooled {np.round(s['kalibr']['ratio_pooled'], 3)}")


def run(quick: bool = False) -> dict:
    """``python -m benchmarks drift_check``: 50 seeds per preset (quick: 5) and, where the
    shared logs are there, the real logs' halves."""
    from benchmarks.real_logs import SHARED

    load0 = os.getloadavg()[0]
    out = {"horizons_s": list(HORIZONS), "bias_window_s": WINDOW, "hours": 3.0,
           "presets": run_presets(5 if quick else 50, 3.0)}
    if SHARED.exists():
        out["real"] = run_real()
    out["load_1min"] = [load0, os.getloadavg()[0]]
    return out


def markdown(result: dict) -> str:
    """The presets' and real logs' tables of docs/results.md."""
    h = " / ".join(f"{v:g}" for v in result["horizons_s"])
    out = ["## Predicted drift against observed drift", "",
           f"Error integrated after a {result['bias_window_s']:g}-s bias window at {h} s. "
           f"Presets: fit on one {result['hours']:g}-h log, check on an independent log of "
           "the same sensor, per seed; pooled observed/predicted RMS, coverage of the 95 % "
           "band, and the Kalibr/imu_utils reading's observed/predicted (target 1.00 +- 0.05 "
           "and 93-97 %).", "",
           "| preset | seeds | observed/predicted | coverage | Kalibr reading |",
           "|---|---|---|---|---|"]
    for p, s in result["presets"].items():
        m, k = s["model"], s["kalibr"]
        out.append(f"| {p} | {s['seeds']} | "
                   + " / ".join(f"{v:.3f}" for v in m["ratio_pooled"]) + " | "
                   + " / ".join(f"{100 * v:.1f} %" for v in m["coverage_95"]) + " | "
                   + " / ".join(f"{v:.2f}" for v in k["ratio_pooled"]) + " |")
    if result.get("real"):
        out += ["", "Real logs, fitted on the first half and checked on the second "
                "(target 0.8-1.25), observed/predicted at 1 / 10 / 60 / 300 s (model; "
                "Kalibr reading); beside them the model on the half it was fitted on, and "
                "the second half's observed drift over the first's (no model: where it is "
                "outside 0.8-1.25, no model right on the first half meets the check on the "
                "second):", "",
                "| log axis | model | Kalibr reading | model, own half | 2nd / 1st half "
                "observed | windows |", "|---|---|---|---|---|---|"]
        for name, r in result["real"].items():
            cols = [r["ratio"], r["kalibr_ratio"], r.get("own_half_ratio"),
                    r.get("second_over_first_observed")]
            out.append(f"| {name} | " + " | ".join(
                " / ".join(f"{v:.2f}" for v in c) if c else "-" for c in cols) + " | "
                + " / ".join(str(v) for v in r["n_windows"]) + " |")
        samp = next(iter(result["real"].values())).get("sampling_95")
        if samp:
            out += ["", "A right model's ratio scatters over the windows like "
                    "sqrt(chi2_n/n): 95 % ranges " + ", ".join(
                        f"{lo:.2f}-{hi:.2f}" for lo, hi in samp) + " at the four horizons."]
    return "\n".join(out)


def _listed(d: dict) -> dict:
    return {k: (np.round(v, 4).tolist() if isinstance(v, np.ndarray) else v)
            for k, v in d.items()}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seeds", type=int, default=10)
    ap.add_argument("--first-seed", type=int, default=0,
                    help="presets: the first seed (a preset run on its own block of seeds "
                         "shares no noise stream with another preset's block)")
    ap.add_argument("--hours", type=float, default=3.0)
    ap.add_argument("--preset", action="append")
    ap.add_argument("--real", action="store_true")
    ap.add_argument("--real-intervals", action="store_true",
                    help="the RMS interval on the shared logs: halves after the warm-up, "
                         "with no warm-up cut, and leave-one-log-out")
    ap.add_argument("--pooled", action="store_true",
                    help="presets: pool three logs, check the interval on a fourth")
    ap.add_argument("--unit-spread", type=float, default=0.0,
                    help="with --pooled: each log from its own unit, whose N, K and B "
                         "amplitudes differ by this log-sd (0.15: 15 %%)")
    ap.add_argument("--pooled-halves", action="store_true",
                    help="the shared logs' four halves as four logs: pool three, check the "
                         "fourth")
    ap.add_argument("--pooled-halves-cli", choices=("wls", "gmwm"),
                    help="--pooled-halves through the command line: the halves as four "
                         "files, each with its own warm-up, pooled by allan --imu --pool "
                         "with this method")
    ap.add_argument("--json")
    a = ap.parse_args(argv)
    t0 = time.time()
    result = {"horizons_s": list(HORIZONS), "bias_window_s": WINDOW, "hours": a.hours,
              "machine": {"platform": platform.platform(), "cpus": os.cpu_count(),
                          "load_1min_start": os.getloadavg()[0]}}
    if a.real:
        result["real"] = run_real()
    elif a.real_intervals:
        result["real_intervals"] = run_real_intervals()
    elif a.pooled_halves:
        result["pooled_halves"] = run_pooled_halves()
    elif a.pooled_halves_cli:
        result["pooled_halves_cli"] = run_pooled_halves_cli(a.pooled_halves_cli)
    elif a.pooled:
        result["pooled"] = run_pooled(a.seeds, a.hours, a.preset or PRESETS, a.unit_spread)
        result["pooled_all"] = _listed(across_presets(result["pooled"]))
        print("pooled, all presets", result["pooled_all"], flush=True)
    else:
        result["presets"] = run_presets(a.seeds, a.hours, a.preset or PRESETS,
                                        a.first_seed)
        result["first_seed"] = a.first_seed
        result["presets_all"] = _listed(across_presets(result["presets"]))
        print("all presets", result["presets_all"], flush=True)
    result["machine"]["load_1min_end"] = os.getloadavg()[0]
    result["wall_s"] = time.time() - t0
    if a.json:
        Path(a.json).write_text(json.dumps(result, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
