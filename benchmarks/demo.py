"""Demo time budgets (issue 9): the full demo within 3 minutes and ``--quick`` within 60 s
on 2 cores, measured by running ``inertialab demo`` as a user does (a fresh process)."""

from __future__ import annotations

import subprocess
import sys
import tempfile
import time


def _time_demo(extra: list[str]) -> dict:
    with tempfile.TemporaryDirectory() as d:
        t0 = time.perf_counter()
        res = subprocess.run([sys.executable, "-m", "inertialab", "demo", "--quiet", "--json",
                              "--out", d, *extra], capture_output=True, text=True)
        wall = time.perf_counter() - t0
    out = {"args": extra, "wall_s": wall, "exit": res.returncode}
    if res.returncode == 0:
        import json

        obj = json.loads(res.stdout)
        out["per_study_s"] = obj.get("wall_s", {})
        out["summary"] = obj.get("summary", [])
    else:
        out["stderr"] = res.stderr[-500:]
    return out


def run(quick: bool = False) -> dict:
    result = {"quick": _time_demo(["--quick"])}
    if not quick:
        result["full"] = _time_demo([])
    return result


def markdown(result: dict) -> str:
    lines = ["## Demo time budgets (issue 9)", "",
             "| run | budget | wall time | exit | per study (s) |", "|---|---|---|---|---|"]
    for key, budget in (("quick", 60), ("full", 180)):
        r = result.get(key)
        if r is None:
            continue
        per = ", ".join(f"{k} {v:.1f}" for k, v in r.get("per_study_s", {}).items())
        lines.append(f"| `inertialab demo{' --quick' if key == 'quick' else ''}` | {budget} s | "
                     f"{r['wall_s']:.1f} s | {r['exit']} | {per} |")
    return "\n".join(lines)
