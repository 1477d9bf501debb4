"""Noise terms on real static IMU logs: the physical-consistency checks.

For every axis of a static log, fit the noise terms (default WLS and GMWM) to the
octave overlapping Allan deviation and check what a curve can and cannot hold:

* **B <= textbook**: the bias-instability component 0.6643 B cannot exceed the curve
  it is read from. Two readings are reported: ``B_over_textbook``, B over the textbook
  min(sigma)/0.6643 over the fitted taus (the least *point*, biased low: the true B of
  simulated flicker floors lies above it in 19 of 20 seeds), and the check ``ok_B``:
  B at most the least simultaneous 95 % upper limit of the curve over the fitted taus
  divided by 0.6643 (the curve's own bound at every tau at once), and where B is
  significant at least half the textbook reading. Beside them,
  ``B_shown_over_textbook_all``: the B the user is shown (its bound where it is one)
  over min(sigma)/0.6643 over every point of the curve; every axis is fitted as
  ``allan --imu`` fits it (:func:`inertialab.workflows.imu_noise.fit_axis_terms`, B held
  to 1.05 x that reading), the model's own B (``B_over_textbook``) read from its
  coefficients.
* **N**: within 10 % of the white-noise reading sigma(tau) sqrt(tau) at tau = 16
  samples (past the sensor's own filter, before the bias terms show).
* **model inside the data**: the fitted model's Allan curve lies inside the data's
  95 % interval at >= 90 % of the fitted taus.
* **a significant rise is named**: where the curve rises significantly after its
  minimum (the last tau's lower 95 % limit above the minimum's upper limit), at least
  one of K or R is reported significant.

The development logs are the two 2.8-h ADIS16405 logs of the R package imudata
(SMAC-Group, CC BY-NC-SA 4.0), read from ``imudata/`` in the real-data folder
(:func:`benchmarks.real_data.real_data_dir`: ``$INERTIALAB_REAL_DATA``) with ``pyreadr`` (``pip install pyreadr``); they are never copied into the
repository. Any other static log (CSV with the usual columns) can be checked with
``--csv``. Commands::

    python -m benchmarks.real_logs                  # both shared logs, wls and gmwm
    python -m benchmarks.real_logs --method wls --log imu3
    python -m benchmarks.real_logs --csv my_log.csv --rate 100
    python -m benchmarks.real_logs --halves         # and each 1.4-h half (held out)
    python -m benchmarks.real_logs --loo            # settings by leave-one-log-out
                                                    # (benchmarks.method_choice)

The same checks run on the MEMS presets (``--preset consumer-100hz --seeds 5``), so a
method is judged on both.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import sys
import time
from pathlib import Path

import numpy as np

from benchmarks.real_data import real_data_dir

ROOT = Path(__file__).resolve().parents[1]
SHARED = real_data_dir() / "imudata"
LOGS = {"imu3": "adis_16405_imu3.rda", "imu4": "adis_16405_imu4.rda"}
#: imudata's columns: (axis, unit suffix)
COLUMNS = {"Gyro. X": ("gx", "dps"), "Gyro. Y": ("gy", "dps"), "Gyro. Z": ("gz", "dps"),
           "Accel. X": ("ax", "g"), "Accel. Y": ("ay", "g"), "Accel. Z": ("az", "g")}
RATE_HZ = 100.0
N_WHITE_SAMPLES = 16
#: sqrt(2 ln2 / pi) = 0.66428: the flat Allan deviation of a flicker floor per unit B, the
#: constant the fit's B rule reads with (a rounded 0.6643 would fail a B held exactly at
#: 1.05 x the reading by 3e-5)
BI = math.sqrt(2.0 * math.log(2.0) / math.pi)


def load_shared(name: str) -> dict:
    """``{axis: (samples, unit)}`` of one shared imudata log."""
    import pyreadr

    path = SHARED / LOGS[name]
    df = next(iter(pyreadr.read_r(str(path)).values()))
    return {COLUMNS[c][0]: (df[c].to_numpy(dtype=float), COLUMNS[c][1]) for c in df.columns}


def load_csv(path: str) -> dict:
    import pandas as pd

    from inertialab.units import split_suffix

    df = pd.read_csv(path)
    out = {}
    for c in df.columns:
        base, unit = split_suffix(c)
        if base in ("gx", "gy", "gz", "ax", "ay", "az") and unit:
            out[base] = (df[c].to_numpy(dtype=float), unit)
    return out


def axis_checks(y, rate_hz: float, unit: str, method: str, *, seed: int = 0,
                terms=None, lines: bool = True) -> dict:
    """Fit one axis and evaluate the checks; returns a flat row."""
    from inertialab.noise.statistics.allan import oadev
    from inertialab.workflows.imu_noise import fit_axis_terms

    kind = "gyro" if unit in ("dps", "dph", "rps") else "accel"
    t0 = time.process_time()
    y = np.asarray(y, dtype=float)
    res = oadev(y, rate_hz=rate_hz, taus="octave", confidence=0.95)
    if terms is None:
        # the fit `allan --imu` shows (lines in the model, its B rule)
        terms = fit_axis_terms(y, res, unit, kind, method, rate_hz=rate_hz, seed=seed,
                               lines=None if lines else ())
    cpu = time.process_time() - t0
    return check_terms(res, terms) | {"cpu_s": cpu, "method": method, "unit": unit}


def check_terms(res, terms) -> dict:
    """The checks of the module docstring for a fitted :class:`NoiseTerms` on its curve
    ``res`` (a 95 % DeviationResult)."""
    from inertialab.noise.statistics.edf import chi2_interval

    taus = np.asarray(res.taus_s)
    dev = np.asarray(res.dev)
    lo_fit, hi_fit = terms.tau_range_s
    sel = (taus >= lo_fit * (1 - 1e-9)) & (taus <= hi_fit * (1 + 1e-9))
    lo, hi = chi2_interval(dev, np.asarray(res.edf), 0.95)
    # textbook reading over the fitted taus, in the report unit of B
    i_min = int(np.argmin(np.where(sel, dev, np.inf)))
    b_text_data = dev[i_min] / BI
    k_sel = int(sel.sum())
    _, hi_sim = chi2_interval(dev[sel], np.asarray(res.edf)[sel], 1.0 - 0.1 / k_sel)
    b_bound = float(np.min(hi_sim)) / BI
    b_data = math.sqrt(max(terms.coefficients[2], 0.0)) / BI
    b_sig = "upper_bound" not in terms.B.flags and "not_observable" not in terms.B.flags
    ratio_b = b_data / b_text_data
    # white-noise reading at 16 samples
    tau_n = N_WHITE_SAMPLES / terms.rate_hz
    j = int(np.argmin(abs(np.log(taus / tau_n))))
    n_read = dev[j] * math.sqrt(taus[j])
    n_fit = math.sqrt(max(terms.coefficients[1], 0.0))
    model = terms.model_dev(taus[sel])
    inside = (model >= lo[sel]) & (model <= hi[sel])
    # a significant rise after the minimum
    i_last = int(np.flatnonzero(sel)[-1])
    rise = bool(i_last > i_min and lo[i_last] > hi[i_min])
    named = any("upper_bound" not in getattr(terms, k).flags
                and "not_observable" not in getattr(terms, k).flags
                and getattr(terms, k).value > 0 for k in ("K", "R"))
    # the B the user is shown (its bound where it is one), against the textbook reading
    # over every point of the curve (noise.terms._bounds: at most 1.05 x for a bound)
    from inertialab.workflows.imu_noise_plan import report_factor

    shown = terms.B.upper_bound if "upper_bound" in terms.B.flags else terms.B.value
    b_text_all = float(np.min(dev[dev > 0])) / BI * report_factor(terms, "B")
    row = {
        "B_shown_over_textbook_all": float(shown) / b_text_all if b_text_all > 0 else math.nan,
        "B": terms.B.value, "B_unit": terms.B.unit, "B_sig": b_sig,
        "B_over_textbook": ratio_b,
        "B_over_bound": b_data / b_bound,
        "ok_B": bool(b_data <= b_bound * (1 + 1e-9) and (not b_sig or ratio_b >= 0.5)),
        "N_over_white": n_fit / n_read, "tau_white_s": float(taus[j]),
        "ok_N": bool(abs(n_fit / n_read - 1) <= 0.10),
        "inside_share": float(inside.mean()), "ok_model": bool(inside.mean() >= 0.90),
        "rise": rise, "rise_named": named, "ok_rise": bool(not rise or named),
        "K": terms.K.value, "K_sig": "upper_bound" not in terms.K.flags,
        "R_sig": "upper_bound" not in terms.R.flags,
    }
    row["ok"] = row["ok_B"] and row["ok_N"] and row["ok_model"] and row["ok_rise"]
    return row


def run_logs(logs, methods, out=sys.stdout, halves: bool = False) -> list[dict]:
    """The checks on every axis of ``logs``; ``halves``: on each half of each log as
    well (1.4 h each: records the methods were not chosen on, the held-out reading
    within the logs held; the name gets ``/1`` or ``/2``)."""
    rows = []
    for name in logs:
        data = load_shared(name) if name in LOGS else load_csv(name)
        parts = [("", slice(None))]
        if halves:
            n = len(next(iter(data.values()))[0])
            parts += [("/1", slice(0, n // 2)), ("/2", slice(n // 2, None))]
        for tag, part in parts:
            for method in methods:
                for axis, (y, unit) in data.items():
                    r = axis_checks(y[part], RATE_HZ, unit, method) | {"log": name + tag,
                                                                       "axis": axis}
                    rows.append(r)
                    print(_line(r), file=out, flush=True)
    return rows


def run_presets(presets, seeds: int, methods, hours: float = 10.0, out=sys.stdout):
    from inertialab.sim.mems_presets import simulate

    rows = []
    for p in presets:
        for s in range(seeds):
            run = simulate(p, hours=hours, seed=s)
            for method in methods:
                r = axis_checks(run.y, run.rate_hz, run.unit, method) | {"log": p,
                                                                       "axis": str(s)}
                rows.append(r)
                print(_line(r), file=out, flush=True)
    return rows


def _line(r) -> str:
    flags = "".join(c if r[f"ok_{k}"] else "-" for c, k in
                    (("B", "B"), ("N", "N"), ("M", "model"), ("R", "rise")))
    return (f"{r['log']:>16} {r['axis']:>3} {r['method']:>5} [{flags}] "
            f"B/text {r['B_over_textbook']:.2f}{'*' if r['B_sig'] else ' '} "
            f"shown/text {r['B_shown_over_textbook_all']:.2f} "
            f"N/white {r['N_over_white']:.3f} inside {r['inside_share']:.2f} "
            f"rise {int(r['rise'])} K {r['K']:.4g}{'*' if r['K_sig'] else ''} "
            f"R{'*' if r['R_sig'] else ''} {r['cpu_s']:.1f}s")


def run(quick: bool = False) -> dict:
    """``python -m benchmarks real_logs``: both shared logs, WLS and GMWM (quick: WLS on
    one log); skipped with the reason where the logs or ``pyreadr`` are absent."""
    if not SHARED.exists():
        return {"skipped": f"no real logs at {SHARED}"}
    try:
        import pyreadr  # noqa: F401
    except ImportError:
        return {"skipped": "pyreadr is not installed (pip install pyreadr)"}
    load0 = os.getloadavg()[0]
    rows = run_logs(["imu3"] if quick else list(LOGS), ["wls"] if quick else ["wls", "gmwm"])
    return {"rows": rows, "load_1min": [load0, os.getloadavg()[0]]}


def markdown(result: dict) -> str:
    """The per-axis check table of docs/results.md."""
    out = ["## Noise terms on real static logs (ADIS16405, 2 x 2.8 h)", ""]
    if "skipped" in result:
        return "\n".join(out + [f"Not run: {result['skipped']}."])
    out += ["Checks of docs/noise-terms.md §10 per axis: B over the textbook reading "
            "(B within the curve's simultaneous 95 % limit: yes/no), N over the white-noise "
            "reading at 16 samples, the share of fitted taus where the model lies inside the "
            "curve's 95 % interval (target >= 90 %), a significant rise named, all checks.", "",
            "| log | axis | method | B/textbook (within limit) | N/white | model inside | "
            "rise named | all |", "|---|---|---|---|---|---|---|---|"]
    for r in result["rows"]:
        out.append(f"| {r['log']} | {r['axis']} | {r['method']} | "
                   f"{r['B_over_textbook']:.2f} ({'yes' if r['ok_B'] else 'no'}) | "
                   f"{r['N_over_white']:.3f} | {100 * r['inside_share']:.0f} % | "
                   f"{'-' if not r['rise'] else ('yes' if r['rise_named'] else 'no')} | "
                   f"{'pass' if r['ok'] else 'fail'} |")
    n = sum(r["ok"] for r in result["rows"])
    lo, hi = result.get("load_1min", [float("nan")] * 2)
    out += ["", f"{n} of {len(result['rows'])} fits pass every check (machine load "
                f"{lo:.1f}-{hi:.1f})."]
    return "\n".join(out)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--log", action="append", help="imu3, imu4 or a CSV path")
    ap.add_argument("--method", action="append")
    ap.add_argument("--preset", action="append")
    ap.add_argument("--seeds", type=int, default=3)
    ap.add_argument("--json", help="write the rows here")
    ap.add_argument("--halves", action="store_true",
                    help="also check each half of each log (held-out halves)")
    ap.add_argument("--loo", action="store_true",
                    help="choose the method settings by leave-one-log-out and by halves "
                         "(benchmarks.method_choice)")
    a = ap.parse_args(argv)
    if a.loo:
        from benchmarks import method_choice

        return method_choice.main([f"--method={m}" for m in a.method or ()]
                                  + ([f"--json={a.json}"] if a.json else []))
    methods = a.method or ["wls", "gmwm"]
    rows = []
    if a.preset:
        rows += run_presets(a.preset, a.seeds, methods)
    if a.log or not a.preset:
        rows += run_logs(a.log or list(LOGS), methods, halves=a.halves)
    n_ok = sum(r["ok"] for r in rows)
    print(f"{n_ok}/{len(rows)} axis fits pass every check; load {os.getloadavg()[0]:.1f}")
    if a.json:
        Path(a.json).write_text(json.dumps(rows, indent=1, default=float))
    return 0


if __name__ == "__main__":
    sys.exit(main())
