"""Workflow ``allan``: the Allan family of one series (issue 3, issue 15).

Verbs (issue 13): :func:`prepare` (= :func:`prepare_log`) turns a validated ``gyro_log`` :class:`~inertialab.io.Record` into one
rate series (column choice, units, sample rate from ``--rate``, the sidecar or a uniform
``t_s``); :func:`analyze` computes the requested statistics of the Allan family with
their confidence intervals (:mod:`inertialab.noise.allan`) and the five noise terms
(:mod:`inertialab.noise.terms`, fitted on the overlapping Allan deviation); the result
serialises to the JSON keys of issue 3; :func:`fit` is :func:`analyze`. The virtual-lab
study (``allan-test`` record, recovery over seeds) is :mod:`inertialab.studies.allan`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from inertialab import units
from inertialab.errors import InputError
from inertialab.noise.allan import STATISTICS, DeviationResult, deviation
from inertialab.noise.terms import NoiseTerms, fit_noise_terms

#: Relative jitter of ``t_s`` above which a log is not uniform (spec 001 §2.2).
T_JITTER_TOL = 1e-6

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


def _rate_from_time(t: np.ndarray, path) -> float:
    n = t.size
    if n < 2:
        raise InputError("needs at least two time stamps", path=path, column="t_s")
    dt = np.diff(t)
    step = float(np.median(dt))
    if not step > 0:
        raise InputError("time stamps do not increase", path=path, column="t_s")
    # each step against the median step; the rate is the mean step's inverse
    bad = np.flatnonzero(np.abs(dt - step) > T_JITTER_TOL * step)
    tau0 = (float(t[-1]) - float(t[0])) / (n - 1)
    if bad.size:
        rows = [int(i) + 2 for i in bad[:5]]  # 1-based data row of the later stamp
        raise InputError(
            f"time stamps not uniform (step deviates from {step:.9g} s by more than "
            f"{T_JITTER_TOL:g} relative at {bad.size} step(s)); give argument 'rate_hz' to ignore t_s",
            path=path, column="t_s", row=rows)
    return 1.0 / tau0


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
        Sample rate; else the sidecar's ``fs_hz``, else a uniform ``t_s`` (relative
        jitter <= 1e-6, else an InputError naming the rows).
    input : {"rate", "angle"}
        ``"angle"`` reads a cumulative ``theta_*`` column (phase analogue).
        ``dtheta_*`` increments are divided by tau0 (CONTRACTS.md "Records").
    """
    path = record.path
    if input not in ("rate", "angle"):
        raise InputError(f"argument 'input' must be rate or angle, got '{input}'")
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
    if rate_hz is not None:
        fs = float(rate_hz)
        if not math.isfinite(fs) or fs <= 0:
            raise InputError(f"argument 'rate_hz' must be positive, got {rate_hz}")
    elif record.meta.get("fs_hz") is not None and "t_s" not in record.data.columns:
        fs = float(record.meta["fs_hz"])
    elif "t_s" in record.data.columns:
        fs = _rate_from_time(record.data["t_s"].to_numpy(dtype=float), path)
    elif record.meta.get("fs_hz") is not None:
        fs = float(record.meta["fs_hz"])
    else:
        raise InputError("no sample rate: give argument 'rate_hz' or a t_s column", path=path)
    values = record.column(col)
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
        """Unit of a statistic's deviation: the rate unit; ``tdev`` is rate unit x s
        (arcsec for deg/h)."""
        if statistic != "tdev":
            return self.unit
        return {"dph": "arcsec", "dps": "deg", "rps": "rad", "mps2": "m/s"}.get(
            self.unit, f"{self.unit}*s")

    def statistic_json(self, r: DeviationResult) -> dict:
        """The issue-3 JSON object of one statistic."""
        terms = None
        if self.terms is not None:
            terms = {}
            for k, t in self.terms.terms().items():
                d = {"value": t.value, "unit": t.unit, "ci": [t.ci[0], t.ci[1]],
                     "method": t.method, "tau_range_s": [t.tau_range_s[0], t.tau_range_s[1]]}
                if t.density is not None:
                    d["density"] = t.density
                if t.per_sample_std is not None:
                    d["per_sample_std"] = t.per_sample_std
                if t.flags:
                    d["flags"] = list(t.flags)
                terms[k] = d
        return {"statistic": r.statistic, "tau0_s": r.tau0_s, "taus_s": r.taus_s,
                "dev": r.dev, "ci_low": r.ci_low, "ci_high": r.ci_high,
                "n_terms": r.n_terms, "alpha": r.alpha, "edf": r.edf,
                "unit": self.dev_unit(r.statistic), "noise_terms": terms}

    def to_json(self) -> dict:
        """One statistic: its object; several: ``{"results": [...]}`` (issue 3 item 6)."""
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


def parse_taus(taus: str):
    """``"octave" | "decade" | "all" | "<int>" | "0.1,1,10"`` (seconds)."""
    t = str(taus).strip().lower()
    if t in ("octave", "decade", "all"):
        return t
    if t.isdigit():
        return int(t)
    try:
        vals = [float(v) for v in t.split(",") if v.strip()]
    except ValueError:
        raise InputError(f"argument 'taus' must be octave, decade, all, a count or seconds, got "
                         f"'{taus}'") from None
    if not vals:
        raise InputError("argument 'taus' is empty")
    return vals


def analyze(log: LogData | np.ndarray, *, rate_hz: float | None = None, unit: str | None = None,
            stats=("oadev",), taus="octave", confidence: float = 0.683, method: str = "wls",
            input: str = "rate", kind: str | None = None, alpha=None,
            edf_method: str = "default", chunked="auto",
            fit_terms: bool = True) -> AllanAnalysis:
    """Allan family with confidence intervals and the five noise terms.

    Parameters
    ----------
    log : LogData or ndarray
        A prepared log, or raw values (then ``rate_hz`` and ``unit`` are required).
    stats : str or sequence, default ("oadev",)
    taus, confidence, alpha, edf_method : see :func:`inertialab.noise.allan.deviation`
    chunked : bool or "auto", default "auto"
        Out-of-core path; "auto" uses it for a memory-mapped input of more than
        :data:`CHUNKED_MIN` samples (the in-memory path needs one float64 copy).
    method : {"wls", "ols", "slope"}, default "wls"
        Noise-term method (:func:`inertialab.noise.terms.fit_noise_terms`).
    fit_terms : bool, default True
        Fit the noise terms; a curve too short for them (fewer than 3 taus in
        [tau0, T/8]) gives ``terms=None`` and a DataQualityWarning instead of an error.
    """
    if not isinstance(log, LogData):
        if rate_hz is None or unit is None:
            raise InputError("analyze() of a bare array needs rate_hz and unit")
        dim = units.dimension(unit)
        kk = kind or {"angular_rate": "gyro", "acceleration": "accel"}.get(dim)
        if kk is None:
            raise InputError(f"unit '{unit}' is a {dim}, not a rate or acceleration")
        vals = log if isinstance(log, np.ndarray) else np.asarray(log)  # keeps a memmap
        log = LogData(values=vals, rate_hz=float(rate_hz), unit=unit, column="",
                      input=input, kind=kk)
    names = parse_stats(stats)
    if chunked == "auto":
        chunked = isinstance(log.values, np.memmap) and log.values.size > CHUNKED_MIN
    results = []
    common = dict(rate_hz=log.rate_hz, taus=taus, input=log.input, confidence=confidence,
                  alpha=alpha, edf_method=edf_method,
                  chunked=chunked and log.input == "rate")
    for s in names:
        results.append(deviation(s, log.values, **common))
    oad = next((r for r in results if r.statistic == "oadev"), None)
    terms = None
    if fit_terms:
        if oad is None:
            oad = deviation("oadev", log.values, **{**common, "taus": "octave"})
        try:
            terms = fit_noise_terms(oad, unit=log.unit, kind=kind or log.kind, method=method,
                                    rate_hz=log.rate_hz, g_local=log.g_local)
        except InputError as exc:
            if "at least 3 taus" not in str(exc):
                raise
            import warnings

            from inertialab.errors import DataQualityWarning

            warnings.warn(f"noise terms not fitted: {exc}", DataQualityWarning, stacklevel=2)
    n = results[0].n_samples
    return AllanAnalysis(results=tuple(results), terms=terms, unit=log.unit, column=log.column,
                         rate_hz=log.rate_hz, n_samples=n, input=log.input, kind=log.kind,
                         oadev=oad,
                         settings={"stats": list(names), "taus": taus, "confidence": confidence,
                                   "method": method, "input": log.input,
                                   "edf_method": edf_method, "rate_hz": log.rate_hz})


#: The workflow verbs (issue 13): prepare(record) -> LogData, fit(data, ...) -> AllanAnalysis.
prepare = prepare_log
fit = analyze

__all__ = ["AllanAnalysis", "LogData", "T_JITTER_TOL", "analyze", "fit", "parse_stats",
           "parse_taus", "prepare", "prepare_log"]
