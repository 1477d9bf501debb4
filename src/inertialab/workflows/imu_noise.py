"""Six IMU axes in one call, and noise parameters for Kalibr / ROS.

:func:`analyse_imu` runs the noise core's overlapping Allan deviation
(:func:`inertialab.noise.statistics.allan.oadev`) and five-term fit
(:func:`inertialab.noise.terms.fit.fit_noise_terms`) on gyro x/y/z and accelerometer x/y/z
of one log and returns an :class:`IMUNoise`: per axis the curve, the terms and the
two numbers visual-inertial estimators ask for, in SI units:

* **noise density** (white noise, continuous time): ``N`` of the Allan model
  ``sigma^2(tau) = N^2 / tau + ...``, i.e. ``sqrt(c_-1)``; rad/s/sqrt(Hz) for gyros,
  m/s^2/sqrt(Hz) for accelerometers. The discrete per-sample standard deviation at
  the IMU rate is ``density * sqrt(update_rate)``.
* **random walk** (bias random walk, continuous time): ``K`` of
  ``sigma^2(tau) = ... + K^2 tau / 3``, i.e. ``sqrt(3 c_1)``; rad/s^2/sqrt(Hz) and
  m/s^3/sqrt(Hz). Discrete: ``K / sqrt(update_rate)`` per sample. When the record is
  too short to show the +1/2 slope, or K is not significant, the value written is an
  upper bound (K's upper bound, else the rate-random-walk line through the upper
  confidence limit of the longest tau) and the axis is flagged ``random_walk_bound``
  (JSON ``"bound": "upper"``).

* **bias instability** ``B`` (rad/s, m/s^2): every B, estimate or bound, at most
  1.05 min(ADEV)/0.664 of the axis's curve (:data:`B_RULE`,
  :mod:`inertialab.noise.terms._bounds`): a significant estimate above that reading is
  held to it (flag ``held_to_curve_minimum``, the model's own estimate in its reason, a
  note under the table), a bound is that reading as a bound (JSON ``"bound": "upper"``).

Per axis also: spectral lines (:mod:`inertialab.noise.spectral.lines`), a ``status`` (an axis
that is not static keeps its deviation and gets no terms; the others go on), and with
:class:`inertialab.workflows.imu_drift.DriftOptions` the predicted drift, its check and
the record-length plan.

:func:`export_yaml` writes these for any noise target of
:data:`inertialab.export.EXPORTERS` (Kalibr, ROS, OpenVINS, VINS, imu_utils,
GTSAM): one value per sensor, the largest of its three axes (the conservative choice
for an estimator that takes one number); the continuous/discrete convention and any
bound are stated in the file's comments.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from inertialab import units as U
from inertialab.config import DEFAULT_CONFIDENCE
from inertialab.errors import InputError
from inertialab.io.gaps import is_constant
from inertialab.noise.terms.imu_result import SI_UNITS as _SI
from inertialab.noise.terms.imu_result import AxisNoise, IMUNoise, term_text
from inertialab.result import ResultBase
from inertialab.workflows.imu_drift import AXES, axis_columns

__all__ = ["AXES", "B_RULE", "AxisNoise", "IMUNoise", "SixAxisRun", "analyse_imu",
           "analyse_record", "check_drift_confidence", "check_log", "check_six_axis_curve", "check_settings", "export_pairs", "export_refusal",
           "export_yaml", "fit_axis_terms", "reading", "run", "term_text", "write_exports"]

# AxisNoise, IMUNoise and term_text live in inertialab.noise.terms.imu_result (the result is the
# noise floor's; the exporters above read it typed); imported here, the workflow's face.


def _axis(name: str, column: str, y, unit: str, *, rate_hz: float, taus, method: str,
          g_local: float, tau_range_s, terms_on: bool = True, drift=None,
          confidence: float = 0.95, motion: str | None = None) -> AxisNoise:
    from inertialab.noise.terms.fit import not_static_reason

    kind = AXES[name]
    dim = U.lookup(unit).dimension
    want = "angular_rate" if kind == "gyro" else "acceleration"
    if dim != want:
        raise InputError(f"unit '{unit}' is a {dim}, expected a {want}", column=column)
    y = np.asarray(y)
    fit_y = y if drift is None or drift.check_on != "half" else y[: y.size // 2]
    nan = float("nan")
    blank = dict(axis=name, column=column, kind=kind, unit=unit, deviation=None, terms=None,
                 noise_density=nan, random_walk=nan, random_walk_bound=False,
                 bias_instability=nan)
    if is_constant(fit_y):
        return AxisNoise(**blank, status="constant",
                         reason="every sample is the same value: a stuck or absent sensor, "
                                "nothing to analyse on this axis")
    stuck = _stuck_reason(fit_y, rate_hz)
    if stuck:
        return AxisNoise(**blank, status="stuck", reason=stuck)
    dev = _deviation(fit_y, rate_hz, taus, confidence)
    blank["deviation"] = dev
    if not terms_on:
        return AxisNoise(**blank, status="no terms")
    why = motion or (not_static_reason(dev.taus_s, dev.dev) if tau_range_s is None else None)
    if why:
        # one axis that is not static does not stop the others: its deviation is kept
        import warnings

        from inertialab.errors import DataQualityWarning

        warnings.warn(f"column '{column}' is not static: {why}; its noise terms are not "
                      "fitted",
                      DataQualityWarning, stacklevel=3)
        return AxisNoise(**blank, status="not static", reason=why)
    try:
        terms = fit_axis_terms(fit_y, dev, unit, kind, method, rate_hz=rate_hz,
                               tau_range_s=tau_range_s, g_local=g_local, column=column,
                               confidence=confidence)
    except InputError as exc:  # this axis's curve holds no terms; the others go on
        if tau_range_s is not None:
            raise
        return AxisNoise(**blank, status="no terms", reason=str(exc))
    si = _SI[kind][0]

    def to_si(v):
        return U.convert(v, unit, si, g_local=g_local)

    c = np.asarray(terms.coefficients, dtype=float)
    # N^2 = c_-1 (unit^2 s): N in unit/sqrt(Hz); K^2 = 3 c_1 (unit^2 / s): K in unit*sqrt(Hz)/s
    density = to_si(math.sqrt(c[1])) if np.isfinite(c[1]) and c[1] > 0 else nan
    if "upper_bound" in terms.N.flags and np.isfinite(terms.N.upper_bound):
        # N only a bound: the density written is the bound (the JSON and table alike)
        density = to_si(terms.N.upper_bound / _report_factor(terms, "N"))
    k_bound = "upper_bound" in terms.K.flags or "not_observable" in terms.K.flags
    if np.isfinite(c[3]) and c[3] > 0 and not k_bound:
        rw = to_si(math.sqrt(3.0 * c[3]))
    elif k_bound and np.isfinite(terms.K.upper_bound) and terms.K.upper_bound > 0:
        # K not significant: its upper bound (the conservative value for a filter)
        rw = to_si(terms.K.upper_bound / _report_factor(terms, "K"))
    else:
        # no +1/2 slope to read: the random-walk line through the upper limit of the
        # longest tau (an upper bound at the curve's confidence)
        tmax = float(dev.taus_s[-1])
        hi = float(dev.ci_high[-1]) if np.isfinite(dev.ci_high[-1]) else float(dev.dev[-1])
        rw = to_si(hi * math.sqrt(3.0 / tmax))
        k_bound = True
    b_bound = "upper_bound" in terms.B.flags or "not_observable" in terms.B.flags
    # the table's B in SI: the bound itself where B is a bound (the JSON value alike)
    b_rep = terms.B.upper_bound if b_bound else terms.B.value
    b = to_si(b_rep / _report_factor(terms, "B")) if np.isfinite(b_rep) and b_rep >= 0 else nan
    axis = AxisNoise(axis=name, column=column, kind=kind, unit=unit, deviation=dev,
                     terms=terms, noise_density=float(density), random_walk=float(rw),
                     random_walk_bound=k_bound, bias_instability=float(b),
                     bias_instability_bound=b_bound,
                     random_walk_t_s=float(terms.k_gm["t_s"]) if terms.k_gm else None)
    from inertialab.workflows.imu_segments import axis_stationarity

    st = axis_stationarity(fit_y, rate_hz, column)
    axis = replace(axis, stationarity=None if st is None else st.to_dict())
    if drift is not None:
        from inertialab.workflows.imu_drift import axis_drift
        from inertialab.workflows.imu_noise_plan import axis_plan_with_interval

        y_check = y[y.size // 2:] if drift.check_on == "half" else drift.other.get(name)

        def refit(seg):  # a segment of the fitted samples, fitted as the axis was
            d = _deviation(seg, rate_hz, "octave", confidence)
            return d, fit_axis_terms(seg, d, unit, kind, method, rate_hz=rate_hz,
                                     g_local=g_local, column=column, confidence=confidence)

        axis = replace(axis, drift=axis_drift(axis, rate_hz, drift, y_check, stationarity=st,
                                              segments=(fit_y, refit)),
                       plan=axis_plan_with_interval(axis, rate_hz, fit_y.size) if drift.plan
                       else None)
    return axis


def _stuck_reason(y, rate_hz: float) -> str | None:
    """Why the axis is a stuck sensor (:func:`inertialab.io.gaps.stuck_run`), or None."""
    from inertialab.io.gaps import stuck_run

    run = stuck_run(y)
    if run is None:
        return None
    start, length, p = run
    return (f"{length} identical samples from sample {start} of the fitted span "
            f"({length / rate_hz:.4g} s; its other samples repeat their predecessor at a "
            f"rate of {p:.2g}): a stuck sensor or resent samples, no noise to read")


#: sqrt(2 ln2 / pi): sigma of flicker = BI * B
BI = math.sqrt(2.0 * math.log(2.0) / math.pi)


def _report_factor(terms, name: str) -> float:
    """Report unit of a term per its native unit (data unit based) for a fit."""
    from inertialab.workflows.imu_noise_plan import report_factor

    return report_factor(terms, name)


def _deviation(y, rate_hz, taus, confidence):
    from inertialab.noise.statistics.allan import oadev

    if np.isnan(y).any():  # lost samples on the sensor's grid (analyse_record)
        from inertialab.noise.statistics.gaps import gap_deviation

        return gap_deviation("oadev", y, rate_hz=rate_hz, taus=taus, confidence=confidence)
    return oadev(y, rate_hz=rate_hz, taus=taus, confidence=confidence)


#: how every six-axis B is held to its curve (:mod:`inertialab.noise.terms._bounds`): each
#: B, estimate or bound, at most 1.05 min(ADEV)/0.664 of the axis's curve, the number a
#: filter's user copies
B_RULE = "literal"


def fit_axis_terms(y, dev, unit: str, kind: str, method: str = "wls", *, rate_hz: float,
                   tau_range_s=None, g_local: float = U.G_STANDARD, column=None,
                   confidence: float = DEFAULT_CONFIDENCE["imu"], lines=None,
                   **fit_options):
    """The noise terms of one axis as ``allan --imu`` shows them: the samples ``y`` and
    their curve ``dev`` fitted by :func:`inertialab.noise.terms.fit.fit_noise_terms`
    with the record's spectral lines in the model (``lines``: found here when None) and
    B held by :data:`B_RULE`; ``fit_options`` go to the fit (``b_shape``, ``n_boot``,
    ``seed``). An :class:`InputError` names ``column``."""
    from inertialab.noise.spectral.lines import spectral_lines
    from inertialab.noise.terms.fit import fit_noise_terms

    if lines is None:
        finite = y[np.isfinite(y)]
        lines = spectral_lines(finite, rate_hz) if finite.size == y.size else ()
    try:
        return fit_noise_terms(dev, unit=unit, kind=kind, method=method, rate_hz=rate_hz,
                               tau_range_s=tau_range_s, g_local=g_local, lines=lines,
                               confidence=confidence, b_rule=B_RULE, **fit_options)
    except InputError as exc:
        raise InputError(str(exc), column=column) from None


def analyse_imu(columns: dict, *, rate_hz: float, taus="octave", method: str = "wls",
                g_local: float = U.G_STANDARD, tau_range_s=None, progress=None,
                terms: bool = True, drift=None, confidence: float = 0.95,
                warmup="auto", temperature=None) -> IMUNoise:
    """Noise of up to six axes.

    Parameters
    ----------
    columns : dict
        Axis (``gx gy gz ax ay az``) -> ``(column_name, samples, unit_suffix)``.
    rate_hz : float
        Sample rate, Hz (the ``update_rate`` written to Kalibr/ROS files).
    taus, method, tau_range_s
        As :func:`inertialab.noise.statistics.allan.oadev` and
        :func:`inertialab.noise.terms.fit.fit_noise_terms` (default octave taus, "wls").
    g_local : float, default 9.80665
        Local gravity for g-based accelerometer units, m/s^2.
    terms : bool, default True
        Fit the noise terms (False: the deviations only).
    confidence : float, default 0.95
        Two-sided confidence of every interval: the curves' and the terms'.
    drift : :class:`inertialab.workflows.imu_drift.DriftOptions`, optional
        Predict the integrated error per horizon, check it on another record or the
        second half, and plan the record length (:mod:`inertialab.workflows.imu_drift`).
    warmup : "auto", seconds or 0, default "auto"
        The log's warm-up span left out of every axis before fitting (and before the
        halves of a check on the second half): found in the data, given, or none
        (:func:`inertialab.workflows.imu_segments.apply_warmup`; ``temperature``: the
        log's temperature samples, judged with the axes).

    An axis that is not static (broadband excess over its white floor, gross
    excursions, the gravity direction turning:
    :mod:`inertialab.workflows.imu_noise_static`; or a curve that rises to 1 s or
    beyond) gets status ``not static`` with the reason and its deviation; the other axes
    go on.
    """
    if not columns:
        raise InputError("no IMU axis to analyse: need gx/gy/gz and/or ax/ay/az columns")
    unknown = set(columns) - set(AXES)
    if unknown:
        raise InputError(f"unknown axes {sorted(unknown)} (known: {', '.join(AXES)})")
    from inertialab.workflows.imu_segments import apply_warmup, axis_warmup

    columns, wu = apply_warmup(columns, float(rate_hz), warmup, temperature)
    out = []
    names = [a for a in AXES if a in columns]
    if drift is not None:  # the horizons against what the warm-up leaves, before any fit
        from inertialab.workflows.imu_drift import check_lengths

        check_lengths(drift, int(np.asarray(columns[names[0]][1]).shape[0]), float(rate_hz),
                      float(wu["span_s"]))
    moving = _motion(columns, names, float(rate_hz)) if terms else {}
    for i, name in enumerate(names):
        col, y, unit = columns[name]
        out.append(_axis(name, col, y, unit, rate_hz=float(rate_hz), taus=taus, method=method,
                         g_local=g_local, tau_range_s=tau_range_s, terms_on=terms,
                         drift=drift, confidence=confidence, motion=moving.get(name)))
        out[-1] = replace(out[-1], warmup=axis_warmup(wu, name))
        if progress is not None:
            progress.update(i + 1, len(names), name)
    n = int(np.asarray(columns[names[0]][1]).shape[0])
    settings = {"rate_hz": float(rate_hz), "taus": taus if isinstance(taus, (str, int)) else
                list(taus), "method": method, "g_local_mps2": float(g_local),
                "tau_range_s": None if tau_range_s is None else list(tau_range_s),
                "terms": bool(terms), "confidence": float(confidence)}
    if drift is not None:
        settings["drift"] = drift.to_dict()
    settings["warmup"] = {k: wu[k] for k in ("setting", "span_s", "from")}
    half = drift is not None and drift.check_on == "half"
    settings["fitted_on"] = {"first_sample": int(wu["n_samples"]),
                             "n_samples": n // 2 if half else n}
    return IMUNoise(axes=tuple(out), rate_hz=float(rate_hz), n_samples=n, settings=settings)


def _motion(columns: dict, names, rate_hz: float) -> dict:
    """``{axis: reason}`` of the axes that are not static
    (:func:`inertialab.workflows.imu_noise_static.motion_reasons`)."""
    from inertialab.workflows.imu_noise_static import motion_reasons

    return motion_reasons({n: np.asarray(columns[n][1], dtype=float) for n in names}, rate_hz)


def analyse_record(rec, *, rate_hz: float | None = None, taus="octave", method: str = "wls",
                   g_local: float | None = None, tau_range_s=None, progress=None,
                   terms: bool = True, drift=None, confidence: float = 0.95,
                   warmup="auto") -> IMUNoise:
    """:func:`analyse_imu` on the ``gx gy gz ax ay az`` columns of a ``gyro_log`` record
    (rate from ``rate_hz``, else the record's time base)."""
    if rate_hz is None:
        from inertialab.workflows.preflight import preflight

        preflight(rec, "imu")  # the checks `validate --kind imu` runs
    else:
        from inertialab.io.unit_check import check_static_units
        from inertialab.workflows.preflight import check_length, check_varying

        check_length(rec, "imu")  # preflight's length and unit checks, with the rate given
        check_varying(rec, "imu")
        check_static_units(rec)
    cols = axis_columns(rec)
    if not cols:
        raise InputError("no IMU axis columns (gx_*, gy_*, gz_*, ax_*, ay_*, az_*); map them "
                         "with a column map (argument 'column_map')", path=rec.path)
    if "segment" in rec.data.columns and rec.data["segment"].nunique() > 1:
        raise InputError("the log has several segments (argument 'gaps' split); analyse one segment",
                         path=rec.path)
    fs, tb = rate_hz, rec.timebase  # the record's one time base (io.timestamps)
    if fs is None:
        if tb is None:
            raise InputError("needs a t_s column or argument 'rate_hz'", path=rec.path)
        fs = tb.rate_hz  # lost samples NaN on the grid (gap-resistant OADEV)
        cols = {name: (c, tb.place(y), u) for name, (c, y, u) in cols.items()}
    tc = rec.find("temp")  # a temperature column is judged for the warm-up with the axes
    temp = None if tc is None else np.asarray(rec.column(tc), dtype=float)
    if temp is not None and rate_hz is None and tb is not None:
        temp = tb.place(temp)
    g = g_local if g_local is not None else float(rec.meta.get("g_local_mps2", U.G_STANDARD))
    note = filtered_source_note(rec)
    try:
        res = analyse_imu(cols, rate_hz=float(fs), taus=taus, method=method, g_local=g,
                           tau_range_s=tau_range_s, progress=progress, terms=terms,
                           drift=drift, confidence=confidence, warmup=warmup,
                           temperature=temp)
    except InputError as exc:
        if exc.path is not None or rec.path is None:
            raise
        raise InputError(str(exc), path=rec.path) from None
    if note:
        res.settings["source_note"] = note
    return res


def filtered_source_note(rec) -> str | None:
    """A warning (and the returned note) when the record is a filtered product rather
    than the sensor's own samples: PX4's ``sensor_combined`` is the flight controller's
    low-pass filtered, bias-corrected output, whose noise is not the sensor's."""
    ulog = rec.meta.get("ulog")
    if not (isinstance(ulog, dict) and ulog.get("topic") == "sensor_combined"):
        return None
    import warnings

    from inertialab.errors import DataQualityWarning

    note = ("read from PX4's sensor_combined, the flight controller's filtered output: its "
            "noise is the filter's, not the sensor's; read the raw sensors: argument 'topic' "
            "sensor_gyro, then sensor_accel")
    warnings.warn(f"{rec.path}: {note}", DataQualityWarning, stacklevel=3)
    return note


# ----------------------------------------------------- the command ``allan --imu``


def check_settings(config, exports=()) -> None:
    """Refuse, before any record is read, the six-axis settings of ``config`` (an
    :class:`~inertialab.workflows.allan.AllanConfig`) that cannot go together, and an
    unknown export target of ``exports`` (:func:`export_pairs`)."""
    from inertialab.export import get

    c = config
    for target, _ in exports:
        get("noise", target)  # an unknown target before anything is read
    if c.inflate not in (None, "auto", "none"):
        raise InputError(f"argument 'inflate' must be 'auto' or 'none', got '{c.inflate}'")
    if c.inflate == "auto" and not (exports and c.check_on and c.predict_drift):
        raise InputError("argument 'inflate' auto needs an export, a drift prediction and a "
                         "check log (the inflation comes from the observed drift)")
    if c.gaps not in (None, "error", "split"):
        raise InputError(f"argument 'gaps' must be 'error' or 'split', got '{c.gaps}'")
    if c.check_on and not c.predict_drift:
        raise InputError("argument 'check_on' needs argument 'predict_drift'")
    check_drift_confidence(c)
    check_six_axis_curve(c)
    if getattr(c, "pool_kind", None) not in (None, "runs") and not getattr(c, "pool", False):
        raise InputError(f"argument 'pool_kind' {c.pool_kind} needs argument 'pool' and "
                         "several logs: one log has no between-log spread to describe")
    if c.terms is False and (c.predict_drift or c.plan):
        raise InputError("a drift prediction or plan needs the noise terms")


def check_drift_confidence(config) -> None:
    """Refuse ``--confidence`` other than 0.95 with a drift prediction: its RMS interval
    (:func:`inertialab.noise.terms.drift_prediction.predicted_rms_ci`) is a 95 % interval
    that reads each term's interval as a 95 % one; with 68 % term intervals it came out
    about half as wide in its terms part and was still called 95 %."""
    c, want = getattr(config, "confidence", None), DEFAULT_CONFIDENCE["imu"]
    if c is not None and getattr(config, "predict_drift", None) and abs(float(c) - want) > 1e-9:
        raise InputError(f"argument 'confidence' {c:g} with argument 'predict_drift': the drift "
                         f"interval is a {100 * want:g} % interval built from the terms' "
                         f"{100 * want:g} % intervals; leave argument 'confidence' at {want:g} "
                         "for a drift prediction")


def check_six_axis_curve(config) -> None:
    """Refuse ``--stat`` and ``--taus`` other than the six-axis mode's own (the octave
    OADEV every term, drift and pool rests on): they were accepted and not used."""
    stat = str(getattr(config, "stat", "oadev") or "oadev").strip().lower()
    taus = str(getattr(config, "taus", "octave") or "octave").strip().lower()
    if stat != "oadev" or taus != "octave":
        raise InputError("argument 'stat' and argument 'taus' are not used in the six-axis "
                         "mode (argument 'imu': the octave OADEV of each axis); leave them "
                         "unset, or analyse one column without argument 'imu'")


def reading(config) -> dict:
    """The keywords with which ``allan --imu`` reads a log (the analysed one, and a check
    log): :func:`inertialab.io.read_record` ``(path, "gyro_log", **reading(config),
    options=...)``."""
    return {"unit": config.unit, "rate_hz": config.rate, "g_local": config.g_local,
            "gaps": config.gaps}


def check_log(config) -> str | None:
    """The other log a drift prediction is checked on (``--check-on LOG``), which the
    runner reads like the analysed one; None for ``half`` or no check."""
    c = config.check_on
    return None if not c or str(c).strip().lower() == "half" else str(c)


@dataclass
class SixAxisRun(ResultBase):
    """``allan --imu``: the six axes' :class:`IMUNoise` (``imu``), the log it came from
    (``file``) and the canonical hash of its record (``record_sha256``); ``settings``
    are the analysis's, the reading's (``map``, ``parse``, ``gaps``) and the exports'
    (:func:`write_exports`)."""

    imu: IMUNoise
    file: str
    record_sha256: str | None
    settings: dict
    units = {"rate_hz": "Hz"}

    def to_json(self) -> dict:
        return {"imu": self.imu.to_dict(), "sha256_canonical": self.record_sha256}

    def artifacts(self) -> dict:
        return {}  # the figures are the command's; the exports are written by run()

    def summary_rows(self) -> list:
        from inertialab.workflows.imu_drift import display_tables

        return [*display_tables(self.imu, self.file), "\n".join(self.imu.notes())]


def run(record, config, *, check=None, exports=(), rostopic=None, force: bool = False,
        read=None, progress=None) -> SixAxisRun:
    """``allan --imu`` on a ``gyro_log`` ``record`` (read with :func:`reading`) and its
    ``config`` (:class:`~inertialab.workflows.allan.AllanConfig`): the six axes analysed
    (:func:`analyse_record`; a drift prediction checked on ``check``, the record of
    :func:`check_log`), then, with the result complete, every ``(target, file)`` of
    ``exports`` written (:func:`write_exports`: all refused, nothing written, while an
    axis is not usable unless ``force``). ``read``: the reading options, named in the
    settings."""
    from inertialab.config import DEFAULT_CONFIDENCE
    from inertialab.io.mapping import ReadOptions
    from inertialab.workflows.imu_drift import drift_options

    c, exports = config, list(exports)
    check_settings(c, exports)
    ro = read if read is not None else ReadOptions()
    drift = drift_options(c.predict_drift, c.bias_window, c.check_on, c.plan, record,
                          rate=c.rate, unit=c.unit, g_local=c.g_local, gaps=c.gaps, ro=ro,
                          warmup=c.warmup, check_record=check)
    res = analyse_record(record, rate_hz=c.rate, method=c.method, g_local=c.g_local,
                         progress=progress, terms=c.terms is not False, drift=drift,
                         confidence=DEFAULT_CONFIDENCE["imu"] if c.confidence is None
                         else c.confidence, warmup=c.warmup)
    written = write_exports(res, exports, rostopic=rostopic or record.topic, force=force,
                            drift={"inflate": c.inflate})
    settings = {**res.settings, "map": ro.column_map.to_text() or None,
                "parse": ro.parse.to_dict(), "gaps": c.gaps, **written}
    return SixAxisRun(res, str(record.path), record.sha256, settings)


def export_pairs(export, *, seen=()) -> list[tuple[str, str]]:
    """``[(target, file), ...]`` of one ``(target, file)`` pair or a list of them;
    ``seen``: every pair of a command line where the option was repeated (taken when its
    last pair is ``export``). Two exports to one file are refused."""
    from inertialab.export import get

    if export and seen and tuple(seen[-1]) == tuple(export):
        export = list(seen)
    if not export:
        return []
    pairs = [tuple(export)] if isinstance(export[0], str) else [tuple(e) for e in export]
    for target, _ in pairs:
        get("noise", target)  # an unknown target before anything is read
    files = [str(f) for _, f in pairs]
    dup = next((f for f in files if files.count(f) > 1), None)
    if dup is not None:
        raise InputError(f"argument 'export': two exports write the same file '{dup}'; give "
                         "each its own file")
    return pairs


def export_refusal(res: IMUNoise, *, force: bool = False) -> tuple[str, ...]:
    """Refuse to export noise parameters while an axis is not usable (not static,
    constant, or without terms): one-line :class:`InputError` naming the axes, before
    any file is written. With ``force`` the lines the file must carry are returned
    instead (the axes left out and why)."""
    bad = [a for a in res.axes if a.status != "ok"]
    if not bad:
        return ()
    named = ", ".join(f"{a.axis} ({a.status})" for a in bad)
    if not force:
        raise InputError(f"argument 'export': the axes {named} give no noise parameters a "
                         "filter can "
                         "take (a record that moves describes the motion, not the sensor); "
                         "nothing written. Record the sensor at rest, or give argument 'force' to "
                         "write the other axes' values with this stated in the file")
    return (f"Written (forced) although {named}: those axes are left out, and their "
            "sensor's value comes from its other axes only.",)


def write_exports(res: IMUNoise, pairs, *, rostopic, drift=None, force=False) -> dict:
    """Write every ``(target, file)`` of ``pairs`` (:func:`export_pairs`; inflated where
    the drift settings ``drift`` say ``inflate: auto``), refused before any is written
    while an axis is not usable unless ``force`` (:func:`export_refusal`); returns the
    JSON settings that name them (``export``, ``export_file``: the last; ``exports``:
    all; ``force``)."""
    inflate = (drift or {}).get("inflate")
    if pairs:
        export_refusal(res, force=force)
    done = [(export_noise_file(res, t, f, rostopic=rostopic, inflate=inflate, force=force),
             str(f)) for t, f in pairs]
    return {"export": done[-1][0] if done else None,
            "export_file": done[-1][1] if done else None,
            "exports": [{"target": t, "file": f} for t, f in done], "force": bool(force)}


def export_noise_file(res: IMUNoise, target: str, path, *, rostopic: str, inflate=None,
                      force: bool = False) -> str:
    """Write the noise parameters for ``target`` (an exporter of
    :data:`inertialab.export.EXPORTERS`), inflated where ``inflate`` is ``auto``
    (:func:`inertialab.workflows.imu_drift.inflated`); returns the target's name.
    Refused while an axis is not usable unless ``force`` (:func:`export_refusal`)."""
    from inertialab.export import export_noise, get
    from inertialab.workflows.imu_drift import inflated

    target = get("noise", target).target
    forced = export_refusal(res, force=force)
    exported, note = inflated(res) if inflate == "auto" else (res, ())
    export_noise(exported, target, path, rostopic=rostopic, note=(*forced, *note))
    return target


def export_yaml(result: IMUNoise, style: str = "kalibr", *, rostopic: str = "/imu0",
                 namespace: str = "imu") -> str:
    """The text of a noise-parameter file for ``style`` (any noise target of
    :data:`inertialab.export.EXPORTERS`: kalibr, ros, openvins, vins, imu_utils,
    gtsam), continuous-time values, each sensor's largest axis."""
    from inertialab.export import noise_text

    return noise_text(result, style, rostopic=rostopic, namespace=namespace)
