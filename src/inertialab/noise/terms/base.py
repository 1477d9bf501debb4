"""The data types and constants of the noise-term fit (split from
:mod:`inertialab.noise.terms.fit` so that its method modules — least squares, slope, GMWM —
share them without importing the dispatcher back: no import circle).

:class:`NoiseTerm` (one term with its interval, its JSON form ``to_dict``) and
:class:`NoiseTerms` (Q N B K R), the IEEE 952 constants, and :func:`auto_tau_range` and
:func:`local_slopes`, which every method reads the curve with.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from inertialab import units
from inertialab.errors import InputError
from inertialab.io.model_schemas import check_own_payload
from inertialab.noise.spectral.lines import Line, line_avar
from inertialab.noise.terms.band import band_shape, rw_gm_shape

#: ``sqrt(2 ln2 / pi)``: the Allan floor of bias instability B.
BI_FACTOR = math.sqrt(2.0 * math.log(2.0) / math.pi)  # 0.66428

#: Taus whose model EDF is below this are not fitted (their estimate is too scattered).
EDF_MIN = 3.0

#: A term is read (and can be significant) only where it carries at least this share of
#: the model AVAR at some fitted tau.
READ_SHARE = 0.25

#: Correlation of log AVAR estimates one octave apart, per noise type (alpha), measured
#: by Monte Carlo (oadev, 2^15 samples, 300 records, m = 1..1024; docs/noise-terms.md):
#: white rate 0.5, flicker 0.67, random walk 0.88; white angle not measured, taken 0.5.
OCTAVE_RHO = {2: 0.5, 1: 0.5, 0: 0.5, -1: 0.67, -2: 0.88}

#: Default bootstrap replicates and confidence of the term intervals.
N_BOOT = 200
CONFIDENCE = 0.95

#: The short-tau corner of the band-limited B term is searched up to this multiple of the
#: shortest fitted tau: below it white noise dominates and the corner
#: is poorly identified, so it is not allowed to wander into the flat region. 16 was
#: tried first; on industrial-400hz (shortest Gauss-Markov tc 10 s, 250x the shortest
#: tau) it left N -0.08 % and K -17 % biased (80 seeds, no bootstrap), 64 -0.04 % and
#: -2 %, the other presets unchanged (docs/noise-terms.md).
BAND_LO_MAX = 64.0
#: shortest correlation time of a Gauss–Markov wander read as K (a random walk held by
#: that time), as a share of the longest fitted tau: its Allan variance then peaks at
#: ~1.9 t_c, inside the last three octaves of the curve (shorter ones are bias
#: instability); the five-term fit's K time and GMWM's slow Gauss–Markov processes
K_TIME_MIN = 0.05

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


def span_intervals(a, b) -> tuple:
    """The smallest interval holding the finite ones of the intervals ``a`` and ``b``
    (``a`` where neither is finite): how the term intervals carry a choice the data leave
    open (a ramp in or out, models the WIC does not tell apart, readings that move)."""
    fin_a = all(math.isfinite(v) for v in a)
    if not all(math.isfinite(v) for v in b):
        return tuple(a)
    if not fin_a:
        return tuple(b)
    return (min(a[0], b[0]), max(a[1], b[1]))


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
        show the internal filter, ``c_-2 < 0``); B only (:mod:`inertialab.noise.terms._bounds`):
        ``"held_to_curve_minimum"`` (a significant estimate held to 1.05 min(ADEV)/0.664,
        the model's own estimate in ``reason``), ``"above_curve_minimum"`` (above that
        reading, within the curve's simultaneous upper limits).
    sd : float
        1-sigma uncertainty in ``unit`` (NaN where not defined).
    density, per_sample_std : dict or None
        N only: ``{"value", "unit"}``.
    reason : str
        Why a term is absent, bounded or not observable.
    upper_bound : float
        Upper end of the interval of a non-significant term (NaN otherwise).

    Examples
    --------
    The N term of white rate noise of 0.1 deg/s at 100 Hz (0.6 deg/sqrt(h); per sample
    0.1 deg/s, here in rad/s):

    >>> import numpy as np
    >>> y = np.random.default_rng(0).normal(0.0, 0.1, 20_000)
    >>> from inertialab.noise import fit_noise_terms, oadev
    >>> n = fit_noise_terms(oadev(y, rate_hz=100.0), unit="dps", n_boot=0).N
    >>> n.significant, round(float(n.value), 1), n.per_sample_std["unit"]
    (True, 0.6, 'rad/s')
    >>> bool(np.isclose(n.per_sample_std["value"], np.deg2rad(0.1), rtol=0.05))
    True
    >>> bool(NoiseTerm.from_dict(n.to_dict()).value == n.value)
    True
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
        """The one JSON form of a term (docs/noise-terms.md): ``value, unit, ci, method,
        tau_range_s, sd, flags`` (+ ``density``, ``per_sample_std`` for N, ``reason`` and
        ``upper_bound`` where set, ``"bound": "upper"`` where the term is only a bound)."""
        bound = "upper_bound" in self.flags and math.isfinite(self.upper_bound)
        # a bound's value is the bound (what a user copies), the estimate beside it
        d = {"value": float(self.upper_bound if bound else self.value), "unit": self.unit,
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
        if "upper_bound" in self.flags:
            d["bound"] = "upper"  # the value is not a confident number: use upper_bound
            if bound:
                d["estimate"] = float(self.value)
        return d

    @classmethod
    def from_dict(cls, d: dict) -> NoiseTerm:
        value = d["estimate"] if d.get("bound") == "upper" and "estimate" in d else d["value"]
        return cls(value=_nan(value), unit=d["unit"], ci=tuple(_nan(v) for v in d["ci"]),
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
    lines : tuple of :class:`inertialab.noise.spectral.lines.Line`
        Spectral lines (sinusoids) found in the record and held in the model as IEEE
        952's sinusoidal term (:mod:`inertialab.noise.spectral.lines`); their Allan variance was
        taken off the curve before the terms were fitted and is part of
        :meth:`model_dev`.
    bias_gm : dict or None
        The band limits of the B term (:func:`band_shape`):
        ``{"t_lo_s", "t_hi_s"}``, the shortest and longest Gauss–Markov correlation time
        of the band-limited flicker (None: no roll-off on that side). None for pure
        flicker (the IEEE five-term model; files written before the band existed).
    k_gm : dict or None
        ``{"t_s"}``: the K term is a rate random walk held by a first-order Gauss–Markov
        correlation time ``t_s`` (:func:`rw_gm_shape`): K is its random-walk density below
        ``t_s``, and its Allan variance falls like white noise past ``~1.9 t_s``. None: a
        pure random walk (the IEEE five-term model).

    Examples
    --------
    The model of white rate noise of 0.1 deg/s at 100 Hz reproduces its Allan deviation,
    ``0.1 / sqrt(tau * 100)`` deg/s, and survives its JSON form:

    >>> import numpy as np
    >>> y = np.random.default_rng(0).normal(0.0, 0.1, 20_000)
    >>> from inertialab.noise import fit_noise_terms, oadev
    >>> terms = fit_noise_terms(oadev(y, rate_hz=100.0), unit="dps", n_boot=0)
    >>> terms.kind, terms.unit
    ('gyro', 'dps')
    >>> taus = np.array([0.01, 1.0])
    >>> bool(np.allclose(terms.model_dev(taus), 0.1 / np.sqrt(taus * 100.0), rtol=0.05))
    True
    >>> bool(NoiseTerms.from_dict(terms.to_dict()).N.value == terms.N.value)
    True
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
    bias_gm: dict | None = None
    lines: tuple = ()
    k_gm: dict | None = None

    def b_shape(self, taus_s) -> np.ndarray:
        """Shape of the B term's AVAR at ``taus_s`` (peak 1; ones for pure flicker)."""
        t = np.asarray(taus_s, dtype=float)
        if not self.bias_gm:
            return np.ones(t.shape)
        lo, hi = self.bias_gm.get("t_lo_s"), self.bias_gm.get("t_hi_s")
        return band_shape(t, 0.0 if lo is None else lo, math.inf if hi is None else hi)

    def contributions(self, taus_s) -> np.ndarray:
        """Each term's AVAR at ``taus_s``, shape (k, 5) in the data unit^2 (NaN -> 0)."""
        t = np.asarray(taus_s, dtype=float)
        c = np.nan_to_num(np.asarray(self.coefficients, dtype=float))
        cols = [c[i] * t ** _POWERS[i] for i in range(5)]
        cols[2] = c[2] * self.b_shape(t)
        if self.k_gm:
            cols[3] = c[3] * rw_gm_shape(t, float(self.k_gm["t_s"]))
        return np.stack(cols, axis=-1)

    def terms(self) -> dict[str, NoiseTerm]:
        return {k: getattr(self, k) for k in _NAMES}

    def model_dev(self, taus_s) -> np.ndarray:
        """Model deviation at ``taus_s`` (s) in the data unit: the five terms and the
        spectral lines."""
        with np.errstate(invalid="ignore"):
            return np.sqrt(self._model_avar(taus_s) + line_avar(taus_s, self.lines))

    def _model_avar(self, taus_s) -> np.ndarray:
        """AVAR of the fitted noise model (without lines): the five terms, or for a GMWM
        fit the sum of its latent processes (whose Gauss-Markov processes the five
        coefficients only summarise)."""
        procs = (self.gmwm or {}).get("processes")
        tau0 = ((self.gmwm or {}).get("wv") or {}).get("tau0_s")
        if not procs or not tau0:
            return self.contributions(taus_s).sum(axis=-1)
        from inertialab.noise.gmwm.model import Process

        m = np.asarray(taus_s, dtype=float) / float(tau0)
        return sum(Process(d["process"], dict(d["params"])).avar(m, float(tau0))
                   for d in procs)

    def report_factor(self, name: str) -> float:
        """Report value of term ``name`` (``"N"``, ``"B"``, ``"K"`` ...) per unit amplitude
        in the data unit (the linear factor of the report unit)."""
        return _Converter(self.unit, self.kind, self.g_local).factor(name)

    def term_devs(self, taus_s) -> dict[str, np.ndarray]:
        """Each term's own deviation line at ``taus_s`` in the data unit (NaN if absent)."""
        t = np.asarray(taus_s, dtype=float)
        contrib = self.contributions(t)
        out = {}
        for j, (name, ck) in enumerate(zip(_NAMES, self.coefficients)):
            out[name] = (np.sqrt(contrib[..., j]) if (ck is not None and np.isfinite(ck)
                                                      and ck > 0)
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
        if self.bias_gm is not None:
            d["bias_gm"] = dict(self.bias_gm)
        if self.lines:
            d["lines"] = [ln.to_dict(self.unit) for ln in self.lines]
        if self.k_gm is not None:
            d["k_gm"] = dict(self.k_gm)
        return d

    @classmethod
    def from_dict(cls, d: dict) -> NoiseTerms:
        check_own_payload(cls.MODEL_TYPE, d)  # types, shapes, ranges: one line naming the key
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
                   gmwm=d.get("gmwm"), misfit=float(d.get("misfit", 1.0)),
                   bias_gm=d.get("bias_gm"), k_gm=d.get("k_gm"),
                   lines=tuple(Line.from_dict(x) for x in d.get("lines", ())))


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


#: largest first-peak tau (s) of the Allan deviation a static record's own filter makes:
#: an IMU's internal low-pass/decimation filter (bandwidth >= ~5 Hz; correlation time
#: <= 1/(2 pi 5 Hz) = 0.03 s) puts the peak near a few correlation times, below ~0.1 s;
#: a curve still rising at 1 s follows something slower than any such filter (motion,
#: vibration, a rig that turns), and the noise terms would describe that, not the sensor
STATIC_PEAK_MAX_S = 1.0


def filter_peak_tau(taus_s, dev) -> float | None:
    """First peak ``tau_p`` of an Allan deviation that starts rising or flat (its first
    log-log slope above -1/4; the peak is where the slope first falls below -1/4), or
    None when the curve starts falling or never falls."""
    lt = np.log(np.asarray(taus_s, dtype=float))
    ld = np.log(np.asarray(dev, dtype=float))
    if lt.size < 3:
        return None
    s = np.diff(ld) / np.diff(lt)
    if s[0] <= -0.25:
        return None
    below = np.nonzero(s <= -0.25)[0]
    if below.size == 0:
        return None
    return math.exp(lt[below[0]])


def auto_tau_range(taus_s, dev) -> int:
    """Index of the first tau not coloured by the sensor's internal filter.

    A low-pass/decimation filter makes the Allan deviation rise or flatten at the first
    taus before it falls like white noise (slope -1/2). When the first log-log slope is
    above -1/4 the curve's first peak ``tau_p`` is found (:func:`filter_peak_tau`) and
    taus below ``4 tau_p`` are cut; the 1/tau^2 remainder of the filter beyond that is
    taken up by the signed ``c_-2`` term. A curve that starts falling (white noise,
    quantisation) keeps every tau (index 0).
    """
    tau_p = filter_peak_tau(taus_s, dev)
    lt = np.log(np.asarray(taus_s, dtype=float))
    k = 0 if tau_p is None else int(np.searchsorted(lt, math.log(4.0 * tau_p) - 1e-9))
    return _white_start(lt, np.log(np.asarray(dev, dtype=float)), k)


#: the curve falls "like white noise" between two taus when its log-log slope there is
#: within this range around -1/2
WHITE_SLOPES = (-0.6, -0.4)


def _white_start(lt, ld, k: int) -> int:
    """Where a filter-coloured start ends: the first index ``>= k`` from which the curve
    falls like white noise over two octaves in a row (both slopes in
    :data:`WHITE_SLOPES`), searched below :data:`STATIC_PEAK_MAX_S` only.

    A curve that starts falling like white noise or faster (angle quantisation) keeps
    every tau. Real MEMS logs (the ADIS16405 logs of docs/noise-terms.md §10) are
    coloured by the sensor's averaging filter and quantiser over their first octaves
    without rising at the start: slopes of -0.3, then a ripple of -0.36/-0.63 beyond the
    first peak. Fitted there, the white-noise term bent 5-7 % away from the curve's own
    sigma(tau) sqrt(tau) past the filter. A curve that never falls like white noise over
    two octaves below 1 s keeps ``k``."""
    s = np.diff(ld) / np.diff(lt)
    lo, hi = WHITE_SLOPES
    if k == 0 and s.size and s[0] <= hi:
        return 0
    for i in range(k, s.size - 1):
        if lt[i] >= math.log(STATIC_PEAK_MAX_S):
            break
        if lo <= s[i] <= hi and lo <= s[i + 1] <= hi:
            return i
    return k


def not_static_reason(taus_s, dev) -> str | None:
    """Why a rate record does not look static (its Allan deviation still rises at
    :data:`STATIC_PEAK_MAX_S` or beyond), or None."""
    tau_p = filter_peak_tau(taus_s, dev)
    if tau_p is None:
        # a curve that starts rising and never falls rises up to its longest tau
        t = np.asarray(taus_s, dtype=float)
        d = np.asarray(dev, dtype=float)
        if t.size < 3 or math.log(d[1] / d[0]) / math.log(t[1] / t[0]) <= -0.25:
            return None
        s = np.diff(np.log(d)) / np.diff(np.log(t))
        if np.any(s <= -0.25):
            return None
        tau_p = float(t[-1])
    if tau_p < STATIC_PEAK_MAX_S:
        return None
    return (f"the Allan deviation rises up to tau = {tau_p:.3g} s, where a sensor's own "
            f"filter colours only tau below ~0.1 s: the record is probably not static "
            f"(motion, vibration or a turning rig), and noise terms read from it describe "
            f"that, not the sensor")


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
