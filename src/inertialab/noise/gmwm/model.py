"""The latent processes of the GMWM fit and the least-squares fit of one candidate model
(:mod:`inertialab.noise.gmwm.fit`): each process's Allan variance, the
log-parameter packing, data-driven starts and bounds, and ``least_squares`` on the log
wavelet moments. Split from :mod:`inertialab.noise.gmwm.fit`, which selects among the
candidates, bootstraps the intervals and turns the processes into IEEE terms.
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass, field

import numpy as np
from scipy.optimize import least_squares

from inertialab.noise.gmwm._avar import avar_ar1, avar_drift, avar_quant, avar_rw, avar_white
from inertialab.noise.terms.band import band_shape

_ORDER = ("QN", "WN", "GM", "BL", "RW", "DR")

#: number of log parameters of each latent process
_N_PARAMS = {"GM": 2, "BL": 3}


def _n_params(spec) -> int:
    return sum(_N_PARAMS.get(k, 1) for k in spec)


@dataclass(frozen=True)
class Process:
    """One latent process: ``kind`` in QN, WN, RW, DR, GM and its parameters (module
    docstring units; GM: ``s2`` and ``tc_s``), with percentile intervals ``ci``."""

    kind: str
    params: dict
    ci: dict = field(default_factory=dict)

    def avar(self, m, tau0: float) -> np.ndarray:
        p = self.params
        if self.kind == "WN":
            return avar_white(m, p["sigma2"])
        if self.kind == "QN":
            return avar_quant(m, p["q2"], tau0)
        if self.kind == "RW":
            return avar_rw(m, p["gamma2"])
        if self.kind == "DR":
            return avar_drift(m, p["omega"])
        if self.kind == "FL":
            return -avar_quant(m, p["f2"], tau0)
        if self.kind == "BL":
            return p["c0"] * band_shape(np.asarray(m, dtype=float) * tau0, p["t_lo_s"],
                                        p["t_hi_s"])
        return avar_ar1(m, math.exp(-tau0 / p["tc_s"]), p["s2"])

    def to_dict(self) -> dict:
        return {"process": self.kind, "params": {k: float(v) for k, v in self.params.items()},
                "ci": {k: [float(a), float(b)] for k, (a, b) in self.ci.items()}}


def _exp(x: float) -> float:
    """exp of a log parameter, clipped to the double range (an optimiser step can
    overshoot to |x| > 709)."""
    return math.exp(min(max(float(x), -700.0), 700.0))


def _unpack(spec, theta, tau0):
    out, i = [], 0
    for kind in spec:
        if kind == "GM":
            out.append(Process("GM", {"s2": _exp(theta[i]), "tc_s": _exp(theta[i + 1])}))
            i += 2
        elif kind == "BL":
            lo = _exp(theta[i + 1])
            out.append(Process("BL", {"c0": _exp(theta[i]), "t_lo_s": lo,
                                      "t_hi_s": lo * _exp(theta[i + 2])}))
            i += 3
        else:
            key = {"WN": "sigma2", "QN": "q2", "RW": "gamma2", "DR": "omega", "FL": "f2"}[kind]
            out.append(Process(kind, {key: _exp(theta[i])}))
            i += 1
    return out


def _model_avar(procs, m, tau0):
    return sum(p.avar(m, tau0) for p in procs)


def _name(spec) -> str:
    k = spec.count("GM")
    base = "+".join(s for s in spec if s != "GM")
    return base + (f"+{k}GM" if k else "")


def _start(spec, wv, taus, tau0, T):
    """Data-driven starting values (log parameters) for a model spec."""
    avar = 2.0 * wv
    m = taus / tau0
    th = []
    k_gm = spec.count("GM")
    tcs = np.geomspace(taus[0] * 2, taus[-1] / 2, k_gm) if k_gm else []
    j_gm = 0
    for kind in spec:
        if kind == "WN":
            th.append(math.log(avar[0] * m[0]))
        elif kind in ("QN", "FL"):
            th.append(math.log(max(avar[0] * taus[0] ** 2 / 3.0 * 0.01, 1e-300)))
        elif kind == "RW":
            th.append(math.log(max(avar[-1] * 3.0 / m[-1] * 0.5, 1e-300)))
        elif kind == "DR":
            th.append(math.log(max(math.sqrt(avar[-1] * 2.0) / m[-1] * 0.3, 1e-300)))
        elif kind == "BL":  # flat at the curve's minimum between the first and last scales
            lo, hi = taus[0] * 2.0, taus[-1] / 2.0
            th += [math.log(float(np.min(avar)) * 0.5), math.log(lo),
                   math.log(max(hi / lo, BL_RATIO_MIN * 1.01))]
        else:
            tc = float(tcs[j_gm])
            j_gm += 1
            i = int(np.argmin(np.abs(np.log(taus / (1.89 * tc)))))
            s2 = avar[i] / (0.19 * max(k_gm, 1))  # peak AVAR of a GM ~ 0.19 s2
            th += [math.log(s2), math.log(tc)]
    return np.array(th)


#: The correlation time of a Gauss–Markov process is capped at this fraction of the
#: longest fitted scale: a GM whose Allan peak (1.89 tc) is not followed
#: by a few octaves of scales is a random walk within the record, and an uncapped fit was
#: measured to trade the random walk K for such a long GM on the MEMS presets.
TC_MAX_FRACTION = 1.0 / 8.0


#: ratio t_hi/t_lo of a BL process: at least two octaves (below, one GM does), at most
#: 1e6 (beyond the fitted scales it is flat, IEEE 952 flicker)
BL_RATIO_MIN, BL_RATIO_MAX = 4.0, 1e6


#: A Gauss–Markov correlation time (and a BL process's lower corner) is at least this
#: multiple of the first fitted scale: above about twice its correlation time a GM's
#: Allan variance falls like white noise, so a faster one is white noise under another
#: name. At 1x, the fits of the real ADIS16405 accelerometers held a GM of 15-19 samples
#: that took 5 % of N.
TC_MIN_SCALES = 4.0


def _bounds(spec, tau_min, tau_max):
    lo, hi = [], []
    tc_lo = math.log(TC_MIN_SCALES * tau_min)
    tc_hi = math.log(max(TC_MAX_FRACTION * tau_max, 1.01 * TC_MIN_SCALES * tau_min))
    for kind in spec:
        if kind == "GM":  # a GM faster than a few fitted scales looks like white noise
            lo += [-np.inf, tc_lo]
            hi += [np.inf, tc_hi]
        elif kind == "BL":  # corners: t_lo as a GM's tc, t_hi >= BL_RATIO_MIN t_lo
            lo += [-np.inf, tc_lo, math.log(BL_RATIO_MIN)]
            hi += [np.inf, tc_hi, math.log(BL_RATIO_MAX)]
        else:
            lo.append(-np.inf)
            hi.append(np.inf)
    return np.array(lo), np.array(hi)


#: log step of the forward differences for the non-linear parameters (correlation times,
#: band corners) in :func:`_log_model_jacobian`
_FD_STEP = 1e-6


def _log_model_jacobian(spec, theta, m, tau0) -> np.ndarray:
    """d ln(model AVAR)/d theta at the scales ``m``, shape (k, p).

    A process's amplitude enters linearly (its column is its share of the model; a
    drift's ``omega`` squared: twice that), so only the correlation times and band
    corners need a difference, and that of their own process only: the Jacobian costs
    about one model evaluation plus one process per non-linear parameter, where a forward
    difference of the whole model cost one model per parameter (the GMWM fits spent 80 %
    of their time there)."""
    procs = _unpack(spec, theta, tau0)
    comps = [p.avar(m, tau0) for p in procs]
    tot = sum(comps)
    with np.errstate(divide="ignore", invalid="ignore"):
        inv = np.where(np.abs(tot) > 0, 1.0 / tot, 0.0)
    J = np.zeros((np.size(m), len(theta)))
    col = 0
    for kind, comp in zip(spec, comps):
        n_p = _N_PARAMS.get(kind, 1)
        J[:, col] = comp * inv * (2.0 if kind == "DR" else 1.0)
        for j in range(1, n_p):
            th = np.array(theta[col:col + n_p], dtype=float)
            th[j] += _FD_STEP
            moved = _unpack((kind,), th, tau0)[0].avar(m, tau0)
            J[:, col + j] = (moved - comp) / _FD_STEP * inv
        col += n_p
    return J


def _fit_spec(spec, target, taus, W, tau0, T, theta0=None, max_nfev=200, fixed_last=None,
              second_start: bool = True):
    """Least squares ``|W (target - ln nu(theta))|^2`` on log parameters (``W``: a vector
    of diagonal weights or a whitening matrix; ``fixed_last``: the last log parameter held
    at this value; ``second_start``: also start from the Gauss–Markov processes halved
    with their times x3, keeping the better fit)."""
    m = taus / tau0
    W = np.asarray(W, dtype=float)

    def resid(theta):
        with np.errstate(over="ignore", invalid="ignore"):  # optimiser excursions
            mod = _model_avar(_unpack(spec, theta, tau0), m, tau0) / 2.0
        d = target - np.log(np.clip(np.nan_to_num(mod, nan=1e300), 1e-300, 1e300))
        return W * d if W.ndim == 1 else W @ d

    def jac(theta):
        J = _log_model_jacobian(spec, theta, m, tau0)
        return -(W[:, None] * J) if W.ndim == 1 else -(W @ J)

    lo, hi = _bounds(spec, float(taus[0]), float(taus[-1]))
    if fixed_last is not None:
        lo[-1], hi[-1] = fixed_last - 1e-7, fixed_last + 1e-7
    starts = [theta0] if theta0 is not None else [_start(spec, np.exp(target), taus, tau0, T)]
    if theta0 is None and second_start and spec.count("GM") >= 1:
        alt = starts[0].copy()
        k = 0
        for kind in spec:  # second start: GM amplitudes halved, correlation times x3
            if kind == "GM":
                alt[k] -= math.log(2.0)
                alt[k + 1] = min(alt[k + 1] + math.log(3.0), hi[k + 1] - 1e-6)
                k += 2
            else:
                k += _N_PARAMS.get(kind, 1)
        starts.append(alt)
    best = None
    for th0 in starts:
        th0 = np.clip(th0, lo + 1e-9, hi - 1e-9)
        try:
            # scipy's trust-region step divides by a zero norm at an exact optimum; the
            # step it takes then is fine, its RuntimeWarning is no news for the user
            with np.errstate(divide="ignore", invalid="ignore"), warnings.catch_warnings():
                warnings.simplefilter("ignore", RuntimeWarning)
                r = least_squares(resid, th0, jac=jac, bounds=(lo, hi), method="trf",
                                  x_scale=1.0, max_nfev=max_nfev)
        except ValueError:
            continue
        if best is None or r.cost < best.cost:
            best = r
    return best
