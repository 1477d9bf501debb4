"""Workflow ``triaxial`` (spec 002): records -> static data -> calibration -> calibrated
record, and the commands ``triaxial fit|ferraris|apply|export``, one call each.

Three verbs:

- :func:`prepare` (record, :class:`FitConfig` -> :class:`Session`): static-record tables
  (``triaxial_static``) give one mean per pose; raw logs (``triaxial_raw``) go through
  static-interval detection with the threshold sweep (§2.4). Units: m/s^2 or g columns
  are converted to m/s^2; counts with a known ``lsb_per_g`` are converted with
  ``(raw - lsb_offset)/lsb_per_g·g``; counts without it stay counts ("counts mode",
  §2.3). References come from ``ref_*`` > ``pitch_deg/heading_deg`` > ``face`` (or a
  schedule matched in time order to the detected intervals).
- :func:`fit` (session, :class:`FitConfig` -> :class:`~inertialab.calib.triaxial_session.CalibrationRun`
  or, for a file of many units, :class:`~inertialab.calib.triaxial_batch.BatchCalibration`):
  the estimators of :mod:`inertialab.calib.triaxial`.
- :func:`apply` (model, record -> record): calibrated ``ax_mps2 ay_mps2 az_mps2`` (and
  ``gx_rps gy_rps gz_rps``) columns in place of the raw ones.

:func:`read` tells a raw log (a time column) from a static-record table. The commands:
a :class:`~inertialab.config.Config` of settings per command (:class:`FitConfig`, the
settings of :func:`prepare` and :func:`fit` too; :class:`ApplyConfig`,
:class:`ExportConfig`; ``triaxial ferraris`` lives in :mod:`inertialab.workflows.ferraris`)
and ``run_*(record, config) -> result`` whose result (:class:`inertialab.result.Result`)
knows ``to_json()``, ``settings``, ``units``, ``artifacts()`` and ``summary_rows()``.
The demo study is :mod:`inertialab.studies.triaxial`.

The estimators (:mod:`inertialab.calib`, pandas, scipy) are imported inside the
functions that use them, so that ``triaxial fit --help`` starts light; their names
re-exported here (``METHODS``, ``calibrate``, ``StaticData`` ...) load on first use.
"""

from __future__ import annotations

import dataclasses
import warnings
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from inertialab import units
from inertialab.config import Config as _Settings
from inertialab.config import seed_setting, setting
from inertialab.errors import DataQualityWarning, InputError
from inertialab.result import ResultBase
from inertialab.sensors.triaxial import OBJECTIVES

if TYPE_CHECKING:
    import pandas as pd

    from inertialab.calib.triaxial import TriaxialCalibration
    from inertialab.calib.triaxial_session import CalibrationRun, StaticData
    from inertialab.io.readers import Record
    from inertialab.noise.segments.static_intervals import StaticIntervals

__all__ = ["NOT_WRITTEN", "UNITS", "USES", "ApplyConfig", "ExportConfig",
           "FitConfig", "Session", "apply", "fit", "fit_methods", "gyro_applied", "is_batch",
           "is_raw_log", "methods_from", "prepare", "raw_log_data", "read", "result_payload",
           "result_units", "run_apply", "run_export", "run_fit",
           "run_fit_file", "static_data_from_frame", "unit_conversion"]

#: Names of the floors below, re-exported for callers of the workflow and loaded on first
#: use (name -> the floor's module name).
_FLOORS = {
    **dict.fromkeys(("METHODS", "CalibrationFit", "TriaxialCalibration", "calibrate",
                     "fit_lm", "initial_estimate"), "triaxial"),
    **dict.fromkeys(("BatchCalibration", "calibrate_batch"), "triaxial_batch"),
    **dict.fromkeys(("ImplausibleCalibrationError", "Limits", "check_accel", "check_gyro",
                     "refusal"), "triaxial_checks"),
    **dict.fromkeys(("CalibrationRun", "StaticData", "calibrate_record_data", "quality",
                     "to_model"), "triaxial_session"),
    **dict.fromkeys(("StaticIntervals", "sweep_thresholds"), "static_intervals"),
}


def __getattr__(name: str):
    """The floors' names on first use; ``Config``, the fit's settings before
    :class:`FitConfig` was the one class, with a DeprecationWarning."""
    if name == "Config":
        warnings.warn("inertialab.workflows.triaxial.Config is deprecated: use FitConfig "
                      "(bias_limit_mps2/norm_tol_mps2 in place of limits)", DeprecationWarning,
                      stacklevel=2)
        return FitConfig
    if name in _FLOORS:
        from inertialab.calib import triaxial, triaxial_batch, triaxial_checks, triaxial_session
        from inertialab.noise.segments import static_intervals

        floors = {"triaxial": triaxial, "triaxial_batch": triaxial_batch,
                  "triaxial_checks": triaxial_checks, "triaxial_session": triaxial_session,
                  "static_intervals": static_intervals}
        return getattr(floors[_FLOORS[name]], name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


UNITS = ("mps2", "g", "mg", "lsb")
"""Accelerometer units a suffix-less column may be declared in (argument ``unit``)."""


# =========================================================================== reading

def read(path, *, options=None, unit: str | None = None, g_local: float | None = None) -> Record:
    """Read a calibration record: a raw log (``triaxial_raw``) when it has a time column,
    else a static-record table (``triaxial_static``).

    ``unit`` (one of :data:`UNITS`) declares the unit of suffix-less ``ax ay az``;
    ``options`` are the reading options of the front door (column map, parse options).
    """
    from inertialab.io.readers import read_record

    if unit is not None and unit.lower() not in UNITS:
        raise InputError(f"argument 'unit' must be one of {', '.join(UNITS)}, got '{unit}'")
    unit_arg = None if unit is None else dict.fromkeys(("ax", "ay", "az"), unit.lower())
    try:
        return read_record(path, "triaxial_raw", unit=unit_arg, g_local=g_local, options=options)
    except InputError as exc:
        if exc.column != "t_s":
            raise
        raw_error = exc
    try:
        return read_record(path, "triaxial_static", unit=unit_arg, g_local=g_local,
                           options=options)
    except InputError as exc:  # neither a static table nor a log: the log's cause
        raise (raw_error if exc.column == "pos_id" else exc) from None


def is_raw_log(record: Record) -> bool:
    """True for a continuous log (``triaxial_raw``), False for static records."""
    return record.kind == "triaxial_raw"


# =========================================================================== records -> arrays

def _acc_columns(df: pd.DataFrame):
    cols = []
    for ax in ("ax", "ay", "az"):
        c = next((c for c in df.columns if units.split_suffix(c)[0] == ax
                  and units.split_suffix(c)[1] is not None), None)
        if c is None:
            raise InputError("missing accelerometer column with a unit suffix", column=ax)
        cols.append(c)
    sufs = {units.split_suffix(c)[1] for c in cols}
    if len(sufs) != 1:
        raise InputError(f"accelerometer columns have different units: {', '.join(cols)}")
    return cols, sufs.pop()


def adc_zero(meta: dict, raw) -> float:
    """The count a counts log reads at zero: the sidecar's ``lsb_offset`` when given;
    else the zero of its ADC range (:func:`inertialab.calib.triaxial_checks.adc_range`:
    the sidecar's ``adc`` when declared, mid-scale 2^(bits-1) for an unsigned one),
    and for a detected unsigned range only when the counts sit about mid-scale (their
    median within a quarter of the half range), else 0."""
    if meta.get("lsb_offset") is not None:
        return float(meta["lsb_offset"])
    if raw is None:
        return 0.0
    from inertialab.calib.triaxial_checks import adc_range

    declared = meta.get("adc") if isinstance(meta.get("adc"), dict) else None
    adc = adc_range(raw, declared)
    if adc.signed:
        return 0.0
    if declared is not None:
        return adc.zero
    v = np.asarray(raw, dtype=float)
    med = float(np.nanmedian(v)) if v.size else 0.0
    return adc.zero if abs(med - adc.zero) < 0.25 * adc.half else 0.0


def unit_conversion(suffix: str, meta: dict, *, g: float, lsb_per_g: float | None = None,
                    header_check: bool = True, path=None, raw=None):
    """``(scale, offset, counts)`` from the raw unit to the working unit (spec 002 §2.3).

    With ``header_check`` a column suffix that contradicts the header's ``units`` key is
    an :class:`InputError` (spec 002 §2.3); pass False when the user overrode the unit.
    Counts with a known sensitivity are taken from their ADC's zero (:func:`adc_zero`
    of ``raw``, the counts: mid-scale of an unsigned ADC).
    """
    hu = meta.get("units")
    if header_check and isinstance(hu, str) and hu.strip().lower() in units.SUFFIXES \
            and hu.strip().lower() != suffix:
        raise InputError(f"accelerometer columns are in '{suffix}' but the header says "
                         f"units={hu}; fix one of them or give argument 'unit'", path=path)
    if suffix == "lsb":
        lpg = lsb_per_g if lsb_per_g is not None else meta.get("lsb_per_g")
        if lpg is None:
            return 1.0, 0.0, True
        off = adc_zero(meta, raw)
        lpg = float(lpg)
        if not np.isfinite(lpg) or lpg <= 0:
            raise InputError(f"lsb_per_g must be a positive number, got {lpg}")
        return g / lpg, off, False
    u = units.lookup(suffix)
    if u.dimension != "acceleration":
        raise InputError(f"accelerometer unit '{suffix}' is a {u.dimension}, expected an acceleration")
    return float(units.to_si(1.0, suffix, g_local=g)), 0.0, False


def _references(df: pd.DataFrame, g: float, *, path=None):
    """Reference vectors (m/s^2) by precedence ref_* > pitch/heading > face; None if absent."""
    import pandas as pd

    n = len(df)
    ref = np.full((n, 3), np.nan)
    if all(c in df.columns for c in ("ref_x", "ref_y", "ref_z")):
        r = df[["ref_x", "ref_y", "ref_z"]].to_numpy(dtype=float)
        nr = np.linalg.norm(r, axis=1)
        ok = np.isfinite(nr) & (nr > 0)
        ref[ok] = g * r[ok] / nr[ok, None]
    if "pitch_deg" in df.columns and "heading_deg" in df.columns:
        p = df["pitch_deg"].to_numpy(dtype=float)
        h = df["heading_deg"].to_numpy(dtype=float)
        need = ~np.all(np.isfinite(ref), axis=1) & np.isfinite(p) & np.isfinite(h)
        pr, hr = np.deg2rad(p[need]), np.deg2rad(h[need])
        ref[need] = g * np.column_stack([np.sin(pr) * np.cos(hr), np.sin(pr) * np.sin(hr), np.cos(pr)])
    if "face" in df.columns:
        faces = df["face"].astype("string").str.strip().str.lower()
        for i in np.flatnonzero(~np.all(np.isfinite(ref), axis=1)):
            f = faces.iloc[i]
            if pd.isna(f):
                continue
            if f not in ("+x", "-x", "+y", "-y", "+z", "-z", "x", "y", "z"):
                raise InputError(f"face must be one of +x,-x,+y,-y,+z,-z, got '{f}'", path=path,
                                 column="face", row=i + 1)
            f = f if f[0] in "+-" else "+" + f
            e = np.zeros(3)
            e["xyz".index(f[1])] = g if f[0] == "+" else -g
            ref[i] = e
    has = np.all(np.isfinite(ref), axis=1)
    if not has.any():
        return None
    return ref


def static_data_from_frame(df: pd.DataFrame, meta: dict | None = None, *, g: float | None = None,
                           lsb_per_g: float | None = None, path=None,
                           header_check: bool = True) -> StaticData:
    """Static-record table (``triaxial_static`` kind, validated) -> :class:`StaticData`.

    ``header_check``: refuse a column unit that contradicts the header's ``units``.
    """
    from inertialab.calib.triaxial_session import StaticData
    from inertialab.io.gaps import at_rails, rails

    meta = dict(meta or {})
    g = _g_from(meta, g)
    cols, suf = _acc_columns(df)
    raw = df[cols].to_numpy(dtype=float)
    scale, off, counts = unit_conversion(suf, meta, g=g, lsb_per_g=lsb_per_g,
                                         header_check=header_check, path=path, raw=raw)
    keep = np.ones(len(df), dtype=bool)
    dropped = []
    lim = rails(suf, meta, units.to_si(1.0, suf, g_local=g) / g if suf != "lsb" else 1, raw)
    if lim is not None:
        sat = at_rails(raw, lim)
        if sat.any():
            rows = (np.flatnonzero(sat) + 1).tolist()
            warnings.warn(f"{path or 'records'}: {int(sat.sum())} record(s) at the sensor's rail "
                          f"(saturated), rows {rows[:5]}; left out", DataQualityWarning, stacklevel=2)
            keep &= ~sat
            dropped.append(("saturated", rows))
    a = (raw[keep] - off) * scale
    ref = _references(df, g, path=path)
    if ref is not None:
        ref = ref[keep]
    return StaticData(
        a=a, ref=ref, g=g, raw_unit=suf, raw_scale=scale, raw_offset=off, counts=counts,
        unit_id=df["unit_id"].astype(str).to_numpy()[keep] if "unit_id" in df.columns else None,
        pos_id=df["pos_id"].to_numpy()[keep] if "pos_id" in df.columns else None,
        n_samples=df["n"].to_numpy()[keep] if "n" in df.columns else None, dropped=tuple(dropped))


def _g_from(meta: dict, g: float | None) -> float:
    if g is not None:
        return float(g)
    for k in ("g_local_mps2", "g_local"):
        if meta.get(k) is not None:
            return float(meta[k])
    warnings.warn("no local gravity given (argument 'g_local' or g_local in the header); using 9.80665 m/s^2",
                  DataQualityWarning, stacklevel=3)
    return units.G_STANDARD


def raw_log_data(t, acc_raw, meta: dict | None = None, *, suffix: str = "mps2",
                 g: float | None = None, lsb_per_g: float | None = None, schedule=None,
                 expected: int | None = None, k_thr: float | None = None,
                 threshold: float | None = None, window_s: float = 1.0, t_init_s: float = 10.0,
                 min_duration_s: float = 1.5, path=None, header_check: bool = True,
                 gyro_raw=None, rate_hz: float | None = None) -> StaticData:
    """Raw log -> static records by the detector of spec 002 §2.4 (with the threshold sweep).

    The sweep keeps the k_thr whose LM-norm residual RMS is smallest among those giving the
    expected count (the schedule length, ``expected``, or >= 12). A given ``k_thr`` or
    absolute ``threshold`` (on the summed moving variance in the working unit squared:
    (m/s^2)^2, or counts^2 in counts mode) skips the sweep. Intervals with saturated samples are dropped
    with a warning. A ``schedule`` (DataFrame with ``pitch_deg, heading_deg`` or
    ``face`` or ``ref_*``) is matched in time order; a count mismatch is an InputError.
    With ``gyro_raw`` (N, 3), any unit, a rest needs the gyro at rest as well
    (:func:`~inertialab.noise.segments.static_intervals.gyro_rest`): a turn about the vertical is
    not taken for a rest. ``rate_hz``: the record's sample rate (``record.timebase``;
    default the rate the stamps ``t`` give).
    """
    from inertialab.calib.triaxial import fit_lm, initial_estimate
    from inertialab.calib.triaxial_session import StaticData
    from inertialab.io.gaps import at_rails, rails
    from inertialab.noise.segments.static_intervals import detect_static_intervals, sweep_thresholds

    meta = dict(meta or {})
    g = _g_from(meta, g)
    raw = np.asarray(acc_raw, dtype=float)
    scale, off, counts = unit_conversion(suffix, meta, g=g, lsb_per_g=lsb_per_g,
                                         header_check=header_check, path=path, raw=raw)
    a_all = (raw - off) * scale
    if schedule is not None and expected is None:
        expected = len(schedule)
    kw = dict(window_s=window_s, t_init_s=t_init_s, min_duration_s=min_duration_s,
              rate_hz=rate_hz, gyro=None if gyro_raw is None else np.asarray(gyro_raw, dtype=float))

    def score(iv: StaticIntervals) -> float:
        try:
            x0, _ = initial_estimate(iv.mean, objective="norm", g=g, counts=counts)
            res = fit_lm(iv.mean, None, "norm", g, x0)
            return float(np.sqrt(np.mean(res.residuals**2)))
        except (InputError, np.linalg.LinAlgError):
            return float("inf")

    sweep_counts = None
    if threshold is not None or k_thr is not None:
        iv = detect_static_intervals(t, a_all, k_thr=6.0 if k_thr is None else k_thr,
                                     threshold=threshold,
                                     **kw)
        if expected is not None and iv.count != expected:
            raise InputError(f"{iv.count} static intervals detected, the schedule has {expected}; "
                             "adjust argument 'k_thr' or argument 'threshold', or drop both to run the sweep",
                             path=path)
        kused = iv.k_thr
    else:
        sw = sweep_thresholds(t, a_all, expected=expected, score=score, **kw)
        iv, kused, sweep_counts = sw.best, sw.k_best, sw.counts
    keep = np.ones(iv.count, dtype=bool)
    dropped = []
    lim = rails(suffix, meta, 1.0 if suffix == "lsb" else units.to_si(1.0, suffix, g_local=g) / g,
                raw)
    if lim is not None:
        sat_s = at_rails(raw, lim)
        csum = np.r_[0, np.cumsum(sat_s)]
        nsat = csum[iv.stop] - csum[iv.start]
        if np.any(nsat > 0):
            bad = np.flatnonzero(nsat > 0)
            warnings.warn(f"{path or 'log'}: {bad.size} static interval(s) contain saturated samples "
                          f"(intervals {(bad + 1).tolist()[:5]}); left out", DataQualityWarning,
                          stacklevel=2)
            keep[bad] = False
            dropped.append(("saturated", (bad + 1).tolist()))
    ref = None
    if schedule is not None:
        ref = _references(schedule.reset_index(drop=True), g, path=path)
        if ref is None:
            raise InputError("schedule has no pitch_deg/heading_deg, face or ref_* columns", path=path)
        ref = ref[keep]
    return StaticData(a=iv.mean[keep], ref=ref, g=g, raw_unit=suffix, raw_scale=scale,
                      raw_offset=off, counts=counts, n_samples=iv.n[keep], intervals=iv,
                      dropped=tuple(dropped), k_thr=kused, sweep_counts=sweep_counts,
                      pos_id=np.arange(1, iv.count + 1)[keep])


# =========================================================================== verbs

@dataclass(frozen=True)
class Session:
    """What :func:`prepare` hands to :func:`fit`: the static data and, for a raw log, the
    time stamps and gyro channels (raw unit ``gyro_suffix``)."""

    data: StaticData
    meta: dict
    t: np.ndarray | None = None
    gyro_raw: np.ndarray | None = None
    gyro_suffix: str | None = None
    schedule: pd.DataFrame | None = None


def _acc_cols(record: Record) -> list[str]:
    cols = [record.find(b) for b in ("ax", "ay", "az")]
    if any(c is None for c in cols):
        raise InputError("missing accelerometer columns ax, ay, az (with a unit suffix)",
                         path=record.path)
    return cols


def _gyro_cols(record: Record) -> list[str] | None:
    cols = [record.find(b) for b in ("gx", "gy", "gz")]
    return None if any(c is None for c in cols) else cols


def prepare(record: Record, config: FitConfig | None = None, *,
            schedule: pd.DataFrame | None = None, header_check: bool = True,
            **settings) -> Session:
    """Record -> :class:`Session` (spec 002 §2.3-2.4).

    Parameters
    ----------
    record : a ``triaxial_raw`` or ``triaxial_static`` record (:func:`read`)
    config : the :class:`FitConfig` whose reading settings apply: ``lsb_per_g`` (counts
        per g of a counts record; without it counts stay counts), the static detector
        (§2.4) ``k_thr``, ``threshold``, ``t_init_s``, ``window_s``, ``min_duration_s``
        (defaults: threshold sweep, 10 s initial rest, 1 s window, 1.5 s shortest run)
        and ``gyro`` (also keep the gyro channels; raw logs only)
    schedule : pose schedule of a raw log (``pitch_deg/heading_deg``, ``face`` or
        ``ref_*``), matched in time order to the detected intervals
    header_check : refuse a column unit contradicting the header's ``units``
    settings : fields of :class:`FitConfig` given one by one (``gyro=True, k_thr=6``)

    Gyro columns of a raw log take part in the static detection whether or not ``gyro``
    is asked for: a rest is the accelerometer still and the gyro at rest.
    """
    from inertialab.io.record import naming

    c = dataclasses.replace(config or FitConfig(), **settings)
    gyro = c.gyro
    meta = dict(record.meta)
    cols = _acc_cols(record)
    suffix = units.split_suffix(cols[0])[1]
    raw_log = is_raw_log(record)
    if gyro and not raw_log:
        raise InputError("gyro calibration needs a raw log (t_s column): static records carry "
                         "no motion", path=record.path)
    gcols = _gyro_cols(record) if raw_log else None
    if gyro and gcols is None:
        raise InputError("gyro calibration asked for but the log has no gx, gy, gz columns",
                         path=record.path)
    log_gyro = None if gcols is None else record.data[gcols].to_numpy(dtype=float)
    if raw_log:
        t = record.column("t_s")
        with naming(record.path):  # every error names the file
            data = raw_log_data(t, record.data[cols].to_numpy(dtype=float), meta,
                                suffix=suffix, lsb_per_g=c.lsb_per_g, schedule=schedule,
                                k_thr=c.k_thr, threshold=c.threshold, window_s=c.window_s,
                                t_init_s=c.t_init_s, min_duration_s=c.min_duration_s,
                                path=record.path, header_check=header_check,
                                gyro_raw=log_gyro, rate_hz=None if record.timebase is None
                                else record.timebase.rate_hz)
    else:
        data = static_data_from_frame(record.data, meta, lsb_per_g=c.lsb_per_g, path=record.path,
                                      header_check=header_check)
        t = None
    gyro_raw = gsuf = None
    if gyro:
        gyro_raw = log_gyro
        gsuf = units.split_suffix(gcols[0])[1]
    return Session(data=data, meta=meta, t=t, gyro_raw=gyro_raw, gyro_suffix=gsuf,
                   schedule=schedule)


@dataclass(frozen=True)
class FitConfig(_Settings):
    """Settings of ``triaxial fit`` and of :func:`prepare`/:func:`fit` (one class: each
    field's name is its JSON key in ``settings``, its flag the same with ``-``, or the
    one the field names; defaults: spec 002 §3.6 LM on the field objective J_H).

    ``None`` means the method's own default: objective ``norm`` (``scalar`` for the
    six-position method), 1000 generations for the metaheuristics, a 2 deg face tilt for
    the six-position refinement. A setting the method does not use is refused, not
    ignored (:data:`USES`). ``robust`` uses the soft-L1 loss with f_scale = 3 x the
    robust residual scale of a plain fit (§7.3); ``seed`` and ``max_generations`` drive
    the metaheuristics (§3.3). ``bias_limit_mps2`` and ``norm_tol_mps2`` bound what
    counts as a plausible calibration (:mod:`inertialab.calib.triaxial_checks`); a fit
    beyond them is refused (``ImplausibleCalibrationError``) unless ``force``, which
    writes it flagged.

    The fields are declared in the order ``settings`` writes them; the fields of
    :data:`NOT_WRITTEN` stay out of it.
    """

    method: str = setting("lm", help="lm | acs | cs | pso | six-position | ellipsoid, a comma "
                                     "list of them, or all: several methods write the "
                                     "per-method parameter and error tables (with an output "
                                     "directory).")
    objective: str | None = setting(None, help="norm (J_H, field mode; default) | norm2 (J_H2) "
                                               "| scalar (S9, needs references) | scalar12 "
                                               "(S12, with mount rotation). lm, acs, cs, pso "
                                               "only.",
                                    choices=("norm", "norm2", "scalar", "scalar12"))
    unit: str | None = setting(None, help="Unit of suffix-less ax/ay/az: mps2 | g | lsb "
                                          "(overrides suffixes and header).")
    lsb_per_g: float | None = setting(None, help="Counts per g (e.g. 16384); without it counts "
                                                 "stay counts.", lo=1e-9, hi=1e12)
    gyro: bool = setting(False, help="Also calibrate the gyro channels of a raw log.")
    g_local: float | None = setting(None, help="Local gravity (else header, else 9.80665 with "
                                               "a warning).", unit="m/s^2", lo=1.0, hi=100.0)
    seed: int = seed_setting("Random seed (same seed, same numbers).")
    k_thr: float | None = setting(None, help="Static-detector threshold multiplier (default: "
                                             "sweep 2..10).", lo=1e-6, hi=1e6)
    threshold: float | None = setting(None, help="Absolute detector threshold on the summed "
                                                 "moving variance, (m/s^2)^2 (counts^2 in "
                                                 "counts mode).", lo=0.0, hi=1e30)
    t_init_s: float = setting(10.0, help="Initial rest used by the detector.", unit="s",
                              flag="t-init", lo=0.0, hi=1e6)
    window_s: float = setting(1.0, help="Moving-variance window.", unit="s", flag="window",
                              lo=1e-6, hi=1e6)
    min_duration_s: float = setting(1.5, help="Shortest static run.", unit="s",
                                    flag="min-duration", lo=0.0, hi=1e6)
    robust: bool = setting(False, help="soft-L1 loss in the LM (f_scale = 3 x the robust "
                                       "residual scale of a plain fit).")
    max_generations: int | None = setting(None, help="Metaheuristic generation budget (acs, "
                                                     "cs, pso; default 1000).", lo=1, hi=1_000_000)
    placement_deg: float | None = setting(None, help="six-position: standard deviation of a "
                                                     "hand-placed face's tilt (default 2).",
                                          unit="deg", lo=0.0, hi=45.0)
    bias_limit_mps2: float | None = setting(None, help="Largest plausible |accelerometer bias| "
                                                       "(default 0.5 g).", unit="m/s^2",
                                            flag="bias-limit", lo=0.0, hi=1e6)
    norm_tol_mps2: float | None = setting(None, help="Largest plausible | |a| - g | of a "
                                                     "calibrated pose (default 0.02 g).",
                                          unit="m/s^2", flag="norm-tol", lo=0.0, hi=1e6)
    force: bool = setting(False, help="Write a non-identifiable or implausible calibration "
                                      "anyway, flagged (apply then needs force too).")
    gyro_lsb_per_rps: float | None = setting(None, help="Gyro counts per rad/s (counts logs).",
                                             lo=1e-9, hi=1e12)
    schedule: str | None = setting(None, help="Schedule CSV of a raw log (pos_id, pitch_deg, "
                                              "heading_deg or face); default "
                                              "<stem>.schedule.csv if present.")

    def limits(self, meta: dict | None = None):
        """The plausibility bounds of this fit (:class:`~inertialab.calib.triaxial_checks.Limits`):
        ``bias_limit_mps2``, ``norm_tol_mps2`` and a counts log's ADC range declared in the
        sidecar key ``adc`` of ``meta``."""
        from inertialab.calib.triaxial_checks import Limits

        adc = (meta or {}).get("adc")
        return Limits(bias=self.bias_limit_mps2, norm_tol=self.norm_tol_mps2,
                      adc=adc if isinstance(adc, dict) else None)

    def written(self) -> dict:
        """The settings as ``settings`` writes them before the run fills in what it decided
        (method, objective, unit, g_local)."""
        return {k: v for k, v in self.to_dict().items() if k not in NOT_WRITTEN}


#: Settings of :class:`FitConfig` the result's ``settings`` leaves out (they were never
#: written: the gyro's counts scale and the schedule file, named among the inputs).
NOT_WRITTEN = ("gyro_lsb_per_rps", "schedule")

#: Method-specific settings of :class:`FitConfig` -> the methods that use them; a setting
#: given to another method is refused (:func:`fit`) or left out (:func:`fit_methods`).
USES = {
    "objective": ("lm", "acs", "cs", "pso"),
    "max_generations": ("acs", "cs", "pso"),
    "robust": ("lm",),
    "placement_deg": ("six-position",),
}

def is_batch(session: Session) -> bool:
    """True when the static records hold more than one ``unit_id`` (production line)."""
    uid = session.data.unit_id
    return uid is not None and len(set(uid)) > 1


def fit(session: Session, config: FitConfig | None = None):
    """Calibrate with one method (``config.method``): a :class:`CalibrationRun`
    (accelerometer, and gyro when the session has gyro channels), or a
    :class:`BatchCalibration` for a file of many units (S9 only)."""
    from inertialab.calib.triaxial import METHODS
    from inertialab.calib.triaxial_batch import calibrate_batch
    from inertialab.calib.triaxial_checks import (
        ImplausibleCalibrationError,
        check_accel,
        check_gyro,
        refusal,
    )
    from inertialab.calib.triaxial_session import calibrate_record_data

    config = config or FitConfig()
    m = config.method.strip().lower()
    if m not in METHODS:
        raise InputError(f"argument 'method' must be one of {', '.join(METHODS)}, got '{config.method}'")
    _refuse_ignored(m, config)
    default_obj = "scalar" if m == "six-position" else "norm"
    obj = (config.objective or default_obj).strip().lower()
    if obj not in OBJECTIVES:
        raise InputError(f"argument 'objective' must be one of {', '.join(OBJECTIVES)}, "
                         f"got '{config.objective}'")
    data = session.data
    if is_batch(session):
        if m != "lm" or obj != "scalar":
            raise InputError(f"{len(set(data.unit_id))} units in one file: the batch solver runs "
                             "argument 'method' 'lm' with argument 'objective' 'scalar' (S9) only")
        return calibrate_batch(data)
    kw = {"loss": "soft_l1", "f_scale": None} if config.robust else {}
    if config.max_generations is not None:
        kw["max_generations"] = int(config.max_generations)
    if config.placement_deg is not None:
        kw["placement_rad"] = float(np.deg2rad(config.placement_deg))
    run = calibrate_record_data(
        data, method=m, objective=obj, rng=config.seed, gyro_raw=session.gyro_raw, t=session.t,
        gyro_suffix=session.gyro_suffix, gyro_lsb_per_rps=config.gyro_lsb_per_rps,
        meta=session.meta, **kw)
    limits = config.limits(session.meta)
    findings = check_accel(run.fit, data.a, data.ref, data.g, counts=data.counts,
                           limits=limits)
    if run.gyro_fit is not None:
        findings += check_gyro(run.gyro_fit, run.gyro_nominal, limits=limits,
                               raw=session.gyro_raw if session.gyro_suffix == "lsb" else None)
    if findings:
        if not config.force:
            raise ImplausibleCalibrationError(refusal(findings))
        flags = [f.text() for f in findings]
        warnings.warn("calibration written flagged: " + " | ".join(flags), DataQualityWarning,
                      stacklevel=2)
        run = dataclasses.replace(run, model=dataclasses.replace(run.model, flags=flags))
    return run


def methods_from(text: str) -> list[str]:
    """``'all'`` (every method, ``lm`` first) or a comma list (``'lm,acs,six-position'``)
    -> method names; an unknown name is an InputError."""
    from inertialab.calib.triaxial import METHODS

    t = str(text).strip().lower()
    if t == "all":
        return list(METHODS)
    out = []
    for m in (x.strip() for x in t.split(",")):
        if m not in METHODS:
            raise InputError(f"argument 'method' must be 'all' or a comma list of "
                             f"{', '.join(METHODS)}, got '{m}'")
        if m not in out:
            out.append(m)
    return out


def fit_methods(session: Session, config: FitConfig, methods) -> tuple[dict, dict]:
    """Several methods on one session: ``(runs, skipped)``.

    Each method-specific setting of ``config`` (:data:`USES`) goes to the methods that
    use it; the others run with their defaults. A method that cannot run on these data
    (too few poses, no references, an implausible fit without ``force``) is left out
    with its one-line reason in ``skipped``; when every method fails, the first failure
    is raised.
    """
    from inertialab.calib.triaxial_checks import ImplausibleCalibrationError

    if is_batch(session):
        raise InputError("a file of many units runs one method (argument 'method' 'lm')")
    runs, skipped, first = {}, {}, None
    unset = {f.name: f.default for f in dataclasses.fields(FitConfig)}
    for m in methods:
        cfg = dataclasses.replace(
            config, method=m, **{name: (getattr(config, name) if m in users else unset[name])
                                 for name, users in USES.items()})
        try:
            runs[m] = fit(session, cfg)
        except (InputError, ImplausibleCalibrationError) as exc:
            first = first or exc
            skipped[m] = str(exc)
    if not runs:
        raise first
    return runs, skipped


def _refuse_ignored(method: str, config: FitConfig) -> None:
    """A setting the method would ignore (given: not its default) is an error."""
    unset = {f.name: f.default for f in dataclasses.fields(FitConfig)}
    for name, methods in USES.items():
        if getattr(config, name) != unset[name] and method not in methods:
            raise InputError(f"method '{method}' does not use argument '{name}' (used by "
                             f"{', '.join(repr(x) for x in methods)}); drop it")


def result_payload(run: CalibrationRun) -> dict:
    """The JSON result of a calibration (``result.json`` and ``--json``)."""
    from inertialab.calib.triaxial_session import quality

    fit_, data = run.fit, run.data
    d = run.model.to_dict()
    out = {
        "method": d["method"], "objective": d["objective"], "params": d["params"],
        "stderr": d["stderr"], "correction_matrix": d["correction_matrix"],
        "offset": d["offset"], "residual_rms": d["residual_rms"], "iterations": d["iterations"],
        "nfev": d["nfev"], "n_records": d["n_records"], "static_intervals": d["static_intervals"],
        "raw_unit": d["raw_unit"], "g_local": d["g_local"], "phi": d["phi"],
        "J": fit_.J, "J_final": fit_.J, "x": fit_.x.tolist(),
        "x_names": list(d["params"]), "converged": fit_.converged, "cond": fit_.cond,
        "cov": None if fit_.cov is None else fit_.cov.tolist(),
        "counts_mode": bool(data.counts), "wall_s": fit_.wall_s, "flags": d["flags"],
        "quality": quality(run),
    }
    if data.intervals is not None:
        out["detection"] = {"k_thr": data.k_thr, "threshold": data.intervals.threshold,
                            "counts_per_k_thr": None if data.sweep_counts is None else
                            {f"{k:g}": v for k, v in data.sweep_counts.items()},
                            "t_start_s": data.intervals.t_start.tolist(),
                            "t_end_s": data.intervals.t_end.tolist()}
    if fit_.extra:
        out["extra"] = fit_.extra
    if d["gyro"] is not None:
        out["gyro"] = d["gyro"]
    return out


def result_units(run: CalibrationRun) -> dict:
    """Units of the keys of :func:`result_payload` and of the model file."""
    data = run.data
    gyro_unit = None if run.model.gyro is None else run.model.gyro.get("raw_unit")
    work = "lsb" if data.counts else "m/s^2"
    u = {"params.bx": work, "params.by": work, "params.bz": work,
         "params.kx": "lsb per m/s^2" if data.counts else "1",
         "params.ky": "lsb per m/s^2" if data.counts else "1",
         "params.kz": "lsb per m/s^2" if data.counts else "1",
         "params.theta_yz": "rad", "params.theta_zy": "rad", "params.theta_zx": "rad",
         "phi": "rad", "correction_matrix": f"m/s^2 per {data.raw_unit}",
         "offset": data.raw_unit, "residual_rms": work, "J": f"({work})^2",
         "g_local": "m/s^2", "wall_s": "s", "quality.norm_error": "m/s^2",
         "quality.eq21": "m/s^2", "quality.per_pose": "m/s^2",
         "quality.ci95": "unit of each parameter", "quality.coverage": "1"}
    if gyro_unit is not None:
        u.update({"gyro.correction_matrix": f"rad/s per {gyro_unit}", "gyro.offset": gyro_unit,
                  "gyro.residual_rms": "rad"})
    return u


def apply(model: TriaxialCalibration, record: Record, *, model_path=None,
          force: bool = False) -> Record:
    """Calibrated record: ``ax_mps2 ay_mps2 az_mps2`` = correction_matrix @ (raw - offset)
    in place of the raw accelerometer columns and, when the model has a gyro block and
    the record gyro columns, ``gx_rps gy_rps gz_rps`` likewise. A flagged model
    (``model.flags``) is refused unless ``force``.

    The record must be in the model's raw unit(s); the metadata loses the raw-unit keys
    (``lsb_per_g``, ``lsb_offset``, ``gyro_lsb_per_rps``) and names its sources.
    """
    if model.flags and not force:
        raise InputError("the calibration is flagged as not identifiable or implausible ("
                         + " | ".join(model.flags) + "); set argument 'force' to apply it anyway",
                         path=model_path)
    from inertialab.calib.model_checks import refuse_or_flag, triaxial_findings
    from inertialab.io.readers import Record, hash_frame

    forced = refuse_or_flag(triaxial_findings(model), "triaxial", force=force, path=model_path)
    cols = _acc_cols(record)
    suffix = units.split_suffix(cols[0])[1]
    if suffix != model.raw_unit:
        raise InputError(f"the file's accelerometer unit is '{suffix}', the calibration "
                         f"expects '{model.raw_unit}'", path=record.path, column=cols[0])
    df = record.data.copy()
    cal = model.apply(df[cols].to_numpy(dtype=float))
    pos = df.columns.get_loc(cols[0])
    df = df.drop(columns=cols)
    for i, c in enumerate(("ax_mps2", "ay_mps2", "az_mps2")):
        df.insert(pos + i, c, cal[:, i])
    out_units = {k: v for k, v in record.units.items() if k not in cols}
    out_units.update(dict.fromkeys(("ax_mps2", "ay_mps2", "az_mps2"), "mps2"))
    gcols = _gyro_cols(record)
    if gcols is not None and model.gyro is not None:
        gs = units.split_suffix(gcols[0])[1]
        if gs != model.gyro.get("raw_unit"):
            raise InputError(f"the file's gyro unit is '{gs}', the calibration expects "
                             f"'{model.gyro.get('raw_unit')}'", path=record.path, column=gcols[0])
        gcal = model.apply_gyro(df[gcols].to_numpy(dtype=float), acc=cal)
        gpos = df.columns.get_loc(gcols[0])
        df = df.drop(columns=gcols)
        for i, c in enumerate(("gx_rps", "gy_rps", "gz_rps")):
            df.insert(gpos + i, c, gcal[:, i])
        out_units = {k: v for k, v in out_units.items() if k not in gcols}
        out_units.update(dict.fromkeys(("gx_rps", "gy_rps", "gz_rps"), "rps"))
    meta = dict(record.meta)
    meta.update(units="mps2", calibrated_with=str(model_path), source_record=str(record.path))
    if forced:
        meta["flags"] = forced
    for k in ("lsb_per_g", "lsb_offset", "gyro_lsb_per_rps"):
        meta.pop(k, None)
    return Record(kind=record.kind, data=df, meta=meta, path=record.path, units=out_units,
                  sha256=hash_frame(df), timebase=record.timebase)


def gyro_applied(model: TriaxialCalibration, record: Record) -> bool:
    """Whether :func:`apply` calibrates the gyro columns of ``record``."""
    return model.gyro is not None and _gyro_cols(record) is not None


def _matrix_lines(title: str, rows) -> list[str]:
    return [title] + ["  [" + "  ".join(f"{v:+.9g}" for v in row) + "]" for row in rows]


def _method_tables(runs: dict) -> dict:
    from inertialab.calib import triaxial_compare as tc

    poses = tc.pose_error_table(runs)
    return {"params": tc.parameter_table(runs), "poses": poses,
            "summary": tc.error_summary(poses)}


def _methods_payload(tables: dict, skipped: dict) -> dict:
    out = {}
    for name, grp in tables["params"].groupby("method", sort=False):
        out[name] = {"objective": grp["objective"].iloc[0],
                     "params": dict(zip(grp["parameter"], grp["value"])),
                     "stderr": dict(zip(grp["parameter"], grp["stderr"])),
                     "ci95": {p: [lo, hi] for p, lo, hi in
                              zip(grp["parameter"], grp["ci95_low"], grp["ci95_high"])}}
    for row in tables["summary"].to_dict("records"):
        out[row.pop("method")]["errors"] = row
    return {"fitted": out, "skipped": dict(skipped)}


def _method_files(tables: dict, skipped: dict, name: str) -> dict:
    """params.csv/.md, pose_errors.csv, method_errors.csv (file name -> text)."""
    from inertialab.calib.triaxial_compare import markdown

    files = {fname: tables[key].to_csv(index=False, float_format="%.17g")
             for key, fname in (("params", "params.csv"), ("poses", "pose_errors.csv"),
                                ("summary", "method_errors.csv"))}
    parts = [f"# Calibration parameters per method: {name}\n",
             "Value, standard error and 95 % t-interval of every parameter (spec 002 "
             "Tables 3-6, 8-9, 11-12 from these data). b in the working unit, k "
             "dimensionless (counts per m/s^2 in counts mode), angles in rad.\n"]
    for method, grp in tables["params"].groupby("method", sort=False):
        parts.append(f"## {method} (objective {grp['objective'].iloc[0]})\n")
        parts.append(markdown(grp[["parameter", "value", "stderr", "ci95_low", "ci95_high",
                                   "unit"]]))
    parts.append("## Errors per method (m/s^2)\n")
    parts.append(markdown(tables["summary"]))
    if skipped:
        parts.append("## Methods left out\n")
        parts.extend(f"- {k}: {v}\n" for k, v in skipped.items())
    files["params.md"] = "\n".join(parts)
    return files


@dataclass
class FitResult(ResultBase):
    """``triaxial fit`` of one unit: the run (:class:`CalibrationRun`), the per-method
    tables when several methods were fitted, the effective settings."""

    run: object
    settings: dict
    name: str
    seed: int
    tables: dict | None = None
    skipped: dict | None = None
    gyro_unit: str | None = None
    sha256: str | None = None

    @property
    def units(self) -> dict:
        return result_units(self.run)

    def to_json(self) -> dict:
        payload = result_payload(self.run)
        payload["seed"] = self.seed
        if self.tables is not None:
            payload["methods"] = _methods_payload(self.tables, self.skipped)
        return payload

    def artifacts(self) -> dict:
        files = {} if self.tables is None else _method_files(self.tables, self.skipped,
                                                             self.name)
        return {"models": [("model.json", self.run.model, self.units)], "files": files}

    def corrected(self) -> np.ndarray:
        """The records corrected by the fit (the working unit), for the figures."""

        from inertialab.sensors.triaxial import correct

        return correct(self.run.fit.x, self.run.data.a)

    def norm_error(self) -> np.ndarray:
        """|corrected record| - g per record (the working unit), for the figures."""
        import numpy as np

        return np.linalg.norm(self.corrected(), axis=1) - self.run.data.g

    def summary_rows(self) -> list:
        fit, data, p = self.run.fit, self.run.data, self.to_json()
        rows = [[n, p["params"][n], (p["stderr"] or {}).get(n)] for n in p["params"]]
        if fit.phi is not None:
            rows += [[n + " (rad)", float(fit.phi[i]), (p["stderr"] or {}).get(n)]
                     for i, n in enumerate(("phi_x", "phi_y", "phi_z"))]
        out = [(f"triaxial fit: {fit.method}, objective {self.run.model.objective}, "
                f"{fit.n_records} records"
                + (f" ({data.intervals.count} static intervals)" if data.intervals else ""),
                ["parameter", "value", "std. error"], rows)]
        out += _matrix_lines("calibrated = correction_matrix @ (raw - offset)   [m/s^2]",
                             p["correction_matrix"])
        out.append("offset = [" + ", ".join(f"{v:.9g}" for v in p["offset"])
                   + f"] {data.raw_unit}")
        out.append(f"residual RMS = {fit.residual_rms:.4g}, iterations = {fit.iterations}, "
                   f"nfev = {fit.nfev}")
        q = p["quality"]
        ne = q["norm_error"]
        out.append(f"| |a| - g |: RMSE {ne['rmse_mps2']:.4g}, max {ne['max_abs_mps2']:.4g} "
                   f"m/s^2 over {len(q['per_pose'])} poses")
        if "eq21" in q:
            out.append(f"eq. 21 vector error: RMSE {q['eq21']['rmse_mps2']:.4g}, SD "
                       f"{q['eq21']['sd_mps2']:.4g} m/s^2 ({q['eq21']['frame']} frame)")
        out.append(f"95 % intervals (t, {q['dof']} dof): " + "; ".join(
            f"{k} [{lo:.6g}, {hi:.6g}]" for k, (lo, hi) in q["ci95"].items()))
        gf = self.run.gyro_fit
        if gf is not None:
            out += _matrix_lines("gyro: rate = M_g @ (raw - bias)   [rad/s]", gf.matrix)
            out.append("bias = [" + ", ".join(f"{v:.6g}" for v in gf.bias)
                       + f"] {self.gyro_unit}; direction residual RMS = "
                       f"{gf.residual_rms:.3g} rad over {gf.n_pairs} motions")
        out += [f"FLAGGED: {flag}" for flag in self.run.model.flags]
        if self.tables is not None:
            out += self._methods_rows(fit.method)
        return out

    def _methods_rows(self, primary: str) -> list:
        t = self.tables
        wide = t["params"].pivot(index="parameter", columns="method", values="value")
        wide = wide.reindex(index=list(dict.fromkeys(t["params"]["parameter"])),
                            columns=list(dict.fromkeys(t["params"]["method"])))
        summ = t["summary"]
        cols = [c for c in summ.columns if c.endswith("rmse_mps2") or c.endswith("sd_mps2")]
        return [(f"parameters per method (model.json holds {primary})",
                 ["parameter", *wide.columns],
                 [[p, *row] for p, row in zip(wide.index, wide.to_numpy().tolist())]),
                ("errors per method (m/s^2)", ["method", *cols],
                 summ[["method", *cols]].to_numpy().tolist())] + \
            [f"left out {k}: {v}" for k, v in (self.skipped or {}).items()]


@dataclass
class BatchResult(ResultBase):
    """``triaxial fit`` of a multi-unit (production-line) file: yield and per-unit table."""

    batch: object
    settings: dict = field(default_factory=lambda: {"batch": True})
    units = {"rmse_limit": "m/s^2", "rmse_median": "m/s^2", "rmse_p95": "m/s^2",
             "wall_s": "s"}

    def to_json(self) -> dict:
        import numpy as np

        t, b = self.batch.table, self.batch
        return {"method": "lm-batch", "objective": "scalar", "n_units": int(len(t)),
                "yield_fraction": b.yield_fraction, "rmse_limit": b.rmse_limit,
                "rmse_median": float(np.median(t["rmse_mps2"])),
                "rmse_p95": float(np.percentile(t["rmse_mps2"], 95)),
                "converged_fraction": float(t["converged"].mean()), "wall_s": b.wall_s,
                "failed_units": t.loc[~t["pass"], "unit_id"].tolist()[:100]}

    def artifacts(self) -> dict:
        return {"files": {"units.csv": self.batch.table.to_csv(index=False,
                                                               lineterminator="\n")}}

    def summary_rows(self) -> list:
        p, b = self.to_json(), self.batch
        return [f"{p['n_units']} units: yield {100 * b.yield_fraction:.1f} % (RMSE <= "
                f"{b.rmse_limit} m/s^2 and datasheet ranges); RMSE median "
                f"{p['rmse_median']:.4f}, p95 {p['rmse_p95']:.4f} m/s^2; solver "
                f"{b.wall_s:.2f} s"]


def run_fit(record, config: FitConfig, *, schedule=None, name: str = "", progress=None):
    """Calibrate a triaxial accelerometer (and gyro) from static records or a raw log
    (``schedule``: the pose schedule frame of a raw log, or None)."""
    c = config.validate()
    methods = methods_from(c.method)
    unit = None if c.unit is None else c.unit.lower()
    session = prepare(record, c, schedule=schedule, header_check=unit is None)
    fc = dataclasses.replace(c, method=methods[0])
    if is_batch(session) and len(methods) == 1:
        return BatchResult(fit(session, fc))
    if progress is not None:
        progress.update(0.4, 1.0, "records ready")
    runs = skipped = tables = None
    try:
        if len(methods) > 1:
            runs, skipped = fit_methods(session, fc, methods)
            run = next(iter(runs.values()))
            tables = _method_tables(runs)
        else:
            run = fit(session, fc)
    except InputError as exc:  # say what was left out before the fit: one line, whole
        left = "; ".join(f"{len(rows)} {why} record(s) left out" for why, rows in
                         getattr(session.data, "dropped", ()) if len(rows))
        if not left:
            raise
        raise type(exc)(f"{exc} ({left})") from None
    settings = c.written() | {"method": run.fit.method if runs is None else methods,
                              "objective": run.model.objective, "unit": unit,
                              "g_local": run.data.g}
    return FitResult(run=run, settings=settings, name=name, seed=c.seed, tables=tables,
                     skipped=skipped, gyro_unit=session.gyro_suffix, sha256=record.sha256)


def run_fit_file(file, config: FitConfig, *, options=None, progress=None):
    """:func:`run_fit` on the file at ``file`` (read with the reading ``options``); a raw
    log takes its pose schedule from ``config.schedule`` or ``<stem>.schedule.csv`` when
    present. The result's ``inputs`` name the file and the schedule read."""
    from inertialab.io.sidecar import read_schedule, schedule_path
    unit = None if config.unit is None else config.unit.lower()
    rec = read(file, options=options, unit=unit, g_local=config.g_local)
    schedule, inputs = None, [file]
    if is_raw_log(rec):
        sp = config.schedule if config.schedule is not None else schedule_path(file)
        if config.schedule is not None or Path(sp).exists():
            schedule = read_schedule(sp)  # the text front door: regular file, size, encoding
            inputs.append(sp)
    res = run_fit(rec, config, schedule=schedule, name=Path(file).name, progress=progress)
    res.with_inputs(inputs)
    if options is not None and options.reusable():  # kept in the model file for apply
        res.settings["reading"] = options.reusable()
    return res


# -------------------------------------------------------------------------- apply

@dataclass(frozen=True)
class ApplyConfig(_Settings):
    """Settings of ``triaxial apply``."""

    unit: str | None = setting(None, help="Unit of suffix-less ax/ay/az (mps2 | g | lsb).")
    force: bool = setting(False, help="Apply a flagged calibration anyway.")


@dataclass
class ApplyResult(ResultBase):
    """``triaxial apply``: the calibrated record (``data``, ``meta``) and its summary."""

    data: object
    meta: dict
    summary: dict
    settings: dict
    units = {}

    def to_json(self) -> dict:
        return dict(self.summary)

    def artifacts(self) -> dict:
        out = self.summary["output"]
        return {"records": [] if out is None else [(out, self.data, self.meta)]}

    def summary_rows(self) -> list:
        s = self.summary
        return [f"written: {s['output']} ({s['rows']} rows, calibrated to m/s^2"
                + (" and rad/s" if s["gyro_calibrated"] else "") + ")"]


def _trained_settings(model_path) -> dict:
    """The settings a model file was written with (``{}`` without a file or settings)."""
    if model_path is None:
        return {}
    from inertialab.io.modelfile import read_envelope

    settings = read_envelope(model_path).get("settings")
    return settings if isinstance(settings, dict) else {}


def run_apply(model, path, config: ApplyConfig, *, options=None, model_path=None,
              output=None) -> ApplyResult:
    """Apply a triaxial calibration to the record at ``path``:
    calibrated = correction_matrix @ (raw - offset) (and the gyro block). The file is
    read with the reading options and unit the model was fitted with (stored in the
    model file at ``model_path`` by ``fit``; a model file without them, as older ones,
    adds nothing), each one the user gives in ``options`` or ``config`` winning."""
    from inertialab.io.mapping import ReadOptions

    c = config.validate()
    trained = _trained_settings(model_path)
    options = (options or ReadOptions()).over(trained.get("reading"))
    unit = c.unit if c.unit is not None else trained.get("unit")
    unit = None if unit is None else str(unit).lower()
    rec = read(path, options=options, unit=unit)
    cal = apply(model, rec, model_path=model_path, force=c.force)
    summary = {"output": None if output is None else str(output), "rows": int(len(cal.data)),
               "accelerometer_columns": [rec.find(b) for b in ("ax", "ay", "az")],
               "gyro_calibrated": gyro_applied(model, rec), "raw_unit": model.raw_unit}
    return ApplyResult(data=cal.data, meta=cal.meta, summary=summary,
                       settings={"unit": unit, "force": c.force,
                                 "reading": options.reusable()})


# ------------------------------------------------------------------------- export

@dataclass(frozen=True)
class ExportConfig(_Settings):
    """Settings of ``triaxial export`` (the target is its own argument)."""

    drop_g_sensitivity: bool = setting(False, help="imu_tk: export a gyro with a "
                                                   "g-sensitivity without it.")
    force: bool = setting(False, help="Export a flagged calibration anyway.")


@dataclass
class ExportResult(ResultBase):
    """``triaxial export``: the files written for another tool."""

    written: list
    settings: dict
    units = {}

    def to_json(self) -> dict:
        return {"written": self.written, "format": self.settings["to"]}

    def artifacts(self) -> dict:
        return {}

    def summary_rows(self) -> list:
        return ["written: " + ", ".join(self.written)]


def run_export(model, to: str, out, config: ExportConfig) -> ExportResult:
    """Write a triaxial calibration at ``out`` for the tool of target ``to`` (one of the
    registered calibration exporters, :data:`inertialab.export.EXPORTERS`)."""
    from inertialab.export import export_calibration, get

    c = config.validate()
    fmt = get("calibration", to).target
    written = export_calibration(model, fmt, out, force=c.force,
                                 drop_g_sensitivity=c.drop_g_sensitivity)
    return ExportResult(written=written, settings={"to": fmt, **c.to_dict()})
