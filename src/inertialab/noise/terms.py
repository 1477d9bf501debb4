"""IMU noise terms Q, N, B, K, R from an Allan-type curve (spec 001 §3.3–3.4; issue 3).

Five-term model (spec 001 eq. 4, IEEE Std 952-1997 Annex C), sigma in the rate unit u
and tau in s::

    sigma^2(tau) = 3Q^2/tau^2 + N^2/tau + (2 ln2/pi) B^2 + K^2 tau/3 + R^2 tau^2/2
                 = sum_{k=-2..2} c_k tau^k

Methods (every term reports which one and the tau range it used):

``"wls"`` (default)
    Non-negative weighted least squares of the model on the AVAR points (scipy's NNLS on
    the column-scaled design), weights ``w_i = edf_i / (2 model_i^2)`` (inverse variance
    of an AVAR estimate), started with ``model_i = sigma_hat_i^2`` and reweighted three
    times with the fitted model, the EDF re-derived from each tau's dominant term
    (spec 001 §3.4 item 2). Uncertainty: the weighted-LS covariance propagated by the
    delta method; it treats overlapping AVAR points as independent and so understates.
``"ols"``
    The same with unit weights (the paper-compatible mode of spec 001 §3.4 item 3).
``"slope"``
    Automated IEEE 952 slope reading (spec 001 §3.4 item 1): local slopes over three
    consecutive taus, the longest run within 0.15 of each target slope (>= 3 points),
    an EDF-weighted fixed-slope line through it; B = min(sigma)/0.6643 over the run with
    ``|slope| <= 0.1``, else an upper bound (flag ``B_bound``). Missing runs give NaN
    with flag ``not_observable``.

Units (CONTRACTS.md "noise"): gyros report Q arcsec, N deg/sqrt(h), B deg/h,
K deg/h/sqrt(h), R deg/h^2; accelerometers Q m/s, N m/s/sqrt(h), B ug, K m/s^2/sqrt(h),
R m/s^3. N also carries ``density`` (continuous-time white-noise density: rad/s/sqrt(Hz)
for gyros, ug/sqrt(Hz) for accelerometers) and ``per_sample_std`` (the discrete
standard deviation of one sample at the record's rate: density * sqrt(rate); rad/s or
m/s^2), so Kalibr-style estimators get their numbers without hand conversion. All
conversions go through :mod:`inertialab.units`.

Hand-written: no maintained library fits the IEEE five-term model with EDF weights.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from scipy.optimize import nnls
from scipy.stats import norm

from inertialab import units
from inertialab.errors import InputError

#: ``sqrt(2 ln2 / pi)``: the Allan floor of bias instability B.
BI_FACTOR = math.sqrt(2.0 * math.log(2.0) / math.pi)  # 0.66428

_POWERS = (-2, -1, 0, 1, 2)
_NAMES = ("Q", "N", "B", "K", "R")
#: alpha (rate PSD exponent) of each model term, for the EDF of its tau
_TERM_ALPHA = {-2: 2, -1: 0, 0: -1, 1: -2, 2: -2}

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


@dataclass(frozen=True)
class NoiseTerm:
    """One noise coefficient in its report unit.

    Attributes
    ----------
    value : float
        Estimate (NaN when not observable).
    unit : str
    ci : tuple (low, high)
        Interval at the result's confidence (delta method for "wls"/"ols", EDF-based for
        "slope").
    method : str
        ``"wls" | "ols" | "slope"``.
    tau_range_s : tuple (low, high)
        Taus the estimate used.
    flags : tuple of str
        ``"not_observable"``, ``"B_bound"``, ``"zero"`` (NNLS put the term at 0).
    sd : float
        1-sigma uncertainty in ``unit`` (NaN where not defined).
    density, per_sample_std : dict or None
        N only: ``{"value", "unit"}``.
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

    def to_dict(self) -> dict:
        d = {"value": float(self.value), "unit": self.unit,
             "ci": [float(self.ci[0]), float(self.ci[1])], "method": self.method,
             "tau_range_s": [float(self.tau_range_s[0]), float(self.tau_range_s[1])],
             "sd": float(self.sd), "flags": list(self.flags)}
        if self.density is not None:
            d["density"] = dict(self.density)
        if self.per_sample_std is not None:
            d["per_sample_std"] = dict(self.per_sample_std)
        return d

    @classmethod
    def from_dict(cls, d: dict) -> NoiseTerm:
        return cls(value=float(d["value"]) if d["value"] is not None else float("nan"),
                   unit=d["unit"], ci=tuple(_nan(v) for v in d["ci"]), method=d["method"],
                   tau_range_s=tuple(float(v) for v in d["tau_range_s"]),
                   flags=tuple(d.get("flags", ())), sd=_nan(d.get("sd")),
                   density=d.get("density"), per_sample_std=d.get("per_sample_std"))


def _nan(v):
    return float("nan") if v is None else float(v)


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
        ``c_-2 .. c_2`` of eq. 4 in (data unit)^2 s^k (NaN for "slope" where not read).
    tau_range_s : tuple
    fit_rmse_log : float
        RMSE of ``ln sigma_hat - ln sigma_model`` over the fitted taus ("wls"/"ols").
    rate_hz : float or None
    confidence : float
    statistic : str
    g_local : float
        Local gravity used for g-based accelerometer units (m/s^2).
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
    confidence: float = 0.683
    statistic: str = "oadev"
    g_local: float = units.G_STANDARD
    alpha_model: tuple = field(default_factory=tuple)

    def terms(self) -> dict[str, NoiseTerm]:
        return {k: getattr(self, k) for k in _NAMES}

    def model_dev(self, taus_s) -> np.ndarray:
        """Five-term model deviation at ``taus_s`` (s) in the data unit."""
        t = np.asarray(taus_s, dtype=float)
        c = np.nan_to_num(np.asarray(self.coefficients, dtype=float))
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
                   alpha_model=tuple(int(a) for a in d.get("alpha_model", ())))


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


# ----------------------------------------------------------------------------- fitting


def _amplitudes(c: np.ndarray) -> np.ndarray:
    """sqrt-form amplitude of each term from c_k (same unit as sigma·s^(k/2))."""
    c = np.asarray(c, dtype=float)
    g = np.array([1 / math.sqrt(3), 1.0, 1 / BI_FACTOR, math.sqrt(3), math.sqrt(2)])
    return g * np.sqrt(np.maximum(c, 0.0))


def _edf_for(result, alphas, sel):
    from inertialab.noise.edf import edf as _edf

    n_phase = result.n_samples + 1 if result.input == "rate" else result.n_samples
    if n_phase <= 1:
        return np.asarray(result.edf, dtype=float)[sel]
    e, _ = _edf(result.statistic, n_phase, np.asarray(result.m)[sel], alphas,
                n_terms=np.asarray(result.n_terms)[sel])
    return e


def _select(result, tau_range):
    taus = np.asarray(result.taus_s, dtype=float)
    dev = np.asarray(result.dev, dtype=float)
    ok = np.isfinite(dev) & (dev > 0)
    if tau_range is None:
        T = result.n_samples * result.tau0_s if result.n_samples else taus.max() * 8
        lo, hi = result.tau0_s * (1 - 1e-9), T / 8 * (1 + 1e-9)
    else:
        lo, hi = float(tau_range[0]), float(tau_range[1])
    sel = ok & (taus >= lo) & (taus <= hi)
    if sel.sum() < 3:
        raise InputError(f"need at least 3 taus with a positive deviation in "
                         f"[{lo:g}, {hi:g}] s to fit noise terms, got {int(sel.sum())}")
    return sel


def fit_noise_terms(result, *, unit: str, kind: str | None = "gyro", method: str = "wls",
                    rate_hz: float | None = None, tau_range_s=None,
                    g_local: float = units.G_STANDARD, n_reweight: int = 3) -> NoiseTerms:
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
    method : {"wls", "ols", "slope"}, default "wls"
    rate_hz : float, optional
        Sample rate for N's per-sample std (default ``1/result.tau0_s``).
    tau_range_s : (low, high), optional
        Default ``[tau0, T/8]`` (spec 001 §3.4).
    g_local : float, default 9.80665
        Local gravity for g-based units (m/s^2).
    n_reweight : int, default 3
        WLS reweighting passes (spec 001 §3.4).

    Raises
    ------
    InputError
        Unknown unit or method, unit of the wrong dimension, fewer than 3 usable taus.
    """
    conv = _Converter(unit, kind, g_local)
    if method not in ("wls", "ols", "slope"):
        raise InputError(f"unknown noise-term method '{method}' (use wls, ols, slope)")
    if rate_hz is None:
        rate_hz = 1.0 / float(result.tau0_s)
    sel = _select(result, tau_range_s)
    if method == "slope":
        return _fit_slope(result, sel, conv, rate_hz)
    return _fit_ls(result, sel, conv, rate_hz, method, n_reweight)


def _fit_ls(result, sel, conv, rate_hz, method, n_reweight):
    taus = np.asarray(result.taus_s, dtype=float)[sel]
    avar = np.asarray(result.dev, dtype=float)[sel] ** 2
    X = np.stack([taus**k for k in _POWERS], axis=1)
    conf = float(result.confidence)
    model = avar.copy()
    alphas = np.zeros(taus.size, dtype=np.int64)
    edf = np.asarray(result.edf, dtype=float)[sel]
    edf = np.where(np.isfinite(edf) & (edf > 0), edf, 1.0)
    c = np.zeros(5)
    passes = 1 + (n_reweight if method == "wls" else 0)
    for _ in range(passes):
        w = edf / (2.0 * model**2) if method == "wls" else np.ones_like(avar)
        sw = np.sqrt(w)
        A = X * sw[:, None]
        scale = np.linalg.norm(A, axis=0)
        scale[scale == 0] = 1.0
        cs, _ = nnls(A / scale, avar * sw)
        c = cs / scale
        model = X @ c
        model = np.where(model > 0, model, avar)
        if method == "wls":
            contrib = X * c[None, :]
            dom = np.argmax(contrib, axis=1)
            alphas = np.array([_TERM_ALPHA[_POWERS[j]] for j in dom], dtype=np.int64)
            e2 = _edf_for(result, alphas, sel)
            edf = np.where(np.isfinite(e2) & (e2 > 0), e2, edf)
    # covariance of c (weighted LS, independent points); unit weights -> residual scale
    w = edf / (2.0 * model**2) if method == "wls" else np.ones_like(avar)
    A = X * np.sqrt(w)[:, None]
    scale = np.linalg.norm(A, axis=0)
    scale[scale == 0] = 1.0
    cov_s = np.linalg.pinv((A / scale).T @ (A / scale))
    cov = cov_s / np.outer(scale, scale)
    if method == "ols":
        resid = avar - X @ c
        dof = max(taus.size - int(np.sum(c > 0)), 1)
        cov = cov * float(resid @ resid) / dof
    sd_c = np.sqrt(np.maximum(np.diag(cov), 0.0))
    fit_rmse = float(np.sqrt(np.mean((0.5 * np.log(avar / model)) ** 2)))
    z = float(norm.ppf(0.5 * (1 + conf)))
    amps = _amplitudes(c)
    g = np.array([1 / math.sqrt(3), 1.0, 1 / BI_FACTOR, math.sqrt(3), math.sqrt(2)])
    f2 = conv.f**2
    rng_s = (float(taus.min()), float(taus.max()))
    terms = {}
    for j, name in enumerate(_NAMES):
        amp = amps[j] * conv.f
        lo_c, hi_c = max(c[j] - z * sd_c[j], 0.0), c[j] + z * sd_c[j]
        lo = g[j] * math.sqrt(lo_c * f2)
        hi = g[j] * math.sqrt(hi_c * f2)
        sd = (g[j] * conv.f * sd_c[j] / (2 * math.sqrt(c[j])) if c[j] > 0 else float("nan"))
        flags = ("zero",) if c[j] == 0 else ()
        val = conv.value(name, amp)
        k = conv.value(name, 1.0)  # linear factor of the conversion
        dens = per = None
        if name == "N":
            dens, per = conv.n_extras(amp, rate_hz)
        terms[name] = NoiseTerm(value=val, unit=_REPORT[conv.kind][name],
                                ci=(k * lo, k * hi), method=method, tau_range_s=rng_s,
                                flags=flags, sd=k * sd, density=dens, per_sample_std=per)
    return NoiseTerms(**terms, kind=conv.kind, unit=conv.unit, method=method,
                      coefficients=tuple(float(v) for v in c), tau_range_s=rng_s,
                      fit_rmse_log=fit_rmse, rate_hz=float(rate_hz), confidence=conf,
                      statistic=result.statistic, g_local=conv.g,
                      alpha_model=tuple(int(a) for a in alphas))


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


def _longest_run(mask: np.ndarray):
    best, cur, start = (0, 0), 0, 0
    for i, v in enumerate(mask):
        if v:
            if cur == 0:
                start = i
            cur += 1
            if cur > best[1] - best[0]:
                best = (start, i + 1)
        else:
            cur = 0
    return best


def _fit_slope(result, sel, conv, rate_hz):
    taus = np.asarray(result.taus_s, float)[sel]
    dev = np.asarray(result.dev, float)[sel]
    edf = np.asarray(result.edf, float)[sel]
    edf = np.where(np.isfinite(edf) & (edf > 0), edf, 1.0)
    lo_ci = np.asarray(result.ci_low, float)[sel]
    hi_ci = np.asarray(result.ci_high, float)[sel]
    conf = float(result.confidence)
    z = float(norm.ppf(0.5 * (1 + conf)))
    s = local_slopes(taus, dev)
    targets = {"Q": (-1.0, math.sqrt(3)), "N": (-0.5, 1.0), "K": (0.5, 1 / math.sqrt(3)),
               "R": (1.0, 1 / math.sqrt(2))}
    terms = {}
    coeffs = [float("nan")] * 5
    for name, (slope, gain) in targets.items():
        a, b = _longest_run(np.abs(s - slope) <= 0.15)
        if b - a < 3:
            terms[name] = NoiseTerm(value=float("nan"), unit=_REPORT[conv.kind][name],
                                    ci=(float("nan"), float("nan")), method="slope",
                                    tau_range_s=(float("nan"), float("nan")),
                                    flags=("not_observable",))
            continue
        lt, ld, w = np.log(taus[a:b]), np.log(dev[a:b]), edf[a:b]
        lnc = float(np.sum(w * (ld - slope * lt)) / np.sum(w))
        sd_ln = math.sqrt(1.0 / np.sum(2.0 * w))
        C = math.exp(lnc)
        amp = C / gain  # sigma = gain * amp * tau^slope
        j = _NAMES.index(name)
        coeffs[j] = float(C**2)  # sigma = C tau^slope -> c_k = C^2, k = 2 slope
        k = conv.value(name, 1.0)
        val = k * amp * conv.f
        ci = (val * math.exp(-z * sd_ln), val * math.exp(z * sd_ln))
        dens = per = None
        if name == "N":
            dens, per = conv.n_extras(amp * conv.f, rate_hz)
        terms[name] = NoiseTerm(value=val, unit=_REPORT[conv.kind][name], ci=ci, method="slope",
                                tau_range_s=(float(taus[a]), float(taus[b - 1])),
                                sd=val * sd_ln, density=dens, per_sample_std=per)
    # B from the flat run
    a, b = _longest_run(np.abs(s) <= 0.1)
    kB = conv.value("B", 1.0)
    if b - a >= 1:
        i = a + int(np.argmin(dev[a:b]))
        flags = ()
        rng_s = (float(taus[a]), float(taus[b - 1]))
    else:
        i = int(np.argmin(dev))
        flags = ("B_bound",)
        rng_s = (float(taus.min()), float(taus.max()))
    val = kB * dev[i] * conv.f / BI_FACTOR
    ci = (kB * lo_ci[i] * conv.f / BI_FACTOR, kB * hi_ci[i] * conv.f / BI_FACTOR)
    coeffs[2] = float(dev[i] ** 2)
    terms["B"] = NoiseTerm(value=val, unit=_REPORT[conv.kind]["B"], ci=ci, method="slope",
                           tau_range_s=rng_s, flags=flags,
                           sd=val / math.sqrt(2 * edf[i]))
    rng_all = (float(taus.min()), float(taus.max()))
    return NoiseTerms(**terms, kind=conv.kind, unit=conv.unit, method="slope",
                      coefficients=tuple(coeffs), tau_range_s=rng_all,
                      rate_hz=float(rate_hz), confidence=conf, statistic=result.statistic,
                      g_local=conv.g)


__all__ = ["BI_FACTOR", "NoiseTerm", "NoiseTerms", "fit_noise_terms", "local_slopes"]
