"""Generalized method of wavelet moments (GMWM; Guerrier et al. 2013).

The record's Haar wavelet variance (WV) at dyadic scales ``tau_j = m tau0``,
``m = 1, 2, 4, ...`` is matched by the WV of a sum of latent processes:

- ``WN`` white rate noise (per-sample variance ``sigma2``; IEEE N),
- ``QN`` quantisation / white angle noise (``Q^2``, rate unit^2 s^2; IEEE Q),
- ``RW`` rate random walk (per-sample increment variance ``gamma2``; IEEE K),
- ``DR`` drift (rate ramp ``omega`` per sample; IEEE R),
- ``GM`` one or more first-order Gauss–Markov / AR(1) processes (stationary variance
  ``s2``, correlation time ``tc_s`` between the first fitted scale and 1/8 of the last,
  the bias instability),
- ``BL`` band-limited flicker: the log-uniform mixture of Gauss–Markov processes with
  correlation times in ``[t_lo_s, t_hi_s]`` (peak AVAR ``c0``; the Allan fit's B term,
  :func:`inertialab.noise.terms.base.band_shape`), three parameters for a bias
  instability spread over decades that ``k GM`` fits with ``2k`` (candidates hold
  either GMs or one BL),
- ``FL`` the remainder ``-3 f2/tau^2`` a sensor's internal low-pass filter leaves on white
  noise beyond the cut scales (only when a filter was detected; not an IEEE term).

The Haar MODWT wavelet variance equals half the Allan variance at the dyadic scales, so
``wv = oadev^2/2`` (:func:`wavelet_variance`, computed by :mod:`inertialab.noise.statistics.allan`'s
octave pass) and each process's WV is its exact discrete Allan variance over 2
(``avar_*`` below). WV intervals: chi-square with Percival's ``eta3 = max(M_j/2^j, 1)``
degrees of freedom (``M_j`` the number of non-boundary coefficients, ``2^j = 2m``).

Estimator (two steps, on log wavelet moments; logs keep the many-decade moments
balanced):

1. every candidate is fitted by ``argmin sum_j (eta3_j/2) (ln wv_hat_j - ln wv_j(theta))^2``
   (diagonal weights: the inverse of white noise's variance of a log moment) and the WIC
   selects one;
2. every candidate is refitted with the weights ``edf_j/2``, ``edf_j`` Greenhall's EDF of
   the noise type the step-1 model's local slope implies at scale j (white, flicker,
   random walk: eta3 under-weights the scales where the slower noises dominate), and
   the WIC selects again (default ``weighting="edf"``).

``weighting="full"`` is Guerrier et al.'s efficient two-step GMWM instead: step 2 uses
``Omega = Sigma^-1``, ``Sigma`` the full covariance of the log moments across scales
(neighbouring octaves correlated 0.5 under white noise, 0.88 under a random walk) from the
step-1 model's spectrum, with the chi-square bias ``E ln(chi2(eta)/eta)`` removed
(:func:`inertialab.noise.gmwm.covariance.log_weights`). On the MEMS presets, whose fitted
models have fewer Gauss–Markov processes than the truth, it was measured no more accurate
than the diagonal EDF weights (K better on one preset, worse on another, coverage no
better; docs/noise-terms.md §5), so it is not the default.

Both are solved by ``scipy.optimize.least_squares`` on log parameters from data-driven
starts. The short scales coloured by a sensor's internal filter are cut as in
:func:`inertialab.noise.terms.fit.auto_tau_range`; scales with ``eta3 < 3`` are left out.

Model selection (:func:`fit_gmwm`): every candidate ``WN [+QN] [+RW [+DR]] + k GM``
(k = 0..``max_gm``) or ``... + BL`` (a drift only beside a random walk,
:data:`DR_NEEDS_RW`) is fitted and
the one with the least wavelet information criterion ``WIC = objective + 2 p`` is chosen —
Guerrier et al.'s WIC ``E[objective] + 2 tr(...)`` with its optimism term at its
asymptotic value ``p`` (number of parameters) for a correctly weighted objective.

The B and K intervals span those of every candidate within :data:`WIC_WINDOW` of the
selected one (the WIC does not tell them apart), and a random walk or drift left out is
reported as an upper bound from the objective's profile in that process
(:func:`_profile_upper`).

Parameter intervals: parametric bootstrap in the WV domain: replicate WVs drawn around
the selected model with ``chi2(edf_j)/edf_j`` marginals and the cross-scale correlation
of the model's spectrum (:func:`inertialab.noise.gmwm.covariance.wv_covariance`, Gaussian
copula), refitted with the same weights (optionally, for B and K, re-selected by the
WIC among the :data:`BOOT_MODELS` best candidates; off by default); percentile intervals.

IEEE terms from the latent processes (:func:`inertialab.noise.gmwm.terms.gmwm_noise_terms`): ``N^2 = sigma2 tau0``,
``K^2 = gamma2/tau0`` (plus ``2 s2/tc`` of any GM whose Allan peak 1.89 tc is not
followed by an octave of fitted scales: within the record it is a random walk, flag
``from_gm``), ``R = omega/tau0``, Q, and ``B = max_tau sigma_GM(tau)/0.6643`` of the other
GMs or of the BL process —
the IEEE 952 flat-region value of the Gauss–Markov sum, the same definition as the
virtual-lab truth (:mod:`inertialab.sim.mems_presets`).

References: Guerrier, Skaloud, Stebler, Victoria-Feser (2013), "Wavelet-variance-based
estimation for composite stochastic processes", JASA 108(503); Stebler et al. (2014),
"Generalized method of wavelet moments for inertial navigation filter design", IEEE
TAES 50(3) (WIC); Percival & Walden (2000) §8.4 (eta3). Hand-written: R's ``gmwm`` /
``simts`` have no Python counterpart.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from itertools import product

import numpy as np
from scipy.special import gammaincinv

from inertialab.errors import InputError
from inertialab.noise.gmwm._avar import (  # re-exported (public API)
    avar_ar1,
    avar_drift,
    avar_quant,
    avar_rw,
    avar_white,
)
from inertialab.noise.gmwm.model import (  # Process re-exported (public API)
    Process,
    _fit_spec,
    _model_avar,
    _n_params,
    _name,
    _unpack,
)
from inertialab.noise.terms.base import K_TIME_MIN, span_intervals

#: sqrt(2 ln2 / pi) (IEEE 952 flicker floor), as in :mod:`inertialab.noise.terms.fit`.
BI_FACTOR = math.sqrt(2.0 * math.log(2.0) / math.pi)


def _chi2_ppf(q, df):
    """Chi-square quantile, ``2 gammaincinv(df/2, q)``: scipy.stats' own formula, equal to
    ``chi2.ppf`` bit for bit, without importing scipy.stats (half a second of every
    command's start)."""
    return 2.0 * gammaincinv(0.5 * np.asarray(df, dtype=float), q)

# ----------------------------------------------------------------------------- wavelet variance


@dataclass(frozen=True)
class WaveletVariance:
    """Haar wavelet variance at dyadic scales ``taus_s = m tau0`` (rate unit^2)."""

    taus_s: np.ndarray
    m: np.ndarray
    wv: np.ndarray
    eta: np.ndarray
    ci_low: np.ndarray
    ci_high: np.ndarray
    tau0_s: float
    n_samples: int
    confidence: float

    def to_dict(self) -> dict:
        return {"taus_s": [float(v) for v in self.taus_s], "m": [int(v) for v in self.m],
                "wv": [float(v) for v in self.wv], "eta": [float(v) for v in self.eta],
                "ci_low": [float(v) for v in self.ci_low],
                "ci_high": [float(v) for v in self.ci_high], "tau0_s": float(self.tau0_s),
                "n_samples": int(self.n_samples), "confidence": float(self.confidence)}


def _wv_from(taus, m, avar, n, tau0, confidence) -> WaveletVariance:
    m = np.asarray(m, dtype=np.int64)
    wv = np.asarray(avar, dtype=float) / 2.0
    eta = np.maximum((n - 2 * m + 1) / (2.0 * m), 1.0)
    p = float(confidence)
    lo = wv * eta / _chi2_ppf(0.5 * (1 + p), eta)
    hi = wv * eta / _chi2_ppf(0.5 * (1 - p), eta)
    return WaveletVariance(np.asarray(taus, float), m, wv, eta, lo, hi, float(tau0), int(n), p)


def wavelet_variance(y, rate_hz: float, *, confidence: float = 0.95) -> WaveletVariance:
    """Haar wavelet variance of a rate record at every dyadic scale (see module docstring)."""
    from inertialab.noise.statistics.allan import oadev

    r = oadev(np.asarray(y), rate_hz=rate_hz, taus="octave")
    return wv_from_curve(r, confidence=confidence)


def wv_from_curve(result, sel=None, *, confidence: float = 0.95) -> WaveletVariance:
    """The wavelet variance held in an overlapping-Allan curve: its dyadic taus."""
    if result.statistic != "oadev" or result.input != "rate":
        raise InputError("the wavelet variance needs the overlapping Allan deviation of a "
                         f"rate record, got {result.statistic} of {result.input}")
    m = np.asarray(result.m, dtype=np.int64)
    ok = (m & (m - 1)) == 0
    ok &= np.isfinite(result.dev) & (np.asarray(result.dev) > 0)
    if sel is not None:
        ok &= np.asarray(sel, dtype=bool)
    return _wv_from(np.asarray(result.taus_s)[ok], m[ok], np.asarray(result.dev)[ok] ** 2,
                    result.n_samples, result.tau0_s, confidence)


# ----------------------------------------------------------------------------- model

@dataclass(frozen=True)
class GmwmFit:
    """A fitted latent model.

    ``processes``: the selected model's processes; ``wv``: the wavelet variance it was
    fitted on; ``wic``: its criterion; ``candidates``: name -> WIC of every model tried;
    ``objective``; ``tau_range_s`` of the fitted scales; ``k_upper``: where the selected
    model has no random walk, the upper end of K (rate unit per sqrt(s)) from the
    objective's profile in a random walk added (its upper bound; NaN otherwise);
    ``r_upper``: the same for a drift (``omega``, rate unit per sample)."""

    processes: tuple
    wv: WaveletVariance
    wic: float
    objective: float
    candidates: dict
    tau_range_s: tuple
    n_boot: int = 0
    b_ci: tuple = (float("nan"), float("nan"))
    k_ci: tuple = (float("nan"), float("nan"))
    k_upper: float = float("nan")
    r_upper: float = float("nan")

    @property
    def name(self) -> str:
        return _name(tuple(p.kind for p in self.processes))

    def model_wv(self, taus_s) -> np.ndarray:
        m = np.asarray(taus_s, dtype=float) / self.wv.tau0_s
        return _model_avar(self.processes, m, self.wv.tau0_s) / 2.0

    def process_wv(self, taus_s) -> list:
        m = np.asarray(taus_s, dtype=float) / self.wv.tau0_s
        return [(p.kind, p.avar(m, self.wv.tau0_s) / 2.0) for p in self.processes]

    def to_dict(self) -> dict:
        return {"model": self.name, "processes": [p.to_dict() for p in self.processes],
                "wic": float(self.wic), "objective": float(self.objective),
                "candidates": {k: float(v) for k, v in self.candidates.items()},
                "tau_range_s": [float(v) for v in self.tau_range_s],
                "n_boot": int(self.n_boot), "b_ci": [float(v) for v in self.b_ci],
                "k_ci": [float(v) for v in self.k_ci], "k_upper": float(self.k_upper),
                "r_upper": float(self.r_upper),
                "b": float(b_of(self.processes, self.wv.tau0_s, self.tau_range_s,
                                rise_start(self.wv))),
                "t_rise_s": rise_start(self.wv),
                "wv": self.wv.to_dict()}


#: a drift (DR) is a candidate only beside a random walk (RW): on the last two or three
#: scales of a record their rises (tau^2 and tau) are not told apart, and a DR chosen
#: instead of the RW sets K to 0 (measured on industrial-400hz: K = 0 in 13 of 50 seeds);
#: the same order as the Allan fit's backward elimination, which drops R before K
DR_NEEDS_RW = True


def _specs(max_gm: int, with_qn: bool, with_fl: bool, with_bl: bool = True):
    out = []
    for qn, rw, dr in product((False, True) if with_qn else (False,), (False, True),
                              (False, True)):
        if dr and not rw and DR_NEEDS_RW:
            continue
        for bias in [("GM",) * k for k in range(0, max_gm + 1)] + ([("BL",)] if with_bl else []):
            spec = (("FL",) if with_fl else ()) + (("QN",) if qn else ()) + ("WN",) \
                + bias + (("RW",) if rw else ()) + (("DR",) if dr else ())
            out.append(spec)
    return out


def _with_discrepancy(eta, lw, ref, taus, tau0, n_par: int):
    """Degrees of freedom of the log moments with a model discrepancy folded in, as the
    Allan fit does (:func:`inertialab.noise.terms.least_squares._with_discrepancy`): where the
    step-1 model leaves chi2/dof above the trigger (real logs: structure at the short
    scales no latent model holds, measured with eta of 10^5), each log moment gets the
    variance ``2/eta + s2`` with ``s2`` the random-effects variance that brings chi2/dof
    to 1; a Gauss-Markov process then no longer bends to the short scales' structure."""
    from inertialab.noise.terms.least_squares import _discrepancy_s2

    model = _model_avar(ref, taus / tau0, tau0) / 2.0
    r2 = (lw - np.log(model)) ** 2
    s2 = _discrepancy_s2(r2, eta, taus.size - n_par)
    return 1.0 / (1.0 / eta + 0.5 * s2) if s2 > 0 else eta


def _drop_low_eta(wv: WaveletVariance, min_eta: float) -> WaveletVariance:
    keep = wv.eta >= min_eta
    if keep.sum() < 3 or keep.all():
        return wv
    return WaveletVariance(wv.taus_s[keep], wv.m[keep], wv.wv[keep], wv.eta[keep],
                           wv.ci_low[keep], wv.ci_high[keep], wv.tau0_s, wv.n_samples,
                           wv.confidence)


def fit_gmwm_wv(wv: WaveletVariance, *, max_gm: int = 3, n_boot: int = 50, seed: int = 0,
                confidence: float = 0.95, filtered: bool = False,
                min_eta: float | None = None, weighting: str = "edf") -> GmwmFit:
    """Fit and select the latent model on a wavelet variance (module docstring).
    ``filtered``: the short scales were cut for a sensor filter; every candidate then
    carries the filter's ``-f2 3/tau^2`` remainder (process ``FL``). ``min_eta``: scales
    with fewer degrees of freedom are left out of the objective (default
    :data:`inertialab.noise.terms.fit.EDF_MIN`, the Allan fit's rule; the last one or two
    scales of a record), and every Gauss–Markov correlation time is capped at
    :data:`inertialab.noise.gmwm.model.TC_MAX_FRACTION` of the longest remaining scale
   .
    ``weighting``: ``"edf"`` (default) diagonal weights of the log moments from the
    Greenhall EDF of the step-1 model's noise type per scale; ``"full"`` Guerrier et
    al.'s efficient weight matrix, the inverse of the log moments' full covariance across
    scales (module docstring; measured no more accurate on the MEMS presets,
    docs/noise-terms.md §5)."""
    from inertialab.noise.gmwm.covariance import log_weights, model_edf

    if weighting not in ("edf", "full"):
        raise InputError(f"GMWM weighting must be 'edf' or 'full', got {weighting!r}")
    if min_eta is None:
        from inertialab.noise.terms.base import EDF_MIN as min_eta
    wv = _drop_low_eta(wv, float(min_eta))
    taus, wvv, eta = wv.taus_s, wv.wv, wv.eta
    if taus.size < 3:
        raise InputError(f"GMWM needs at least 3 dyadic scales, got {taus.size}")
    tau0 = wv.tau0_s
    T = wv.n_samples * tau0
    lt, lw = np.log(taus), np.log(wvv)
    with_qn = taus.size >= 4 and (lw[1] - lw[0]) / (lt[1] - lt[0]) < -0.75
    specs = _specs(max_gm, with_qn and not filtered, filtered)
    # step 1: diagonal weights eta3/2 of the log moments (white noise's variance)
    cands, fits = _select(specs, lw, taus, np.sqrt(eta / 2.0), tau0, T, STEP1_NFEV)
    ref = _unpack(*fits[min(cands, key=cands.get)][:2], tau0)
    # the step-1 model's covariance of the moments across scales (_gmwm_cov)
    bias, linv, eta_a, corr = log_weights(ref, wv.m, wv.n_samples, tau0)
    if weighting == "full":
        # Guerrier et al.'s two-step estimator: Omega = the inverse of that covariance
        target, W = lw - bias, linv
    else:
        # diagonal weights from the Greenhall EDF of the noise type the step-1 model
        # implies at each scale (eta3 is white noise's and under-weights the scales
        # where flicker-like or random-walk noise dominates; measured: the WIC then chose
        # one GM for the three of consumer-100hz in 17 of 30 seeds, K +19 % med |err|)
        eta_a = model_edf(ref, wv)
        target, W, bias = lw, np.sqrt(eta_a / 2.0), np.zeros(lw.size)
        eta_a = _with_discrepancy(eta_a, lw, ref, taus, tau0, _n_params(
            tuple(p.kind for p in ref)))
        W = np.sqrt(eta_a / 2.0)
    # step 2 refits the step-1 candidates the WIC has not already ruled out
    ranked1 = sorted(cands, key=cands.get)
    keep = {k for k in ranked1[:STEP2_MAX] if cands[k] - cands[ranked1[0]] <= STEP2_WIC}
    cands, fits = _select([sp for sp in specs if _name(sp) in keep], target, taus, W, tau0,
                          T)
    best = min(cands, key=cands.get)
    spec, theta, obj = fits[best]
    procs = _unpack(spec, theta, tau0)
    ranked = sorted(cands, key=cands.get)[:BOOT_MODELS]
    procs, b_ci, k_ci = _with_intervals(spec, theta, procs, wv, (bias, W, eta_a, corr),
                                        n_boot, seed, confidence,
                                        [fits[k][:2] for k in ranked])
    # the models the WIC cannot tell from the selected one (within WIC_WINDOW): B and K
    # intervals span theirs too, so they carry the model choice's uncertainty
    for name in sorted(cands, key=cands.get)[1:]:
        if cands[name] - cands[best] > WIC_WINDOW or n_boot <= 0:
            break
        sp, th, _ = fits[name]
        _, b2, k2 = _with_intervals(sp, th, _unpack(sp, th, tau0), wv,
                                    (bias, W, eta_a, corr), n_boot, seed, confidence)
        b_ci, k_ci = span_intervals(b_ci, b2), span_intervals(k_ci, k2)
    # a random walk or a drift not selected: its upper bound is the upper bootstrap
    # percentile of K (R) in the best candidate that has one (an absent
    # term as an upper bound, never a bare 0)
    k_upper = r_upper = float("nan")
    if "RW" not in spec and n_boot > 0:
        k_upper = min(math.sqrt(_profile_upper("RW", spec, target, taus, W, tau0, T, obj,
                                               confidence) / tau0),
                      K_SCATTER * float(np.min(np.sqrt(6.0 * np.exp(target) / taus))))
    if "DR" not in spec and n_boot > 0:
        r_upper = _profile_upper("DR", spec, target, taus, W, tau0, T, obj, confidence)
    return GmwmFit(tuple(procs), wv, cands[best], obj, cands,
                   (float(taus[0]), float(taus[-1])), n_boot, b_ci, k_ci, k_upper, r_upper)


#: a random walk left out is bounded by the curve too: its AVAR K^2 tau/3 at most this
#: squared times the AVAR (2 x the wavelet variance) at every fitted scale, the scatter
#: allowance of the B rule (:data:`inertialab.noise.terms._bounds.B_SCATTER`). Measured
#: on 19 faint walks left out (:func:`_profile_upper`): the profile alone covered the
#: true K on 19, with this cap 19; a cap at the Allan curve's longest taus instead
#: (EDF 1-2) on 9
K_SCATTER = 1.05

#: shares of the AVAR at the longest scale, taken by the random walk or drift held
#: fixed, scanned by :func:`_profile_upper`
DRIFT_SHARES = np.geomspace(1e-3, 100.0, 21)


def _profile_upper(kind, spec, target, taus, W, tau0, T, obj, confidence):
    """Upper end of a random walk's ``gamma2`` (``kind`` "RW") or a drift's ``omega``
    ("DR"; rate unit per sample) where the selected model has none: the profile of the
    objective with that process held fixed (a drift beside a random walk added where the
    model has none, :data:`DR_NEEDS_RW`), scanned upward in its share of the AVAR at the
    longest scale until the objective exceeds the selected model's by
    ``chi2(confidence, 1)`` times the misfit ratio ``max(1, obj/dof)``.

    A bootstrap of the best model that has the process is not used: its parameter is
    log-parametrised around a point estimate near 0. For the drift, its upper percentile
    covered the presets' true ramp in 40-44 % of 25 seeds (industrial-400hz,
    accel-200hz); for the random walk, on 10 minutes of white noise at 100 Hz it gave
    K <= 0.003 deg/h/sqrt(h) on one axis and <= 959 on another, where the curve allows
    about 300 (docs/noise-terms.md)."""
    if kind == "RW":
        spec2 = spec + ("RW",)
    else:
        spec2 = (spec if "RW" in spec else spec + ("RW",)) + ("DR",)
    m_last = taus[-1] / tau0
    avar_last = 2.0 * math.exp(target[-1])
    dof = max(taus.size - _n_params(spec), 1)
    crit = float(_chi2_ppf(confidence, 1.0)) * max(1.0, obj / dof)

    def log_param(share):  # the process's log parameter giving it ``share`` at m_last
        if kind == "RW":  # avar_rw = gamma2 (2 m^2 + 1) / (6 m)
            return math.log(share * avar_last * 6.0 * m_last / (2.0 * m_last**2 + 1.0))
        return math.log(math.sqrt(2.0 * share * avar_last) / m_last)

    theta, prev = None, None
    for share in DRIFT_SHARES:
        lw = log_param(share)
        th0 = None if theta is None else np.append(theta[:-1], lw)
        r = _fit_spec(spec2, target, taus, W, tau0, T, theta0=th0, fixed_last=lw)
        if r is None:
            continue
        theta = r.x
        d = 2.0 * float(r.cost) - obj
        if d > crit:
            if prev is None:
                return math.exp(lw)
            # log-linear interpolation between the last point inside and this one
            f = (crit - prev[1]) / (d - prev[1]) if d > prev[1] else 1.0
            return math.exp(prev[0] + f * (lw - prev[0]))
        prev = (lw, d)
    return math.exp(prev[0]) if prev else float("nan")


def _select(specs, target, taus, W, tau0, T, max_nfev: int = 200):
    """Fit every candidate; ``({name: WIC}, {name: (spec, theta, objective)})``."""
    cands, fits = {}, {}
    for spec in specs:
        p = _n_params(spec)
        if taus.size < p + 2:
            continue
        r = _fit_spec(spec, target, taus, W, tau0, T, max_nfev=max_nfev,
                      second_start=STEP1_TWO_STARTS or max_nfev > STEP1_NFEV)
        if r is None:
            continue
        obj = 2.0 * float(r.cost)
        cands[_name(spec)] = obj + 2.0 * p
        fits[_name(spec)] = (spec, r.x, obj)
    if not cands:
        raise InputError("GMWM: no candidate model could be fitted")
    return cands, fits


#: evaluations per candidate in step 1, which only ranks the candidates and gives step 2
#: its weights (step 2 refits the leaders with 200): the same selections and terms on the
#: 12 ADIS16405 axes and the preset seeds checked, 16 % less CPU (docs/noise-terms.md §10)
STEP1_NFEV = 60
#: whether step 1 also tries each Gauss–Markov candidate's second start (step 2 always
#: does): one start gave the same selections and terms on the 12 real axes and 9 preset
#: seeds, 10 % less CPU
STEP1_TWO_STARTS = False

#: step 2 (EDF weights) refits at most STEP2_MAX of the step-1 candidates, those within
#: STEP2_WIC of the best step-1 WIC: the rest are ruled out by tens to thousands of WIC
#: units and refitting them cost half of a fit on the real ADIS16405 logs
STEP2_MAX = 6
STEP2_WIC = 50.0

#: candidates whose WIC is within this of the selected model's widen its B and K
#: intervals to span theirs (0: the selected model's intervals only); 2 is the usual
#: "not distinguished" difference of an information criterion. Measured, 25 seeds:
#: industrial-400hz B coverage 80 -> 88 %, accel-200hz K 64 -> 68 %, nothing else changed
WIC_WINDOW = 2.0

#: evaluations per bootstrap refit (warm-started at the fitted parameters, with the
#: analytic Jacobian); 60 before that Jacobian existed
BOOT_NFEV = 30

#: models (best WIC first) among which each bootstrap replicate re-selects for B and K.
#: 1: no re-selection. Measured on industrial-400hz (16 seeds, 50 replicates): 3 models
#: gave the same coverage (B 88 %, K 69 %) at twice the cost (5.5 s against 2.6 s CPU)
BOOT_MODELS = 1


def _with_intervals(spec, theta, procs, wv, weights, n_boot, seed, confidence, alts=()):
    """Parametric bootstrap in the WV domain: replicate wavelet variances drawn around
    the fitted model with the chi-square marginals (``eta``) and the cross-scale
    correlation of :func:`inertialab.noise.gmwm.covariance.log_weights` (Gaussian copula),
    each refitted with the same weights; percentile intervals. The processes' intervals
    come from refits of the selected model; B and K from the model the WIC selects in
    each replicate among ``alts`` (the selected model and the runners-up, ``(spec,
    theta)``), so their intervals carry the model-selection uncertainty."""
    from scipy.stats import norm

    nan2 = (float("nan"), float("nan"))
    if n_boot <= 0:
        return procs, nan2, nan2
    bias, W, eta, corr = weights
    tau0, taus = wv.tau0_s, wv.taus_s
    T = wv.n_samples * tau0
    m = taus / tau0
    model = _model_avar(procs, m, tau0) / 2.0
    rng = np.random.default_rng(seed)
    C = np.linalg.cholesky(corr + 1e-9 * np.eye(m.size))
    z = rng.standard_normal((n_boot, m.size)) @ C.T
    u = np.clip(norm.cdf(z), 1e-12, 1 - 1e-12)
    draws = model[None, :] * _chi2_ppf(u, eta[None, :]) / eta[None, :]
    alts = [(spec, theta)] + [a for a in alts if a[0] != spec]
    reps, bs, ks = [], [], []
    rng_s = (float(taus[0]), float(taus[-1]))
    t_rise = rise_start(wv)
    for b in range(n_boot):
        target = np.log(draws[b]) - bias
        best = None
        for j, (sp, th) in enumerate(alts):
            r = _fit_spec(sp, target, taus, W, tau0, T, theta0=th, max_nfev=BOOT_NFEV)
            if r is None:
                continue
            if j == 0:
                reps.append(r.x)
            wic = 2.0 * float(r.cost) + 2.0 * _n_params(sp)
            if best is None or wic < best[0]:
                best = (wic, _unpack(sp, r.x, tau0))
        if best is not None:
            bs.append(b_of(best[1], tau0, rng_s, t_rise))
            ks.append(k_of(best[1], tau0, rng_s, t_rise))
    reps = np.array(reps)
    q = (0.5 * (1 - confidence), 0.5 * (1 + confidence))
    b_ci = k_ci = nan2
    if bs and any("GM" in a[0] or "BL" in a[0] for a in alts):
        b_ci = tuple(float(v) for v in np.quantile(bs, q))
    if ks and any("GM" in a[0] or "RW" in a[0] for a in alts):
        k_ci = tuple(float(v) for v in np.quantile(ks, q))
    out, i = [], 0
    for p in procs:
        ci = {}
        for key in p.params:
            lo, hi = np.quantile(np.exp(reps[:, i]), q) if reps.size else (np.nan, np.nan)
            ci[key] = (float(lo), float(hi))
            i += 1
        out.append(Process(p.kind, p.params, ci))
    return out, b_ci, k_ci


def is_slow_process(p, tau_range_s, t_rise=None) -> bool:
    """A GM read as random walk (K), not bias instability: its Allan peak (1.89 tc) is not
    followed by an octave of fitted scales (in the record it is indistinguishable from a
    random walk, its low-tau behaviour), or, where the curve rises significantly after its
    minimum at ``t_rise`` (:func:`rise_start`), it is a wander of that rise: tc at least
    ``t_rise`` and :data:`K_TIME_MIN` of the longest scale (the five-term fit's K time, the
    same rule)."""
    if p.kind != "GM" or tau_range_s is None:
        return False
    tc = p.params["tc_s"]
    if 1.89 * tc > tau_range_s[1] / 2.0:
        return True
    return t_rise is not None and tc >= max(t_rise, K_TIME_MIN * tau_range_s[1])


def rise_start(wv) -> float | None:
    """The scale of the wavelet variance's minimum where a later scale's lower interval
    limit lies above the minimum's upper limit (a significant rise), else None."""
    i = int(np.argmin(wv.wv))
    if i >= wv.wv.size - 1:
        return None
    return float(wv.taus_s[i]) if np.any(wv.ci_low[i + 1:] > wv.ci_high[i]) else None


def k_of(processes, tau0: float, tau_range_s=None, t_rise=None) -> float:
    """Random-walk amplitude K (rate unit/sqrt(s)): ``gamma2/tau0`` of RW plus, for each
    slow GM (:func:`is_slow_process`), the random walk it behaves as below its correlation time,
    ``2 s2/tc`` (its driving-noise density)."""
    k2 = 0.0
    for p in processes:
        if p.kind == "RW":
            k2 += p.params["gamma2"] / tau0
        elif is_slow_process(p, tau_range_s, t_rise):
            k2 += 2.0 * p.params["s2"] / p.params["tc_s"]
    return math.sqrt(k2)


def b_of(processes, tau0: float, tau_range_s=None, t_rise=None) -> float:
    """IEEE 952 flat-region B of the Gauss–Markov processes: ``max sigma_GM / 0.6643``
    over 1024 log-spaced taus of ``tau_range_s`` (the fitted scales: a flat region must
    be seen in the data — a GM whose peak lies beyond the record, or that is the wander
    of a significant rise, is read as random walk, not as bias instability,
    :func:`is_slow_process`), else over ``[tau0, 1e3 max tc]``. Rate unit; 0 without GM."""
    gms = [p for p in processes
           if (p.kind == "GM" and not is_slow_process(p, tau_range_s, t_rise)) or p.kind == "BL"]
    if not gms:
        return 0.0
    if tau_range_s is None:
        lo = tau0
        hi = 1e3 * max(p.params.get("tc_s", p.params.get("t_hi_s", tau0)) for p in gms)
    else:
        lo, hi = tau_range_s
    m = np.geomspace(max(lo / tau0, 1.0), max(hi / tau0, 2.0), 1024)
    av = sum(p.avar(m, tau0) for p in gms)
    if t_rise is not None:
        # up to the curve's minimum a wander's Gauss-Markov is part of the floor B is read
        # from (it takes over as K only in the rise after it)
        wander = [p for p in processes if p.kind == "GM" and is_slow_process(p, tau_range_s, t_rise)]
        if wander:
            av = av + np.where(m * tau0 <= t_rise, sum(p.avar(m, tau0) for p in wander), 0.0)
    return float(math.sqrt(float(np.max(av))) / BI_FACTOR)


def fit_gmwm(y, rate_hz: float, *, max_gm: int = 3, n_boot: int = 50, seed: int = 0,
             confidence: float = 0.95, auto_range: bool = True,
             weighting: str = "edf") -> GmwmFit:
    """GMWM of a rate record ``y`` sampled at ``rate_hz`` (module docstring).

    A workflow calls it on the raw record (``fit_gmwm(log.values, log.rate_hz)``) and
    turns it into IEEE terms with :func:`inertialab.noise.gmwm.terms.gmwm_noise_terms`; ``fit_noise_terms(result,
    method="gmwm")`` does both from the record's octave overlapping-Allan curve, which
    holds the same wavelet variance.

    Examples
    --------
    White rate noise of variance 0.01 (deg/s)^2: the model chosen is white noise alone,
    with its variance:

    >>> import numpy as np
    >>> y = np.random.default_rng(0).normal(0.0, 0.1, 2000)
    >>> fit = fit_gmwm(y, 100.0, max_gm=0, n_boot=0)
    >>> [p.kind for p in fit.processes]
    ['WN']
    >>> bool(abs(fit.processes[0].params["sigma2"] - 0.01) < 0.0005)
    True
    """
    from inertialab.noise.statistics.allan import oadev

    r = oadev(np.asarray(y), rate_hz=rate_hz, taus="octave")
    return fit_gmwm_curve(r, None, max_gm=max_gm, n_boot=n_boot, seed=seed,
                          confidence=confidence, auto_range=auto_range, weighting=weighting)


def fit_gmwm_curve(result, sel=None, *, max_gm: int = 3, n_boot: int = 50, seed: int = 0,
                   confidence: float = 0.95, auto_range: bool = True,
                   weighting: str = "edf") -> GmwmFit:
    """GMWM on the dyadic taus of an overlapping-Allan curve of a rate record."""
    from inertialab.noise.terms.base import auto_tau_range

    wv = wv_from_curve(result, sel, confidence=confidence)
    k = 0
    if auto_range and wv.taus_s.size >= 3:
        k = auto_tau_range(wv.taus_s, np.sqrt(wv.wv))
        if k:
            wv = WaveletVariance(wv.taus_s[k:], wv.m[k:], wv.wv[k:], wv.eta[k:],
                                 wv.ci_low[k:], wv.ci_high[k:], wv.tau0_s, wv.n_samples,
                                 wv.confidence)
    return fit_gmwm_wv(wv, max_gm=max_gm, n_boot=n_boot, seed=seed, confidence=confidence,
                       filtered=bool(auto_range and k), weighting=weighting)


__all__ = ["GmwmFit", "Process", "WaveletVariance", "avar_ar1", "avar_drift", "avar_quant",
           "avar_rw", "avar_white", "fit_gmwm", "fit_gmwm_curve", "fit_gmwm_wv",
           "wavelet_variance", "wv_from_curve"]
