"""IMU noise terms Q, N, B, K, R from an Allan-type curve (spec 001 §3.3–3.4; issues 3, 14).

Five-term model (spec 001 eq. 4, IEEE Std 952-1997 Annex C), sigma in the rate unit u
and tau in s::

    sigma^2(tau) = 3Q^2/tau^2 + N^2/tau + (2 ln2/pi) B^2 + K^2 tau/3 + R^2 tau^2/2
                 = sum_{k=-2..2} c_k tau^k

Methods (every term reports which one and the tau range it was read on):

``"wls"`` (default)
    Weighted least squares of the model on the AVAR points, weights ``edf_i/(2 model_i^2)``
    (inverse variance of an AVAR estimate), iteratively reweighted with the fitted
    model; each tau's EDF is Greenhall's (:func:`inertialab.noise.edf.edf_greenhall`) for
    the noise type of the model's dominant term there (issue 14 item 4). Robust defaults
    (issue 14 item 2, see :func:`auto_tau_range`): the short-tau region coloured by the
    sensor's internal low-pass/decimation filter is cut (the curve rises or flattens
    before it falls like white noise; everything below 4x its peak is dropped), and the
    ``c_-2`` coefficient is signed: a filter leaves ``-c/tau^2`` behind on white noise
    (``sigma^2 = N^2/tau - c/tau^2`` beyond the filter's length), angle quantisation
    ``+3Q^2/tau^2``; a negative or non-significant ``c_-2`` reports Q as absent. Taus
    whose model EDF is below :data:`EDF_MIN` are dropped. A record too short to separate
    a term (fewer than two taus per parameter) drops R, then K, then Q, reported
    ``not_observable`` with the reason.
``"ols"``
    The same with unit weights (the paper-compatible mode of spec 001 §3.4 item 3).
``"slope"``
    Automated IEEE 952 slope reading (spec 001 §3.4 item 1; ``noise/_terms_slope.py``).
``"gmwm"``
    Generalized method of wavelet moments (:mod:`inertialab.noise.gmwm`) on the dyadic
    points of the curve (the Haar wavelet variance is half the Allan variance there).

Intervals (issue 14 item 3): a parametric bootstrap on the fitted noise model in the
Allan domain. Each replicate draws every fitted tau's AVAR as
``model_i chi2(edf_i)/edf_i`` (Greenhall EDF of the model's noise type), correlated
across taus through a Gaussian copula whose correlation is a Markov chain in log2(tau)
with the measured one-octave correlation of the dominant noise type
(:data:`OCTAVE_RHO`), and is refitted by the same method; the term's interval is the percentile
interval at ``confidence`` (default 0.95). Drawing records instead would cost a full
simulation and Allan pass per replicate (seconds on a 10-h log); the Allan-domain draw
is the same model's sampling law to the extent the copula captures the dependence of
the taus, which the coverage benchmark (benchmarks/noise_terms.py) measures. A term whose lower
percentile is at 0 (or, for Q, at or below 0), or that never carries :data:`READ_SHARE`
of the model at a fitted tau, is not significant: it is reported with
``ci = [0, upper]``, flag ``upper_bound`` and the reason. (The second rule matters
because neighbouring octave AVAR estimates are correlated — they share the record — so a
term of 1 % of the curve can look significant to a bootstrap that draws the taus
independently; measured on white + random-walk data, where it produced the issue's
spurious Q.)

B is IEEE 952's flat-region value ``sqrt(c_0)/0.6643``; the textbook reading
``min(sigma)/0.6643`` over the fitted taus is reported beside it
(:attr:`NoiseTerms.b_textbook`).

Units (CONTRACTS.md "noise"): gyros report Q arcsec, N deg/sqrt(h), B deg/h,
K deg/h/sqrt(h), R deg/h^2; accelerometers Q m/s, N m/s/sqrt(h), B ug, K m/s^2/sqrt(h),
R m/s^3. N also carries ``density`` (continuous-time white-noise density: rad/s/sqrt(Hz)
for gyros, ug/sqrt(Hz) for accelerometers) and ``per_sample_std`` (the discrete
standard deviation of one sample at the record's rate: density * sqrt(rate); rad/s or
m/s^2). Estimator-specific values (Kalibr, OpenVINS, VINS, GTSAM) come from
:func:`inertialab.noise.robotics.robotics_values`.

Hand-written: no maintained library fits the IEEE five-term model with EDF weights.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

import numpy as np

from inertialab import units
from inertialab.errors import InputError

#: ``sqrt(2 ln2 / pi)``: the Allan floor of bias instability B.
BI_FACTOR = math.sqrt(2.0 * math.log(2.0) / math.pi)  # 0.66428

#: Taus whose model EDF is below this are not fitted (issue 14 item 2: "EDF < a few").
EDF_MIN = 3.0

#: A term is read (and can be significant) only where it carries at least this share of
#: the model AVAR at some fitted tau (issue 14 item 2).
READ_SHARE = 0.25

#: Correlation of log AVAR estimates one octave apart, per noise type (alpha), measured
#: by Monte Carlo (oadev, 2^15 samples, 300 records, m = 1..1024; docs/noise-terms.md):
#: white rate 0.5, flicker 0.67, random walk 0.88; white angle not measured, taken 0.5.
OCTAVE_RHO = {2: 0.5, 1: 0.5, 0: 0.5, -1: 0.67, -2: 0.88}

#: Default bootstrap replicates and confidence of the term intervals (issue 14 item 3).
N_BOOT = 200
CONFIDENCE = 0.95

_POWERS = (-2, -1, 0, 1, 2)
_NAMES = ("Q", "N", "B", "K", "R")
#: alpha (rate PSD exponent) of each model term, for the EDF of its tau
_TERM_ALPHA = (2, 0, -1, -2, -2)
#: sqrt-form amplitude = gain * sqrt(c_k)
_GAIN = np.array([1 / math.sqrt(3), 1.0, 1 / BI_FACTOR, math.sqrt(3), math.sqrt(2)])

_REPORT = {
    "gyro": {"rate": "deg/h", "Q": "arcsec", "N": "deg/sqrt(h)", "B": "deg/h",
             "K": "deg/h/sqrt(h)", "R": "deg/h^2", "density": "rad/s/sqrt(Hz)",
             "per_sample": "rad/s"},
    "accel": {"rate": "m/s^2", "Q": "m/s", "N": "m/s/sqrt(h)", "B": "ug",
              "K": "m/s^2/sqrt(h)", "R": "m/s^3", "density": "ug/sqrt(Hz)",
              "per_sample": "m/s^2"},
}
# native unit of each coefficient's sqrt-form, given the rate unit in the first column
_NATIVE = {
    "gyro": {"Q": "arcsec", "N": "deg/h/sqrt(Hz)", "K": "rad/s/sqrt(s)", "R": "rad/s^2"},
    "accel": {"Q": "m/s", "N": "m/s/sqrt(s)", "K": "m/s^2/sqrt(s)", "R": "m/s^3"},
}


def _nan(v):
    return float("nan") if v is None else float(v)


@dataclass(frozen=True)
class NoiseTerm:
    """One noise coefficient in its report unit.

    Attributes
    ----------
    value : float
        Estimate (NaN when not observable).
    unit : str
    ci : tuple (low, high)
        Interval at the result's confidence (bootstrap for "wls"/"ols"/"gmwm",
        EDF-based for "slope"); ``(0, upper)`` for a term that is not significant.
    method : str
        ``"wls" | "ols" | "slope" | "gmwm"``.
    tau_range_s : tuple (low, high)
        Taus the term was read on (where it carries at least a quarter of the model).
    flags : tuple of str
        ``"not_observable"``, ``"upper_bound"`` (not significant), ``"B_bound"`` (slope),
        ``"zero"`` (the fit put the term at 0), ``"filter"`` (Q only: the short taus
        show the internal filter, ``c_-2 < 0``).
    sd : float
        1-sigma uncertainty in ``unit`` (NaN where not defined).
    density, per_sample_std : dict or None
        N only: ``{"value", "unit"}``.
    reason : str
        Why a term is absent, bounded or not observable.
    upper_bound : float
        Upper end of the interval of a non-significant term (NaN otherwise).
    """

    value: float
    unit: str
    ci: tuple
    method: str
    tau_range_s: tuple
    flags: tuple = ()
    sd: float = float("nan")
    density: dict | None = None
    per_sample_std: dict | None = None
    reason: str = ""
    upper_bound: float = float("nan")

    @property
    def significant(self) -> bool:
        return not ({"upper_bound", "not_observable"} & set(self.flags))

    def to_dict(self) -> dict:
        """The one JSON form of a term (CONTRACTS.md "noise"): ``value, unit, ci, method,
        tau_range_s, sd, flags`` (+ ``density``, ``per_sample_std`` for N, ``reason`` and
        ``upper_bound`` where set)."""
        d = {"value": float(self.value), "unit": self.unit,
             "ci": [float(self.ci[0]), float(self.ci[1])], "method": self.method,
             "tau_range_s": [float(self.tau_range_s[0]), float(self.tau_range_s[1])],
             "sd": float(self.sd), "flags": list(self.flags)}
        if self.density is not None:
            d["density"] = dict(self.density)
        if self.per_sample_std is not None:
            d["per_sample_std"] = dict(self.per_sample_std)
        if self.reason:
            d["reason"] = self.reason
        if math.isfinite(self.upper_bound):
            d["upper_bound"] = float(self.upper_bound)
        return d

    @classmethod
    def from_dict(cls, d: dict) -> NoiseTerm:
        return cls(value=_nan(d["value"]), unit=d["unit"], ci=tuple(_nan(v) for v in d["ci"]),
                   method=d["method"], tau_range_s=tuple(_nan(v) for v in d["tau_range_s"]),
                   flags=tuple(d.get("flags", ())), sd=_nan(d.get("sd")),
                   density=d.get("density"), per_sample_std=d.get("per_sample_std"),
                   reason=d.get("reason", ""), upper_bound=_nan(d.get("upper_bound")))


@dataclass(frozen=True)
class NoiseTerms:
    """The five IEEE noise terms of one record.

    Attributes
    ----------
    Q, N, B, K, R : NoiseTerm
    kind : {"gyro", "accel"}
    unit : str
        Unit suffix of the rate data the curve came from ('dph', 'dps', 'rps', 'mps2', 'g' ...).
    method : str
    coefficients : tuple of 5 float
        ``c_-2 .. c_2`` of eq. 4 in (data unit)^2 s^k (``c_-2`` may be negative: filter).
    tau_range_s : tuple
        Taus of the whole fit.
    fit_rmse_log : float
        RMSE of ``ln sigma_hat - ln sigma_model`` over the fitted taus.
    rate_hz : float or None
    confidence : float
        Confidence of the term intervals.
    statistic : str
    g_local : float
        Local gravity used for g-based accelerometer units (m/s^2).
    alpha_model : tuple of int
        Noise type of the model's dominant term at each fitted tau.
    b_textbook : dict or None
        ``{"value", "unit", "tau_s", "ci"}``: min(sigma)/0.6643 over the fitted taus.
    interval : str
        How the intervals were made (e.g. ``"bootstrap-allan/200"``).
    gmwm : dict or None
        The GMWM model (method "gmwm"): latent processes, their parameters, WIC.
    misfit : float
        ``sqrt(chi2/dof)`` of the fit when above 1 (the factor the bootstrap spread was
        widened by), else 1.
    """

    MODEL_TYPE = "noise-terms"

    Q: NoiseTerm
    N: NoiseTerm
    B: NoiseTerm
    K: NoiseTerm
    R: NoiseTerm
    kind: str
    unit: str
    method: str
    coefficients: tuple
    tau_range_s: tuple
    fit_rmse_log: float = float("nan")
    rate_hz: float | None = None
    confidence: float = CONFIDENCE
    statistic: str = "oadev"
    g_local: float = units.G_STANDARD
    alpha_model: tuple = field(default_factory=tuple)
    b_textbook: dict | None = None
    interval: str = ""
    gmwm: dict | None = None
    misfit: float = 1.0

    def terms(self) -> dict[str, NoiseTerm]:
        return {k: getattr(self, k) for k in _NAMES}

    def model_dev(self, taus_s) -> np.ndarray:
        """Five-term model deviation at ``taus_s`` (s) in the data unit."""
        t = np.asarray(taus_s, dtype=float)
        c = np.nan_to_num(np.asarray(self.coefficients, dtype=float))
        with np.errstate(invalid="ignore"):
            return np.sqrt(sum(ck * t**k for ck, k in zip(c, _POWERS)))

    def term_devs(self, taus_s) -> dict[str, np.ndarray]:
        """Each term's own deviation line at ``taus_s`` in the data unit (NaN if absent)."""
        t = np.asarray(taus_s, dtype=float)
        out = {}
        for name, ck, k in zip(_NAMES, self.coefficients, _POWERS):
            out[name] = (np.sqrt(ck * t**k) if (ck is not None and np.isfinite(ck) and ck > 0)
                         else np.full(t.shape, np.nan))
        return out

    def to_dict(self) -> dict:
        d = {k: getattr(self, k).to_dict() for k in _NAMES}
        d.update({"kind": self.kind, "unit": self.unit, "method": self.method,
                  "coefficients": [float(v) for v in self.coefficients],
                  "tau_range_s": [float(v) for v in self.tau_range_s],
                  "fit_rmse_log": float(self.fit_rmse_log),
                  "rate_hz": None if self.rate_hz is None else float(self.rate_hz),
                  "confidence": float(self.confidence), "statistic": self.statistic,
                  "g_local": float(self.g_local),
                  "alpha_model": [int(a) for a in self.alpha_model]})
        if self.b_textbook is not None:
            d["b_textbook"] = dict(self.b_textbook)
        if self.interval:
            d["interval"] = self.interval
        if self.gmwm is not None:
            d["gmwm"] = self.gmwm
        d["misfit"] = float(self.misfit)
        return d

    @classmethod
    def from_dict(cls, d: dict) -> NoiseTerms:
        return cls(**{k: NoiseTerm.from_dict(d[k]) for k in _NAMES},
                   kind=d["kind"], unit=d["unit"], method=d["method"],
                   coefficients=tuple(_nan(v) for v in d["coefficients"]),
                   tau_range_s=tuple(float(v) for v in d["tau_range_s"]),
                   fit_rmse_log=_nan(d.get("fit_rmse_log")), rate_hz=d.get("rate_hz"),
                   confidence=float(d.get("confidence", 0.683)),
                   statistic=d.get("statistic", "oadev"),
                   g_local=float(d.get("g_local", units.G_STANDARD)),
                   alpha_model=tuple(int(a) for a in d.get("alpha_model", ())),
                   b_textbook=d.get("b_textbook"), interval=d.get("interval", ""),
                   gmwm=d.get("gmwm"), misfit=float(d.get("misfit", 1.0)))


# ----------------------------------------------------------------------------- conversion


class _Converter:
    """sqrt-form coefficients (data unit) -> report units."""

    def __init__(self, unit: str, kind: str | None, g_local: float):
        try:
            dim = units.dimension(unit)
        except InputError:
            raise InputError(f"unknown unit '{unit}' (use dph, dps, rps, mps2, g, mg, ug)") from None
        if kind is None:
            kind = {"angular_rate": "gyro", "acceleration": "accel"}.get(dim)
        if kind not in ("gyro", "accel"):
            raise InputError(f"kind must be 'gyro' or 'accel', got {kind!r} (unit '{unit}' is a "
                             f"{dim})")
        want = "angular_rate" if kind == "gyro" else "acceleration"
        if dim != want:
            raise InputError(f"unit '{unit}' is a {dim}, not a {want} ({kind} data)")
        self.kind, self.unit, self.g = kind, unit, float(g_local)
        rep = _REPORT[kind]
        # factor: data unit -> report rate unit (deg/h or m/s^2)
        self.f = float(units.convert(1.0, unit, rep["rate"], g_local=self.g))

    def _c(self, x, a, b):
        return float(units.convert(x, a, b, g_local=self.g))

    def value(self, name: str, s: float) -> float:
        """``s`` = the term's natural amplitude in (report rate unit)·s^(power/2)."""
        rep, nat = _REPORT[self.kind], _NATIVE[self.kind]
        if name == "Q":  # (deg/h)·s = arcsec ; (m/s^2)·s = m/s
            return s
        if name == "N":  # (deg/h)·sqrt(s) = deg/h/sqrt(Hz) ; (m/s^2) sqrt(s) = m/s/sqrt(s)
            return self._c(s, nat["N"], rep["N"])
        if name == "B":
            return s if self.kind == "gyro" else self._c(s, "m/s^2", "ug")
        if name == "K":  # (deg/h)/sqrt(s) -> rad/s/sqrt(s) -> deg/h/sqrt(h)
            if self.kind == "gyro":
                return self._c(self._c(s, "deg/h", "rad/s"), nat["K"], rep["K"])
            return self._c(s, nat["K"], rep["K"])
        if name == "R":  # (deg/h)/s -> rad/s^2 -> deg/h^2
            if self.kind == "gyro":
                return self._c(self._c(s, "deg/h", "rad/s"), nat["R"], rep["R"])
            return s
        raise KeyError(name)

    def factor(self, name: str) -> float:
        """Linear factor: data-unit amplitude -> report value."""
        return self.value(name, 1.0) * self.f

    def n_extras(self, n_report_rate: float, rate_hz: float | None):
        """density and per-sample std of the white noise (N in report-rate·sqrt(s))."""
        rep = _REPORT[self.kind]
        if self.kind == "gyro":
            dens = self._c(self._c(n_report_rate, "deg/h", "rad/s"), "rad/s/sqrt(Hz)",
                           rep["density"])
        else:
            dens = self._c(n_report_rate, "m/s^2/sqrt(Hz)", rep["density"])
        density = {"value": dens, "unit": rep["density"]}
        per = None
        if rate_hz:
            si = (self._c(n_report_rate, "deg/h", "rad/s") if self.kind == "gyro"
                  else n_report_rate)
            per = {"value": si * math.sqrt(float(rate_hz)), "unit": rep["per_sample"],
                   "rate_hz": float(rate_hz)}
        return density, per


# ----------------------------------------------------------------------------- tau range


def auto_tau_range(taus_s, dev) -> int:
    """Index of the first tau not coloured by the sensor's internal filter.

    A low-pass/decimation filter makes the Allan deviation rise or flatten at the first
    taus before it falls like white noise (slope -1/2). When the first log-log slope is
    above -1/4 the curve's first peak ``tau_p`` is found (first slope below -1/4) and taus
    below ``4 tau_p`` are cut; the 1/tau^2 remainder of the filter beyond that is taken up
    by the signed ``c_-2`` term. A curve that starts falling (white noise, quantisation)
    keeps every tau (index 0).
    """
    lt = np.log(np.asarray(taus_s, dtype=float))
    ld = np.log(np.asarray(dev, dtype=float))
    if lt.size < 3:
        return 0
    s = np.diff(ld) / np.diff(lt)
    if s[0] <= -0.25:
        return 0
    below = np.nonzero(s <= -0.25)[0]
    if below.size == 0:
        return 0
    tau_p = math.exp(lt[below[0]])
    return int(np.searchsorted(lt, math.log(4.0 * tau_p) - 1e-9))


def _select(result, tau_range, auto: bool):
    taus = np.asarray(result.taus_s, dtype=float)
    dev = np.asarray(result.dev, dtype=float)
    ok = np.isfinite(dev) & (dev > 0)
    if tau_range is None:
        lo, hi = result.tau0_s * (1 - 1e-9), np.inf
    else:
        lo, hi = float(tau_range[0]), float(tau_range[1])
    sel = ok & (taus >= lo) & (taus <= hi)
    cut = 0
    if auto and tau_range is None and sel.sum() >= 3:
        idx = np.nonzero(sel)[0]
        k = auto_tau_range(taus[idx], dev[idx])
        if k:
            cut = k
            sel[idx[:k]] = False
    if sel.sum() < 3:
        raise InputError(f"need at least 3 taus with a positive deviation in "
                         f"[{lo:g}, {hi:g}] s to fit noise terms, got {int(sel.sum())}")
    return sel, cut


def fit_noise_terms(result, *, unit: str, kind: str | None = "gyro", method: str = "wls",
                    rate_hz: float | None = None, tau_range_s=None,
                    g_local: float = units.G_STANDARD, n_reweight: int = 5,
                    confidence: float = CONFIDENCE, n_boot: int | None = None, seed: int = 0,
                    auto_range: bool = True) -> NoiseTerms:
    """Fit Q N B K R to a :class:`~inertialab.noise.allan.DeviationResult`.

    Parameters
    ----------
    result : DeviationResult
        An Allan-type curve of rate data (``oadev`` recommended; ``adev``, ``mdev`` ...
        are fitted with the same AVAR model, which is exact only for the Allan variance).
    unit : str
        Unit suffix of the rate data ('dph', 'dps', 'rps', 'mps2', 'g', 'mg', 'ug').
    kind : {"gyro", "accel"} or None, default "gyro"
        None infers it from the unit's dimension.
    method : {"wls", "ols", "slope", "gmwm"}, default "wls"
        "gmwm" uses the curve's dyadic taus (use :func:`inertialab.noise.gmwm.fit_gmwm`
        on the record for its own scales).
    rate_hz : float, optional
        Sample rate for N's per-sample std (default ``1/result.tau0_s``).
    tau_range_s : (low, high), optional
        Fit only these taus (then no automatic cut).
    g_local : float, default 9.80665
        Local gravity for g-based units (m/s^2).
    n_reweight : int, default 5
        WLS reweighting passes.
    confidence : float, default 0.95
        Confidence of the term intervals (issue 14 item 3).
    n_boot : int, optional
        Bootstrap replicates (0: no intervals, NaN); default 200 (50 for "gmwm", whose
        refits cost ~0.1 s each).
    seed : int, default 0
        Seed of the bootstrap.
    auto_range : bool, default True
        Cut the filter-coloured short taus (:func:`auto_tau_range`).

    Raises
    ------
    InputError
        Unknown unit or method, unit of the wrong dimension, fewer than 3 usable taus.
    """
    conv = _Converter(unit, kind, g_local)
    if method not in ("wls", "ols", "slope", "gmwm"):
        raise InputError(f"unknown noise-term method '{method}' (use wls, ols, slope, gmwm)")
    if not 0 < confidence < 1:
        raise InputError(f"confidence must be in (0, 1), got {confidence}")
    if rate_hz is None:
        rate_hz = 1.0 / float(result.tau0_s)
    if n_boot is None:
        n_boot = 50 if method == "gmwm" else N_BOOT
    sel, _ = _select(result, tau_range_s, auto_range and method != "gmwm")
    if method == "slope":
        from inertialab.noise._terms_slope import fit_slope

        return fit_slope(result, sel, conv, rate_hz)
    if method == "gmwm":
        from inertialab.noise.gmwm import fit_gmwm_curve, gmwm_noise_terms

        g = fit_gmwm_curve(result, sel, confidence=confidence, n_boot=n_boot, seed=seed)
        return gmwm_noise_terms(g, conv, rate_hz, result)
    from inertialab.noise._terms_ls import fit_ls

    return fit_ls(result, sel, conv, rate_hz, method, n_reweight, confidence, n_boot, seed)


# ----------------------------------------------------------------------------- identification


def model_alpha(terms: NoiseTerms, taus_s) -> np.ndarray:
    """Noise type (rate PSD exponent) of the fitted model's dominant term at ``taus_s``:
    Q +2, N 0, B -1, K and R -2."""
    t = np.asarray(taus_s, dtype=float)
    c = np.nan_to_num(np.asarray(terms.coefficients, dtype=float))
    contrib = np.stack([c[i] * t ** _POWERS[i] for i in range(5)], axis=1)
    return np.array([_TERM_ALPHA[j] for j in np.argmax(contrib, axis=1)], dtype=np.int64)


def model_intervals(result, terms: NoiseTerms, *, min_points: int = 1000):
    """The curve's intervals with the noise type following the fitted model (issue 14
    item 5), for rate records of inertial sensors.

    The lag-1 identification is kept where it is significant: decided on at least
    ``min_points`` decimated points (lag-1 ACF standard error <= 0.03, well below the 0.25
    spacing of the noise classes in ``delta``) *and* not calling angle noise (alpha >= +1)
    where the model says white rate or slower noise dominates. Everywhere else the model's
    alpha is used; the EDF (Greenhall) and the chi-square interval are recomputed. Clock
    (angle/phase) records and user-given noise types are returned unchanged.
    """
    from inertialab.noise.edf import chi2_interval, edf

    if result.input != "rate" or result.alpha_method == "user":
        return result
    ma = model_alpha(terms, result.taus_s)
    alpha = np.asarray(result.alpha, dtype=np.int64).copy()
    n_pts = result.n_samples // np.maximum(np.asarray(result.m), 1)
    src = list(result.alpha_source) or ["lag1"] * alpha.size
    new_src = []
    for i in range(alpha.size):
        weak = n_pts[i] < min_points or src[i] != "lag1"
        angle_in_rate = alpha[i] >= 1 and ma[i] <= 0
        if weak or angle_in_rate:
            alpha[i] = ma[i]
            new_src.append("model")
        else:
            new_src.append(src[i])
    n_phase = result.n_samples + 1
    e, label = edf(result.statistic, n_phase, result.m, alpha)
    lo, hi = chi2_interval(result.dev, e, result.confidence)
    return replace(result, alpha=alpha, edf=e, ci_low=lo, ci_high=hi, alpha_method="model",
                   alpha_source=tuple(new_src), edf_method=label)


def local_slopes(taus, dev) -> np.ndarray:
    """Least-squares slope of ln(dev) vs ln(tau) over each point and its neighbours."""
    lt, ld = np.log(np.asarray(taus, float)), np.log(np.asarray(dev, float))
    k = lt.size
    s = np.empty(k)
    for i in range(k):
        a, b = max(0, i - 1), min(k, i + 2)
        x, y = lt[a:b], ld[a:b]
        xm = x - x.mean()
        s[i] = float(xm @ (y - y.mean()) / (xm @ xm))
    return s


__all__ = ["BI_FACTOR", "CONFIDENCE", "EDF_MIN", "N_BOOT", "NoiseTerm", "NoiseTerms",
           "auto_tau_range", "fit_noise_terms", "local_slopes", "model_alpha",
           "model_intervals"]
