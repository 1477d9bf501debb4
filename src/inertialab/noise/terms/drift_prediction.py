"""The drift a fitted noise model predicts, and the same drift observed in a record.

What a dead-reckoning or zero-velocity filter accumulates: at rest, the bias is taken as
the mean of the rate over the preceding ``W`` seconds (the bias window), and the rate
minus that bias is integrated over the next ``t`` seconds (the horizon)::

    e(t) = int_0^t (y(s) - b_W) ds,   b_W = (1/W) int_{-W}^0 y(s) ds

(angle for a gyro, velocity for an accelerometer). ``e`` is a linear functional of the
rate with weight ``h = 1`` on ``[0, t]`` and ``-t/W`` on ``[-W, 0]``, so for each
stationary noise term of one-sided PSD ``G(f)`` (the convention in which the Allan
variance is ``2 int G(f) sin^4(pi f tau)/(pi f tau)^2 df``)::

    Var e(t) = int_0^inf G(f) |H(f)|^2 df,
    H(f) = [(1 - e^{-i 2 pi f t}) - (t/W)(e^{i 2 pi f W} - 1)] / (i 2 pi f)

``|H|^2`` vanishes like ``f^2`` at 0, so the random walk's ``1/f^2`` and flicker's
``1/f`` are integrable. The terms (rate unit ``u``; the model's coefficients as in
:mod:`inertialab.noise.terms.fit`):

=============  ===============================================  ===========================
term           G(f)                                             Var e(t)
=============  ===============================================  ===========================
white N        ``2 N^2``                                        ``N^2 (t + t^2/W)`` exact
random walk K  ``K^2 / (2 pi^2 f^2)``                           integral
band B         ``q (2/(pi f)) [atan(2pi f t_hi) - atan(2pi f t_lo)]``, ``q = c_0/peak``
                                                                integral (log-uniform
                                                                Gauss-Markov mixture)
Gauss-Markov   ``4 s2 T / (1 + (2 pi f T)^2)``                  integral
quantisation Q angle white noise                                ``Q^2 (1 + (1+r)^2 + r^2)``,
                                                                ``r = t/W``
ramp R         deterministic                                    ``(R t (t + W)/2)^2``
line A, f0     sinusoid of random phase                         ``A^2 |H(f0)|^2 / 2``
=============  ===============================================  ===========================

The integral runs on a log grid that resolves ``|H|^2``'s oscillation (period ``1/t``
and ``1/W`` in f) up to 40 oscillations, and beyond on the phase average
``<|H|^2> = ((1+r)^2 + 1 + r^2)/(2 pi f)^2``, up to the Nyquist frequency. ``e`` is
Gaussian for the noise terms, so its 95 % band is ``1.96 RMS`` (the ramp, whose sign the
model does not know, counted in the RMS).

:func:`observed_error` integrates a record the same way over non-overlapping windows
(``W`` then ``t``, back to back). :func:`check_prediction` compares both and gives, per
term, the inflation of its amplitude that would make prediction and observation agree.
:func:`kalibr_reading` gives the two values a Kalibr / imu_utils user reads off the
Allan curve (sigma at tau = 1 s as the white density, the +1/2 line at tau = 3 s as the
random walk), for the same prediction.

Hand-written: no maintained library predicts the integrated error of an Allan-fitted
noise model with a bias window. Tested against the closed form (white noise) and a
Monte Carlo of each process (tests/noise/test_drift_prediction.py).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from inertialab.errors import InputError

#: the 95 % band of a Gaussian error, in RMS
Z95 = 1.959963984540054
#: oscillations of |H|^2 resolved by the fine grid before its phase average takes over
N_OSC = 40
#: points per decade of the fine log grid
PER_DECADE = 1200


@dataclass(frozen=True)
class Component:
    """One term of a noise model, in the rate unit ``u`` of its record.

    ``kind``: ``white`` (``a`` = N^2, u^2 s), ``rw`` (``a`` = K^2, u^2/s), ``band``
    (``a`` = q, u^2 per unit ln T; ``b``, ``c`` = t_lo, t_hi in s, 0/inf allowed), ``gm``
    (``a`` = variance u^2, ``b`` = T s), ``quant`` (``a`` = Q^2, (u s)^2), ``ramp``
    (``a`` = R, u/s), ``line`` (``a`` = amplitude u, ``b`` = f0 Hz). ``term``: the IEEE
    name it belongs to (N K B Q R or S for a line)."""

    kind: str
    term: str
    a: float
    b: float = 0.0
    c: float = 0.0


def components_of(terms) -> list[Component]:
    """The noise model of a :class:`~inertialab.noise.terms.fit.NoiseTerms` as components:
    a GMWM fit's latent processes, else the five coefficients with the B band."""
    from inertialab.noise.terms.band import _band_peak

    out: list[Component] = []
    gm = (terms.gmwm or {}).get("processes")
    tau0 = ((terms.gmwm or {}).get("wv") or {}).get("tau0_s")
    if gm and tau0:
        for d in gm:
            p, k = d["params"], d["process"]
            if k == "WN":
                out.append(Component("white", "N", p["sigma2"] * tau0))
            elif k == "RW":
                out.append(Component("rw", "K", p["gamma2"] / tau0))
            elif k == "QN":
                out.append(Component("quant", "Q", p["q2"]))
            elif k == "DR":
                out.append(Component("ramp", "R", p["omega"] / tau0))
            elif k == "GM":
                out.append(Component("gm", "B", p["s2"], p["tc_s"]))
            elif k == "BL":
                q = p["c0"] / _band_peak(p["t_lo_s"], p["t_hi_s"])
                out.append(Component("band", "B", q, p["t_lo_s"], p["t_hi_s"]))
    else:
        c = [0.0 if not np.isfinite(v) else float(v) for v in terms.coefficients]
        if c[0] > 0:
            out.append(Component("quant", "Q", c[0] / 3.0))
        if c[1] > 0:
            out.append(Component("white", "N", c[1]))
        if c[2] > 0:
            bg = terms.bias_gm or {}
            lo = bg.get("t_lo_s") or 0.0
            hi = bg.get("t_hi_s") or math.inf
            out.append(Component("band", "B", c[2] / _band_peak(lo, hi), lo, hi))
        if c[3] > 0 and terms.k_gm:
            t_k = float(terms.k_gm["t_s"])
            out.append(Component("gm", "K", 1.5 * c[3] * t_k, t_k))
        elif c[3] > 0:
            out.append(Component("rw", "K", 3.0 * c[3]))
        if c[4] > 0:
            out.append(Component("ramp", "R", math.sqrt(2.0 * c[4])))
    for ln in getattr(terms, "lines", ()) or ():
        out.append(Component("line", "S", ln.amplitude, ln.f_hz))
    return out


def _h2(f, t: float, w: float) -> np.ndarray:
    """|H(f)|^2 of the bias-window integral (module docstring)."""
    r = t / w
    a, b = 2 * np.pi * f * t, 2 * np.pi * f * w
    re = (1 + r) - np.cos(a) - r * np.cos(b)
    im = np.sin(a) - r * np.sin(b)
    return (re * re + im * im) / (2 * np.pi * f) ** 2


def _psd(comp: Component, f) -> np.ndarray:
    if comp.kind == "rw":
        return comp.a / (2 * np.pi**2 * f * f)
    if comp.kind == "gm":
        T = comp.b
        return 4 * comp.a * T / (1 + (2 * np.pi * f * T) ** 2)
    if comp.kind == "band":
        hi = np.arctan(2 * np.pi * f * comp.c) if math.isfinite(comp.c) else np.pi / 2
        lo = np.arctan(2 * np.pi * f * comp.b) if comp.b > 0 else 0.0
        return comp.a * 2.0 / (np.pi * f) * (hi - lo)
    raise ValueError(comp.kind)


def _integral(comp: Component, t: float, w: float, f_max: float) -> float:
    """``int_0^f_max G |H|^2 df`` on the fine grid, then on the phase average."""
    f_lo = 1e-5 / (t + w)
    if comp.kind == "gm":
        f_lo = min(f_lo, 1e-3 / (2 * np.pi * comp.b))
    f_c = min(N_OSC / min(t, w), f_max)
    n = max(int(PER_DECADE * math.log10(f_c / f_lo)), 64)
    lf = np.linspace(math.log(f_lo), math.log(f_c), n)
    f = np.exp(lf)
    y = _psd(comp, f) * _h2(f, t, w) * f
    total = float(np.sum(0.5 * (y[1:] + y[:-1]) * np.diff(lf)))
    # below f_lo: |H|^2 ~ (pi f t (t+W))^2, G at most 1/f^2: a term ~ f_lo, left out
    if f_max > f_c:
        r = t / w
        lf2 = np.linspace(math.log(f_c), math.log(f_max), 400)
        f2 = np.exp(lf2)
        y2 = _psd(comp, f2) * ((1 + r) ** 2 + 1 + r * r) / (2 * np.pi * f2) ** 2 * f2
        total += float(np.sum(0.5 * (y2[1:] + y2[:-1]) * np.diff(lf2)))
    return total


def component_variance(comp: Component, t: float, w: float, rate_hz: float) -> float:
    """Variance of the integrated error ``e(t)`` from one component, (u s)^2."""
    r = t / w
    if comp.kind == "white":
        return comp.a * (t + t * t / w)
    if comp.kind == "quant":
        return comp.a * (1 + (1 + r) ** 2 + r * r)
    if comp.kind == "ramp":
        return (comp.a * t * (t + w) / 2.0) ** 2
    if comp.kind == "line":
        return 0.5 * comp.a**2 * float(_h2(np.asarray(comp.b), t, w))
    return _integral(comp, t, w, 0.5 * rate_hz)


@dataclass(frozen=True)
class DriftPrediction:
    """Predicted integrated error per horizon: ``rms`` and ``band_95`` (u s), and
    ``by_term`` (IEEE name -> variance per horizon, (u s)^2)."""

    horizons_s: tuple
    bias_window_s: float
    rms: np.ndarray
    band_95: np.ndarray
    by_term: dict
    components: tuple = ()

    def to_dict(self, scale: float = 1.0, unit: str = "") -> dict:
        return {"horizons_s": [float(v) for v in self.horizons_s],
                "bias_window_s": float(self.bias_window_s),
                "predicted_rms": [float(v) * scale for v in self.rms],
                "band_95": [float(v) * scale for v in self.band_95], "unit": unit,
                "rms_by_term": {k: [float(math.sqrt(max(x, 0.0))) * scale for x in v]
                                for k, v in self.by_term.items()}}


def _check_args(horizons_s, bias_window_s: float):
    h = np.atleast_1d(np.asarray(horizons_s, dtype=float))
    if h.size == 0 or not np.all(np.isfinite(h)) or np.any(h <= 0):
        raise InputError(f"argument 'horizons_s' must be positive seconds, got {list(h)}")
    if not (math.isfinite(bias_window_s) and bias_window_s > 0):
        raise InputError(f"argument 'bias_window_s' must be positive seconds, got "
                         f"{bias_window_s}")
    return h


def predict(components, horizons_s, bias_window_s: float, rate_hz: float) -> DriftPrediction:
    """Integrated error the components predict at each horizon (module docstring)."""
    h = _check_args(horizons_s, bias_window_s)
    by: dict[str, list] = {}
    for comp in components:
        v = [component_variance(comp, float(t), float(bias_window_s), rate_hz) for t in h]
        acc = by.setdefault(comp.term, [0.0] * h.size)
        by[comp.term] = [a + b for a, b in zip(acc, v)]
    var = np.sum([np.asarray(v) for v in by.values()], axis=0) if by else np.zeros(h.size)
    rms = np.sqrt(var)
    return DriftPrediction(tuple(float(t) for t in h), float(bias_window_s), rms, Z95 * rms,
                           {k: np.asarray(v) for k, v in by.items()}, tuple(components))


def predict_terms(terms, horizons_s, bias_window_s: float = 10.0,
                  rate_hz: float | None = None) -> DriftPrediction:
    """:func:`predict` for a fitted :class:`~inertialab.noise.terms.fit.NoiseTerms`."""
    fs = float(rate_hz or terms.rate_hz)
    return predict(components_of(terms), horizons_s, bias_window_s, fs)


def observed_error(y, rate_hz: float, horizon_s: float, bias_window_s: float) -> np.ndarray:
    """Integrated errors ``e(t)`` (u s) of a rate record over non-overlapping windows:
    each window takes the mean of ``W`` seconds as the bias and integrates the next ``t``
    seconds minus that bias; windows follow back to back. Windows holding a NaN are
    skipped. Empty when the record is shorter than one window."""
    y = np.asarray(y, dtype=float)
    nw = max(int(round(bias_window_s * rate_hz)), 1)
    nt = max(int(round(horizon_s * rate_hz)), 1)
    n_win = y.size // (nw + nt)
    if n_win == 0:
        return np.empty(0)
    blocks = y[: n_win * (nw + nt)].reshape(n_win, nw + nt)
    bias = blocks[:, :nw].mean(axis=1)
    e = (blocks[:, nw:].sum(axis=1) - nt * bias) / rate_hz
    return e[np.isfinite(e)]


def effective_windows(e) -> float:
    """Independent windows the mean square of the window errors ``e`` is worth: ``n``
    times the variance of the mean of ``e^2`` were the windows independent over its
    variance from ``sqrt(n)`` batch means of ``sqrt(n)`` windows each (back-to-back
    windows share slow noise: a Gauss-Markov process or a random walk correlates them);
    at most ``n``."""
    x = np.asarray(e, dtype=float) ** 2
    n = x.size
    b = int(math.isqrt(n))
    k = n // max(b, 1)
    if b < 4 or k < 2:
        return float(n)
    v_ind = float(np.var(x, ddof=1)) / n
    bm = x[: k * b].reshape(b, k).mean(axis=1)
    v_b = float(np.var(bm, ddof=1)) / b
    if not (v_ind > 0 and v_b > 0):
        return float(n)
    return float(n) / max(v_b / v_ind, 1.0)


def _gm_cross(tc, t: float, w: float, lags) -> np.ndarray:
    """``Cov(e_0, e_k)`` (per unit variance) of a Gauss-Markov rate of correlation time
    ``tc`` (s, array) between windows ``k >= 1`` apart (``lags``), windows of ``w + t`` s
    back to back: the windows do not overlap, so the covariance ``exp(-|s|/tc)`` factors,
    ``exp(-(k-1)(t+w)/tc) A B`` with ``A = int h(s) e^{(s-t)/tc} ds`` and
    ``B = int h(s) e^{-(s+w)/tc} ds`` (``h`` of the module docstring). Shape
    ``(len(tc), len(lags))``."""
    tc = np.asarray(tc, dtype=float)[:, None]
    k = np.asarray(lags, dtype=float)[None, :]
    r = t / w
    et = np.exp(-t / tc)
    a = -tc * np.expm1(-t / tc) + r * tc * et * np.expm1(-w / tc)
    b = tc * np.exp(-w / tc) * (-np.expm1(-t / tc)) + r * tc * np.expm1(-w / tc)
    return np.exp(-(k - 1.0) * (t + w) / tc) * a * b


def _band_cross(comp: Component, t: float, w: float, lags) -> np.ndarray:
    """:func:`_gm_cross` of the band: a log-uniform mixture of Gauss-Markov processes of
    variance ``q`` per unit ``ln T`` between its corners (an open corner cut where the
    integrand has vanished: 1e-4 min(t, w) below, 1e3 windows' span above)."""
    span = (t + w) * max(float(np.max(lags)), 1.0)
    lo = comp.b if comp.b > 0 else 1e-4 * min(t, w)
    hi = comp.c if math.isfinite(comp.c) else 1e3 * span
    if not hi > lo:
        return np.zeros(len(lags))
    lt = np.linspace(math.log(lo), math.log(hi), max(int(60 * math.log10(hi / lo)), 32))
    y = _gm_cross(np.exp(lt), t, w, lags)
    return comp.a * np.sum(0.5 * (y[1:] + y[:-1]) * np.diff(lt)[:, None], axis=0)


def window_covariances(components, t: float, w: float, n_lags: int) -> np.ndarray:
    """``Cov(e_0, e_k)``, ``k = 1 .. n_lags`` ((u s)^2), of the back-to-back windows of
    :func:`observed_error` under the components: white noise and the random walk give
    none (disjoint windows see disjoint increments, ``int h = 0``); a Gauss-Markov
    process and the band decay with the lag (:func:`_gm_cross`); quantisation shares the
    angle sample at each window's joint (``r Q^2`` at lag 1). The ramp and the lines are
    not Gaussian (a fixed slope, a fixed amplitude): :func:`model_effective_windows`
    handles them apart."""
    lags = np.arange(1, max(int(n_lags), 0) + 1, dtype=float)
    out = np.zeros(lags.size)
    if lags.size == 0:
        return out
    for comp in components:
        if comp.kind == "gm":
            out += comp.a * _gm_cross([comp.b], t, w, lags)[0]
        elif comp.kind == "band":
            out += _band_cross(comp, t, w, lags)
        elif comp.kind == "quant":
            out[0] += comp.a * t / w
    return out


def _fixed_parts(pred: DriftPrediction, t: float, n: int, ck, c0: float) -> float:
    """The part of ``Var(mean e^2)`` the ramp and the lines at horizon ``t`` over
    ``n`` windows about Gaussian errors of covariances ``c0, ck``: a part ``s_i`` fixed by
    the log (the ramp's slope; a line's amplitude, its phase ``phi + i theta``,
    ``theta = 2 pi f0 (t + W)``) adds ``4 (1/n^2) sum_ij <s_i s_j> c_|i-j|`` and, a
    line, the phase's ``Var(mean s_i^2) = (m^2/2) |mean_i exp(2 i i theta)|^2``."""
    w = pred.bias_window_s
    k = np.arange(1, n)
    wk = 2.0 * (n - k)
    var = 0.0
    for comp in pred.components:
        if comp.kind not in ("ramp", "line"):
            continue
        m2 = component_variance(comp, t, w, 1.0)
        cos_k = np.ones(k.size)
        if comp.kind == "line":
            theta = 2.0 * np.pi * comp.b * (t + w)
            cos_k = np.cos(theta * k)
            var += 0.5 * m2 * m2 * abs(np.mean(np.exp(2j * theta * np.arange(n)))) ** 2
        var += 4.0 * m2 * (n * c0 + float(np.sum(wk * ck * cos_k))) / n**2
    return var


def model_effective_windows(pred: DriftPrediction, n_windows) -> np.ndarray:
    """Per horizon, the independent windows the mean square of ``n_windows`` back-to-back
    window errors is worth under the predicted model: ``2 V^2 / Var(mean e^2)``, with
    ``(2/n^2) sum_ij c_|i-j|^2`` from the Gaussian terms (covariances ``c_k``,
    :func:`window_covariances`) and the parts the ramp and the lines add
    (:func:`_fixed_parts`). It is the sampling the check's RMS has where the model is
    right; unlike :func:`effective_windows` it is not itself a noisy estimate from the
    few windows of a long horizon (34 at 300 s in 3 h), and it leaves the data's
    non-stationarity to the interval's own part. ``n`` for white noise and random walks;
    more where a ramp or a line, the same in every window, makes part of ``V`` fixed."""
    nw = np.asarray(n_windows, dtype=float)
    out = np.zeros(len(pred.horizons_s))
    for i, t in enumerate(pred.horizons_s):
        n = int(nw[i])
        v = float(pred.rms[i]) ** 2
        if n < 1 or not v > 0:
            out[i] = float(n)
            continue
        gauss = [c for c in pred.components if c.kind not in ("ramp", "line")]
        ck = window_covariances(gauss, float(t), pred.bias_window_s, n - 1)
        c0 = v - sum(component_variance(c, float(t), pred.bias_window_s, 1.0)
                     for c in pred.components if c.kind in ("ramp", "line"))
        var_fixed = _fixed_parts(pred, float(t), n, ck, c0)
        var_sq = 2.0 * (n * c0 * c0 + float(np.sum(2.0 * (n - np.arange(1, n)) * ck * ck)))
        var_sq = var_sq / n**2 + var_fixed
        out[i] = 2.0 * v * v / var_sq if var_sq > 0 else float(n)
    return out


def check_prediction(pred: DriftPrediction, y, rate_hz: float) -> dict:
    """Prediction against the record ``y`` (the other half, or another log): per horizon
    the observed RMS (u s), the number of windows, observed/predicted, the coverage of
    the 95 % band, the effective number of independent windows measured on the windows
    (:func:`effective_windows`, ``n_effective``) and under the predicted model
    (:func:`model_effective_windows`, ``n_effective_model``: the one the RMS interval's
    sampling uses), and per term the inflation of its amplitude that would make the
    predicted RMS equal the observed one (NaN where that term alone cannot)."""
    obs, n_win, cover, n_eff = [], [], [], []
    infl: dict[str, list] = {k: [] for k in pred.by_term}
    for i, t in enumerate(pred.horizons_s):
        e = observed_error(y, rate_hz, t, pred.bias_window_s)
        o = float(np.sqrt(np.mean(e * e))) if e.size else float("nan")
        obs.append(o)
        n_win.append(int(e.size))
        n_eff.append(effective_windows(e))
        cover.append(float(np.mean(np.abs(e) <= pred.band_95[i])) if e.size else float("nan"))
        tot = float(pred.rms[i]) ** 2
        for k, v in pred.by_term.items():
            vk = float(v[i])
            need = o * o - (tot - vk)
            infl[k].append(math.sqrt(need / vk) if vk > 0 and need > 0 else float("nan"))
    obs_a = np.asarray(obs)
    return {"observed_rms": obs_a, "n_windows": n_win, "n_effective": n_eff,
            "n_effective_model": model_effective_windows(pred, n_win).tolist(),
            "ratio": obs_a / np.asarray(pred.rms), "coverage_95": cover, "inflation": infl}


def kalibr_reading(result) -> tuple[float, float]:
    """``(N, K)`` as a Kalibr / imu_utils user reads them off an Allan deviation of rate
    data (u sqrt(s) and u/sqrt(s)): N = sigma(1 s) (log-log interpolation), K = the
    height at tau = 3 s of the +1/2-slope line laid on the rising part of the curve past
    its minimum (least squares in log over the points whose slope from the previous one
    exceeds +1/4; with no such point, the line through the last point)."""
    taus = np.asarray(result.taus_s, dtype=float)
    dev = np.asarray(result.dev, dtype=float)
    ok = np.isfinite(dev) & (dev > 0)
    taus, dev = taus[ok], dev[ok]
    if taus.size < 2:
        raise InputError("the Allan curve has fewer than 2 usable taus")
    lt, ld = np.log(taus), np.log(dev)
    n = float(np.exp(np.interp(0.0, lt, ld)))
    i_min = int(np.argmin(dev))
    slope = np.diff(ld) / np.diff(lt)
    rising = [i + 1 for i in range(i_min, slope.size) if slope[i] > 0.25]
    pts = np.asarray(rising if rising else [taus.size - 1])
    k = float(np.exp(np.mean(ld[pts] - 0.5 * (lt[pts] - math.log(3.0)))))
    return n, k


def kalibr_components(result) -> list[Component]:
    """The white noise and random walk of :func:`kalibr_reading` as components."""
    n, k = kalibr_reading(result)
    return [Component("white", "N", n * n), Component("rw", "K", k * k)]


#: the IEEE terms whose intervals carry a prediction's parameter uncertainty
_TERM_NAMES = ("Q", "N", "B", "K", "R")


def _term_spread(term, z: float):
    """``(sd of ln amplitude, upper/value)`` of a fitted term: a significant term's
    interval read as lognormal (``ln(hi/lo) / 2z``), an upper bound as ``(0, ub/value)``
    (its part of the drift anywhere between none and the bound's)."""
    lo, hi = (float(v) for v in term.ci)
    val = float(term.value)
    if "upper_bound" in term.flags or "not_observable" in term.flags:
        ub = float(term.upper_bound) if math.isfinite(term.upper_bound) else hi
        return 0.0, (ub / val if val > 0 and math.isfinite(ub) else 1.0)
    if val > 0 and lo > 0 and math.isfinite(hi) and hi >= lo:
        return math.log(hi / lo) / (2.0 * z), None
    return 0.0, None


def misfit_log_var(result, terms, horizons_s, *, span: float = 2.0) -> np.ndarray:
    """Per horizon ``t``, the mean squared log misfit ``(ln AVAR_data - ln AVAR_model)^2``
    beyond the curve's own sampling (less ``psi'(edf/2)``, at least 0) of the fitted model
    over the curve's taus in ``[t/span, t span]`` (the nearest tau where none is inside): where the model's shape departs from the curve near a
    horizon (a band-limited flicker for several Gauss-Markov processes, say), the drift
    it predicts there departs alike, by more than the terms' intervals say. ``result``:
    the Allan deviation the terms were fitted on."""
    taus = np.asarray(result.taus_s, dtype=float)
    dev = np.asarray(result.dev, dtype=float)
    model = np.asarray(terms.model_dev(taus), dtype=float)
    ok = np.isfinite(dev) & (dev > 0) & np.isfinite(model) & (model > 0)
    if not ok.any():
        return np.zeros(len(np.atleast_1d(horizons_s)))
    lo, hi = terms.tau_range_s if getattr(terms, "tau_range_s", None) else (0, np.inf)
    fitted = ok & (taus >= lo * (1 - 1e-9)) & (taus <= hi * (1 + 1e-9))
    ok = fitted if fitted.any() else ok
    from scipy.special import polygamma

    edf = np.asarray(getattr(result, "edf", np.full(taus.size, np.inf)), dtype=float)[ok]
    samp = np.where(np.isfinite(edf) & (edf > 0), polygamma(1, np.maximum(edf, 1e-9) / 2.0),
                    0.0)
    t = taus[ok]
    r2 = np.maximum((2.0 * np.log(dev[ok] / model[ok])) ** 2 - samp, 0.0)
    out = []
    for h in np.atleast_1d(np.asarray(horizons_s, dtype=float)):
        near = (t >= h / span) & (t <= h * span)
        out.append(float(np.mean(r2[near])) if near.any()
                   else float(r2[int(np.argmin(np.abs(np.log(t / h))))]))
    return np.asarray(out)


def predicted_rms_ci(pred: DriftPrediction, terms=None, *, extra_log_var=None,
                     n_windows=None, confidence: float = 0.95) -> dict:
    """Interval of the drift RMS per horizon (u s), from three sources in the log of the
    drift variance ``V``:

    * the fitted terms' uncertainty (``terms``: a :class:`~inertialab.noise.terms.fit.NoiseTerms`):
      each significant term's interval as a lognormal spread of its amplitude, so of its
      part ``v_k`` of ``V`` with log-sd ``2 s_k``, summed as ``sum (v_k/V)^2 (2 s_k)^2``
      (the terms' correlation left out: wider, not narrower); a term that is an upper
      bound moves ``V`` between ``V - v_k`` and ``V + v_k ((ub/value)^2 - 1)``;
    * ``extra_log_var`` per horizon: variance of ``ln V`` the data's non-stationarity
      (:func:`inertialab.noise.segments.stationarity.excess_at`) and, pooled over logs, the
      between-log spread add;
    * ``n_windows`` per horizon (optional): the observed RMS's own chi-square sampling
      over that many windows, ``psi'(n/2)`` (for the check of an observed RMS).

    Returns ``{"confidence", "low", "high", "log_sd": {"terms", "extra", "sampling"}}``."""
    from scipy.special import ndtri, polygamma

    z = float(ndtri(0.5 + confidence / 2.0))
    nh = len(pred.horizons_s)
    extra = np.zeros(nh) if extra_log_var is None else np.asarray(extra_log_var, float)
    samp = np.zeros(nh) if n_windows is None else np.where(
        np.asarray(n_windows, float) > 0, polygamma(1, np.maximum(
            np.asarray(n_windows, float), 1.0) / 2.0), np.inf)
    s_terms, lo_b, hi_b = np.zeros(nh), np.zeros(nh), np.zeros(nh)
    var = pred.rms ** 2
    for name, vk in pred.by_term.items():
        vk = np.asarray(vk, dtype=float)
        if terms is None or name not in _TERM_NAMES:
            continue
        sd, ub = _term_spread(getattr(terms, name), z)
        if ub is not None:
            lo_b += vk
            hi_b += vk * max(ub * ub - 1.0, 0.0)
        else:
            with np.errstate(divide="ignore", invalid="ignore"):
                f = np.where(var > 0, vk / var, 0.0)
            s_terms += (f * 2.0 * sd) ** 2
    s = np.sqrt(s_terms + extra + samp)
    low = np.sqrt(np.maximum(var * np.exp(-z * s) - lo_b, 0.0))
    high = np.sqrt(var * np.exp(z * s) + hi_b)
    return {"confidence": float(confidence), "low": low, "high": high,
            "log_sd": {"terms": np.sqrt(s_terms), "extra": np.sqrt(extra),
                       "sampling": np.sqrt(samp)}}


__all__ = ["Component", "DriftPrediction", "Z95", "check_prediction", "component_variance",
           "components_of", "kalibr_components", "kalibr_reading", "observed_error",
           "effective_windows", "misfit_log_var", "model_effective_windows", "window_covariances", "predict", "predict_terms", "predicted_rms_ci"]
