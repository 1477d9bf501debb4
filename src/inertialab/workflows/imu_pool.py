"""``allan --imu LOG1 LOG2 ... --pool``: several static logs as one noise model per axis.

Each log is read (by the command runner) with its own units, column names and time
base (the reader's), its axes converted to the first log's units, its warm-up cut
(:func:`inertialab.workflows.imu_segments.apply_warmup`), and its octave overlapping
Allan deviation computed. A log that cannot join (no IMU axis, axes the first log has
missing, a column of another quantity, an axis that is not static) is refused in one
line naming it before anything is fitted. Per axis then (:mod:`inertialab.noise.terms.pooled`):

* the pooled curve on the first log's taus (logs of another rate only from
  ``QN_SPLIT_S``: Q and N pooled only across logs of one rate);
* the model chosen among ``candidates`` (:data:`CANDIDATES` of the method: WLS with the
  band-limited B or with IEEE 952's flicker B; GMWM or WLS) by leave-one-log-out: each
  fitted on the other logs' pooled curve and scored on the left-out log's curve
  (:func:`inertialab.noise.terms.pooled.cv_score`); the pooled terms are the chosen model's;
* each log's own terms beside them (``logs[]``), and the near-stationarity test between
  the logs' curves;
* the N, B and K intervals widened by the between-log spread of the logs' own terms
  (random effects, never below the logs' within-log segment spread, with Student's
  t on n - 1 degrees of freedom: the interval for the next log); ``pool_kind``
  says what that spread is: run to run of one unit, or unit to unit of one model;
* with a drift prediction, its RMS interval carries the between-log spread of each log's
  own predicted drift the same way (a log too short for a horizon and its bias window is
  left out there, named in a warning), and ``check_on`` another log checks it there;
* warnings name the log: where the logs differ beyond sampling (the farthest), where one
  is not stationary, and axes a log has that the first lacks (left out).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

import numpy as np

from inertialab import units as U
from inertialab.config import DEFAULT_CONFIDENCE
from inertialab.errors import InputError
from inertialab.result import ResultBase
from inertialab.workflows.imu_drift import AXES, axis_columns, usable_check_axes

#: what the between-log spread means, per pool kind
POOL_KINDS = {"runs": "run-to-run spread of one unit (turn-on to turn-on)",
              "units": "unit-to-unit spread of one sensor model"}
_SI = {"gyro": "rps", "accel": "mps2"}


@dataclass
class PoolLog:
    """One log of a pool: ``file``, ``rate_hz``, ``columns`` (``{axis: (column, samples
    in the pool's unit, unit)}``), ``units`` (its own unit per axis), ``warmup`` (the span
    and its evidence), ``sha256``."""

    file: str
    rate_hz: float
    columns: dict
    units: dict
    warmup: dict
    sha256: str | None = None
    curves: dict = field(default_factory=dict)

    def summary(self) -> dict:
        n = min(len(v[1]) for v in self.columns.values())
        return {"file": self.file, "rate_hz": self.rate_hz, "n_samples": int(n),
                "duration_s": n / self.rate_hz, "units": self.units,
                "columns": {k: v[0] for k, v in self.columns.items()},
                "warmup": {k: self.warmup[k] for k in ("setting", "span_s", "from")}}


def log_columns(rec, *, rate=None):
    """``(rate_hz, columns, temperature)`` of one log's record (read by the command
    runner as ``allan --imu`` reads it): the rate from ``rate`` or the record's time
    base, the axes and temperature placed on that time base."""
    file = rec.path
    cols = axis_columns(rec)
    if not cols:
        raise InputError("cannot join the pool: no IMU axis columns (gx_*, gy_*, gz_*, ax_*, "
                         "ay_*, az_*)", path=file)
    tb, fs = rec.timebase, rate
    tc = rec.find("temp")
    temp = None if tc is None else np.asarray(rec.column(tc), dtype=float)
    if fs is None:
        if tb is None:
            raise InputError("cannot join the pool: needs a t_s column or argument 'rate'",
                             path=file)
        fs = tb.rate_hz
        cols = {k: (c, tb.place(y), u) for k, (c, y, u) in cols.items()}
        temp = None if temp is None else tb.place(temp)
    return float(fs), cols, temp


def _to_pool_units(cols: dict, ref_units: dict, g: float, file) -> tuple[dict, dict]:
    """The axes in the first log's units (each axis read with its own)."""
    out, own = {}, {}
    for k, (c, y, u) in cols.items():
        want = "angular_rate" if AXES[k] == "gyro" else "acceleration"
        dim = U.lookup(u).dimension
        if dim != want:
            raise InputError(f"cannot join the pool: column '{c}' is a {dim}, expected a "
                             f"{want}", path=file)
        f = U.convert(1.0, u, ref_units.get(k, u), g_local=g)
        out[k] = (c, np.asarray(y, dtype=float) * f, ref_units.get(k, u))
        own[k] = u
    return out, own


def join_pool(records, *, rate=None, g_local=None, warmup="auto",
              name_extra: bool = True) -> list[PoolLog]:
    """Every log of a pool (its record, read with its own units and time base) checked
    to join (module docstring), its axes in the first log's units, its warm-up cut; a
    log's axes the first log lacks are left out, named in a warning (``name_extra``)."""
    from inertialab.workflows.imu_segments import apply_warmup

    logs, ref_units, ref_axes = [], {}, None
    for rec in records:
        f = rec.path
        same = [lg.file for lg in logs if lg.file == str(f)
                or (rec.sha256 is not None and lg.sha256 == rec.sha256)]
        if same:  # a log twice would be a between-log spread of none
            raise InputError(f"cannot join the pool: the same samples as {same[0]} (a log "
                             "given twice would read as two logs that agree)", path=f)
        fs, cols, temp = log_columns(rec, rate=rate)
        if ref_axes is None:
            ref_axes = tuple(a for a in AXES if a in cols)
            ref_units = {k: v[2] for k, v in cols.items()}
        missing = [a for a in ref_axes if a not in cols]
        if missing:
            raise InputError(f"cannot join the pool: axes {' '.join(missing)} missing (the "
                             f"first log has {' '.join(ref_axes)})", path=f)
        extra = [a for a in cols if a not in ref_axes]
        if extra and name_extra:  # pooled are the first log's axes: say which of this log's are left out
            import warnings

            from inertialab.errors import DataQualityWarning

            warnings.warn(f"{f}: axes {' '.join(extra)} are not in the first log "
                          f"({logs[0].file if logs else f}): left out of the pool",
                          DataQualityWarning, stacklevel=3)
        cols = {k: v for k, v in cols.items() if k in ref_axes}
        g = g_local if g_local is not None else float(rec.meta.get("g_local_mps2",
                                                                   U.G_STANDARD))
        cols, own = _to_pool_units(cols, ref_units, g, f)
        try:
            cols, wu = apply_warmup(cols, fs, warmup, temp)
        except InputError as exc:  # a span too long for this log: the log named
            raise InputError(str(exc), path=f) from None
        logs.append(PoolLog(str(f), fs, cols, own, wu, rec.sha256))
    return logs


def _curves(logs, confidence: float) -> None:
    """Each log's octave OADEV per axis, refusing (naming the log and column) an axis that
    is constant, stuck (:func:`inertialab.io.gaps.stuck_run`) or not static."""
    from inertialab.io.gaps import is_constant
    from inertialab.noise.terms.fit import not_static_reason
    from inertialab.workflows.imu_noise import _deviation, _stuck_reason

    for lg in logs:
        for k, (c, y, _u) in lg.columns.items():
            y = np.asarray(y, dtype=float)
            if is_constant(y, empty=True):
                raise InputError(f"cannot join the pool: column '{c}' is constant (every "
                                 "sample the same value: a stuck or absent sensor)",
                                 path=lg.file)
            stuck = _stuck_reason(y, lg.rate_hz)
            if stuck:
                raise InputError(f"cannot join the pool: column '{c}' has {stuck}",
                                 path=lg.file)
            dev = _deviation(y, lg.rate_hz, "octave", confidence)
            why = not_static_reason(dev.taus_s, dev.dev)
            if why:
                raise InputError(f"cannot join the pool: column '{c}' {why}", path=lg.file)
            lg.curves[k] = dev


#: the models the leave-one-log-out chooses among, per method: WLS with the band-limited
#: B against IEEE 952's flicker B; GMWM (its WIC's processes) against that WLS
CANDIDATES = {"wls": ("wls", "wls-flicker"), "gmwm": ("gmwm", "wls")}


def _fit(dev, unit: str, kind: str, method: str, rate_hz: float, g: float, confidence: float):
    """The noise terms of a curve by ``method`` (``wls-flicker``: WLS with IEEE 952's
    flicker B, :func:`inertialab.noise.terms.fit.fit_noise_terms` ``b_shape="flicker"``)."""
    from inertialab.noise.terms.fit import fit_noise_terms
    from inertialab.workflows.imu_noise import B_RULE

    shape = "flicker" if method == "wls-flicker" else "band"
    return fit_noise_terms(dev, unit=unit, kind=kind, method=method.replace("-flicker", ""),
                           rate_hz=rate_hz, g_local=g, confidence=confidence, b_shape=shape,
                           b_rule=B_RULE)


def choose_model(curves, rates, unit, kind, candidates, g, confidence) -> dict:
    """Leave-one-log-out choice among ``candidates`` (module docstring):
    ``{"criterion", "scores": {method: mean score}, "chosen"}``; with one log (nothing to
    leave out) the first candidate."""
    from inertialab.noise.terms.pooled import cv_score, pool_curves

    if len(curves) < 2 or len(candidates) < 2:
        return {"criterion": None, "scores": {}, "chosen": candidates[0],
                "reason": "one log or one candidate: nothing to choose by leave-one-out"}
    scores = {}
    for m in candidates:
        per = []
        for j in range(len(curves)):
            rest = [c for i, c in enumerate(curves) if i != j]
            r_rates = [r for i, r in enumerate(rates) if i != j]
            try:
                t = _fit(pool_curves(rest, r_rates, confidence), unit, kind, m, r_rates[0], g,
                         confidence)
            except InputError:
                per.append(math.inf)
                continue
            per.append(cv_score(curves[j], t.model_dev(np.asarray(curves[j].taus_s))))
        scores[m] = float(np.mean(per))
    chosen = min(scores, key=lambda k: (scores[k], candidates.index(k)))
    return {"criterion": "leave-one-log-out: mean over the left-out log's taus of "
                         "(ln AVAR - ln model)^2 / psi'(edf/2)",
            "scores": scores, "chosen": chosen}


def _term_prior(stats, term) -> float:
    """Prior of a term's between-log log-variance: the logs' within-log segment spread
    of ln AVAR over the term's read range (where it has none, a bound read nowhere: the
    largest over the tested taus), over 4 (a term's amplitude is a square root)."""
    from inertialab.noise.segments.stationarity import excess_at

    lo, hi = term.tau_range_s if term.tau_range_s else (1.0, 1.0)
    if math.isfinite(lo) and math.isfinite(hi):
        taus = [math.sqrt(max(lo, 1e-9) * max(hi, 1e-9))]
    else:  # a term read nowhere (a bound at 0): the most spread any tested tau shows
        taus = np.geomspace(1e-3, 1e6, 46)
    v = [float(np.max(excess_at(st, taus))) for st in stats if st is not None]
    return float(np.mean(v)) / 4.0 if v else 0.0


def widen_terms(pooled, own_terms, stats, same_rate, z,
                confidence: float = DEFAULT_CONFIDENCE["imu"]) -> tuple[object, dict]:
    """The pooled terms with N, B and K intervals carrying the between-log spread of the
    logs' own terms (N and Q only over the logs of the reference rate), and the spreads
    ``{term: variance of the next log's ln term}``
    (:func:`inertialab.noise.terms.pooled.next_log_var`)."""
    from inertialab.noise.terms.pooled import next_log_var, widen_term

    spread, new = {}, {}
    for name in ("N", "B", "K"):
        vals, samp = [], []
        for i, t in enumerate(own_terms):
            term = getattr(t, name)
            if name == "N" and not same_rate[i]:
                continue
            lo, hi = (float(v) for v in term.ci)
            if term.significant and term.value > 0 and lo > 0 and math.isfinite(hi):
                vals.append(math.log(term.value))
                samp.append((math.log(hi / lo) / (2 * z)) ** 2)
        prior = _term_prior(stats, getattr(pooled, name))
        spread[name] = next_log_var(vals, samp, prior, confidence)
        new[name] = widen_term(getattr(pooled, name), spread[name], z)
    return replace(pooled, **new), spread


def pooled_axis(name, column, unit, dev, terms, g):
    """An :class:`~inertialab.workflows.imu_noise.AxisNoise` of pooled terms: the SI
    densities as ``allan --imu`` reports them (a K or B that is a bound as its upper
    end)."""
    from inertialab.workflows.imu_noise import AxisNoise, _report_factor

    kind = AXES[name]

    def si(v):
        return U.convert(v, unit, _SI[kind], g_local=g)

    c = [float(v) if np.isfinite(v) else math.nan for v in terms.coefficients]
    nan = math.nan
    dens = si(math.sqrt(c[1])) if c[1] > 0 else nan
    k_bound = not terms.K.significant
    if not k_bound and c[3] > 0:
        rw = si(math.sqrt(3.0 * c[3]))
    elif math.isfinite(terms.K.upper_bound) and terms.K.upper_bound > 0:
        rw, k_bound = si(terms.K.upper_bound / _report_factor(terms, "K")), True
    else:
        rw, k_bound = nan, True
    b_bound = not terms.B.significant
    # the B the table and JSON show (its bound where it is one, the held reading where
    # the curve holds it: noise.terms._bounds), in SI
    b_rep = terms.B.upper_bound if b_bound else terms.B.value
    b = si(b_rep / _report_factor(terms, "B")) if math.isfinite(b_rep) and b_rep >= 0 \
        else nan
    return AxisNoise(axis=name, column=column, kind=kind, unit=unit, deviation=dev,
                     terms=terms, noise_density=float(dens), random_walk=float(rw),
                     random_walk_bound=k_bound, bias_instability=float(b),
                     bias_instability_bound=b_bound,
                     random_walk_t_s=float(terms.k_gm["t_s"]) if terms.k_gm else None)


def drift_between(own_terms, rates, stats, opts, within=None,
                  confidence: float = DEFAULT_CONFIDENCE["imu"], lengths_s=None) -> np.ndarray:
    """Variance of the next log's log drift variance per horizon about the pool's
    (:func:`inertialab.noise.terms.pooled.next_log_var`: each log's own model's
    prediction; its terms' uncertainty as sampling; the logs' mean within-log spread as
    the floor: ``within``, one array per log, the spread of its segments' own predicted
    drift (:func:`inertialab.noise.segments.drift_spread.segment_log_var`), or without
    it the segments test's Allan excess of ``stats``). ``lengths_s``: each log's fitted
    length, s; a log too short for a horizon with its bias window (its own prediction
    there would extrapolate its model past every tau it saw, as one log's horizon is
    refused) is left out at that horizon, its value and its floor alike."""
    from inertialab.noise.terms.drift_prediction import predict_terms, predicted_rms_ci
    from inertialab.noise.terms.pooled import next_log_var
    from inertialab.workflows.imu_drift import nonstationary_log_var

    vals, samp, prior = [], [], []
    for t, fs, st in zip(own_terms, rates, stats):
        p = predict_terms(t, opts.horizons_s, opts.bias_window_s, fs)
        ci = predicted_rms_ci(p, t)
        vals.append(np.log(np.maximum(p.rms, 1e-300) ** 2))
        samp.append(ci["log_sd"]["terms"] ** 2)
        prior.append(nonstationary_log_var(st, opts.horizons_s))
    if within is not None:
        prior = [np.asarray(w, dtype=float) for w in within]
    vals, samp, prior = np.array(vals), np.array(samp), np.array(prior, dtype=float)
    if lengths_s is not None:
        need = np.asarray(opts.horizons_s, dtype=float) + opts.bias_window_s
        short = need[None, :] > np.asarray(lengths_s, dtype=float)[:, None]
        if short.all(axis=0).any():  # a horizon no log holds (refused before): all kept
            short[:, short.all(axis=0)] = False
        vals, prior = np.where(short, np.nan, vals), np.where(short, np.nan, prior)
    prior = np.nanmean(prior, axis=0)
    return np.array([next_log_var(vals[:, i], samp[:, i], prior[i], confidence)
                     for i in range(vals.shape[1])])


def _within(lg, name, unit, kind, method, g, confidence, opts) -> np.ndarray:
    """One log's within-log drift spread on ``name`` (its segments fitted by ``method``:
    :func:`inertialab.noise.segments.drift_spread.segment_log_var`)."""
    from inertialab.noise.segments.drift_spread import segment_log_var
    from inertialab.workflows.imu_noise import _deviation

    def refit(seg):
        d = _deviation(seg, lg.rate_hz, "octave", confidence)
        return d, _fit(d, unit, kind, method, lg.rate_hz, g, confidence)

    return segment_log_var(np.asarray(lg.columns[name][1], dtype=float), lg.rate_hz, refit,
                           opts.horizons_s, opts.bias_window_s)


def warn_between(name: str, logs, curves, between: dict) -> None:
    """A warning when the logs' curves of axis ``name`` differ beyond sampling (the
    between-log test, :func:`inertialab.noise.terms.pooled.homogeneity`), naming the log
    farthest from the others' median Allan deviation at the worst tau: the pooled terms
    average the logs, and their intervals carry the spread."""
    import warnings

    from inertialab.errors import DataQualityWarning
    from inertialab.noise.terms.pooled import curve_at

    if between.get("verdict") != "differ beyond sampling":
        return
    tau = between["worst_tau_s"]
    dev = np.array([math.sqrt(curve_at(c, [tau])[0][0]) for c in curves])
    head = (f"axis {name}: the logs differ beyond sampling (p = {between['p_value']:.2g} "
            f"at tau = {tau:g} s)")
    tail = "The pooled terms average the logs and their intervals carry that spread"
    if len(logs) == 2:  # neither is 'farthest': one against the other
        what = (f"{logs[1].file}'s Allan deviation is {dev[1] / dev[0]:.3g}x "
                f"{logs[0].file}'s there")
    else:
        ratio = dev / np.nanmedian(dev)
        i = int(np.nanargmax(np.abs(np.log(ratio))))
        what = (f"farthest: {logs[i].file} (column '{logs[i].columns[name][0]}'), its Allan "
                f"deviation {ratio[i]:.3g}x the logs' median there")
    warnings.warn(f"{head}; {what}. {tail}", DataQualityWarning, stacklevel=3)


def pool_axis(name, logs, *, candidates, confidence, drift=None, y_check=None,
              g=U.G_STANDARD) -> tuple:
    """``(AxisNoise, extras)`` of one axis pooled over ``logs`` (module docstring)."""
    from scipy.special import ndtri

    from inertialab.noise.terms.fit import held_to_curve
    from inertialab.noise.terms.pooled import homogeneity, joins_at, pool_curves
    from inertialab.workflows.imu_segments import axis_stationarity, stationarity_text

    kind = AXES[name]
    curves = [lg.curves[name] for lg in logs]
    rates = [lg.rate_hz for lg in logs]
    col, _, unit = logs[0].columns[name]
    choice = choose_model(curves, rates, unit, kind, list(candidates), g, confidence)
    m = choice["chosen"]
    pooled = _fit(pool_curves(curves, rates, confidence), unit, kind, m, rates[0], g,
                  confidence)
    own = [_fit(c, unit, kind, m, fs, g, confidence) for c, fs in zip(curves, rates)]
    stats = [axis_stationarity(lg.columns[name][1], lg.rate_hz, lg.columns[name][0],
                               path=lg.file) for lg in logs]
    same = joins_at(rates, rates[0], [0.0])[:, 0]
    z = float(-ndtri((1 - confidence) / 2))
    widened, spread = widen_terms(pooled, own, stats, same, z, confidence)
    shortest = min(len(lg.columns[name][1]) / lg.rate_hz for lg in logs)
    between = homogeneity(curves, rates, max_tau_s=shortest / 16.0)
    warn_between(name, logs, curves, between)
    curve = pool_curves(curves, rates, confidence)
    # the widened B read again against the pooled curve it came from (every B within it)
    widened = held_to_curve(widened, curve)
    axis = pooled_axis(name, col, unit, curve, widened, g)
    if drift is not None:
        from inertialab.workflows.imu_drift import axis_drift

        # the drift interval takes the between-log spread of the logs' own drift once, on
        # the pooled fit's own intervals (the widened terms would count it twice)
        within = [_within(lg, name, unit, kind, m, g, confidence, drift) for lg in logs]
        extra = drift_between(own, rates, stats, drift, within=within,
                              confidence=confidence,
                              lengths_s=[len(lg.columns[name][1]) / lg.rate_hz for lg in logs])
        d = axis_drift(pooled_axis(name, col, unit, curve, pooled, g), rates[0], drift,
                       y_check, extra_log_var=extra)
        axis = replace(axis, drift=d | {"between_log_var": [float(v) for v in extra]})
    per_log = []
    for lg, t, st, ok in zip(logs, own, stats, same):
        a = pooled_axis(name, lg.columns[name][0], unit, lg.curves[name], t, g)
        per_log.append({"file": lg.file, "rate_hz": lg.rate_hz, "column": a.column,
                        "N": t.N.to_dict(), "B": t.B.to_dict(), "K": t.K.to_dict(),
                        "noise_density": a.noise_density, "random_walk": a.random_walk,
                        "random_walk_bound": a.random_walk_bound, "qn_pooled": bool(ok),
                        "stationarity": None if st is None else st.to_dict(),
                        "stationary": stationarity_text(None if st is None else st.to_dict())})
    extras = {"logs": per_log, "between_logs": between, "model_choice": choice,
              "between_log_var": spread,
              "ci_fit": {k: list(getattr(pooled, k).ci) for k in ("N", "B", "K")}}
    return axis, extras


@dataclass(frozen=True)
class PoolResult(ResultBase):
    """The pooled analysis: ``imu`` (an :class:`~inertialab.workflows.imu_noise.IMUNoise`
    of the pooled axes, for the usual table and figure), ``logs``, ``extras`` per axis
    (``logs[]``, ``between_logs``, ``model_choice``, ``between_log_var``, ``ci_fit``),
    ``pool_kind``."""

    imu: object
    logs: tuple
    extras: dict
    pool_kind: str

    def to_dict(self) -> dict:
        d = self.imu.to_dict()
        for a in d["axes"]:
            a.update(self.extras.get(a["axis"], {}))
        return d | {"pooled": True, "pool_kind": self.pool_kind,
                    "spread_means": POOL_KINDS[self.pool_kind],
                    "between_log_dof": len(self.logs) - 1,
                    "logs": [lg.summary() for lg in self.logs]}

    # the command runner's protocol (inertialab.cli.runner.Run.execute)
    @property
    def settings(self) -> dict:
        return self.imu.settings

    @property
    def units(self) -> dict:
        return {"rate_hz": "Hz"}

    def to_json(self) -> dict:
        return {"imu": self.to_dict()}

    def artifacts(self) -> dict:
        return {}

    def summary_rows(self) -> list:
        return self.tables()

    def tables(self) -> list:
        """``(title, columns, rows)``: the pooled table, the drift tables, and each log's
        own terms with the between-log test and the model choice."""
        from inertialab.workflows.imu_drift import display_tables
        from inertialab.workflows.imu_noise import term_text

        names = ", ".join(lg.file for lg in self.logs)
        out = display_tables(self.imu, f"pooled over {len(self.logs)} logs ({names})")
        rates = sorted({lg.rate_hz for lg in self.logs})
        if len(rates) > 1:  # the samples of logs at several rates: not all at the first's
            t, c, r = out[0]
            out[0] = (t.replace(f"{self.imu.n_samples} samples at {self.imu.rate_hz:g} Hz",
                                f"{self.imu.n_samples} samples in all at "
                                f"{' and '.join(f'{v:g}' for v in rates)} Hz"), c, r)
        rows = []
        for a in self.imu.axes:
            ex = self.extras[a.axis]
            b = ex["between_logs"]
            rows.append([a.axis, "pooled", term_text(a.terms.N), term_text(a.terms.B),
                         term_text(a.terms.K), ex["model_choice"]["chosen"],
                         f"{b['verdict']}" + (f" (p={b['p_value']:.2g})"
                                              if b.get("p_value") is not None else "")])
            for lg in ex["logs"]:
                rows.append([a.axis, lg["file"], _term_cell(lg["N"]), _term_cell(lg["B"]),
                             _term_cell(lg["K"]), "", lg["stationary"]])
        out.append((f"Each log's own terms ({self.pool_kind}: {POOL_KINDS[self.pool_kind]}); "
                    "pooled intervals carry the between-log spread for the next log "
                    + spread_note(len(self.logs), self.imu.settings.get(
                        "confidence", DEFAULT_CONFIDENCE["imu"])),
                    ["axis", "log", "N", "B", "K", "model (leave-one-log-out)",
                     "between logs / stationary"], rows))
        return out


def spread_note(n_logs: int, confidence: float = DEFAULT_CONFIDENCE["imu"]) -> str:
    """How well ``n_logs`` logs know their between-log spread: Student's t quantile on
    ``n - 1`` degrees of freedom against the normal one at ``confidence``
    (:func:`inertialab.noise.terms.pooled.next_log_var`).

    >>> spread_note(3)
    "(known with 2 degrees of freedom: Student's t = 4.3 in place of 1.96)"
    """
    from scipy.special import ndtri, stdtrit

    q = 0.5 + confidence / 2.0
    dof = max(n_logs - 1, 1)
    note = (f"(known with {dof} degree{'s' if dof > 1 else ''} of freedom: Student's "
            f"t = {float(stdtrit(dof, q)):.3g} in place of {float(ndtri(q)):.3g})")
    if n_logs == 2:
        note += (f"; with two logs the intervals are wide: a third log narrows them to "
                 f"t = {float(stdtrit(2, q)):.3g}")
    return note


def _term_cell(d: dict) -> str:
    flags = d.get("flags") or []
    if "not_observable" in flags:
        return "n/o"
    lo, hi = d.get("ci") or (None, None)
    if "upper_bound" in flags:
        return f"<= {hi:.4g}" if hi is not None else "-"
    v = d.get("value")
    return "-" if v is None else f"{v:.4g}"


def analyse_pool(records, *, rate=None, g_local=None, warmup="auto", pool_kind="runs",
                 candidates=CANDIDATES["wls"], predict_drift=None, bias_window=10.0,
                 check=None, confidence=DEFAULT_CONFIDENCE["imu"],
                 progress=None) -> PoolResult:
    """Several logs' records (:class:`inertialab.io.Record`, each read with its own units
    and time base) as one noise model per axis (module docstring). ``check``: the record
    of another log (not one of ``records``) on which the predicted drift is checked."""
    from inertialab.workflows.imu_drift import DriftOptions
    from inertialab.workflows.imu_noise import IMUNoise

    if pool_kind not in POOL_KINDS:
        raise InputError(f"argument 'pool_kind' must be runs or units, got '{pool_kind}'")
    if len(records) < 2:
        raise InputError("argument 'pool' needs at least two logs")
    if check is not None and not predict_drift:
        raise InputError("argument 'check_on' needs argument 'predict_drift'")
    if check is not None and (str(check.path) in [str(r.path) for r in records] or (
            check.sha256 is not None and check.sha256 in [r.sha256 for r in records])):
        raise InputError("argument 'check_on' must be a log not in the pool (its samples "
                         "are one of the pool's logs)", path=check.path)
    kw = dict(rate=rate, g_local=g_local, warmup=warmup)
    logs = join_pool(records, **kw)
    check_on = None if check is None else check.path
    if check is not None:
        try:
            check = join_pool([records[0], check], **kw, name_extra=False)[1]
        except InputError as exc:  # said of the check log, which joins no pool
            if exc.path is None or str(exc.path) != str(check_on):
                raise
            text = str(exc).removeprefix(f"{exc.path}: ")
            raise InputError(text.replace("cannot join the pool", "cannot be the check log"),
                             path=check_on) from None
    if check is not None and abs(check.rate_hz / logs[0].rate_hz - 1) > 1e-3:
        raise InputError(f"the check log is at {check.rate_hz:g} Hz, the pool's first log at "
                         f"{logs[0].rate_hz:g} Hz: give a check log of that rate",
                         path=check_on)
    _curves(logs, confidence)  # refuses a log that is not static, before any fit
    drift = None
    if predict_drift:
        from inertialab.workflows.imu_options import check_horizons

        h = tuple(float(v) for v in str(predict_drift).split(",") if v.strip())
        # as one log's: no horizon past the longest log; a check log too short is named
        span = [min(len(v[1]) for v in lg.columns.values()) / lg.rate_hz
                for lg in (*logs, *([check] if check is not None else []))]
        check_horizons(h, float(bias_window), max(span[:len(logs)]),
                       check_s=span[-1] if check is not None else None,
                       check_name=str(check_on) if check is not None else None)
        _warn_short_logs(logs, span[:len(logs)], h, float(bias_window))
        drift = DriftOptions(horizons_s=h, bias_window_s=float(bias_window),
                             check_on="other" if check else None,
                             other_name=str(check_on) if check else None)
    g = g_local if g_local is not None else U.G_STANDARD
    axes, extras = [], {}
    names = [a for a in AXES if a in logs[0].columns]
    usable = {} if check is None else usable_check_axes(
        {k: v[1] for k, v in check.columns.items()}, check_on,
        {k: v[0] for k, v in check.columns.items()})
    for i, name in enumerate(names):
        y_check = usable.get(name)
        ax, ex = pool_axis(name, logs, candidates=candidates, confidence=confidence,
                           drift=drift, y_check=y_check, g=g)
        axes.append(ax)
        extras[name] = ex
        if progress is not None:
            progress.update(i + 1, len(names), name)
    settings = {"rate_hz": logs[0].rate_hz, "taus": "octave", "method": "pooled",
                "candidates": list(candidates), "confidence": confidence,
                "pool_kind": pool_kind, "warmup": warmup}
    if drift is not None:
        settings["drift"] = drift.to_dict()
    imu = IMUNoise(axes=tuple(axes), rate_hz=logs[0].rate_hz,
                   n_samples=int(sum(lg.summary()["n_samples"] for lg in logs)),
                   settings=settings)
    return PoolResult(imu, tuple(logs), extras, pool_kind)


def _warn_short_logs(logs, spans_s, horizons_s, bias_window_s: float) -> None:
    """A warning naming each pool log too short for a horizon with its bias window: it is
    left out of the between-log drift spread there (:func:`drift_between`)."""
    import warnings

    from inertialab.errors import DataQualityWarning

    for lg, span in zip(logs, spans_s):
        bad = [h for h in horizons_s if h + bias_window_s > span]
        if bad:
            warnings.warn(f"{lg.file} ({span:.6g} s fitted) holds no {bias_window_s:g}-s bias "
                          f"window + {', '.join(f'{h:g}' for h in bad)}-s horizon: left out "
                          "of the between-log drift spread there (its own prediction would "
                          "extrapolate its model)", DataQualityWarning, stacklevel=3)


def _candidates(method: str) -> tuple:
    if method not in CANDIDATES:
        raise InputError(f"argument 'method' with argument 'pool' must be wls or gmwm, got "
                         f"'{method}'")
    return CANDIDATES[method]


def check_pool(files, config, *, imu: bool, export=None) -> tuple:
    """The settings of ``allan --imu LOG1 LOG2 ... --pool`` checked before any log is read
    (several logs need the six-axis mode and pooling; no export, plan or inflation; a
    ``--check-on`` log not in the pool and with a drift prediction); returns the
    candidates of the method (:data:`CANDIDATES`)."""
    c = config
    if not (imu and c.pool and len(files) > 1):
        raise InputError("several logs are pooled in the six-axis mode with argument 'pool' "
                         "(and argument 'pool' needs several logs)")
    if export or c.plan or c.inflate:
        raise InputError("argument 'export', argument 'plan' and argument 'inflate' are not "
                         "available with argument 'pool'")
    candidates = _candidates(c.method)
    from inertialab.workflows.imu_noise import check_drift_confidence, check_six_axis_curve

    check_drift_confidence(c)
    check_six_axis_curve(c)
    if c.terms is False:
        raise InputError("argument 'pool' fits the noise terms: argument 'terms' off "
                         "(no terms) is not available with it")
    if c.pool_kind not in POOL_KINDS:
        raise InputError(f"argument 'pool_kind' must be runs or units, got '{c.pool_kind}'")
    if c.check_on and str(c.check_on).strip().lower() == "half":
        raise InputError("argument 'check_on' with a pool must be a log not in the pool")
    if c.check_on and not c.predict_drift:
        raise InputError("argument 'check_on' needs argument 'predict_drift'")
    if c.check_on and str(c.check_on) in [str(f) for f in files]:
        raise InputError("argument 'check_on' must be a log not in the pool", path=c.check_on)
    return candidates


def run_pool(records, config, *, check=None, progress=None):
    """``allan --imu LOG1 LOG2 ... --pool`` as one call on the logs' records (the command
    runner reads them, and a ``--check-on`` log's as ``check``, as ``allan --imu`` reads
    a log: :func:`inertialab.workflows.imu_noise.reading`): the settings checked
    (:func:`check_pool`), then :func:`analyse_pool`."""
    c = config
    candidates = check_pool([r.path for r in records], c, imu=True)
    return analyse_pool(records, rate=c.rate, g_local=c.g_local, warmup=c.warmup,
                        pool_kind=c.pool_kind, candidates=candidates,
                        predict_drift=c.predict_drift, bias_window=c.bias_window,
                        check=check,
                        confidence=DEFAULT_CONFIDENCE["imu"] if c.confidence is None
                        else c.confidence,
                        progress=progress)


__all__ = ["CANDIDATES", "POOL_KINDS", "PoolLog", "PoolResult", "analyse_pool", "choose_model",
           "check_pool", "drift_between", "join_pool", "warn_between", "log_columns", "pool_axis",
           "pooled_axis", "run_pool", "widen_terms"]
