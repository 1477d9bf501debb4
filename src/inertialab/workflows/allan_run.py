"""``allan FILE`` (one series) as one call (docs/allan.md): :class:`AllanConfig` and
``run(path, config, options) -> AllanRun`` whose result knows ``to_json()``,
``settings``, ``units`` (per statistic), ``artifacts()`` (the noise terms as a model)
and ``summary_rows()``. The six-axis mode (``--imu``) is
:mod:`inertialab.workflows.imu_noise`.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from inertialab.config import DEFAULT_CONFIDENCE, Config, setting
from inertialab.errors import InputError
from inertialab.result import ResultBase
from inertialab.units import CLOCK_RATIO, CLOCK_TIME
from inertialab.workflows.registries import stat_help

__all__ = ["AllanConfig", "AllanRun", "run"]


@dataclass(frozen=True)
class AllanConfig(Config):
    """Settings of ``allan FILE`` (one series)."""

    column: str | None = setting(None, help="Column to analyse (default: the first "
                                            "rate/dtheta/accel column).")
    rate: float | None = setting(None, help="Sample rate in Hz (default: from a uniform t_s or "
                                            "the sidecar).", lo=1e-9, hi=1e9)
    input: str = setting("rate", help="rate | angle (cumulative theta_* column) | phase (clock "
                                      "time error) | frequency (clock fractional frequency).",
                         choices=("rate", "angle", "phase", "frequency"))
    unit: str | None = setting(None, help="Unit of the data: dph, dps, rps, mps2, g ... (IMU); "
                                          "s, ms, us, ns, ps (phase); 1 (or ratio, frac), ppm, "
                                          "ppb, ppt, hz (frequency; hz needs a nominal "
                                          "frequency). Overrides the column suffix.")
    nominal: float | None = setting(None, help="Nominal frequency, Hz, of a frequency record in "
                                               "hz: y = (f - nominal)/nominal.", lo=1e-12,
                                    hi=1e15)
    stat: str = setting("oadev", help=stat_help())
    taus: str = setting("octave", help="octave | decade | many | all | a count | "
                                       "comma-separated seconds.")
    terms: bool | None = setting(None, help="Fit the IMU noise terms Q N B K R (default: on for "
                                            "IMU logs, off for clocks).", flag="terms/no-terms")
    bias_correction: bool | None = setting(None, help="Stable32 bias corrections of TOTDEV, "
                                                      "MTOT, TTOT, HTOT and Theo1 where a "
                                                      "noise type was identified (default: on "
                                                      "for clocks, off for IMU logs).",
                                           flag="bias-correction/no-bias-correction")
    confidence: float | None = setting(None, help="Two-sided confidence of every interval, "
                                                  "the curve's and the noise terms' (default "
                                                  "0.683 for clocks as Stable32, 0.95 for IMU "
                                                  "logs).", lo=1e-6, hi=1 - 1e-9)
    method: str = setting("wls", help="Noise terms: wls | ols | slope | gmwm.")
    g_local: float | None = setting(None, help="Local gravity, m/s^2 (g-based accelerometer "
                                               "units).", lo=1.0, hi=100.0)
    predict_drift: str | None = setting(None, help="Six-axis mode: horizons in s, comma-"
                                        "separated (1,10,60,300): RMS and 95 % band of the "
                                        "angle/velocity error integrated after a bias window, "
                                        "from the model and the Kalibr reading.")
    bias_window: float = setting(10.0, help="Seconds averaged for the bias before each "
                                            "predicted horizon.", lo=1e-3, hi=1e6,
                                 unit="s")
    check_on: str | None = setting(None, help="With a drift prediction: half (fit the first "
                                              "half, check the second) or another log of the "
                                              "sensor: observed RMS, coverage, inflation.")
    plan: bool = setting(False, help="Six-axis mode: record length for K within +-20 % at "
                                     "95 %, and whether this log is that long.",
                         flag="plan/no-plan")
    inflate: str | None = setting(None, help="auto: with an export and a check log, the "
                                             "exported densities and random walks inflated so "
                                             "the prediction covers the observed drift.",
                                  choices=("auto", "none"))
    warmup: str = setting("auto", help="Six-axis mode: auto (a start-of-log transient found "
                                       "per axis against the rest of the log; one span "
                                       "per log, the latest end, left out of every fit), "
                                       "seconds to leave out, or 0 (none).")
    pool: bool = setting(False, help="Six-axis mode, several logs: one noise model per axis "
                                     "over them, with each log's own terms beside it.",
                         flag="pool/no-pool")
    pool_kind: str = setting("runs", help="With argument 'pool': runs (several runs of one unit) or "
                                          "units (units of one model): what the between-log "
                                          "spread means.", choices=("runs", "units"))
    noise_type: str | None = setting(None, help="Noise type for the bias corrections and "
                                                "EDF instead of the identification per tau, "
                                                "as Stable32 fixes it: one alpha (2 1 0 -1 "
                                                "-2) or name (WPM FPM WFM FFM RWFM) for every "
                                                "statistic, or stat=type pairs "
                                                "(totdev=FFM,theo1=-2).")
    gaps: str | None = setting(None, help="error | split: refuse time-stamp dropouts and "
                                          "repeats, or split the log at them (default: jitter "
                                          "and dropouts analysed on the sensor's grid, lost "
                                          "samples as gaps, with a warning).")

    def drift_settings(self) -> dict:
        """The six-axis drift settings (:func:`inertialab.workflows.imu_noise.analyse_file`);
        ``bias_window`` only where a prediction is asked for, ``warmup`` where not the
        default."""
        d = {"predict_drift": self.predict_drift, "check_on": self.check_on,
             "plan": self.plan, "inflate": self.inflate}
        if self.warmup != "auto":  # the six-axis default; another needs --imu
            d["warmup"] = self.warmup
        return d | {"bias_window": self.bias_window} if self.predict_drift else d

    def check(self) -> AllanConfig:
        """Bounds and the rules between settings (before any reading)."""
        from inertialab.workflows import allan as wf

        self.validate()
        wf.parse_noise_type(self.noise_type, wf.parse_stats(self.stat))
        wf.parse_taus(self.taus)
        if self.input not in ("phase", "frequency") and self.unit is not None:
            u = self.unit.strip().lower()
            if u in CLOCK_RATIO or u == "hz" or u in CLOCK_TIME:
                kind = "phase" if u in CLOCK_TIME else "frequency"
                raise InputError(f"argument 'unit' {self.unit} is a clock unit: give argument "
                                 f"'input' {kind} (clock "
                                 f"{'time error' if kind == 'phase' else 'fractional frequency'})")
        if self.confidence is not None and not 0.0 < self.confidence < 1.0:
            raise InputError(f"argument 'confidence' must be in (0, 1), got {self.confidence}")
        return self


#: default confidence of an IMU log's intervals (curve and noise terms alike), from the
#: one table :data:`inertialab.config.DEFAULT_CONFIDENCE`
IMU_CONFIDENCE = DEFAULT_CONFIDENCE["imu"]


@dataclass
class AllanRun(ResultBase):
    """One series' analysis (:class:`~inertialab.workflows.allan.AllanAnalysis`) and the
    series it came from."""

    res: object
    log: object
    settings: dict
    sha256: str | None = None

    @property
    def units(self) -> dict:
        dev_units = {r.statistic: self.res.dev_unit(r.statistic) for r in self.res.results}
        one = next(iter(dev_units.values())) if len(set(dev_units.values())) == 1 else \
            "per statistic: see each result's unit"
        return {"tau0_s": "s", "taus_s": "s", "dev": one, "ci_low": one, "ci_high": one,
                "n_terms": "1", "alpha": "1", "edf": "1"}

    def to_json(self) -> dict:
        return self.res.to_json()

    def artifacts(self) -> dict:
        if self.res.terms is None:
            return {}
        return {"models": [("model.json", self.res.terms, {"rate": self.log.unit})]}

    def summary_rows(self) -> list:
        res, log = self.res, self.log
        out = [(f"{r.statistic.upper()} of {log.column} ({res.dev_unit(r.statistic)}), "
                f"{r.confidence:.1%} intervals",
                ["tau_s", "m", "dev", "ci_low", "ci_high", "n_terms", "alpha", "edf"],
                [[t, int(m), d, lo, hi, int(n), int(a), e] for t, m, d, lo, hi, n, a, e
                 in zip(r.taus_s, r.m, r.dev, r.ci_low, r.ci_high, r.n_terms, r.alpha, r.edf)])
               for r in res.results]
        if res.terms is None:
            return out
        from inertialab.workflows.imu_noise import term_text

        rows = [[k, term_text(t), t.unit, t.method,
                 f"{t.tau_range_s[0]:.3g}-{t.tau_range_s[1]:.3g}", ",".join(t.flags)]
                for k, t in res.terms.terms().items()]
        n = res.terms.N
        if n.density is not None:
            rows.append(["N density", f"{n.density['value']:.4g}", n.density["unit"],
                         n.method, "continuous-time", ""])
        if n.per_sample_std is not None:
            rows.append(["N per-sample std", f"{n.per_sample_std['value']:.4g}",
                         n.per_sample_std["unit"], n.method, f"at {log.rate_hz:g} Hz", ""])
        out.append((f"Noise terms (fitted on OADEV; {res.terms.confidence:.1%} intervals, "
                    "'<=' an upper bound, n/o not observable)",
                    ["term", "value [interval]", "unit", "method", "tau range (s)", "flags"],
                    rows))
        return out


def lone_series(path, input: str, options=None):
    """The reading options of a text file holding one series (a Stable32 ``.DAT``: one
    number a line, read as ``col1``; or one column of a name the reader does not know):
    its column mapped to the series ``input`` names (``rate`` or ``theta``), so it needs
    no ``--column``; the unit still comes from ``--unit``. Any other file: ``options``
    unchanged."""
    import dataclasses
    import re

    from inertialab import units
    from inertialab.io import peek_columns
    from inertialab.io.mapping import ReadOptions, parse_map
    from inertialab.io.schemas import SCHEMAS

    if Path(path).suffix.lower() == ".npy" or input not in ("rate", "angle"):
        return options
    ro = options if options is not None else ReadOptions()
    if ro.column_map:
        return options
    data = [c for c in peek_columns(path, ro) if c != "t_s"]
    if len(data) != 1:
        return options
    known = {c.name for c in SCHEMAS["gyro_log"].columns}
    if units.split_suffix(data[0])[0] in known or not re.fullmatch(r"[a-z_][a-z0-9_]*|col\d+",
                                                                   data[0]):
        return options  # a named series the reader knows, or a name a map cannot take
    target = "rate" if input == "rate" else "theta"
    return dataclasses.replace(ro, column_map=parse_map(f"{target}={data[0]}"))


def run(path, config: AllanConfig, *, options=None, progress=None) -> AllanRun:
    """Read ``path`` (a ``gyro_log``, or a ``clock_log`` for phase/frequency input) and
    compute the requested statistics and noise terms."""
    from inertialab.io import read_record
    from inertialab.workflows import allan as wf

    c = config.check()
    clock = c.input in ("phase", "frequency")
    if clock:
        log = wf.read_clock(path, input=c.input, column=c.column, unit=c.unit, rate_hz=c.rate,
                            nominal_hz=c.nominal, options=options)
        sha = log.sha256
    else:
        npy_col = None
        if Path(path).suffix.lower() == ".npy" and c.unit is not None and c.column is None \
                and c.input == "angle":
            npy_col = f"theta_{c.unit.strip().lower()}"
        if npy_col is None and c.column is None:
            options = lone_series(path, c.input, options)
        rec = read_record(path, "gyro_log", unit=c.unit, rate_hz=c.rate,
                          column=c.column or npy_col, g_local=c.g_local, gaps=c.gaps,
                          options=options)
        log = wf.prepare_log(rec, column=c.column, rate_hz=c.rate, input=c.input,
                             g_local=c.g_local)
        sha = rec.sha256
    stats = wf.parse_stats(c.stat)
    conf = c.confidence if c.confidence is not None else \
        DEFAULT_CONFIDENCE["clock" if clock else "imu"]
    alpha = wf.parse_noise_type(c.noise_type, stats)
    res = wf.analyze(log, stats=stats, taus=wf.parse_taus(c.taus), confidence=conf,
                     method=c.method, fit_terms=c.terms, bias_correction=c.bias_correction,
                     alpha=alpha, progress=progress)
    settings = {"column": log.column, "rate_hz": log.rate_hz, "input": log.input,
                "stat": list(stats), "taus": c.taus, "confidence": conf,
                "method": c.method, "unit": log.unit, "n_samples": res.n_samples,
                "noise_type": alpha}
    if clock:
        settings.update({"input": c.input, "nominal_hz": c.nominal,
                         "bias_correction": res.settings.get("bias_correction"),
                         "noise_terms": res.settings.get("fit_terms")})
    return AllanRun(res=res, log=log, settings=settings, sha256=sha)
