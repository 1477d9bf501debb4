"""The drift an IMU noise model predicts, checked against a record, and how long to log.

For each axis of ``allan --imu`` (:mod:`inertialab.workflows.imu_noise`):

* **predicted drift** (:mod:`inertialab.noise.terms.drift_prediction`): the RMS and 95 % band
  of the error integrated over each horizon after removing a bias averaged over the
  preceding bias window — angle (deg) for a gyro, velocity (m/s) for an accelerometer —
  from the fitted model, and from the two values a Kalibr / imu_utils user reads off the
  curve (sigma at 1 s as the white density, the +1/2 line at 3 s as the random walk);
* **check** on another record of the same sensor, or on the second half of the log
  (the model then fitted on the first half): the observed RMS over non-overlapping
  windows, observed/predicted, the coverage of the 95 % band, and per term the inflation
  of its amplitude that would make prediction and observation agree;
* **plan**: the record length at which the Cramer-Rao bound (Whittle, every parameter
  free; :mod:`inertialab.noise.terms.information`) puts K, and B, within +-20 % at 95 %, for
  the fitted model, and whether this log is that long.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from inertialab import units as U
from inertialab.errors import InputError

#: axis name -> (kind) of the six IMU axes (column bases ``gx_<unit>`` ...)
AXES = {"gx": "gyro", "gy": "gyro", "gz": "gyro", "ax": "accel", "ay": "accel", "az": "accel"}

#: default bias window, s (a zero-velocity update or a short stop)
BIAS_WINDOW_S = 10.0
#: plan target: K within +-20 % at 95 % (1.96 sd of log K <= ln 1.2)
PLAN_REL = 0.20
PLAN_Z = 1.959963984540054


@dataclass(frozen=True)
class DriftOptions:
    """What :func:`axis_drift` does: ``horizons_s``; ``bias_window_s``; ``check_on``:
    None, ``"half"`` (fit the first half, check the second) or ``"other"`` (check on
    ``other``: axis -> samples of another record at the same rate); ``plan``."""

    horizons_s: tuple
    bias_window_s: float = BIAS_WINDOW_S
    check_on: str | None = None
    other: dict = field(default_factory=dict)
    other_name: str | None = None
    plan: bool = False

    def __post_init__(self):
        h = tuple(float(v) for v in self.horizons_s)
        if not h or not all(math.isfinite(v) and v > 0 for v in h):
            raise InputError(f"argument 'predict_drift' must be positive horizons in s, "
                             f"got {list(self.horizons_s)}")
        if not (math.isfinite(self.bias_window_s) and self.bias_window_s > 0):
            raise InputError(f"argument 'bias_window' must be positive seconds, got "
                             f"{self.bias_window_s}")
        if self.check_on not in (None, "half", "other"):
            raise InputError(f"argument 'check_on' must be 'half' or a file, got "
                             f"{self.check_on!r}")
        object.__setattr__(self, "horizons_s", h)

    def to_dict(self) -> dict:
        return {"horizons_s": list(self.horizons_s), "bias_window_s": self.bias_window_s,
                "check_on": self.other_name if self.check_on == "other" else self.check_on,
                "plan": self.plan}


def _integral_unit(axis) -> tuple[float, str]:
    """Factor from (data unit * s) to the report unit of the integrated error."""
    if axis.kind == "gyro":
        return U.convert(1.0, axis.unit, "dps"), "deg"
    return U.convert(1.0, axis.unit, "mps2", g_local=axis.terms.g_local), "m/s"


#: the new stretch's own deviation (the excess) plus that of the level fitted on the mean of
#: two halves (half the excess): the non-stationarity's part of a prediction's log-variance
NONSTATIONARY_FACTOR = 1.5


def nonstationary_log_var(stationarity, horizons_s) -> np.ndarray:
    """Variance of the log drift variance the measured between-segment spread adds at
    each horizon (:func:`inertialab.noise.segments.stationarity.excess_at` at tau = horizon, times
    ``NONSTATIONARY_FACTOR``) where the test's verdict is "not stationary"; zeros without
    a test or where it passed (a spread the test cannot tell from sampling is sampling:
    the clipped estimate max(0, s^2 - psi') is positive on half the stationary logs, and
    widened the presets' 60-300 s intervals to 100 % coverage)."""
    from inertialab.noise.segments.stationarity import excess_at

    h = np.atleast_1d(np.asarray(horizons_s, dtype=float))
    if stationarity is None or stationarity.verdict != "not stationary":
        return np.zeros(h.size)
    return NONSTATIONARY_FACTOR * excess_at(stationarity, h)


def _ci_dict(ci, f) -> dict:
    return {"confidence": ci["confidence"], "low": [float(v) * f for v in ci["low"]],
            "high": [float(v) * f for v in ci["high"]],
            "log_sd": {k: [float(x) for x in v] for k, v in ci["log_sd"].items()}}


def nonstationary_part(opts: DriftOptions, rate_hz: float, *, stationarity=None,
                       segments=None) -> np.ndarray:
    """The log-variance a log's non-stationarity adds to its drift prediction per
    horizon: with ``segments = (y_fit, fit)`` (the fitted samples and the axis's fit,
    ``fit(samples) -> (deviation, terms)``) the spread of the segments' own predicted
    drift (:func:`inertialab.noise.segments.drift_spread.segment_log_var`); without the
    samples, the segments test's Allan excess (:func:`nonstationary_log_var`)."""
    if segments is not None:
        from inertialab.noise.segments.drift_spread import segment_log_var

        y_fit, fit = segments
        return segment_log_var(y_fit, rate_hz, fit, opts.horizons_s, opts.bias_window_s)
    return nonstationary_log_var(stationarity, opts.horizons_s)


#: what a check on another log means when one log was fitted (the interval carries the
#: fitted log's own non-stationarity, not the difference between runs or units)
ONE_LOG_CAVEAT = ("not measured: one log was fitted, so the interval carries its own "
                  "non-stationarity but not how another run or unit differs; pool several "
                  "logs (argument 'pool') to measure that spread")


def axis_drift(axis, rate_hz: float, opts: DriftOptions, y_check=None, *,
               stationarity=None, extra_log_var=None, segments=None) -> dict:
    """``drift_prediction`` of one fitted axis (module docstring), JSON-ready, with the
    RMS's 95 % interval (``predicted_rms_ci``: the terms' uncertainty, the log's
    non-stationarity (:func:`nonstationary_part` of ``segments`` or ``stationarity``)
    and ``extra_log_var``, e.g. a pool's between-log spread) and, on a check, whether the
    observed RMS lies inside it."""
    from inertialab.noise.terms.drift_prediction import (
        check_prediction,
        kalibr_components,
        kalibr_reading,
        misfit_log_var,
        predict,
        predict_terms,
        predicted_rms_ci,
    )

    f, unit = _integral_unit(axis)
    pred = predict_terms(axis.terms, opts.horizons_s, opts.bias_window_s, rate_hz)
    out = pred.to_dict(f, unit)
    extra = nonstationary_part(opts, rate_hz, stationarity=stationarity, segments=segments)
    extra = extra + misfit_log_var(axis.deviation, axis.terms, opts.horizons_s)
    if extra_log_var is not None:
        extra = extra + np.asarray(extra_log_var, dtype=float)
    out["predicted_rms_ci"] = _ci_dict(predicted_rms_ci(pred, axis.terms,
                                                        extra_log_var=extra), f)
    n_k, k_k = kalibr_reading(axis.deviation)
    kal = predict(kalibr_components(axis.deviation), opts.horizons_s, opts.bias_window_s,
                  rate_hz)
    out["kalibr"] = {"noise_density": n_k, "random_walk": k_k, "unit": axis.unit + " (s)",
                     "predicted_rms": [float(v) * f for v in kal.rms],
                     "band_95": [float(v) * f for v in kal.band_95]}
    if y_check is not None:
        y_check = np.asarray(y_check, dtype=float)
        chk = check_prediction(pred, y_check, rate_hz)
        chk_k = check_prediction(kal, y_check, rate_hz)
        out["check"] = {
            "on": opts.other_name if opts.check_on == "other" else "second half",
            "observed_rms": [float(v) * f for v in chk["observed_rms"]],
            "n_windows": chk["n_windows"], "n_effective": chk["n_effective"],
            "n_effective_model": chk["n_effective_model"],
            "observed_over_predicted": [float(v) for v in chk["ratio"]],
            "coverage_95": chk["coverage_95"],
            "inflation": {k: [None if not math.isfinite(x) else float(x) for x in v]
                          for k, v in chk["inflation"].items()},
            "kalibr_observed_over_predicted": [float(v) for v in chk_k["ratio"]],
            "kalibr_coverage_95": chk_k["coverage_95"]}
        ci = predicted_rms_ci(pred, axis.terms, extra_log_var=extra,
                              n_windows=chk["n_effective_model"])
        obs = np.asarray(chk["observed_rms"], dtype=float)
        with_s = _ci_dict(ci, f)
        for key in ("low", "high"):  # no interval where nothing was observed (not [0, inf])
            with_s[key] = [v if math.isfinite(o) else None for v, o in zip(with_s[key], obs)]
        out["check"] |= {"rms_ci_with_sampling": with_s,
                         # None where the check log holds no window of that horizon
                         "inside_rms_ci": [bool(lo <= o <= hi) if math.isfinite(o) else None
                                           for o, lo, hi in zip(obs, ci["low"], ci["high"])]}
        if opts.check_on == "other" and extra_log_var is None:
            out["check"]["between_logs"] = ONE_LOG_CAVEAT
    return out


def axis_plan(axis, rate_hz: float, n_samples: int) -> dict:
    """Record length for K and for B, each within +-20 % at 95 % under the fitted model,
    and whether the analysed record (``n_samples``) is that long (``needed_h``,
    ``long_enough``, ``k_rel_95_now`` for K; ``b_needed_h``, ``b_long_enough``,
    ``b_rel_95_now`` for B). ``None`` values, with ``reason`` / ``b_reason``, where the
    model has no such term (nothing is then read, and no length is promised).

    K is the random walk's, or the Gauss–Markov random walk's of correlation time
    ``k_t_s`` (:func:`_processes`). B is what each fit's B summarises: the default fit's
    band-limited flicker (its amplitude free, its corners held), or the GMWM fit's
    Gauss–Markov and band processes other than those it reads as K (a GM whose Allan
    peak is not followed by an octave of fitted scales), read on the fitted scales as
    GMWM reads B (:func:`inertialab.noise.terms.information.processes_bounds`)."""
    from inertialab.noise.terms.information import processes_bounds

    tau0 = 1.0 / rate_hz
    procs, k_gm = _processes(axis.terms, tau0, n_samples)
    rng = axis.terms.tau_range_s if axis.terms.gmwm else None

    def sd_at(n):
        b = processes_bounds(procs, tau0, int(n), k_gm=k_gm, tau_range_s=rng)
        return {t: (None if v is None else v.free) for t, v in b.items()}

    have_h = n_samples * tau0 / 3600.0
    target = math.log(1.0 + PLAN_REL) / PLAN_Z
    now = sd_at(n_samples)
    t_k = next((procs[i].params["tc_s"] for i in k_gm), None)
    out = {"target": f"K and B each within +-{100 * PLAN_REL:g} % at 95 %",
           "record_h": have_h, "bound": "Whittle Cramer-Rao, all parameters free",
           "k_process": ("random walk" if t_k is None
                         else "Gauss-Markov random walk"),
           "k_t_s": t_k,
           "b_process": ("Gauss-Markov processes" if axis.terms.gmwm
                         else "band-limited flicker")}
    for term, pre, what in (("K", "", "random walk"), ("B", "b_", "bias instability")):
        sd_now = now[term]
        if sd_now is None:
            out |= {f"{pre}needed_h": None, f"{pre}long_enough": None,
                    f"{pre}reason": f"the fitted model has no {what}"}
            continue
        n = _needed_n(lambda m, t=term: sd_at(m)[t], n_samples, sd_now, target)
        out |= {f"{pre}needed_h": n * tau0 / 3600.0,
                f"{pre}long_enough": bool(sd_now <= target),
                f"{'k_' if term == 'K' else pre}rel_95_now": PLAN_Z * sd_now}
    return out


def _needed_n(sd_of, n0: int, sd0: float, target: float) -> float:
    """Samples at which the bound ``sd_of(n)`` reaches ``target``: it falls like
    ``n^-p`` locally; ``p`` from the bound at four times the length, then a step, until
    the step changes ``n`` by under 5 %."""
    n, sd = float(n0), sd0
    for _ in range(6):
        sd2 = sd_of(n * 4.0)
        if not (math.isfinite(sd) and math.isfinite(sd2)):
            return math.inf
        p = max(math.log(sd / sd2) / math.log(4.0), 0.05)
        n_next = n * (sd / target) ** (1.0 / p)
        if abs(math.log(n_next / n)) < 0.05:
            return n_next
        n = min(max(n_next, 16.0), 1e12)
        sd = sd_of(n)
    return n


def _processes(terms, tau0: float, n_samples: int):
    """``(processes, k_gm)``: the fitted model as latent processes (GMWM's own, or the
    five-term fit's white noise, band-limited B as a BL process, and K as a random walk
    or, where the fit holds it by a correlation time ``terms.k_gm``, as that
    Gauss–Markov process), and the indices of the Gauss–Markov processes that are K
    (the five-term fit's K process; GMWM's slow GMs, :func:`inertialab.noise.gmwm.fit.k_of`)."""
    from inertialab.noise.gmwm.fit import Process

    gm = (terms.gmwm or {}).get("processes")
    if gm:
        from inertialab.noise.gmwm.fit import is_slow_process

        procs = [Process(d["process"], dict(d["params"])) for d in gm]
        t_rise = terms.gmwm.get("t_rise_s")
        return procs, [i for i, p in enumerate(procs) if is_slow_process(p, terms.tau_range_s, t_rise)]
    c = [0.0 if not np.isfinite(v) else float(v) for v in terms.coefficients]
    out, k_gm = [], []
    if c[1] > 0:
        out.append(Process("WN", {"sigma2": c[1] / tau0}))
    if c[2] > 0:
        bg = terms.bias_gm or {}
        lo = bg.get("t_lo_s") or tau0
        hi = bg.get("t_hi_s") or 2.0 * n_samples * tau0
        out.append(Process("BL", {"c0": c[2], "t_lo_s": lo, "t_hi_s": hi}))
    if c[3] > 0 and terms.k_gm:
        t_k = float(terms.k_gm["t_s"])
        k_gm.append(len(out))
        out.append(Process("GM", {"s2": 1.5 * c[3] * t_k, "tc_s": t_k}))
    elif c[3] > 0:
        out.append(Process("RW", {"gamma2": 3.0 * c[3] * tau0}))
    return out, k_gm


def inflated(res):
    """``(analysis, note)``: the six-axis analysis with each sensor's noise densities and
    random walks multiplied by the largest observed/predicted RMS of its checked axes over
    the horizons (at least 1), so that the drift the exported values predict covers the
    observed drift at every horizon; ``note``: the comment lines that say so."""
    from dataclasses import replace

    out, note = [], []
    for kind, label in (("gyro", "gyroscope"), ("accel", "accelerometer")):
        ratios = [r for a in res.axes if a.kind == kind and a.drift and "check" in a.drift
                  for r in a.drift["check"]["observed_over_predicted"] if math.isfinite(r)]
        f = max([1.0, *ratios])
        checked = [a for a in res.axes if a.kind == kind and a.drift and "check" in a.drift]
        if checked and not ratios:
            _uninflated(label, checked[0].drift["check"]["on"], note)
        others = [a for a in res.axes if a.kind != kind and a.drift and "check" in a.drift]
        if not checked and others and any(a.kind == kind for a in res.axes):
            # the check log has none of this sensor's axes (or only constant ones)
            _uninflated(label, others[0].drift["check"]["on"], note,
                        why=f"has no usable {label} axis")
        if ratios:
            check = next(a.drift["check"]["on"] for a in res.axes
                         if a.kind == kind and a.drift and "check" in a.drift)
            note.append(f"{label} noise density and random walk inflated x{f:.3g}: the "
                        f"largest observed/predicted drift RMS on {check} over horizons "
                        f"{', '.join(f'{h:g}' for h in res.axes[0].drift['horizons_s'])} s "
                        f"after a {res.axes[0].drift['bias_window_s']:g}-s bias window")
        out += [(a.axis, f) for a in res.axes if a.kind == kind]
    scale = dict(out)
    axes = tuple(replace(a, noise_density=a.noise_density * scale[a.axis],
                         random_walk=a.random_walk * scale[a.axis]) for a in res.axes)
    return replace(res, axes=axes), tuple(note)


def _uninflated(label: str, check: str, note: list,
                why: str = "has no usable window at any horizon") -> None:
    """Say (a note in the exported file and a warning) that a sensor's values are
    exported as fitted: its check observed no window at any horizon, or (``why``) the
    check log holds none of its axes."""
    import warnings

    from inertialab.errors import DataQualityWarning

    text = (f"{label} noise density and random walk NOT inflated: the drift check on "
            f"{check} {why}, so the exported values are the fitted ones")
    note.append(text)
    warnings.warn(text, DataQualityWarning, stacklevel=3)


def axis_columns(rec) -> dict:
    """``{axis: (column, samples, unit)}`` of the ``gx gy gz ax ay az`` columns of a
    record."""
    cols = {}
    for name in AXES:
        c = rec.find(name)
        if c is not None:
            cols[name] = (c, rec.column(c), rec.units[c])
    return cols


def drift_options(predict_drift, bias_window, check_on, plan, rec, *, rate, unit, g_local,
                   gaps, ro, warmup="auto", check_record=None):
    """The :class:`DriftOptions` of the command's settings (``check_on``: ``half`` or
    another log, read like the main one, or already read: ``check_record``), or None
    without a prediction or plan."""
    if not predict_drift and not plan:
        return None
    from inertialab.workflows.imu_options import parse_horizons

    horizons = parse_horizons(predict_drift) if predict_drift else ()
    other, name, mode = {}, None, None
    if check_on:
        if str(check_on).strip().lower() == "half":
            mode = "half"
        else:
            rec2 = check_record
            if rec2 is None:
                from inertialab.io import read_record
                rec2 = read_record(check_on, "gyro_log", unit=unit, rate_hz=rate,
                                   g_local=g_local, gaps=gaps, options=ro)
            if getattr(rec, "sha256", None) and getattr(rec2, "sha256", None) == rec.sha256:
                raise InputError("the check log holds the analysed log's samples (a copy "
                                 "under another name): a check needs other data; give half "
                                 "to check on the second half", path=check_on)
            tb1, tb2 = rec.timebase, rec2.timebase
            fs1 = rate or (tb1.rate_hz if tb1 is not None else None)
            fs2 = rate or (tb2.rate_hz if tb2 is not None else None)
            if fs1 and fs2 and abs(float(fs1) / float(fs2) - 1) > 1e-3:
                raise InputError(f"the check log is at {fs2:g} Hz, the analysed log at "
                                 f"{fs1:g} Hz: give logs of the same rate", path=check_on)
            place = tb2.place if (rate is None and tb2 is not None) else (lambda v: v)
            main, theirs = axis_columns(rec), axis_columns(rec2)
            _check_axes(list(main), list(theirs), check_on)
            other = _in_units_of(theirs, main, place, g_local)
            tc = rec2.find("temp")  # its temperature judged for its warm-up, as the log's
            temp = None if tc is None else place(np.asarray(rec2.column(tc), dtype=float))
            other = _other_after_warmup(other, float(fs2 or fs1 or 0.0), warmup, temp,
                                        path=check_on)
            other = usable_check_axes(other, check_on, {k: v[0] for k, v in theirs.items()})
            mode, name = "other", str(check_on)
    return DriftOptions(horizons_s=horizons or (1.0,), bias_window_s=float(bias_window),
                        check_on=mode, other=other, other_name=name, plan=bool(plan))


def usable_check_axes(other: dict, check_on, columns=None) -> dict:
    """The check log's axes (``{axis: samples}``) without those that are constant or stuck
    (:func:`inertialab.io.gaps.stuck_run`): they observe no drift, and would read as
    misses; each is named in a warning (``columns``: axis -> the log's column name), and a
    check log with no usable axis is refused."""
    import warnings

    from inertialab.errors import DataQualityWarning
    from inertialab.io.gaps import is_constant, stuck_run

    out = {}
    for k, y in other.items():
        y = np.asarray(y, dtype=float)
        constant = is_constant(y, empty=True)
        run = None if constant else stuck_run(y)
        if constant or run is not None:
            why = ("constant" if constant else
                   f"stuck ({run[1]} identical samples from sample {run[0]})")
            warnings.warn(f"{check_on}: column '{(columns or {}).get(k, k)}' of the check "
                          f"log is {why}: it observes no drift, that axis is not checked",
                          DataQualityWarning, stacklevel=3)
            continue
        out[k] = y
    if other and not out:
        raise InputError("the check log has no axis that is not constant or stuck: nothing "
                         "to check on", path=check_on)
    return out


def _check_axes(analysed: list, check: list, check_on) -> None:
    """Refuse a check log that holds none of the analysed axes (another sensor kind: it
    would check nothing); warn, naming them, about analysed axes it lacks (not checked)."""
    common = [a for a in analysed if a in check]
    if not common:
        raise InputError(f"the check log has none of the analysed axes ({' '.join(analysed)}"
                         f"); it has {' '.join(check) or 'no IMU axis'}: give a log of the "
                         "same sensor", path=check_on)
    lacking = [a for a in analysed if a not in check]
    if lacking:
        import warnings

        from inertialab.errors import DataQualityWarning

        warnings.warn(f"{check_on}: the check log has no {' '.join(lacking)} column: "
                      f"{'that axis is' if len(lacking) == 1 else 'those axes are'} not "
                      "checked", DataQualityWarning, stacklevel=3)


def check_lengths(opts: DriftOptions, n_samples: int, rate_hz: float,
                  warmup_s: float = 0.0) -> None:
    """:func:`inertialab.workflows.imu_options.check_horizons` on what is fitted:
    ``n_samples`` left after the log's warm-up span (``warmup_s``, named in a refusal),
    its first half where the check is on the second half, and the check data's length
    (the second half, or the other log after its own warm-up)."""
    from inertialab.workflows.imu_options import check_horizons

    fs = float(rate_hz or 0.0)
    if fs <= 0 or n_samples <= 0:
        return
    n = n_samples // 2 if opts.check_on == "half" else n_samples
    check, what = None, None
    if opts.check_on == "half":
        check, what = (n_samples - n) / fs, "the second half"
    elif opts.check_on == "other" and opts.other:
        check, what = min(len(v) for v in opts.other.values()) / fs, opts.other_name
    note = (f" (after the {warmup_s:g}-s warm-up cut" + (", its first half" if n < n_samples
                                                        else "") + ")") if warmup_s > 0 else ""
    check_horizons(opts.horizons_s, opts.bias_window_s, n / fs, check_s=check,
                   check_name=what, fitted_note=note)


def _in_units_of(check_cols: dict, main_cols: dict, place, g_local) -> dict:
    """The check log's axes converted from their own units into the analysed log's
    (a check log in deg/s and g against one in rad/s and m/s^2 compares like with
    like)."""
    g = U.G_STANDARD if g_local is None else float(g_local)
    out = {}
    for k, (_, y, unit) in check_cols.items():
        if k in main_cols:
            y = np.asarray(U.convert(np.asarray(y, dtype=float), unit, main_cols[k][2],
                                     g_local=g), dtype=float)
        out[k] = place(y)
    return out


def _other_after_warmup(other: dict, rate_hz: float, warmup, temperature=None, *,
                        path=None) -> dict:
    """The check log's axes with its own warm-up span cut, as the analysed log's (its
    ``temperature`` judged with them); a span too long for it is refused naming
    ``path``."""
    from inertialab.workflows.imu_segments import apply_warmup

    if not other or not rate_hz:
        return other
    try:
        cols, _ = apply_warmup({k: (k, v, "") for k, v in other.items()}, rate_hz, warmup,
                               temperature)
    except InputError as exc:
        raise InputError(f"the check log: {exc}", path=path) from None
    return {k: v[1] for k, v in cols.items()}


def display_tables(res, file) -> list:
    """``(title, columns, rows)`` of everything ``allan --imu`` prints: the noise table
    (:meth:`IMUNoise.table`), then :func:`drift_tables`."""
    cols, rows = res.table()
    title = (f"{file}: IMU noise, {res.n_samples} samples at {res.rate_hz:g} Hz "
             f"({100 * res.term_confidence:g} % intervals; '<=' an upper bound; densities "
             "continuous-time, SI)")
    return [(title, cols, rows), *drift_tables(res)]


def _cell(v, fmt: str) -> str:
    """A number of a drift table, or '-' where there is none (a horizon the check log
    holds no window of: None or NaN)."""
    return format(v, fmt) if v is not None and math.isfinite(v) else "-"


def _check_rows(axis: str, unit: str, c: dict) -> list:
    """The drift table's rows of one axis's check: the windows observed (what the RMS and
    the band's coverage rest on: 100 % of 3 windows is little), the observed RMS and its
    ratios, the band's coverage, and the RMS interval widened by the observed RMS's own sampling
    (the one ``inside_rms_ci`` is judged by), then that verdict."""
    rows = [[axis, "windows observed"] + [str(int(v)) for v in c["n_windows"]],
            [axis, f"observed RMS ({unit})"] + [_cell(v, ".3g") for v in c["observed_rms"]],
            [axis, "observed/model"] + [_cell(v, ".2f") for v in c["observed_over_predicted"]],
            [axis, "observed/Kalibr"]
            + [_cell(v, ".2f") for v in c["kalibr_observed_over_predicted"]],
            [axis, "in model 95 % band"]
            + [_cell(v, ".0%").replace("%", " %") for v in c["coverage_95"]]]
    ci = c.get("rms_ci_with_sampling")
    if ci and "inside_rms_ci" in c:
        rows.append([axis, "interval with the check's sampling"]
                    + [f"{_cell(lo, '.3g')}-{_cell(hi, '.3g')}" if ok is not None else "-"
                       for lo, hi, ok in zip(ci["low"], ci["high"], c["inside_rms_ci"])])
    if "inside_rms_ci" in c:
        rows.append([axis, "observed inside RMS interval"]
                    + [{True: "yes", False: "NO"}.get(v, "-") for v in c["inside_rms_ci"]])
    return rows


def drift_tables(res) -> list:
    """``(title, columns, rows)`` of the predicted-drift, check and plan tables."""
    out = []
    axes = [a for a in res.axes if a.drift is not None]
    if axes and res.settings.get("drift", {}).get("horizons_s"):
        hz = axes[0].drift["horizons_s"]
        w = axes[0].drift["bias_window_s"]
        cols = ["axis", "source"] + [f"{h:g} s" for h in hz]
        rows = []
        for a in axes:
            d, u = a.drift, a.drift["unit"]
            rows.append([a.axis, f"model RMS ({u})"] + [f"{v:.3g}" for v in d["predicted_rms"]])
            ci = d.get("predicted_rms_ci")
            if ci:
                rows.append([a.axis, "model RMS 95 % interval"]
                            + [f"{lo:.3g}-{hi:.3g}" for lo, hi in zip(ci["low"], ci["high"])])
            rows.append([a.axis, f"Kalibr RMS ({u})"]
                        + [f"{v:.3g}" for v in d["kalibr"]["predicted_rms"]])
            c = d.get("check")
            if c:
                rows += _check_rows(a.axis, u, c)
        chk = next((a.drift["check"] for a in axes if "check" in a.drift), {})
        check = chk.get("on")
        caveat = ("; between logs: " + chk["between_logs"]) if chk.get("between_logs") else ""
        out.append((f"Integrated error after a {w:g}-s bias window (angle for gyros, "
                    "velocity for accelerometers)" + (f"; checked on {check}" if check
                                                      else "") + caveat, cols, rows))
    plans = [a for a in res.axes if a.plan is not None]
    if plans:
        yes = {True: "yes", False: "no", None: "-"}

        def hours(v):
            return "-" if v is None else ("never" if not math.isfinite(v) else f"{v:.3g}")

        def k_hours(p):  # the length with its 95 % interval; at K's bound, at least it
            lo, hi = (p.get("needed_h_95") or [None, None])[:2]
            if p.get("k_at_bound"):
                return f">= {hours(p['needed_h'])}"
            if lo is None or hi is None:
                return hours(p["needed_h"])
            return f"{hours(p['needed_h'])} [{hours(lo)}, {hours(hi)}]"

        rows = []
        for a in plans:
            p = a.plan
            note = [v for v in (p.get("reason"), p.get("b_reason")) if v]
            if p.get("k_t_s") is not None:
                note.insert(0, f"K: Gauss-Markov random walk, T = {p['k_t_s']:.3g} s")
            rows.append([a.axis, k_hours(p), hours(p.get("b_needed_h")),
                         f"{p['record_h']:.3g}", yes[p["long_enough"]],
                         yes[p.get("b_long_enough")], "; ".join(note)])
        out.append(("Record length for K and for B, each within +-20 % at 95 % (Cramer-Rao "
                    "bound of the fitted model; K's length with its 95 % interval from the "
                    "fitted K's, '>=' where K is a bound)",
                    ["axis", "K needs (h)", "B needs (h)", "this log (h)", "K long enough",
                     "B long enough", "note"], rows))
    return out


__all__ = ["AXES", "BIAS_WINDOW_S", "DriftOptions", "NONSTATIONARY_FACTOR", "ONE_LOG_CAVEAT", "axis_columns",
           "axis_drift", "axis_plan", "check_lengths", "usable_check_axes", "display_tables", "drift_options", "drift_tables",
           "inflated", "nonstationary_log_var", "nonstationary_part"]
