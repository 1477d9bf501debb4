"""Workflow ``allan``: the Allan family of one series.

Verbs: :func:`prepare` (= :func:`prepare_log`) turns a validated ``gyro_log`` :class:`~inertialab.io.Record` into one
rate series (column choice, units, sample rate from ``--rate``, the sidecar or a uniform
``t_s``); :func:`analyze` computes the requested statistics of the Allan family with
their confidence intervals (:mod:`inertialab.noise.statistics.allan`) and the five noise terms
(:mod:`inertialab.noise.terms.fit`, fitted on the overlapping Allan deviation); the result
serialises to the JSON keys of :func:`fit` is :func:`analyze`. The virtual-lab
study (``allan-test`` record, recovery over seeds) is :mod:`inertialab.studies.allan`.

The command ``allan FILE`` (one series, docs/allan.md) is one call: :class:`AllanConfig`
and :func:`run` ``(path, config, options) -> AllanRun``, whose result knows
``to_json()``, ``settings``, ``units`` (per statistic), ``artifacts()`` (the noise terms
as a model) and ``summary_rows()``. The six-axis mode (``--imu``) is
:mod:`inertialab.workflows.imu_noise`.
"""

from __future__ import annotations

import math
import os
import warnings
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from inertialab import units
from inertialab.config import DEFAULT_CONFIDENCE, Config, setting
from inertialab.errors import DataQualityWarning, InputError
from inertialab.noise.statistics import registry as stat_registry
from inertialab.noise.statistics.allan import DeviationResult, PageReleaser
from inertialab.noise.statistics.family import compute
from inertialab.result import ResultBase
from inertialab.workflows.registries import stat_help

if TYPE_CHECKING:  # scipy; loaded when terms are fitted
    from inertialab.noise.terms.fit import NoiseTerms

#: Largest magnitude accepted in a record: squares and sums of larger values overflow
#: float64 (1e154 squared is 1e308); no sensor output comes near it.
MAX_MAGNITUDE = 1e100


def _check_magnitude(values, column) -> None:
    """One-line InputError naming the first sample beyond :data:`MAX_MAGNITUDE`
    (a memory-mapped record is scanned in chunks)."""
    v = np.asarray(values)
    if not np.issubdtype(v.dtype, np.floating):
        return
    step = 1 << 20
    release = PageReleaser(values)  # a memory map's pages are dropped once read
    for s in range(0, v.size, step):
        big = np.flatnonzero(np.abs(v[s:s + step]) > MAX_MAGNITUDE)
        release(s + step)
        if big.size:
            raise InputError(f"value {float(v[s + big[0]]):.3g} is beyond {MAX_MAGNITUDE:g} in "
                             "magnitude (sums of squares would overflow)",
                             column=column, row=int(s + big[0]) + 1)


#: Statistics whose intervals take the fitted model's noise type (Greenhall EDF).
_MODEL_EDF_STATS = ("adev", "oadev", "mdev", "tdev", "hdev", "ohdev")

#: Relative jitter of ``t_s`` above which a log is not uniform (spec 001 §2.2).
T_JITTER_TOL = 1e-6

#: Every statistic (names from :mod:`inertialab.noise.statistics.registry`), canonical order.
STATISTICS = stat_registry.names()
#: Statistics in the unit of the phase.
PHASE_UNIT = stat_registry.phase_unit()
#: Statistics with a gap-resistant form.
GAP_STATISTICS = stat_registry.with_gaps()

#: Memory-mapped inputs longer than this (samples) take the out-of-core path.
CHUNKED_MIN = 1 << 26

_ANGLE_TO_RATE = {"arcsec": "dph", "deg": "dps", "rad": "rps"}  # (angle unit)/s
_COLUMN_ORDER = ("rate", "dtheta", "gx", "gy", "gz", "accel", "ax", "ay", "az", "theta")


@dataclass(frozen=True)
class LogData:
    """One series ready for the Allan family.

    ``values`` are rate samples (``input="rate"``) or the cumulative angle
    (``input="angle"``); ``unit`` is the *rate* unit suffix of the deviations ('dph',
    'dps', 'rps', 'mps2', 'g' ...); ``column`` the record column it came from.
    """

    values: np.ndarray
    rate_hz: float
    unit: str
    column: str
    input: str = "rate"
    kind: str = "gyro"
    path: str = ""
    sha256: str | None = None
    g_local: float = units.G_STANDARD


def prepare_log(record, *, column: str | None = None, rate_hz: float | None = None,
                input: str = "rate", g_local: float | None = None) -> LogData:
    """Pick the series to analyse from a ``gyro_log`` record.

    Parameters
    ----------
    record : inertialab.io.Record
    column : str, optional
        Canonical column (``rate_dph``) or its base (``rate``). Default: the first of
        rate, dtheta, gx, gy, gz, accel, ax, ay, az (``theta`` for ``input="angle"``).
    rate_hz : float, optional
        Sample rate, overriding the record's; else the record's time base
        (``record.timebase``, decided once on reading: argument, sidecar ``fs_hz``, time
        stamps), samples lost in dropouts NaN on the sensor's grid; repeated or
        backward stamps are an InputError naming the rows.
    input : {"rate", "angle"}
        ``"angle"`` reads a cumulative ``theta_*`` column (phase analogue).
        ``dtheta_*`` increments are divided by tau0 (docs/records.md).
    """
    path = record.path
    if input not in ("rate", "angle"):
        raise InputError(f"argument 'input' must be rate or angle, got '{input}'")
    if rate_hz is None:
        from inertialab.workflows.preflight import preflight

        preflight(record, "allan")  # the checks `validate --kind allan` runs
    names = list(record.arrays) + [c for c in record.data.columns if c not in record.arrays]
    if column is not None:
        col = column.strip().lower()
        if col not in names:
            found = record.find(col)
            if found is None:
                raise InputError(f"no such column (columns: {', '.join(names)})", path=path,
                                 column=column)
            col = found
    else:
        bases = ("theta",) if input == "angle" else _COLUMN_ORDER[:-1]
        col = next((c for b in bases if (c := record.find(b)) is not None), None)
        if col is None:
            raise InputError("no column to analyse (expected one of "
                             f"{', '.join(b + '_<unit>' for b in bases)})", path=path)
    base, suf = units.split_suffix(col)
    suf = record.units.get(col, suf)
    if suf is None:
        raise InputError("column has no unit; give argument 'unit'", path=path, column=col)
    values = record.column(col)
    if rate_hz is not None:
        fs = float(rate_hz)
        if not math.isfinite(fs) or fs <= 0:
            raise InputError(f"argument 'rate_hz' must be positive, got {rate_hz}")
    else:
        fs = record.timebase.rate_hz
        values = record.timebase.place(values)  # dropouts: lost samples NaN on the grid
    dim = units.dimension(suf)
    kind_input = input
    if dim == "angle":
        rate_unit = _ANGLE_TO_RATE.get(suf)
        if rate_unit is None:
            raise InputError(f"unit '{suf}' has no rate counterpart (use arcsec, deg, rad)",
                             path=path, column=col)
        if base == "theta" or input == "angle":
            kind_input = "angle"
        else:  # increments per sample -> rate
            values = np.asarray(values, dtype=np.float64) * fs
        kind = "gyro"
    elif dim == "angular_rate":
        rate_unit, kind = suf, "gyro"
        if input == "angle":
            raise InputError("argument 'input' angle needs a cumulative angle column (theta_<unit>)",
                             path=path, column=col)
    elif dim == "acceleration":
        rate_unit, kind = suf, "accel"
        if input == "angle":
            raise InputError("argument 'input' angle needs a cumulative angle column (theta_<unit>)",
                             path=path, column=col)
    else:
        raise InputError(f"unit '{suf}' is a {dim}; the Allan analysis needs a rate, "
                         "acceleration or angle (give argument 'unit')", path=path, column=col)
    g = g_local if g_local is not None else float(record.meta.get("g_local_mps2",
                                                                   units.G_STANDARD))
    return LogData(values=values, rate_hz=fs, unit=rate_unit, column=col, input=kind_input,
                   kind=kind, path=str(path), sha256=record.sha256, g_local=g)


#: Clock units (their tables live in :mod:`inertialab.units`).
CLOCK_RATIO = units.CLOCK_RATIO
CLOCK_TIME = units.CLOCK_TIME
_CLOCK_NAMES = {"phase": ("phase", "x", "tie", "time_error"),
                "frequency": ("freq", "frequency", "y", "fract", "ffd")}


def clock_log(values, *, input: str, unit: str | None, rate_hz: float,
              nominal_hz: float | None = None, column: str = "", path: str = "",
              sha256: str | None = None) -> LogData:
    """A clock series as a :class:`LogData` in its own units.

    Parameters
    ----------
    values : array_like
        Phase (time error) or fractional frequency samples; NaN marks a missing sample.
    input : {"phase", "frequency"}
    unit : str or None
        Phase: s, ms, us, ns, ps (default s). Frequency: 1 / ratio (dimensionless,
        default), pct, ppm, ppb, ppt, or hz (an absolute frequency; needs
        ``nominal_hz``, then ``y = (f - nominal) / nominal``).
    rate_hz : float
        Sample rate (1 / tau0).

    The result's deviations are dimensionless (``unit="1"``); TDEV, TTOT, MTIE and TIE rms
    in s. ``kind="clock"``: no IMU noise terms unless asked, Stable32 bias corrections on.
    """
    if input not in ("phase", "frequency"):
        raise InputError(f"argument 'input' must be phase or frequency for a clock, "
                         f"got '{input}'")
    u = (unit or ("s" if input == "phase" else "1")).strip().lower()
    v = np.asarray(values, dtype=np.float64)
    if input == "phase":
        if u not in CLOCK_TIME:
            raise InputError(f"phase unit '{u}' is not a time unit (use "
                             f"{', '.join(CLOCK_TIME)})", path=path or None,
                             column=column or None)
        v = v * CLOCK_TIME[u]
        kind_input = "angle"
    else:
        if u == "hz":
            if nominal_hz is None or not (math.isfinite(nominal_hz) and nominal_hz > 0):
                raise InputError("a frequency in Hz needs the nominal frequency (argument "
                                 "'nominal_hz') to form the fractional frequency",
                                 path=path or None, column=column or None)
            v = (v - float(nominal_hz)) / float(nominal_hz)
        elif u in CLOCK_RATIO:
            v = v * CLOCK_RATIO[u]
        else:
            raise InputError(f"frequency unit '{u}' is not a ratio or hz (use "
                             f"{', '.join(CLOCK_RATIO)} or hz with a nominal frequency)",
                             path=path or None, column=column or None)
        kind_input = "rate"
    fs = float(rate_hz)
    if not math.isfinite(fs) or fs <= 0:
        raise InputError(f"argument 'rate_hz' must be positive, got {rate_hz}")
    return LogData(values=v, rate_hz=fs, unit="1", column=column, input=kind_input,
                   kind="clock", path=str(path), sha256=sha256)


def on_grid(t: np.ndarray, values: np.ndarray, path="", *,
            rate_hz: float | None = None) -> tuple[float, np.ndarray]:
    """``(rate_hz, values on the nominal grid)``: time stamps that skip whole sample
    intervals (a gap) leave NaN at the missing samples (never interpolated); stamps off
    the grid by more than :data:`T_JITTER_TOL` of a step are an InputError naming rows.

    ``rate_hz``: the rate of the stamps as the record's time base found it
    (``timebase.stamps_rate_hz``); default the rate the stamps give
    (:func:`inertialab.io.timestamps.stamps_rate_hz`, the same rule)."""
    from inertialab.io.timestamps import stamps_rate_hz

    t = np.asarray(t, dtype=float)
    if t.size < 2:
        raise InputError("needs at least two time stamps", path=path or None, column="t_s")
    rate = stamps_rate_hz(t) if rate_hz is None else float(rate_hz)
    if not rate > 0 or not np.all(np.isfinite(t)) or not t[-1] > t[0]:
        raise InputError("time stamps do not increase", path=path or None, column="t_s")
    step = 1.0 / rate
    k = np.round((t - t[0]) / step)
    off = np.abs((t - t[0]) - k * step)
    bad = np.flatnonzero((off > T_JITTER_TOL * step * np.maximum(1.0, k)) |
                         np.concatenate(([False], np.diff(k) < 1)))
    if bad.size:
        raise InputError("time stamps off the uniform grid (neither one step nor a whole "
                         "number of missing steps)", path=path or None, column="t_s",
                         row=[int(i) + 1 for i in bad[:5]])
    if k[-1] == t.size - 1:
        return rate, values
    out = np.full(int(k[-1]) + 1, np.nan)
    out[k.astype(np.int64)] = values
    return rate, out


def prepare_clock(frame, meta: dict | None = None, *, input: str, column: str | None = None,
                  unit: str | None = None, rate_hz: float | None = None,
                  nominal_hz: float | None = None, path: str = "",
                  sha256: str | None = None) -> LogData:
    """A clock record (a table with any column names) -> :class:`LogData`.

    ``column`` names the series (any name, case-insensitive); default the first column
    called phase/x/tie (phase) or freq/frequency/y (frequency), with or without a unit
    suffix (``phase_ns``, ``freq_hz``), or the one column of a file holding one series
    (a Stable32 ``.DAT``). The unit comes from ``unit``, else the column's
    suffix, else s / dimensionless. The rate from ``rate_hz``, the sidecar ``fs_hz`` or a
    uniform ``t_s``.
    """
    meta = dict(meta or {})
    cols = {str(c).strip().lower(): c for c in frame.columns}
    if column is not None:
        key = column.strip().lower()
        if key not in cols:
            raise InputError(f"no such column (columns: {', '.join(map(str, frame.columns))})",
                             path=path or None, column=column)
        col = cols[key]
    else:
        col = None
        for name in _CLOCK_NAMES.get(input, ()):
            col = next((cols[c] for c in cols if c == name or units.split_suffix(c)[0] == name),
                       None)
            if col is not None:
                break
        data = [c for c in frame.columns if str(c).strip().lower() != "t_s"]
        if col is None and len(data) == 1:  # one series (Stable32's .DAT): the one asked for
            col = data[0]
        if col is None:
            raise InputError(f"no {input} column (name it with argument 'column')",
                             path=path or None)
    suf = unit
    if suf is None:
        base, s_ = units.split_suffix(str(col).strip().lower())
        if s_ is not None and (s_ in CLOCK_TIME or s_ in CLOCK_RATIO or s_ == "hz"):
            suf = s_
    try:
        vals = np.asarray(frame[col], dtype=np.float64)
    except (TypeError, ValueError):
        raise InputError("column is not numeric", path=path or None, column=str(col)) from None
    timebase = meta.get("timebase") or {}  # the record's one time base (io.timestamps)
    if rate_hz is not None:
        fs = float(rate_hz)
    elif "t_s" in cols:  # the stamps place the samples; clocks allow no jitter
        t = np.asarray(frame[cols["t_s"]], dtype=float)
        stamps_hz = timebase.get("stamps_rate_hz")
        fs, vals = on_grid(t, vals, path, rate_hz=stamps_hz if stamps_hz is not None
                           and math.isfinite(stamps_hz) else None)
        fs = float(timebase.get("rate_hz", fs))
    elif meta.get("fs_hz") is not None:
        fs = float(meta["fs_hz"])
    else:
        raise InputError("needs a t_s column or argument 'rate_hz'", path=path or None)
    return clock_log(vals, input=input, unit=suf, rate_hz=fs, nominal_hz=nominal_hz,
                     column=str(col), path=path, sha256=sha256)


def read_clock(path, *, input: str, column: str | None = None, unit: str | None = None,
               rate_hz: float | None = None, nominal_hz: float | None = None,
               options=None) -> LogData:
    """Read a clock record through the io front door (``read_record(path, "clock_log")``:
    every format it reads, ``# key=value`` header lines, a sidecar, the reading options
    of :class:`~inertialab.io.mapping.ReadOptions`: column map, separator, decimal mark,
    time column) and :func:`prepare_clock` it (any column name, unit, rate, gaps)."""
    from inertialab.io import read_record

    rec = read_record(path, "clock_log", options=options)
    return prepare_clock(rec.data, rec.meta, input=input, column=column, unit=unit,
                         rate_hz=rate_hz, nominal_hz=nominal_hz, path=str(rec.path),
                         sha256=rec.sha256)


@dataclass(frozen=True)
class AllanAnalysis:
    """Deviations and noise terms of one series.

    ``results`` holds one :class:`DeviationResult` per requested statistic; ``terms``
    the five noise terms fitted on the overlapping Allan deviation (computed for the
    fit even when not requested); ``unit`` the rate unit of the deviations.
    """

    results: tuple
    terms: NoiseTerms | None
    unit: str
    column: str
    rate_hz: float
    n_samples: int
    input: str = "rate"
    kind: str = "gyro"
    oadev: DeviationResult | None = None
    settings: dict = field(default_factory=dict)

    def result(self, statistic: str) -> DeviationResult:
        for r in self.results:
            if r.statistic == statistic:
                return r
        raise KeyError(statistic)

    def dev_unit(self, statistic: str) -> str:
        """Unit of a statistic's deviation: the rate unit (``"1"`` for a clock's
        fractional frequency); ``tdev``, ``ttotdev``, ``mtie`` and ``tierms`` are in the
        unit of the phase: rate unit x s (arcsec for deg/h, s for a clock)."""
        if statistic not in PHASE_UNIT:
            return self.unit
        return {"dph": "arcsec", "dps": "deg", "rps": "rad", "mps2": "m/s", "1": "s"}.get(
            self.unit, f"{self.unit}*s")

    def statistic_json(self, r: DeviationResult) -> dict:
        """The JSON object of one statistic (docs/allan.md)."""
        terms = None
        if self.terms is not None:
            terms = {k: t.to_dict() for k, t in self.terms.terms().items()}
        out = {"statistic": r.statistic, "tau0_s": r.tau0_s, "taus_s": r.taus_s,
               "dev": r.dev, "ci_low": r.ci_low, "ci_high": r.ci_high,
               "n_terms": r.n_terms, "alpha": r.alpha, "edf": r.edf,
               "unit": self.dev_unit(r.statistic), "noise_terms": terms}
        if hasattr(r, "used_fraction"):  # a record with gaps (noise.statistics.gaps)
            out.update({"n_gaps": r.n_gaps, "n_missing": r.n_missing,
                        "used_fraction": r.used_fraction})
        if getattr(r, "alpha_source", None):  # how each tau's noise type was identified
            out["alpha_source"] = list(r.alpha_source)
        if hasattr(r, "bias"):  # Stable32 bias factors (noise.statistics.total)
            out["bias_factor"] = r.bias
        return out

    def to_json(self) -> dict:
        """One statistic: its object; several: ``{"results": [...]}``."""
        objs = [self.statistic_json(r) for r in self.results]
        return objs[0] if len(objs) == 1 else {"results": objs}


def parse_stats(stats) -> tuple:
    """``"oadev,mdev"`` or a sequence -> validated tuple of statistic names."""
    items = stats.split(",") if isinstance(stats, str) else list(stats)
    out = []
    for s in (i.strip().lower() for i in items):
        if not s:
            continue
        if s not in STATISTICS:
            raise InputError(f"unknown statistic '{s}' (use {', '.join(STATISTICS)})")
        if s not in out:
            out.append(s)
    if not out:
        raise InputError("no statistic given (argument 'stats', e.g. 'oadev,mdev')")
    return tuple(out)


#: Stable32's power-law noise names -> alpha (frequency PSD ~ f^alpha).
NOISE_TYPES = {"wpm": 2, "fpm": 1, "wfm": 0, "ffm": -1, "rwfm": -2}
_LONG_NAMES = {"whitepm": 2, "flickerpm": 1, "whitefm": 0, "flickerfm": -1, "randomwalkfm": -2}


def _alpha(text: str, where: str) -> int:
    t = text.strip().lower().replace(" ", "").replace("_", "")
    if t in NOISE_TYPES or t in _LONG_NAMES:
        return NOISE_TYPES.get(t, _LONG_NAMES.get(t))
    try:
        a = int(t)
    except ValueError:
        a = None
    if a not in NOISE_TYPES.values():
        raise InputError(f"argument 'noise_type' {where}must be an alpha of 2, 1, 0, -1, -2 or "
                         f"one of {', '.join(k.upper() for k in NOISE_TYPES)}, got "
                         f"'{text.strip()[:20]}'")
    return a


def parse_noise_type(text, stats) -> int | dict | None:
    """The noise type fixed for the bias corrections and EDF (Stable32's choice instead
    of the identification per tau): one alpha or name (``-1``, ``FFM``) for every
    statistic of ``stats``, or ``stat=type`` pairs (``totdev=FFM,theo1=-2``) for some;
    None when unset."""
    if text is None or not str(text).strip():
        return None
    parts = [p for p in str(text).split(",")]
    if any(not p.strip() for p in parts):
        raise InputError(f"argument 'noise_type' has an empty entry in '{str(text)[:40]}'")
    if not any("=" in p for p in parts):
        if len(parts) != 1:
            raise InputError("argument 'noise_type' takes one type for every statistic or "
                             "stat=type pairs")
        return _alpha(parts[0], "")
    out = {}
    for p in parts:
        stat, sep, typ = p.partition("=")
        stat = stat.strip().lower()
        if not sep or stat not in stats:
            raise InputError(f"argument 'noise_type' entry '{p.strip()[:30]}' must be stat=type "
                             f"for a statistic asked for ({', '.join(stats)})")
        if stat in out:
            raise InputError(f"argument 'noise_type' gives {stat} twice")
        out[stat] = _alpha(typ, f"for {stat} ")
    return out


#: ``taus``: at most this many log-spaced taus, and taus in seconds up to this (a larger
#: request is refused before any work instead of allocating or looping without end).
MAX_TAU_COUNT = 100_000
MAX_TAU_S = 1e10


def parse_taus(taus: str):
    """The one grammar of the ``taus`` setting: ``"octave" | "decade" | "many" | "all" |
    "<count>" | "0.1,1,10"`` (seconds), with its bounds (:data:`MAX_TAU_COUNT`,
    :data:`MAX_TAU_S`); the value :func:`inertialab.noise.statistics.allan.tau_grid` takes.

    Examples
    --------
    >>> parse_taus("Octave"), parse_taus("20"), parse_taus("0.1, 1,10")
    ('octave', 20, [0.1, 1.0, 10.0])
    >>> parse_taus("0")
    Traceback (most recent call last):
    ...
    inertialab.errors.InputError: argument 'taus' count must be 1 .. 100000, got 0
    """
    t = str(taus).strip().lower()
    if t in ("octave", "decade", "many", "all"):
        return t
    if t.isdigit():
        if len(t) > 12 or not 1 <= int(t) <= MAX_TAU_COUNT:
            raise InputError(f"argument 'taus' count must be 1 .. {MAX_TAU_COUNT}, got {t[:20]}")
        return int(t)
    try:
        vals = [float(v) for v in t.split(",") if v.strip()]
    except ValueError:
        raise InputError(f"argument 'taus' must be octave, decade, many, all, a count or seconds, got "
                         f"'{taus}'") from None
    if not vals:
        raise InputError("argument 'taus' is empty")
    if not all(math.isfinite(v) and 0 < v <= MAX_TAU_S for v in vals):
        raise InputError(f"argument 'taus' in seconds must be finite, > 0 and <= {MAX_TAU_S:g}, "
                         f"got {t[:40]}")
    return vals


def _check_finite(results, column) -> None:
    """Finite input must give finite output: a one-line error naming the statistic."""
    for r in results:
        if np.isinf(np.asarray(r.dev, dtype=float)).any():
            raise InputError(f"{r.statistic} overflowed to infinity: the record holds values "
                             "too large for the arithmetic (e.g. a 1e308 cell)", column=column)


def _noise_terms(oad, log: LogData, *, kind, method: str, confidence: float):
    """The five noise terms fitted on the OADEV ``oad`` of ``log``; None (with a warning)
    when the curve is too short for them; a warning too when the record is not static."""
    from inertialab.noise.terms.fit import fit_noise_terms, not_static_reason  # scipy: when run

    why = not_static_reason(oad.taus_s, oad.dev)
    try:
        terms = fit_noise_terms(oad, unit=log.unit, kind=kind, method=method,
                                rate_hz=log.rate_hz, g_local=log.g_local,
                                confidence=confidence)
    except InputError as exc:
        if "taus" not in str(exc):
            raise
        warnings.warn(f"column '{log.column}': noise terms not fitted: {exc}",
                      DataQualityWarning, stacklevel=3)
        return None
    if why:
        warnings.warn(f"column '{log.column}': {why}", DataQualityWarning, stacklevel=3)
    return terms


def _statistic_fn(log: LogData, names, common: dict, bias_correction):
    """``one(stat, **overrides)``: one statistic of ``log`` — gap-resistant where the record
    has missing samples (with a warning; statistics with no gap-resistant form refused)."""
    taus, confidence, alpha = common["taus"], common["confidence"], common["alpha"]
    gappy = not isinstance(log.values, np.memmap) and bool(np.isnan(log.values).any())
    if gappy:
        from inertialab.noise.statistics.gaps import count_gaps, gap_deviation

        g, miss = count_gaps(log.values)
        warnings.warn(f"{log.path or 'data'}: {miss} missing sample(s) in {g} gap(s); "
                      "gap-resistant statistics (no interpolation), the fraction of "
                      "summands used per tau is reported", DataQualityWarning, stacklevel=3)
        no_gap = [s for s in names if s not in GAP_STATISTICS]
        if no_gap:
            raise InputError(f"the record has missing samples (NaN or time-stamp gaps); "
                             f"{', '.join(no_gap)} has no gap-resistant form (use "
                             f"{', '.join(GAP_STATISTICS)}; argument 'stats')", path=log.path
                             or None, column=log.column or None)

        def one(stat, **kw):
            return gap_deviation(stat, log.values, rate_hz=log.rate_hz, input=log.input,
                                 confidence=confidence, alpha=kw.get("alpha", alpha),
                                 taus=kw.get("taus", taus))
    else:
        def one(stat, **kw):
            return compute(stat, log.values, bias_correction=bias_correction,
                           **{**common, **kw})
    return one


def analyze(log: LogData | np.ndarray, *, rate_hz: float | None = None, unit: str | None = None,
            stats=("oadev",), taus="octave", confidence: float | None = None,
            method: str = "wls",
            input: str = "rate", kind: str | None = None, alpha=None,
            edf_method: str = "default", chunked="auto",
            fit_terms: bool | None = None, bias_correction: bool | None = None,
            progress=None) -> AllanAnalysis:
    """Allan family with confidence intervals and the five noise terms.

    Parameters
    ----------
    log : LogData or ndarray
        A prepared log, or raw values (then ``rate_hz`` and ``unit`` are required).
    stats : str or sequence, default ("oadev",)
    taus, alpha, edf_method : see :func:`inertialab.noise.statistics.allan.deviation`; ``alpha`` may
        also be ``{statistic: alpha}`` (the noise type fixed for some statistics,
        :func:`parse_noise_type`); a fixed type also replaces the noise-term model's
        intervals of that statistic
    confidence : float, optional
        Two-sided confidence of every interval, the curves' and the noise terms'; None:
        the curves at 0.683 and the terms at 0.95.
    chunked : bool or "auto", default "auto"
        Out-of-core path; "auto" uses it for a memory-mapped input of more than
        :data:`CHUNKED_MIN` samples (the in-memory path needs one float64 copy).
    method : {"wls", "ols", "slope"}, default "wls"
        Noise-term method (:func:`inertialab.noise.terms.fit.fit_noise_terms`).
    fit_terms : bool or None, default None
        Fit the IMU noise terms (None: yes for gyro/accelerometer logs, no for a
        clock); a curve too short for them (fewer than 3 taus in [tau0, T/8])
        gives ``terms=None`` and a DataQualityWarning instead of an error.
    bias_correction : bool or None, default None
        Stable32's bias corrections of TOTDEV, MTOT, TTOT, HTOT and Theo1
        (:mod:`inertialab.noise.statistics.family`); None: on for a clock, off otherwise.
    """
    if not isinstance(log, LogData):
        if rate_hz is None or unit is None:
            raise InputError("analyze() of a bare array needs rate_hz and unit")
        dim = units.dimension(unit)
        kk = kind or {"angular_rate": "gyro", "acceleration": "accel",
                      "ratio": "clock"}.get(dim)
        if kk is None:
            raise InputError(f"unit '{unit}' is a {dim}, not a rate or acceleration")
        vals = log if isinstance(log, np.ndarray) else np.asarray(log)  # keeps a memmap
        log = LogData(values=vals, rate_hz=float(rate_hz), unit=unit, column="",
                      input=input, kind=kk)
    names = parse_stats(stats)
    clock = log.kind == "clock"
    if fit_terms is None:
        fit_terms = not clock
    if bias_correction is None:
        bias_correction = clock
    if fit_terms and clock:
        raise InputError("the IMU noise terms Q N B K R are defined for gyro and "
                         "accelerometer units; a clock's noise is given per tau by alpha "
                         "(argument 'fit_terms')")
    if chunked == "auto":
        chunked = isinstance(log.values, np.memmap) and log.values.size > CHUNKED_MIN
    # one confidence for the curves and the terms when given (the command's); else the
    # curves at 0.683 (1 sigma, Stable32's) and the terms at their benchmarked 0.95
    from inertialab.noise.terms.fit import CONFIDENCE, model_intervals  # scipy: when run

    terms_conf = CONFIDENCE if confidence is None else confidence
    confidence = DEFAULT_CONFIDENCE["clock"] if confidence is None else confidence
    results = []
    common = dict(rate_hz=log.rate_hz, taus=taus, input=log.input, confidence=confidence,
                  alpha=alpha, edf_method=edf_method,
                  chunked=chunked and log.input == "rate")
    if common["chunked"]:  # the out-of-core passes report to the bar (progress)
        common["progress"] = progress
    per_stat = alpha if isinstance(alpha, dict) else {}
    if per_stat:
        common["alpha"] = None
    one = _statistic_fn(log, names, common, bias_correction)
    _check_magnitude(log.values, log.column)
    for s in names:
        results.append(one(s, **({"alpha": per_stat[s]} if s in per_stat else {})))
    _check_finite(results, log.column)
    oad = next((r for r in results if r.statistic == "oadev"), None)
    terms = None
    if fit_terms:
        if oad is None:
            oad = one("oadev", taus="octave")
        terms = _noise_terms(oad, log, kind=kind or log.kind, method=method,
                             confidence=terms_conf)
    if terms is not None:  # rate records: noise types follow the fitted model
        fixed = set(per_stat) if per_stat else (set(names) if alpha is not None else set())
        results = [model_intervals(r, terms) if r.statistic in _MODEL_EDF_STATS and
                   r.statistic not in fixed else r for r in results]
    n = results[0].n_samples
    return AllanAnalysis(results=tuple(results), terms=terms, unit=log.unit, column=log.column,
                         rate_hz=log.rate_hz, n_samples=n, input=log.input, kind=log.kind,
                         oadev=oad,
                         settings={"stats": list(names), "taus": taus, "confidence": confidence,
                                   "method": method, "input": log.input,
                                   "edf_method": edf_method, "rate_hz": log.rate_hz,
                                   "noise_type": alpha,
                                   **({"bias_correction": bool(bias_correction),
                                       "fit_terms": bool(fit_terms)} if clock else {})})


#: The workflow verbs: prepare(record) -> LogData, fit(data, ...) -> AllanAnalysis.
prepare = prepare_log
fit = analyze

# ------------------------------------------------- the command: settings, result, run


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
        """The six-axis drift settings (:func:`inertialab.workflows.imu_noise.run`);
        ``bias_window`` only where a prediction is asked for, ``warmup`` where not the
        default."""
        d = {"predict_drift": self.predict_drift, "check_on": self.check_on,
             "plan": self.plan, "inflate": self.inflate}
        if self.warmup != "auto":  # the six-axis default; another needs --imu
            d["warmup"] = self.warmup
        return d | {"bias_window": self.bias_window} if self.predict_drift else d

    def check(self) -> AllanConfig:
        """Bounds and the rules between settings (before any reading)."""
        self.validate()
        parse_noise_type(self.noise_type, parse_stats(self.stat))
        parse_taus(self.taus)
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


def reading(path, config: AllanConfig, options=None) -> tuple[str, dict]:
    """What ``allan FILE`` reads: the record kind (``gyro_log``, or ``clock_log`` for
    phase/frequency input) and the keywords of :func:`inertialab.io.read_record`
    (``read_record(path, kind, **keywords)``); a one-series text file gets its column
    mapped (:func:`lone_series`)."""
    c = config
    if c.input in ("phase", "frequency"):
        return "clock_log", {"options": options}
    npy_col = None
    if Path(path).suffix.lower() == ".npy" and c.unit is not None and c.column is None \
            and c.input == "angle":
        npy_col = f"theta_{c.unit.strip().lower()}"
    if npy_col is None and c.column is None:
        options = lone_series(path, c.input, options)
    return "gyro_log", {"unit": c.unit, "rate_hz": c.rate, "column": c.column or npy_col,
                        "g_local": c.g_local, "gaps": c.gaps, "options": options}


def run(record, config: AllanConfig, *, options=None, progress=None) -> AllanRun:
    """``allan FILE`` (one series) on ``record``, read as :func:`reading` says (a path is
    read here with the reading ``options``): the requested statistics and noise terms."""
    c = config.check()
    if isinstance(record, (str, os.PathLike)):
        from inertialab.io import read_record

        kind, kw = reading(record, c, options)
        record = read_record(record, kind, **kw)
    clock = c.input in ("phase", "frequency")
    if clock:
        log = prepare_clock(record.data, record.meta, input=c.input, column=c.column,
                            unit=c.unit, rate_hz=c.rate, nominal_hz=c.nominal,
                            path=str(record.path), sha256=record.sha256)
    else:
        log = prepare_log(record, column=c.column, rate_hz=c.rate, input=c.input,
                          g_local=c.g_local)
    stats = parse_stats(c.stat)
    conf = c.confidence if c.confidence is not None else \
        DEFAULT_CONFIDENCE["clock" if clock else "imu"]
    alpha = parse_noise_type(c.noise_type, stats)
    res = analyze(log, stats=stats, taus=parse_taus(c.taus), confidence=conf,
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
    return AllanRun(res=res, log=log, settings=settings, sha256=record.sha256)


__all__ = ["AllanAnalysis", "AllanConfig", "AllanRun", "CLOCK_RATIO", "CLOCK_TIME", "IMU_CONFIDENCE",
           "LogData", "T_JITTER_TOL", "analyze", "clock_log", "fit", "lone_series", "parse_stats",
           "parse_taus", "prepare", "prepare_clock", "prepare_log", "read_clock", "reading",
           "run"]
