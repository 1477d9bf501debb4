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
from inertialab.noise.static_intervals import StaticIntervals
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
        static_intervals=None if data.intervals is None else int(data.intervals.count), gyro=gyro)


def calibrate_record_data(data: StaticData, *, method="lm", objective="norm", rng=0,
                          gyro_raw=None, t=None, gyro_suffix: str | None = None,
                          gyro_lsb_per_rps: float | None = None, meta: dict | None = None,
                          refine_gyro_bias: bool = False, **kw) -> CalibrationRun:
    """Accelerometer calibration, then (with ``gyro_raw`` of a raw log) the gyro (§7.3)."""
    fit = calibrate(data.a, ref=data.ref, method=method, objective=objective, g=data.g, rng=rng,
                    counts=data.counts, **kw)
    gyro_block = None
    gfit = None
    if gyro_raw is not None:
        if data.intervals is None or t is None:
            raise InputError("gyro calibration needs a raw log (static records carry no motion)")
        meta = meta or {}
        graw = np.asarray(gyro_raw, dtype=float)
        if gyro_suffix == "lsb":
            lpr = gyro_lsb_per_rps if gyro_lsb_per_rps is not None else meta.get("gyro_lsb_per_rps")
            if lpr is None:
                raise InputError("gyro columns are in counts: give argument 'gyro_lsb_per_rps' or a "
                                 "'gyro_lsb_per_rps' header key (the start of M_g needs it)")
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
                              refine_bias=refine_gyro_bias)
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
        }
    return CalibrationRun(model=to_model(fit, data, gyro=gyro_block), fit=fit, data=data,
                          gyro_fit=gfit)

