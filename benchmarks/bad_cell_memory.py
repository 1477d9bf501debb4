"""Memory of a big CSV with one bad cell at its end: the error path against the good path.

A gyro log of N rows (``t_s,rate_dph``) is read by ``inertialab validate FILE --kind
gyro_log`` twice, each in a fresh process: as written (the good path, exit 0) and with
``abc`` in place of its last rate (the error path, exit 2 with one line). The peak
resident memory of each run is the kernel's ``ru_maxrss`` of that one child (a wrapper
process per run, so no other child's peak is counted). The promise (docs/robustness.md):
the error path peaks at most 10 % above the good path. Sizes: 1e7 and 1.4e7 rows (the
fuzz's), ``--quick`` 1e6 and 1.4e6.

    python -m benchmarks bad_cell_memory            # also stored, docs/results.md
    python -m benchmarks.bad_cell_memory --rows 1e7 --src OTHER/src   # another tree
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
#: Allowed excess of the error path's peak over the good path's.
MAX_EXCESS = 0.10

_WRAPPER = ("import resource, subprocess, sys, json, time\n"
            "t = time.perf_counter()\n"
            "p = subprocess.run([sys.executable, '-m', 'inertialab', 'validate', sys.argv[1],\n"
            "                    '--kind', 'gyro_log'], capture_output=True, text=True)\n"
            "print(json.dumps({'code': p.returncode, 'wall_s': time.perf_counter() - t,\n"
            "                  'peak_mb': resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss"
            " / 1024, 'stderr': p.stderr.strip().splitlines()[-1:] }))\n")


def write_log(path: Path, n_rows: int, *, bad_last: bool, block: int = 1_000_000) -> None:
    """``t_s,rate_dph`` at 100 Hz, seeded noise; ``abc`` as the last rate when
    ``bad_last``."""
    import numpy as np

    rng = np.random.default_rng(0)
    with open(path, "w") as fh:
        fh.write("t_s,rate_dph\n")
        for start in range(0, n_rows, block):
            k = min(block, n_rows - start)
            t = (np.arange(start, start + k) / 100.0).round(2)
            y = rng.normal(0.0, 0.5, k).round(4)
            lines = [f"{a:.2f},{b:.4f}" for a, b in zip(t.tolist(), y.tolist())]
            if bad_last and start + k == n_rows:
                lines[-1] = lines[-1].split(",")[0] + ",abc"
            fh.write("\n".join(lines) + "\n")


def peak(path: Path, src: Path) -> dict:
    """Peak resident memory (MB), exit status, wall time and last stderr line of one
    ``validate`` run of ``path`` with the package of ``src``."""
    env = dict(os.environ, PYTHONPATH=str(src), MPLBACKEND="Agg")
    out = subprocess.run([sys.executable, "-c", _WRAPPER, str(path)], capture_output=True,
                         text=True, env=env, check=True)
    return json.loads(out.stdout)


def measure(n_rows: int, src: Path = ROOT / "src") -> dict:
    with tempfile.TemporaryDirectory(prefix="inertialab-badcell-") as tmp:
        good, bad = Path(tmp) / "good.csv", Path(tmp) / "bad.csv"
        write_log(good, n_rows, bad_last=False)
        write_log(bad, n_rows, bad_last=True)
        g, b = peak(good, src), peak(bad, src)
        size_mb = good.stat().st_size / 1e6
    return {"rows": n_rows, "file_mb": round(size_mb, 1), "good": g, "bad": b,
            "excess": b["peak_mb"] / g["peak_mb"] - 1.0,
            "within": b["peak_mb"] <= (1 + MAX_EXCESS) * g["peak_mb"]}


def run(quick: bool = False) -> dict:
    sizes = (1_000_000, 1_400_000) if quick else (10_000_000, 14_000_000)
    t0 = time.perf_counter()
    rows = [measure(n) for n in sizes]
    return {"sizes": list(sizes), "rows": rows, "max_excess": MAX_EXCESS,
            "wall_s": time.perf_counter() - t0}


def markdown(result: dict) -> str:
    out = ["## Memory: one bad cell at the end of a big CSV", "",
           "Peak resident memory of `inertialab validate FILE --kind gyro_log` (fresh "
           "process each) on a `t_s,rate_dph` log, as written and with `abc` as its last "
           f"rate. The error path may peak at most {100 * result['max_excess']:.0f} % above "
           "the good path.", "",
           "| rows | file MB | good path MB (exit) | error path MB (exit) | error/good - 1 | "
           "within |", "|---|---|---|---|---|---|"]
    for r in result["rows"]:
        out.append(f"| {r['rows']:.3g} | {r['file_mb']:.0f} | {r['good']['peak_mb']:.0f} "
                   f"({r['good']['code']}) | {r['bad']['peak_mb']:.0f} ({r['bad']['code']}) | "
                   f"{100 * r['excess']:+.1f} % | {'yes' if r['within'] else 'NO'} |")
    return "\n".join(out) + "\n"


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--rows", type=float, action="append", help="rows (repeatable)")
    ap.add_argument("--src", type=Path, default=ROOT / "src", help="package tree measured")
    args = ap.parse_args(argv)
    for n in args.rows or [1e7, 1.4e7]:
        print(json.dumps(measure(int(n), args.src)), flush=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
