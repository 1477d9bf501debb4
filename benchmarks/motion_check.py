"""Motion refused per axis: false positives on static logs, detections on simulated motion.

:func:`inertialab.workflows.imu_noise_static.motion_reasons` (the check ``allan --imu``
runs) on

* the four MEMS presets of :mod:`inertialab.sim.mems_presets` as triads (three
  independent axes, seeds ``3 s``, ``3 s + 1``, ``3 s + 2``; the accelerometer preset
  with standard gravity added to its z axis), seeds ``s`` = 0..7, 0.05, 0.5 and 2 h
  (quick: seeds 0..1, 0.05 and 0.5 h): every axis must pass;
* the 12 axes of the two shared 2.8-h ADIS16405 logs and the six axes of each shared PX4
  log (``sample_logging_tagged_and_default_params.ulg`` is a static bench: must pass);
* simulated motion, seeds 0..7 (:func:`flight`, :func:`handling`, :func:`sway`): every
  axis must be refused; a static bench with a 0.5-Hz wobble (:func:`wobble_bench`): no
  axis refused.

Reported: per case, the axes refused out of the axes judged, and the largest and smallest
band ratio of an axis (its highest band median over the white floor, :func:`band_excess`;
an axis may be refused by the excursion or gravity test instead).

Command: ``python -m benchmarks motion_check`` (``--quick`` for the reduced set).
"""

from __future__ import annotations

import numpy as np
from scipy.signal import butter, iirpeak, lfilter, sosfiltfilt

G = 9.80665
FS = 250.0
AXES = ("gx", "gy", "gz", "ax", "ay", "az")
PRESETS = ("consumer-100hz", "industrial-400hz", "consumer-1khz", "accel-200hz")


def _gravity(roll, pitch):
    """Specific force of gravity in the body frame for roll and pitch (rad)."""
    return G * np.column_stack([-np.sin(pitch), np.sin(roll) * np.cos(pitch),
                                np.cos(roll) * np.cos(pitch)])


def _record(rng, rates, lin_acc=None, gyro_sigma=0.005, acc_sigma=0.03) -> dict:
    """Six axes from body rates (rad/s, n x 3): the accelerometers see gravity turned by
    the integrated roll and pitch (plus ``lin_acc``), each axis with white sensor noise
    of ``gyro_sigma`` rad/s and ``acc_sigma`` m/s^2 per sample."""
    roll = np.cumsum(rates[:, 0]) / FS
    pitch = np.cumsum(rates[:, 1]) / FS
    acc = _gravity(roll, pitch) + (0.0 if lin_acc is None else lin_acc)
    gyro = rates + gyro_sigma * rng.standard_normal(rates.shape)
    acc = acc + acc_sigma * rng.standard_normal(acc.shape)
    return {a: (gyro if a[0] == "g" else acc)[:, "xyz".index(a[1])] for a in AXES}


def flight(seed: int = 0, seconds: float = 69.0) -> dict:
    """A flight-like 69-s record at 250 Hz: body rates band-limited Gaussian noise
    (4th-order Butterworth band 2-4 Hz, zero phase) scaled to peak at +-2.7 rad/s per
    axis, linear accelerations of 1 m/s^2 rms in 1-5 Hz, MEMS-like white noise."""
    rng = np.random.default_rng(seed)
    n = int(seconds * FS)
    sos = butter(2, (2.0, 4.0), btype="bandpass", fs=FS, output="sos")
    rates = sosfiltfilt(sos, rng.standard_normal((n, 3)), axis=0)
    rates *= 2.7 / np.abs(rates).max(axis=0)
    sos_a = butter(2, (1.0, 5.0), btype="bandpass", fs=FS, output="sos")
    lin = sosfiltfilt(sos_a, rng.standard_normal((n, 3)), axis=0)
    lin /= lin.std(axis=0)
    return _record(rng, rates, lin)


def handling(seed: int = 0, seconds: float = 120.0) -> dict:
    """A bench log during which the sensor is picked up and turned 5 times: episodes of
    3-8 s (Hann-windowed low-passed noise below 1.5 Hz, 0.5 rad/s rms) on a static record."""
    rng = np.random.default_rng(seed)
    n = int(seconds * FS)
    rates = np.zeros((n, 3))
    sos = butter(2, 1.5, fs=FS, output="sos")
    for start in np.sort(rng.uniform(5.0, seconds - 10.0, 5)):
        m = int(rng.uniform(3.0, 8.0) * FS)
        i = int(start * FS)
        m = min(m, n - i)
        burst = sosfiltfilt(sos, rng.standard_normal((m, 3)), axis=0)
        burst *= 0.5 / burst.std() * np.hanning(m)[:, None]
        rates[i:i + m] += burst
    return _record(rng, rates)


def sway(seed: int = 0, seconds: float = 300.0) -> dict:
    """A slow sway (a mast, a ship, a person holding the sensor): each rate a resonance
    at 0.3 Hz of quality factor 3 (bandwidth 0.1 Hz) driven by white noise, 0.05 rad/s
    rms (about 1.5 deg of tilt)."""
    rng = np.random.default_rng(seed)
    n = int(seconds * FS)
    b, a = iirpeak(0.3, 3.0, fs=FS)
    rates = lfilter(b, a, rng.standard_normal((n + int(60 * FS), 3)), axis=0)[-n:]
    rates *= 0.05 / rates.std(axis=0)
    return _record(rng, rates)


def wobble_bench(seed: int = 0, seconds: float = 600.0, wobble: float = 0.05) -> dict:
    """A static bench with a 0.5-Hz line of ``wobble`` rad/s on gx (a pump, a fan)."""
    rng = np.random.default_rng(seed)
    n = int(seconds * FS)
    rates = np.zeros((n, 3))
    rates[:, 0] = wobble * np.sin(2 * np.pi * 0.5 * np.arange(n) / FS + rng.uniform(0, 6.3))
    return _record(rng, rates)  # the accelerometers see the +-0.9-deg roll it makes


def _judge(cols: dict, rate_hz: float) -> dict:
    from inertialab.workflows.imu_noise_static import band_excess, motion_reasons

    why = motion_reasons(cols, rate_hz)
    ratios = [band_excess(y, rate_hz) for y in cols.values()]
    vals = [r[0] for r in ratios if r is not None]
    return {"refused": sorted(why), "n_axes": len(cols),
            "max_ratio": float(max(vals, default=float("nan"))),
            "min_ratio": float(min(vals, default=float("nan")))}


def preset_triad(name: str, seed: int, hours: float) -> tuple[dict, float]:
    from inertialab.sim.mems_presets import simulate

    runs = [simulate(name, hours=hours, seed=3 * seed + k) for k in range(3)]
    kind = "a" if runs[0].kind == "accel" else "g"
    cols = {f"{kind}{c}": r.y for c, r in zip("xyz", runs)}
    if kind == "a":
        cols["az"] = cols["az"] + G
    return cols, runs[0].rate_hz


def run_presets(seeds, hours) -> list[dict]:
    rows = []
    for name in PRESETS:
        for h in hours:
            for s in seeds:
                cols, fs = preset_triad(name, s, h)
                rows.append({"case": name, "seed": s, "hours": h} | _judge(cols, fs))
    return rows


def run_real() -> list[dict]:
    rows = []
    try:
        from benchmarks.real_logs import SHARED, load_shared

        for name in ("imu3", "imu4"):
            cols = {a: y for a, (y, _u) in load_shared(name).items()}
            rows.append({"case": f"ADIS16405 {name}", "static": True} | _judge(cols, 100.0))
        from inertialab.io import read_record
        from inertialab.workflows.imu_noise import axis_columns

        for f in sorted((SHARED.parent / "px4").glob("*.ulg")):
            rec = read_record(f, "gyro_log")
            tb = rec.timebase
            cols = {a: tb.place(np.asarray(y, dtype=float))
                    for a, (_c, y, _u) in axis_columns(rec).items()}
            rows.append({"case": f.name, "static": "tagged" in f.name}
                        | _judge(cols, tb.rate_hz))
    except (ImportError, FileNotFoundError, OSError) as exc:
        rows.append({"case": "real logs", "skipped": str(exc)})
    return rows


def low_passed(cols: dict, fraction: float) -> dict:
    """``cols`` through a 2nd-order Butterworth low-pass at ``fraction`` of the rate (a
    sensor's filter set low), started at the first sample."""
    from scipy.signal import sosfilt

    sos = butter(2, 2.0 * fraction, output="sos")
    return {a: sosfilt(sos, y - y[0]) + y[0] for a, y in cols.items()}


def run_filtered(seeds) -> dict:
    """The sensor's own low-pass set low: static presets (3-min gyro axes of
    consumer-100hz and consumer-1khz, the filter moved to ``fraction * rate``) and the
    simulated motion through the same filter."""
    from inertialab.sim.mems_presets import preset, simulate

    static, motion = [], []
    for frac in (0.05, 0.02, 0.01):
        for name in ("consumer-100hz", "consumer-1khz"):
            for s in seeds:
                r = simulate(preset(name).with_(lpf_fraction=frac), hours=0.05, seed=s)
                static.append({"case": f"{name} low-pass at rate*{frac:g}", "seed": s}
                              | _judge({"gx": r.y}, r.rate_hz))
    for frac in (0.1, 0.04, 0.02, 0.01):
        for f in (flight, handling, sway):
            motion += [{"case": f"{f.__name__} low-pass at rate*{frac:g}", "seed": s}
                       | _judge(low_passed(f(s), frac), FS) for s in seeds]
    return {"static": static, "motion": motion}


def run(quick: bool = False) -> dict:
    """``python -m benchmarks motion_check``."""
    import warnings

    seeds = range(2) if quick else range(8)
    hours = (0.05, 0.5) if quick else (0.05, 0.5, 2.0)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        presets = run_presets(seeds, hours)
        real = run_real()
    motion = [{"case": f.__name__, "seed": s} | _judge(f(s), FS)
              for f in (flight, handling, sway) for s in seeds]
    wobble = [{"case": "wobble_bench", "seed": s} | _judge(wobble_bench(s), FS) for s in seeds]
    filtered = run_filtered(range(2) if quick else range(4))
    false_pos = sum(len(r["refused"]) for r in presets + wobble)
    false_pos += sum(len(r.get("refused", [])) for r in real if r.get("static"))
    return {"presets": presets, "real": real, "motion": motion, "wobble": wobble,
            "filtered": filtered,
            "false_positive_axes": false_pos,
            "static_axes": sum(r["n_axes"] for r in presets + wobble)
            + sum(r.get("n_axes", 0) for r in real if r.get("static")),
            "motion_refused": sum(len(r["refused"]) for r in motion),
            "motion_axes": sum(r["n_axes"] for r in motion)}


def markdown(result: dict) -> str:
    lines = ["## Motion refused per axis (`allan --imu`)", "",
             f"Static axes refused (false positives): **{result['false_positive_axes']} of "
             f"{result['static_axes']}**; simulated motion refused: "
             f"**{result['motion_refused']} of {result['motion_axes']}** axes.", "",
             "| case | records | axes refused / judged | band ratio of an axis: largest "
             "| smallest |", "|---|---|---|---|---|"]
    groups: dict = {}
    filt = result.get("filtered", {})
    for r in (result["presets"] + result["motion"] + result["wobble"]
              + filt.get("static", []) + filt.get("motion", [])):
        key = r["case"] + (f" {r['hours']:g} h" if "hours" in r else "")
        g = groups.setdefault(key, [0, 0, 0, 0.0, float("inf")])
        g[0] += 1
        g[1] += len(r["refused"])
        g[2] += r["n_axes"]
        g[3] = max(g[3], r["max_ratio"])
        g[4] = min(g[4], r.get("min_ratio", float("nan")))
    for r in result["real"]:
        if "n_axes" in r:
            groups[r["case"] + (" (static)" if r["static"] else "")] = [
                1, len(r["refused"]), r["n_axes"], r["max_ratio"], r.get("min_ratio")]
    for key, (n, ref, ax, top, low) in groups.items():
        lines.append(f"| {key} | {n} | {ref} / {ax} | {top:.3g} | {low:.3g} |")
    return "\n".join(lines) + "\n"


if __name__ == "__main__":
    import json
    import sys

    print(json.dumps(run(quick="--quick" in sys.argv), indent=1))
