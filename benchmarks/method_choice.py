"""Choosing the noise-term method settings by cross-validation (leave-one-log-out, halves).

Candidates per method (WLS, GMWM) are scored on *cases*: every axis of the two shared
ADIS16405 logs (:mod:`benchmarks.real_logs`), whole and each 1.4-h half, and simulated
MEMS axes (:data:`PRESETS`, :data:`SEEDS`, 2.8 h like the logs). A case passes when all
three checks of the held-out goal hold:

* ``B``: the B the user is shown (the bound where it is one) at most 1.05 x the textbook
  reading min(ADEV)/0.6643 over every point of that record's curve. Every case is
  fitted as ``allan --imu`` fits an axis
  (:func:`inertialab.workflows.imu_noise.fit_axis_terms`: the record's spectral lines in
  the model, B held to that reading), so this check scores what the command shows;
* ``N``: within 10 % of the white reading sigma(tau) sqrt(tau) at 16 samples;
* ``rise``: a significant rise after the curve's minimum has K or R significant.

A setting is *chosen* by its pass count on training cases only (ties: today's default,
then the listed order), and scored on the cases held out:

* **leave-one-log-out**: train on the other log (whole and halves) plus the presets, score
  on the held-out log (whole and halves); one fold per log;
* **halves**: train on the first halves of both logs plus the presets, score on the
  second halves; and the reverse.

The default is the setting chosen on every case (all logs, halves, presets); the
cross-validated figure is the held-out pass count of the fold-wise choices. Usage::

    python -m benchmarks.method_choice               # both methods
    python -m benchmarks.method_choice --method wls
    python -m benchmarks.real_logs --loo             # the same

Cost: the curve and lines once per record, then one fit per candidate (WLS ~1 s, GMWM
~15 s an axis); ~15 min for WLS, ~40 min for GMWM on one core.
"""

from __future__ import annotations

import argparse
import contextlib
import json
import sys
from pathlib import Path

import numpy as np

#: simulated cases: MEMS presets and seeds, at the logs' length
PRESETS = ("consumer-100hz", "accel-200hz")
SEEDS = (0, 1)
HOURS = 2.8

#: candidate settings per method; the first is today's default (``band-below-rise``:
#: :data:`inertialab.noise.terms._grid.BAND_BELOW_RISE`)
CANDIDATES = {
    "wls": {"default": {}, "flicker-B": {"b_shape": "flicker"}, "no-lines": {"lines": False},
            "edf-min-10": {"edf_min": 10.0}, "band-below-rise": {"band_below_rise": True}},
    "gmwm": {"default": {}, "max-gm-2": {"max_gm": 2}, "full-weights": {"weighting": "full"}},
}

#: bootstrap replicates of a GMWM fit in the sweep (None: the method's default, 50);
#: ``--gmwm-boot`` lowers it where time is short (the run says so)
GMWM_BOOT = None


@contextlib.contextmanager
def _applied(setting: dict):
    """The module-level knobs of ``setting`` set for the duration (restored after)."""
    import functools

    from inertialab.noise.gmwm import fit as gmwm
    from inertialab.noise.terms import _grid
    from inertialab.noise.terms import fit as terms
    from inertialab.noise.terms import least_squares as _terms_ls

    saved = (_terms_ls.EDF_MIN, terms.fit_gmwm_curve, _grid.BAND_BELOW_RISE)
    try:
        if "edf_min" in setting:
            _terms_ls.EDF_MIN = float(setting["edf_min"])
        _grid.BAND_BELOW_RISE = bool(setting.get("band_below_rise", False))
        kw = {k: setting[k] for k in ("max_gm", "weighting") if k in setting}
        if kw:
            terms.fit_gmwm_curve = functools.partial(gmwm.fit_gmwm_curve, **kw)
        yield
    finally:
        _terms_ls.EDF_MIN, terms.fit_gmwm_curve, _grid.BAND_BELOW_RISE = saved


def _records(presets: bool = True):
    """``(log, part, axis, y, unit, rate_hz)`` of every case."""
    from benchmarks import real_logs as R
    from inertialab.sim.mems_presets import simulate

    for name in R.LOGS:
        data = R.load_shared(name)
        n = len(next(iter(data.values()))[0])
        for part, sl in (("whole", slice(None)), ("1", slice(0, n // 2)),
                         ("2", slice(n // 2, None))):
            for axis, (y, unit) in data.items():
                yield name, part, axis, np.asarray(y[sl], dtype=float), unit, R.RATE_HZ
    for p in PRESETS if presets else ():
        for s in SEEDS:
            run = simulate(p, hours=HOURS, seed=s)
            yield p, "whole", str(s), np.asarray(run.y, dtype=float), run.unit, run.rate_hz


def score(method: str, out=sys.stdout, candidates=None, presets: bool = True) -> list[dict]:
    """One row per (case, candidate) with the three checks (``candidates``: names of
    :data:`CANDIDATES` to score, default all; ``presets``: the simulated cases too)."""
    from benchmarks import real_logs as R
    from inertialab.noise.spectral.lines import spectral_lines
    from inertialab.noise.statistics.allan import oadev
    from inertialab.workflows.imu_noise import fit_axis_terms

    rows = []
    names = list(candidates or CANDIDATES[method])
    for log, part, axis, y, unit, fs in _records(presets):
        res = oadev(y, rate_hz=fs, taus="octave", confidence=0.95)
        kind = "gyro" if unit in ("dps", "dph", "rps") else "accel"
        ln = spectral_lines(y, fs)  # as benchmarks.real_logs and the workflows pass them
        for cand in names:
            setting = CANDIDATES[method][cand]
            with _applied(setting):
                # the fit `allan --imu` shows (its B rule included), with the setting's knobs
                t = fit_axis_terms(y, res, unit, kind, method, rate_hz=fs,
                                   n_boot=GMWM_BOOT if method == "gmwm" else None,
                                   b_shape=setting.get("b_shape", "band"),
                                   lines=ln if setting.get("lines", True) else ())
            c = R.check_terms(res, t)
            row = {"log": log, "part": part, "axis": axis, "method": method,
                   "candidate": cand, "B_over_text": c["B_shown_over_textbook_all"],
                   "N_over_white": c["N_over_white"], "rise": c["rise"],
                   "ok_B": bool(c["B_shown_over_textbook_all"] <= 1.05 * (1 + 1e-9)),
                   "ok_N": c["ok_N"], "ok_rise": c["ok_rise"]}
            row["ok"] = row["ok_B"] and row["ok_N"] and row["ok_rise"]
            rows.append(row)
            print(f"{log:>15} {part:>5} {axis:>3} {method} {cand:>12} "
                  f"B/text {row['B_over_text']:.2f} N/white {row['N_over_white']:.3f} "
                  f"{'pass' if row['ok'] else 'fail'}", file=out, flush=True)
    return rows


def _count(rows, cand, keep) -> int:
    return sum(r["ok"] for r in rows if r["candidate"] == cand and keep(r))


def _choose(rows, cands, keep) -> str:
    """The candidate with the most passes on the cases ``keep`` selects (ties: order)."""
    return max(cands, key=lambda c: (_count(rows, c, keep), -cands.index(c)))


def folds(rows, method: str) -> dict:
    """Fold-wise choices and held-out counts (module docstring)."""
    cands = [c for c in CANDIDATES[method] if any(r["candidate"] == c for r in rows)]
    logs = sorted({r["log"] for r in rows if r["log"] not in PRESETS})
    sim = set(PRESETS)
    out = {"per_candidate": {}, "loo": [], "halves": []}
    for c in cands:
        n = {"all": _count(rows, c, lambda r: True),
             "of_all": sum(1 for r in rows if r["candidate"] == c)}
        for name, keep in (("whole", lambda r: r["part"] == "whole" and r["log"] not in sim),
                           ("halves", lambda r: r["part"] in ("1", "2")),
                           ("presets", lambda r: r["log"] in sim)):
            n[name] = _count(rows, c, keep)
            n["of_" + name] = sum(1 for r in rows if r["candidate"] == c and keep(r))
        for k in ("ok_B", "ok_N", "ok_rise"):
            n[k] = sum(r[k] for r in rows if r["candidate"] == c)
        out["per_candidate"][c] = n
    for held in logs:
        pick = _choose(rows, cands, lambda r, h=held: r["log"] != h)
        test = [r for r in rows if r["log"] == held and r["candidate"] == pick]
        out["loo"].append({"held_out": held, "chosen": pick, "passed": sum(r["ok"] for r in test),
                           "of": len(test)})
    for train, test_part in (("1", "2"), ("2", "1")):
        pick = _choose(rows, cands, lambda r, p=train: r["part"] == p or r["log"] in sim)
        test = [r for r in rows if r["part"] == test_part and r["candidate"] == pick]
        out["halves"].append({"trained_on_half": train, "chosen": pick,
                              "passed": sum(r["ok"] for r in test), "of": len(test)})
    out["chosen"] = _choose(rows, cands, lambda r: True)
    out["default"] = cands[0]
    return out


def run(quick: bool = False, methods=("wls", "gmwm"), candidates=None,
        presets: bool = True) -> dict:
    from benchmarks.real_logs import SHARED

    if not SHARED.exists():
        return {"skipped": f"no real logs at {SHARED}"}
    if quick:  # smoke run: WLS only, the logs without the presets
        methods, presets = ("wls",), False
    out = {}
    for m in methods:
        rows = score(m, candidates=[c for c in candidates or CANDIDATES[m]
                                    if c in CANDIDATES[m]], presets=presets)
        out[m] = {"rows": rows, "folds": folds(rows, m),
                  "gmwm_boot": GMWM_BOOT if m == "gmwm" else None}
    return out


def markdown(result: dict) -> str:
    out = ["## Method settings chosen by cross-validation (leave-one-log-out, halves)", ""]
    if "skipped" in result:
        return "\n".join(out + [f"Not run: {result['skipped']}."])
    for m, res in result.items():
        f = res["folds"]
        boot = res.get("gmwm_boot")
        out += [f"### {m.upper()}" + (f" ({boot} bootstrap replicates per fit)" if boot else ""),
                "",
                "| candidate | all | whole logs | halves | presets | B <= 1.05 textbook | "
                "N within 10 % | rise named |", "|---|---|---|---|---|---|---|---|"]
        for c, n in f["per_candidate"].items():
            out.append(f"| {c} | {n['all']}/{n['of_all']} | {n['whole']}/{n['of_whole']} | "
                       f"{n['halves']}/{n['of_halves']} | {n['presets']}/{n['of_presets']} | "
                       f"{n['ok_B']} | {n['ok_N']} | {n['ok_rise']} |")
        out.append("")
        for x in f["loo"]:
            out.append(f"* leave {x['held_out']} out: chose {x['chosen']}, held-out "
                       f"{x['passed']}/{x['of']}")
        for x in f["halves"]:
            out.append(f"* trained on half {x['trained_on_half']}: chose {x['chosen']}, "
                       f"other half {x['passed']}/{x['of']}")
        out += ["", f"Chosen on every case: **{f['chosen']}** (today's default: "
                    f"{f['default']}).", ""]
    return "\n".join(out)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--method", action="append", choices=list(CANDIDATES))
    ap.add_argument("--json", help="write the rows and folds here")
    ap.add_argument("--from-json", help="only report rows written before")
    ap.add_argument("--candidate", action="append", help="score only these candidates")
    ap.add_argument("--no-presets", action="store_true", help="real logs only")
    ap.add_argument("--gmwm-boot", type=int, help="GMWM bootstrap replicates in the sweep")
    a = ap.parse_args(argv)
    global GMWM_BOOT
    GMWM_BOOT = a.gmwm_boot
    if a.from_json:
        res = json.loads(Path(a.from_json).read_text())
        res = {m: v | {"folds": folds(v["rows"], m)} for m, v in res.items()}
    else:
        res = run(methods=tuple(a.method or CANDIDATES), candidates=a.candidate,
                  presets=not a.no_presets)
    if a.json:
        Path(a.json).write_text(json.dumps(res, indent=1, default=float))
    print(markdown(res))
    return 0


if __name__ == "__main__":
    sys.exit(main())
