"""Demo time budgets: the full demo within 3 minutes and ``--quick`` within 60 s
on 2 cores, measured by running ``inertialab demo`` as a user does (a fresh process).

The report stage (sections, figures drawn to PNG, ``index.html``, ``results.json``; target:
the report figures render in under half of the earlier time) is measured on its own in
a fresh process that runs the studies first: its CPU (this process and any drawing
processes) and wall time, in one process and with the default number of drawing processes.
With ``INERTIALAB_DEMO_BASELINE=<src dir of another checkout>`` the same stage of that
code runs too, alternated with ours (best of 3 each), and the results.json numbers of both
must be identical (timing keys aside).
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

#: Environment variable naming the ``src`` directory of the code to compare against.
BASELINE_ENV = "INERTIALAB_DEMO_BASELINE"
#: Alternated repeats of the report-stage measurement (the best CPU of each is kept).
REPEATS = 3

_STAGE = r"""
import hashlib, inspect, json, os, sys, tempfile, time
for v in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(v, "1")
import warnings
warnings.simplefilter("ignore")
import inertialab
from inertialab.studies.demo import run_studies
quick, jobs = sys.argv[1] == "1", sys.argv[2]
results = run_studies(quick=quick)
c0, t0 = os.times(), time.perf_counter()
from inertialab.report.build import write_report
kw = {}
if jobs and "jobs" in inspect.signature(write_report).parameters:
    kw["jobs"] = int(jobs)
with tempfile.TemporaryDirectory() as d:
    write_report(results, d, quick=quick, **kw)
    c1, wall = os.times(), time.perf_counter() - t0
    data = json.load(open(os.path.join(d, "results.json")))
    png = os.path.getsize(os.path.join(d, "index.html"))
def strip(o):
    if isinstance(o, dict):
        return {k: strip(v) for k, v in o.items() if k not in ("wall_s", "created_utc")}
    if isinstance(o, list):
        return [strip(v) for v in o]
    return o
def count(o):
    if isinstance(o, dict):
        return sum(count(v) for v in o.values())
    if isinstance(o, list):
        return sum(count(v) for v in o)
    return int(isinstance(o, (int, float)) and not isinstance(o, bool))
canon = json.dumps(strip(data), sort_keys=True)
print(json.dumps({
    "cpu_s": (c1.user + c1.system) - (c0.user + c0.system),
    "children_cpu_s": (c1.children_user + c1.children_system)
                      - (c0.children_user + c0.children_system),
    "wall_s": wall, "jobs": kw.get("jobs"), "index_html_bytes": png,
    "results_sha256": hashlib.sha256(canon.encode()).hexdigest(),
    "results_numbers": count(strip(data)), "package": os.path.dirname(inertialab.__file__)}))
"""


def _time_demo(extra: list[str]) -> dict:
    with tempfile.TemporaryDirectory() as d:
        t0 = time.perf_counter()
        c0 = os.times()
        res = subprocess.run([sys.executable, "-m", "inertialab", "demo", "--quiet", "--json",
                              "--out", d, *extra], capture_output=True, text=True)
        c1 = os.times()
        wall = time.perf_counter() - t0
    out = {"args": extra, "wall_s": wall, "exit": res.returncode,
           "cpu_s": (c1.children_user + c1.children_system)
           - (c0.children_user + c0.children_system)}
    if res.returncode == 0:
        obj = json.loads(res.stdout)
        out["per_study_s"] = obj.get("wall_s", {})
        out["summary"] = obj.get("summary", [])
    else:
        out["stderr"] = res.stderr[-500:]
    return out


def _stage(src: str | None, quick: bool, jobs: int | None) -> dict:
    """One fresh process: the studies, then the timed report stage of the code in ``src``
    (this checkout's package when None)."""
    env = dict(os.environ)
    if src is not None:
        env["PYTHONPATH"] = src
    else:
        env["PYTHONPATH"] = os.pathsep.join(
            [str(Path(__file__).resolve().parents[1] / "src"), env.get("PYTHONPATH", "")])
    res = subprocess.run([sys.executable, "-c", _STAGE, "1" if quick else "0",
                          "" if jobs is None else str(jobs)],
                         capture_output=True, text=True, env=env)
    if res.returncode != 0:
        raise RuntimeError(f"report stage failed: {res.stderr[-800:]}")
    return json.loads(res.stdout.strip().splitlines()[-1])


def report_stage(quick: bool = False, baseline: str | None = None,
                 repeats: int = REPEATS) -> dict:
    """Report-stage CPU and wall time (best of ``repeats``, alternated with the baseline's
    runs when ``baseline`` names another checkout's ``src``), for one drawing process and
    for the default; with ``os.getloadavg()`` before and after."""
    variants = {"ours_1proc": (None, 1), "ours_2proc": (None, 2), "ours_default": (None, None)}
    if baseline:
        variants = {"baseline": (baseline, None), **variants}
    runs: dict[str, list] = {k: [] for k in variants}
    load = [os.getloadavg()]
    for _ in range(repeats):
        for key, (src, jobs) in variants.items():
            runs[key].append(_stage(src, quick, jobs))
    load.append(os.getloadavg())
    out = {"repeats": repeats, "load_before_after": [list(v) for v in load], "runs": runs,
           "cpus": os.cpu_count(), "baseline_src": baseline}
    best = {}
    for key, rs in runs.items():
        total = [r["cpu_s"] + r["children_cpu_s"] for r in rs]
        best[key] = {"cpu_s": min(total), "wall_s": min(r["wall_s"] for r in rs),
                     "median_wall_s": sorted(r["wall_s"] for r in rs)[len(rs) // 2]}
    out["best"] = best
    hashes = {r["results_sha256"] for rs in runs.values() for r in rs}
    out["results_identical"] = len(hashes) == 1
    out["results_numbers"] = runs["ours_1proc"][0]["results_numbers"]
    if baseline:
        b = best["baseline"]
        out["ratio_cpu_1proc"] = best["ours_1proc"]["cpu_s"] / b["cpu_s"]
        out["ratio_wall_default"] = best["ours_default"]["wall_s"] / b["wall_s"]
        out["ratio_wall_2proc"] = best["ours_2proc"]["wall_s"] / b["wall_s"]
        out["ratio_cpu_2proc"] = best["ours_2proc"]["cpu_s"] / b["cpu_s"]
    return out


def run(quick: bool = False) -> dict:
    result = {"quick": _time_demo(["--quick"])}
    if not quick:
        result["full"] = _time_demo([])
    result["report_stage"] = report_stage(quick=quick, baseline=os.environ.get(BASELINE_ENV))
    return result


def markdown(result: dict) -> str:
    lines = ["## Demo time budgets", "",
             "| run | budget | wall time | exit | per study (s) |", "|---|---|---|---|---|"]
    for key, budget in (("quick", 60), ("full", 180)):
        r = result.get(key)
        if r is None:
            continue
        per = ", ".join(f"{k} {v:.1f}" for k, v in r.get("per_study_s", {}).items())
        lines.append(f"| `inertialab demo{' --quick' if key == 'quick' else ''}` | {budget} s | "
                     f"{r['wall_s']:.1f} s | {r['exit']} | {per} |")
    if result.get("budgets_date_utc"):
        lines += ["", f"Budgets re-timed by `python -m benchmarks.demo budgets` on "
                      f"{result['budgets_date_utc']} (1-minute load "
                      f"{result['budgets_load'][0]:.1f}); the report stage below was measured "
                      f"on {result.get('report_stage_date_utc')}."]
    st = result.get("report_stage")
    if st:
        lines += ["", "### Report stage (figures in under half of the time)",
                  "", f"Sections, figures and `index.html`/`results.json` after the studies, "
                      f"in a fresh process; best of {st['repeats']} alternated runs; load "
                      f"average {st['load_before_after'][0][0]:.1f} before, "
                      f"{st['load_before_after'][1][0]:.1f} after ({st.get('cpus')} CPUs).", "",
                  "| code | CPU (s, all processes) | wall (s) | median wall (s) |",
                  "|---|---|---|---|"]
        names = {"baseline": f"baseline (`{st.get('baseline_src')}`)",
                 "ours_1proc": "this code, one process",
                 "ours_2proc": "this code, two drawing processes",
                 "ours_default": "this code, default (2 if a CPU is idle, else 1)"}
        for key, b in st["best"].items():
            lines.append(f"| {names.get(key, key)} | {b['cpu_s']:.2f} | {b['wall_s']:.2f} | "
                         f"{b['median_wall_s']:.2f} |")
        if "ratio_cpu_1proc" in st:
            lines += ["", f"CPU ratio (one process / baseline): {st['ratio_cpu_1proc']:.2f}; "
                          f"two processes: CPU {st['ratio_cpu_2proc']:.2f}, wall "
                          f"{st['ratio_wall_2proc']:.2f}; default: wall "
                          f"{st['ratio_wall_default']:.2f}; "
                          f"results.json numbers identical: "
                          f"{'yes' if st['results_identical'] else 'NO'} "
                          f"({st['results_numbers']} numbers, timing keys aside)."]
    return "\n".join(lines)



def budgets_only() -> int:
    """``python -m benchmarks.demo budgets``: re-time ``inertialab demo --quick`` and
    ``inertialab demo`` (the demo's time budgets) and merge them into the stored
    ``benchmarks/results/demo.json``; the report-stage comparison (minutes, alternated
    with a baseline checkout) stays as stored, with its own date."""
    from benchmarks.__main__ import store

    path = Path(__file__).resolve().parent / "results" / "demo.json"
    record = json.loads(path.read_text())
    res = record["result"]
    stage_date = res.get("report_stage_date_utc", record.get("date_utc"))
    res["quick"] = _time_demo(["--quick"])
    res["full"] = _time_demo([])
    res["report_stage_date_utc"] = stage_date
    res["budgets_date_utc"] = time.strftime("%Y-%m-%d", time.gmtime())
    res["budgets_load"] = list(os.getloadavg())
    print(f"wrote {store('demo', record)}", file=sys.stderr)
    return 0


if __name__ == "__main__":
    if sys.argv[1:] != ["budgets"]:
        sys.exit("usage: python -m benchmarks.demo budgets   (the whole benchmark: "
                 "python -m benchmarks demo)")
    sys.exit(budgets_only())
