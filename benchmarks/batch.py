"""Fleet engine: a lot of triaxial units serial vs a 2-worker Dask LocalCluster,
and the chunked Allan deviation of a long .npy log serial vs Dask.

``run(quick)`` returns wall and CPU times with the seeds and sizes; ``markdown`` writes the
docs/results.md section. There is no paper figure for this (the seed papers calibrate one
unit at a time); the comparison is ours against our serial path.
"""

from __future__ import annotations

import os
import tempfile
import time
from pathlib import Path

import numpy as np

from inertialab.cli.batch import expand_inputs
from inertialab.noise.statistics.allan import oadev
from inertialab.noise.statistics.allan_dask import oadev_dask, open_client
from inertialab.sim.triaxial_poses import simulate_line
from inertialab.workflows.batch import run_batch

SEED = 7


def _lot(d: Path, n_units: int) -> list[Path]:
    sim = simulate_line(n_units, seed=SEED)
    for uid, frame in sim.data.groupby("unit_id", sort=True):
        frame.to_csv(d / f"{uid}.csv", index=False)
    return expand_inputs(str(d / "*.csv"))


def _timed(fn):
    w, c = time.perf_counter(), time.process_time()
    out = fn()
    return out, time.perf_counter() - w, time.process_time() - c


def run(quick: bool = False) -> dict:
    n_units = 40 if quick else 200
    n_samples = 2_000_000 if quick else 20_000_000
    opts = {"g_local": 9.8}
    with tempfile.TemporaryDirectory() as tmp:
        d = Path(tmp)
        paths = _lot(d, n_units)
        ser, ser_wall, ser_cpu = _timed(lambda: run_batch("calibrate-triaxial", paths,
                                                          options=opts, scheduler="serial"))
        rng = np.random.default_rng(SEED)
        y = 0.1 * rng.standard_normal(n_samples) + np.cumsum(1e-4 * rng.standard_normal(
            n_samples))
        npy = d / "long.npy"
        np.save(npy, y)
        ref, allan_ser_wall, allan_ser_cpu = _timed(lambda: oadev(y, rate_hz=100.0))
        t0 = time.perf_counter()
        with open_client("local", workers=2) as cl:
            start_s = time.perf_counter() - t0
            run_batch("calibrate-triaxial", paths[:4], options=opts, client=cl)  # warm imports
            par, par_wall, par_cpu = _timed(lambda: run_batch(
                "calibrate-triaxial", paths, options=opts, client=cl))
            dk, allan_par_wall, _ = _timed(lambda: oadev_dask(npy, rate_hz=100.0, client=cl))
    same = all(a.figures == b.figures for a, b in zip(ser.units, par.units))
    rel = float(np.max(np.abs(dk.dev / ref.dev - 1)))
    return {
        "settings": {"seed": SEED, "n_units": n_units, "lot": "simulate_line (rig18, 18 poses)",
                     "method": "calib.triaxial.calibrate lm/norm", "workers": 2,
                     "allan_samples": n_samples, "allan_taus": "octave", "cpus": os.cpu_count(),
                     "load_avg_1min": os.getloadavg()[0]},
        "lot": {"serial_wall_s": ser_wall, "serial_cpu_s": ser_cpu, "dask_wall_s": par_wall,
                "dask_client_cpu_s": par_cpu, "cluster_start_s": start_s,
                "speedup": ser_wall / par_wall, "identical_figures": same,
                "yield": par.yield_fraction},
        "allan": {"serial_wall_s": allan_ser_wall, "serial_cpu_s": allan_ser_cpu,
                  "dask_wall_s": allan_par_wall, "max_rel_diff": rel,
                  "n_taus": int(len(ref.taus_s))},
    }


def markdown(result: dict) -> str:
    s, lot, al = result["settings"], result["lot"], result["allan"]
    return "\n".join([
        "## Fleets on Dask",
        "",
        f"Lot of {s['n_units']} simulated triaxial units ({s['lot']}, seed {s['seed']}), "
        f"{s['method']}, on {s['cpus']} CPUs (1-minute load average at the start: "
        f"{s['load_avg_1min']:.1f}; the machine is shared, so wall times are noisy).",
        "",
        "| path | wall (s) | notes |",
        "|---|---|---|",
        f"| serial (one process) | {lot['serial_wall_s']:.2f} | CPU {lot['serial_cpu_s']:.2f} s |",
        f"| Dask LocalCluster, {s['workers']} workers | {lot['dask_wall_s']:.2f} | "
        f"speed-up {lot['speedup']:.2f}x; cluster start {lot['cluster_start_s']:.1f} s not "
        "included |",
        "",
        f"Per-unit figures identical between the two paths: {lot['identical_figures']}; "
        f"yield {100 * lot['yield']:.1f} % (no tolerance given: every processed unit passes).",
        "",
        f"Chunked overlapping Allan deviation of {s['allan_samples']:,} samples "
        f"({al['n_taus']} octave taus): in-memory serial {al['serial_wall_s']:.2f} s, Dask "
        f"from the .npy file {al['dask_wall_s']:.2f} s (includes the sequential checkpoint "
        f"pass and the noise identification on the client); largest relative difference "
        f"{al['max_rel_diff']:.1e} (target 1e-12"
        + ("; met)." if al["max_rel_diff"] <= 1e-12 else
           "; NOT met here: the noise core's in-memory octave grid uses a lag-doubling "
           "shortcut whose rounding differs from its own angle-based kernel, which the Dask "
           "path reproduces block for block; against the angle kernel the tests find ~1e-15)."),
        "",
        "The paper has no figure for this; the speed-up is bounded by the two cores, and "
        "on a loaded machine the Dask path can be slower than serial (it does not reproduce "
        "a speed-up where no idle core exists).",
    ])
