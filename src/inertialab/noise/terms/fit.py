"""IMU noise terms Q, N, B, K, R from an Allan-type curve (spec 001 §3.3–3.4).

Five-term model (spec 001 eq. 4, IEEE Std 952-1997 Annex C), sigma in the rate unit u
and tau in s::

    sigma^2(tau) = 3Q^2/tau^2 + N^2/tau + (2 ln2/pi) B^2 + K^2 tau/3 + R^2 tau^2/2
                 = sum_{k=-2..2} c_k tau^k

Methods (every term reports which one and the tau range it was read on):

``"wls"`` (default)
    Weighted least squares of the model on the AVAR points, weights ``edf_i/(2 model_i^2)``
    (inverse variance of an AVAR estimate), iteratively reweighted with the fitted
    model; each tau's EDF is Greenhall's (:func:`inertialab.noise.statistics.edf.edf_greenhall`) for
    the noise type of the model's dominant term there. Robust defaults
    (see :func:`auto_tau_range`): the short-tau region coloured by the
    sensor's internal low-pass/decimation filter is cut (the curve rises or flattens
    before it falls like white noise; everything below 4x its peak is dropped), and the
    ``c_-2`` coefficient is signed: a filter leaves ``-c/tau^2`` behind on white noise
    (``sigma^2 = N^2/tau - c/tau^2`` beyond the filter's length), angle quantisation
    ``+3Q^2/tau^2``; a negative or non-significant ``c_-2`` reports Q as absent. Taus
    whose model EDF is below :data:`EDF_MIN` are dropped. A record too short to separate
    a term (fewer than two taus per parameter) drops R, then K, then Q, reported
    ``not_observable`` with the reason. B is band-limited flicker
    (:func:`inertialab.noise.terms.base.band_shape`: the log-uniform mixture of
    Gauss–Markov processes between two corners, flat between them), the corners
    profiled inside the least squares on a grid (``_terms_grid._corner_grid``; pure
    flicker is the grid's first point) and reported as :attr:`NoiseTerms.bias_gm`: a
    constant B extended to the long taus, where a real sum of Gauss–Markov processes
    falls, took K 15-60 % low on the MEMS presets.
``"ols"``
    The same with unit weights (the paper-compatible mode of spec 001 §3.4 item 3).
``"slope"``
    Automated IEEE 952 slope reading (spec 001 §3.4 item 1; ``noise/terms/_slope.py``).
``"gmwm"``
    Generalized method of wavelet moments (:mod:`inertialab.noise.gmwm.fit`) on the dyadic
    points of the curve (the Haar wavelet variance is half the Allan variance there).

Intervals: a parametric bootstrap on the fitted noise model in the
Allan domain. Each replicate draws every fitted tau's AVAR as
``model_i chi2(edf_i)/edf_i`` (Greenhall EDF of the model's noise type), correlated
across taus through a Gaussian copula whose correlation is a Markov chain in log2(tau)
with the measured one-octave correlation of the dominant noise type
(:data:`OCTAVE_RHO`), and is refitted by the same method (the B corners profiled
again); the term's interval is the percentile interval at ``confidence`` (default
0.95). Drawing records instead would cost a full simulation and Allan pass per replicate
(seconds on a 10-h log); the Allan-domain draw is the same model's sampling law to the
extent the copula captures the dependence of the taus, which the coverage benchmark
(benchmarks/noise_terms.py) measures. A term whose lower percentile is at 0 (or, for Q,
at or below 0), or that never carries :data:`READ_SHARE` of the model at a fitted tau,
is not significant: it is reported with
``ci = [0, upper]``, flag ``upper_bound`` and the reason. (The second rule matters
because neighbouring octave AVAR estimates are correlated — they share the record — so a
term of 1 % of the curve can look significant to a bootstrap that draws the taus
independently; measured on white + random-walk data, where it produced the issue's
spurious Q.)

B is IEEE 952's flat-region value ``sqrt(c_0)/0.6643``; the textbook reading
``min(sigma)/0.6643`` over the fitted taus is reported beside it
(:attr:`NoiseTerms.b_textbook`).

Units (docs/noise-terms.md): gyros report Q arcsec, N deg/sqrt(h), B deg/h,
K deg/h/sqrt(h), R deg/h^2; accelerometers Q m/s, N m/s/sqrt(h), B ug, K m/s^2/sqrt(h),
R m/s^3. N also carries ``density`` (continuous-time white-noise density: rad/s/sqrt(Hz)
for gyros, ug/sqrt(Hz) for accelerometers) and ``per_sample_std`` (the discrete
standard deviation of one sample at the record's rate: density * sqrt(rate); rad/s or
m/s^2). Estimator-specific values (Kalibr, OpenVINS, VINS, GTSAM) come from
:func:`inertialab.noise.terms.robotics.robotics_values`.

Hand-written: no maintained library fits the IEEE five-term model with EDF weights.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from inertialab import units
from inertialab.errors import InputError
from inertialab.noise.gmwm.fit import fit_gmwm_curve
from inertialab.noise.gmwm.terms import gmwm_noise_terms
from inertialab.noise.terms._bounds import B_RULES, bounded_terms, held_to_curve
from inertialab.noise.terms._slope import fit_slope
from inertialab.noise.terms.base import (  # noqa: F401 - the public names live on here too
    _GAIN,
    _NAMES,
    _NATIVE,
    _POWERS,
    _REPORT,
    _TERM_ALPHA,
    BI_FACTOR,
    CONFIDENCE,
    EDF_MIN,
    N_BOOT,
    OCTAVE_RHO,
    READ_SHARE,
    NoiseTerm,
    NoiseTerms,
    _Converter,
    _nan,
    auto_tau_range,
    local_slopes,
    not_static_reason,
)
from inertialab.noise.terms.least_squares import fit_ls, short_end_cut


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
        why = not_static_reason(taus, dev) if cut else None
        if cut:
            raise InputError(
                f"only {int(sel.sum())} of {int(sel.sum()) + cut} taus are left to fit "
                f"noise terms after the rising start of the curve (cut below "
                f"{taus[np.nonzero(sel)[0][0]] if sel.any() else taus[-1]:g} s); "
                + (why if why else "too few taus remain beyond it (a short record, or one "
                          "whose gaps leave few usable taus)"))
        raise InputError(f"need at least 3 taus with a positive deviation in "
                         f"[{lo:g}, {hi:g}] s to fit noise terms, got {int(sel.sum())}")
    return sel, cut


def fit_noise_terms(result, *, unit: str, kind: str | None = "gyro", method: str = "wls",
                    rate_hz: float | None = None, tau_range_s=None,
                    g_local: float = units.G_STANDARD, n_reweight: int = 5,
                    confidence: float = CONFIDENCE, n_boot: int | None = None, seed: int = 0,
                    auto_range: bool = True, b_shape: str = "band",
                    lines=(), b_rule: str = "interval") -> NoiseTerms:
    """Fit Q N B K R to a :class:`~inertialab.noise.statistics.allan.DeviationResult`.

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
        "gmwm" uses the curve's dyadic taus (use :func:`inertialab.noise.gmwm.fit.fit_gmwm`
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
        Confidence of the term intervals.
    n_boot : int, optional
        Bootstrap replicates (0: no intervals, NaN); default 200 (50 for "gmwm", whose
        refits cost ~0.1 s each).
    seed : int, default 0
        Seed of the bootstrap.
    auto_range : bool, default True
        Cut the filter-coloured short taus (:func:`auto_tau_range`).
    b_shape : {"band", "flicker"}, default "band"
        "wls"/"ols" only: B as band-limited flicker with profiled corners (the default,
        for a bias instability that is a sum of Gauss–Markov processes), or IEEE 952's
        textbook constant ``c_0`` at every tau (the conventional five-term fit, kept as the
        baseline; on the MEMS presets it takes K low, docs/noise-terms.md §3).
    lines : sequence of :class:`inertialab.noise.spectral.lines.Line`, optional
        Spectral lines of the record (:func:`inertialab.noise.spectral.lines.spectral_lines`):
        their Allan variance (IEEE 952 sinusoidal term) is taken off the curve before the
        fit, taus where a line carries more than half the Allan variance are left out,
        and the lines are part of the returned model (:attr:`NoiseTerms.lines`).
    b_rule : {"interval", "literal"}, default "interval"
        How B is held to the curve (:mod:`inertialab.noise.terms._bounds`): "literal"
        holds every B, estimate or bound, to 1.05 min(ADEV)/0.664 (what ``allan --imu``
        shows a filter's user); the default holds a significant estimate to the curve's
        least simultaneous 95 % upper limit instead (spec 001's recovery of a
        band-limited flicker B).

    Raises
    ------
    InputError
        Unknown unit or method, unit of the wrong dimension, fewer than 3 usable taus.

    Examples
    --------
    White rate noise of 0.1 deg/s at 100 Hz is an angle random walk ``N = sigma /
    sqrt(fs)`` = 0.01 deg/s/sqrt(Hz) = 0.6 deg/sqrt(h), and nothing else:

    >>> import numpy as np
    >>> y = np.random.default_rng(0).normal(0.0, 0.1, 20_000)
    >>> from inertialab.noise.statistics.allan import oadev
    >>> terms = fit_noise_terms(oadev(y, rate_hz=100.0), unit="dps", n_boot=0)
    >>> terms.N.unit, bool(abs(terms.N.value - 0.6) < 0.03)
    ('deg/sqrt(h)', True)
    >>> float(terms.K.value), float(terms.R.value)
    (0.0, 0.0)"""
    conv = _Converter(unit, kind, g_local)
    _check_options(method, confidence, b_shape, b_rule)
    if rate_hz is None:
        rate_hz = 1.0 / float(result.tau0_s)
    if n_boot is None:
        n_boot = 50 if method == "gmwm" else N_BOOT
    lines, raw = tuple(lines or ()), result
    if lines:
        result = _without_lines(result, lines)
    sel, _ = _select(result, tau_range_s, auto_range and method != "gmwm")
    if method == "slope":
        terms = fit_slope(result, sel, conv, rate_hz, n_boot=n_boot, seed=seed)
    elif method == "gmwm":
        if auto_range and tau_range_s is None:
            # the short taus the five-term fit leaves out (filter, quantiser: structure no
            # noise model holds at their EDFs) are left out of GMWM's scales too
            cut = short_end_cut(result, _select(result, None, True)[0], n_reweight)
            if cut.size:
                sel = sel & (np.arange(sel.size) > cut[-1])
        g = fit_gmwm_curve(result, sel, confidence=confidence, n_boot=n_boot, seed=seed)
        terms = gmwm_noise_terms(g, conv, rate_hz, result)
    else:
        terms = fit_ls(result, sel, conv, rate_hz, method, n_reweight, confidence, n_boot,
                       seed, band=b_shape == "band")
    # B within the curve, an unresolved term a bound (noise.terms._bounds)
    terms = bounded_terms(terms, result, conv, model_intervals(result, terms),
                          b_rule=b_rule, raw=raw)
    return replace(terms, lines=lines) if lines else terms


def _check_options(method: str, confidence: float, b_shape: str, b_rule: str) -> None:
    """Refuse a setting of :func:`fit_noise_terms` outside its choices."""
    if method not in ("wls", "ols", "slope", "gmwm"):
        raise InputError(f"unknown noise-term method '{method}' (use wls, ols, slope, gmwm)")
    if not 0 < confidence < 1:
        raise InputError(f"confidence must be in (0, 1), got {confidence}")
    if b_shape not in ("band", "flicker"):
        raise InputError(f"b_shape must be 'band' or 'flicker', got {b_shape!r}")
    if b_rule not in B_RULES:
        raise InputError(f"b_rule must be one of {', '.join(B_RULES)}, got {b_rule!r}")


#: a tau where the lines carry more than this share of the Allan variance is not fitted
LINE_SHARE_MAX = 0.5


def _without_lines(result, lines):
    """The curve with the lines' Allan variance taken off (NaN where they carry more
    than :data:`LINE_SHARE_MAX` of it: those taus tell about the line, not the noise)."""
    from inertialab.noise.spectral.lines import line_avar

    taus = np.asarray(result.taus_s, dtype=float)
    avar = np.asarray(result.dev, dtype=float) ** 2
    la = line_avar(taus, lines)
    rest = avar - la
    with np.errstate(invalid="ignore"):
        keep = rest > (1.0 - LINE_SHARE_MAX) * avar
        f = np.where(keep, np.sqrt(np.where(keep, rest, 1.0) / avar), np.nan)
    return replace(result, dev=np.asarray(result.dev) * f,
                   ci_low=np.asarray(result.ci_low) * f, ci_high=np.asarray(result.ci_high) * f)


# ----------------------------------------------------------------------------- identification


def model_alpha(terms: NoiseTerms, taus_s) -> np.ndarray:
    """Noise type (rate PSD exponent) of the fitted model's dominant term at ``taus_s``:
    Q +2, N 0, B -1, K and R -2."""
    contrib = terms.contributions(np.asarray(taus_s, dtype=float))
    return np.array([_TERM_ALPHA[j] for j in np.argmax(contrib, axis=1)], dtype=np.int64)


def model_intervals(result, terms: NoiseTerms, *, min_points: int = 1000):
    """The curve's intervals with the noise type following the fitted model, for rate
    records of inertial sensors.

    The lag-1 identification is kept where it is significant: decided on at least
    ``min_points`` decimated points (lag-1 ACF standard error <= 0.03, well below the 0.25
    spacing of the noise classes in ``delta``) *and* not calling angle noise (alpha >= +1)
    where the model says white rate or slower noise dominates. Everywhere else the model's
    alpha is used; the EDF (Greenhall) and the chi-square interval are recomputed. Clock
    (angle/phase) records and user-given noise types are returned unchanged.
    """
    from inertialab.noise.statistics.edf import chi2_interval, edf

    if result.input != "rate" or result.alpha_method == "user":
        return result
    ma = model_alpha(terms, result.taus_s)
    alpha = np.asarray(result.alpha, dtype=np.int64).copy()
    n_pts = result.n_samples // np.maximum(np.asarray(result.m), 1)
    src = list(result.alpha_source) or ["lag1"] * alpha.size
    new_src = []
    for i in range(alpha.size):
        weak = n_pts[i] < min_points or src[i] not in ("lag1", "acf")
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


__all__ = ["BI_FACTOR", "B_RULES", "CONFIDENCE", "EDF_MIN", "N_BOOT", "NoiseTerm",
           "NoiseTerms", "auto_tau_range", "fit_noise_terms", "held_to_curve", "local_slopes",
           "model_alpha", "model_intervals", "not_static_reason"]
