"""One calibration session on arrays (spec 002 §2.3, §7.3): the static data in the working
unit, the accelerometer fit followed by the gyro calibration by integration, and the
folding of fit and unit conversion into a :class:`~inertialab.calib.triaxial.TriaxialCalibration`.

How a record becomes :class:`StaticData` (units, references, static-interval detection)
is the workflow's job (:mod:`inertialab.workflows.triaxial`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from inertialab import units
from inertialab.calib.triaxial import CalibrationFit, TriaxialCalibration, calibrate
from inertialab.errors import InputError
from inertialab.io.timestamps import stamps_rate_hz
from inertialab.noise.segments.static_intervals import StaticIntervals
from inertialab.sensors import triaxial as tx
from inertialab.sensors.gyro_triad import GyroCalibration, calibrate_gyro


@dataclass(frozen=True)
class StaticData:
    """Static records in the working unit, ready for :func:`calibrate`.

    ``raw_scale``/``raw_offset`` map the file's raw unit to the working unit:
    ``working = (raw - raw_offset) * raw_scale``; ``counts`` marks counts mode.
    """

    a: np.ndarray
    ref: np.ndarray | None
    g: float
    raw_unit: str
    raw_scale: float
    raw_offset: float
    counts: bool
    unit_id: np.ndarray | None = None
    pos_id: np.ndarray | None = None
    n_samples: np.ndarray | None = None
    intervals: StaticIntervals | None = None
    dropped: tuple = ()
    k_thr: float | None = None
    sweep_counts: dict | None = None


@dataclass(frozen=True)
class CalibrationRun:
    """What :func:`calibrate_record_data` returns: the model, the fit and the data used."""

    model: TriaxialCalibration
    fit: CalibrationFit
    data: StaticData
    gyro_fit: GyroCalibration | None = None
    gyro_nominal: np.ndarray | None = None


def to_model(fit: CalibrationFit, data: StaticData, *, gyro: dict | None = None) -> TriaxialCalibration:
    """Fold the fit and the unit conversion into ``calibrated = M @ (raw - offset)``."""
    Cx = tx.correction_matrix(fit.x)
    b = fit.x[:3]
    M = Cx * data.raw_scale
    offset = data.raw_offset + b / data.raw_scale
    names = list(tx.PARAM_NAMES) + (list(tx.PHI_NAMES) if fit.phi is not None else [])
    stderr = None
    if fit.stderr is not None:
        stderr = dict(zip(names, [float(s) for s in fit.stderr]))
    else:
        stderr = dict.fromkeys(names)
    return TriaxialCalibration(
        method=fit.method, objective=fit.objective, params=fit.params, correction_matrix=M,
        offset=np.asarray(offset, dtype=float), raw_unit=data.raw_unit, g_local=data.g,
        stderr=stderr, phi=fit.phi, residual_rms=fit.residual_rms, iterations=fit.iterations,
        nfev=fit.nfev, n_records=fit.n_records,
        static_intervals=None if data.intervals is None else int(data.intervals.count), gyro=gyro,
        rest_raw=np.asarray(data.a, dtype=float) / data.raw_scale + data.raw_offset)


def calibrate_record_data(data: StaticData, *, method="lm", objective="norm", rng=0,
                          gyro_raw=None, t=None, gyro_suffix: str | None = None,
                          gyro_lsb_per_rps: float | None = None, meta: dict | None = None,
                          refine_gyro_bias: bool = False, **kw) -> CalibrationRun:
    """Accelerometer calibration, then (with ``gyro_raw`` of a raw log) the gyro (§7.3).

    The gyro's sample interval is the one the static intervals were detected at
    (``data.intervals.fs``: the record's time base when the workflow detected them)."""
    fit = calibrate(data.a, ref=data.ref, method=method, objective=objective, g=data.g, rng=rng,
                    counts=data.counts, **kw)
    gyro_block = None
    gfit = None
    if gyro_raw is not None:
        if data.intervals is None or t is None:
            raise InputError("gyro calibration needs a raw log (static records carry no motion)")
        meta = meta or {}
        graw = np.asarray(gyro_raw, dtype=float)
        dt = 1.0 / float(data.intervals.fs)
        m0_from = "unit"
        if gyro_suffix == "lsb":
            lpr = gyro_lsb_per_rps if gyro_lsb_per_rps is not None else meta.get("gyro_lsb_per_rps")
            if lpr is None:
                iv = data.intervals
                keep = np.zeros(iv.count, dtype=bool)
                keep[np.asarray(data.pos_id, dtype=int) - 1] = True
                M0 = np.eye(3) * gyro_scale_from_data(t, graw, iv.start[keep], iv.stop[keep],
                                                      tx.correct(fit.x, iv.mean[keep]), dt=dt)
                m0_from = "data"
            else:
                M0 = np.eye(3) / float(lpr)
        else:
            M0 = np.eye(3) * float(units.to_si(1.0, gyro_suffix or "rps"))
        iv = data.intervals
        keep_mask = np.zeros(iv.count, dtype=bool)
        keep_mask[np.asarray(data.pos_id, dtype=int) - 1] = True  # saturated ones are out
        # gravity directions from the calibrated accelerometer (interval means, working unit)
        v = tx.correct(fit.x, iv.mean)
        start, stop = iv.start[keep_mask], iv.stop[keep_mask]
        gfit = calibrate_gyro(t, graw, start, stop, v[keep_mask], matrix0=M0,
                              refine_bias=refine_gyro_bias, dt=dt)
        gyro_block = {
            "method": "integration", "raw_unit": gyro_suffix or "rps",
            "correction_matrix": gfit.matrix, "offset": gfit.bias,
            "params": {"bgx": float(gfit.bias[0]), "bgy": float(gfit.bias[1]),
                       "bgz": float(gfit.bias[2]),
                       **{f"m{i + 1}{j + 1}": float(gfit.matrix[i, j]) for i in range(3)
                          for j in range(3)}},
            "stderr": {**({f"bg{c}": float(s) for c, s in zip("xyz", gfit.stderr_bias)}
                          if gfit.stderr_bias is not None else dict.fromkeys(("bgx", "bgy", "bgz"))),
                       **{f"m{i + 1}{j + 1}": (None if gfit.stderr_matrix is None else
                                               float(gfit.stderr_matrix[i, j]))
                          for i in range(3) for j in range(3)}},
            "residual_rms": gfit.residual_rms, "iterations": gfit.nfev, "nfev": gfit.nfev,
            "n_records": gfit.n_pairs, "static_intervals": int(start.size), "cond": gfit.cond,
            "start_from": m0_from,
        }
    return CalibrationRun(model=to_model(fit, data, gyro=gyro_block), fit=fit, data=data,
                          gyro_fit=gfit, gyro_nominal=None if gfit is None else M0)



def gyro_scale_from_data(t, gyro_raw, start, stop, directions, *, min_angle_deg: float = 10.0,
                         dt: float | None = None) -> float:
    """Starting gyro sensitivity (rad/s per raw unit) from the data alone.

    For each motion between consecutive static intervals, the angle between the two
    gravity directions (from the calibrated accelerometer) is a lower bound of the angle
    turned, reached when the motion turns about one axis perpendicular to gravity (as a
    turntable or a hand tipping the sensor over does); the integrated raw rate (minus
    the first rest's mean) measures the angle turned in raw units. Each ratio is thus a
    lower bound of the sensitivity; the 90th percentile over motions of at least
    ``min_angle_deg`` (measured on ``rawlog62-counts``: 1.1 % below the truth; the median
    was 14.5 % below, heading changes about the vertical being invisible to gravity) is
    the start of M_g = s I, which the LM of
    :func:`~inertialab.sensors.gyro_triad.calibrate_gyro` then refines. ``dt``: the
    sample interval, s (the record's ``timebase.tau0_s``); default the one the stamps
    ``t`` give (:func:`inertialab.io.timestamps.stamps_rate_hz`).

    Raises
    ------
    InputError
        No motion tips gravity by ``min_angle_deg`` (the sensitivity cannot be started
        from the data; give it).
    """
    t = np.asarray(t, dtype=float)
    g = np.asarray(gyro_raw, dtype=float)
    start = np.asarray(start, dtype=int)
    stop = np.asarray(stop, dtype=int)
    v = np.asarray(directions, dtype=float)
    v = v / np.linalg.norm(v, axis=1)[:, None]
    dt = 1.0 / stamps_rate_hz(t) if dt is None else float(dt)
    b0 = g[start[0]:stop[0]].mean(axis=0)
    ratios = []
    for j in range(len(start) - 1):
        ang = float(np.arccos(np.clip(v[j] @ v[j + 1], -1.0, 1.0)))
        if ang < np.deg2rad(min_angle_deg):
            continue
        w = np.linalg.norm((g[stop[j] - 1:start[j + 1] + 1] - b0).sum(axis=0) * dt)
        if w > 0:
            ratios.append(ang / w)
    if not ratios:
        raise InputError(f"no motion tips gravity by {min_angle_deg:g} deg: the gyro sensitivity "
                         "cannot be started from the data; give argument 'gyro_lsb_per_rps'")
    return float(np.percentile(ratios, 90))


def quality(run: CalibrationRun, *, level: float = 0.95) -> dict:
    """Quality of a calibration on the user's own data.

    Returns a JSON-ready dict:

    - ``norm_error``: per pose ``|a_cal| - g`` (m/s^2) with its RMSE, SD and max;
    - ``eq21`` (records with references): spec 002 eq. 21, the vector error
      ``e_l = |a_ref - a_cal|`` with RMSE, SD and mean (Table 10); for S12 the references
      are turned by the fitted mount rotation, i.e. scored in the sensor frame the
      model outputs;
    - ``per_pose``: pos_id, norm error and (with references) vector error of every pose;
    - ``ci95`` (``level``): ``value -+ t * stderr`` for every parameter with a standard
      error, Student t with the fit's degrees of freedom (residuals minus parameters);
      the gyro parameters likewise;
    - ``coverage``: the calibrated gravity directions' scatter-matrix eigenvalues (1/3
      each for poses spread evenly over the sphere, one near 0 for poses in a plane).
    """
    from scipy import stats

    from inertialab.metrics import rmse, vector_error

    fit, data = run.fit, run.data
    a_cal = tx.correct(fit.x, data.a)
    ne = np.linalg.norm(a_cal, axis=1) - data.g
    out = {"norm_error": {"rmse_mps2": rmse(np.zeros_like(ne), ne),
                          "sd_mps2": float(np.std(ne, ddof=1)) if ne.size > 1 else None,
                          "max_abs_mps2": float(np.max(np.abs(ne)))}}
    pos = (np.arange(1, len(ne) + 1) if data.pos_id is None else np.asarray(data.pos_id))
    per = [{"pos_id": int(p) if np.issubdtype(np.asarray(p).dtype, np.integer) else str(p),
            "norm_error_mps2": float(e)} for p, e in zip(pos, ne)]
    if data.ref is not None and np.all(np.isfinite(data.ref)):
        ref = data.ref if fit.phi is None else data.ref @ tx.rotation(fit.phi).T
        ve = vector_error(ref, a_cal)
        e = np.linalg.norm(ref - a_cal, axis=1)
        out["eq21"] = {"rmse_mps2": ve.rmse, "sd_mps2": ve.sd, "mean_mps2": ve.mean, "n": ve.n,
                       "frame": "sensor"
                       if fit.phi is not None else "rig"}
        for row, v in zip(per, e):
            row["vector_error_mps2"] = float(v)
    out["per_pose"] = per
    names = list(tx.PARAM_NAMES) + (list(tx.PHI_NAMES) if fit.phi is not None else [])
    values = np.r_[fit.x, fit.phi] if fit.phi is not None else fit.x
    n_res = {"norm": 1, "norm2": 1}.get(fit.objective, 3) * (
        len(fit.extra.get("face_rows", [])) if fit.method == "six-position" else fit.n_records)
    dof = max(n_res - len(names), 1)
    tq = float(stats.t.ppf(0.5 + level / 2, dof))
    ci = {}
    if fit.stderr is not None:
        for n, v, se in zip(names, values, fit.stderr):
            if se is not None and np.isfinite(se):
                ci[n] = [float(v - tq * se), float(v + tq * se)]
    out["ci95"] = ci
    out["ci_level"] = level
    out["dof"] = dof
    if run.gyro_fit is not None:
        gf = run.gyro_fit
        gdof = max(2 * gf.n_pairs - (12 if gf.refine_bias else 9), 1)
        gt = float(stats.t.ppf(0.5 + level / 2, gdof))
        gci = {}
        if gf.stderr_matrix is not None:
            for i in range(3):
                for j in range(3):
                    se = gf.stderr_matrix[i, j]
                    gci[f"m{i + 1}{j + 1}"] = [float(gf.matrix[i, j] - gt * se),
                                               float(gf.matrix[i, j] + gt * se)]
        if gf.stderr_bias is not None:
            for c, b, se in zip("xyz", gf.bias, gf.stderr_bias):
                gci[f"bg{c}"] = [float(b - gt * se), float(b + gt * se)]
        out["gyro_ci95"] = gci
        out["gyro_dof"] = gdof
    d = a_cal / np.linalg.norm(a_cal, axis=1)[:, None]
    ev = np.linalg.eigvalsh(d.T @ d / len(d))
    out["coverage"] = {"eigenvalues": ev.tolist(), "n_poses": int(len(d))}
    return out
