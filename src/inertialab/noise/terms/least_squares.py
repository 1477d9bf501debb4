"""Least-squares fit of the five-term model with bootstrap intervals (the "wls" and "ols"
methods of :func:`inertialab.noise.terms.fit.fit_noise_terms`).

See :mod:`inertialab.noise.terms.fit` for the method; this module holds its core: the
Greenhall EDF table, the reweighted bounded least squares with the signed ``c_-2``,
the observability rule, the correlated Allan-domain bootstrap and the conversion of
coefficients and replicates into :class:`~inertialab.noise.terms.fit.NoiseTerm`.
"""

from __future__ import annotations

import itertools
import math
from dataclasses import replace

import numpy as np

from inertialab.noise.terms._grid import (
    _cross,
    _design,
    _n_shape_params,
    _rise_start,
    _shapes_for,
)
from inertialab.noise.terms.base import (
    _GAIN,
    _NAMES,
    _POWERS,
    _REPORT,
    _TERM_ALPHA,
    BI_FACTOR,
    EDF_MIN,
    OCTAVE_RHO,
    READ_SHARE,
    STATIC_PEAK_MAX_S,
    NoiseTerm,
    NoiseTerms,
    span_intervals,
)


def _edf_table(result, sel):
    """Greenhall EDF of each selected tau for each term's noise type, shape (5, k)."""
    from inertialab.noise.statistics.edf import GREENHALL_STATS, edf_greenhall

    stat = result.statistic if result.statistic in GREENHALL_STATS else "oadev"
    n_phase = result.n_samples + 1 if result.input == "rate" else result.n_samples
    ms = np.asarray(result.m)[sel]
    if n_phase <= 1:
        e = np.asarray(result.edf, dtype=float)[sel]
        return np.tile(np.where(np.isfinite(e) & (e > 0), e, 1.0), (5, 1))
    cache = {}
    out = np.empty((5, ms.size))
    for j, a in enumerate(_TERM_ALPHA):
        if a not in cache:
            cache[a] = np.array([edf_greenhall(stat, n_phase, int(m), a) for m in ms])
        out[j] = cache[a]
    return np.where(np.isfinite(out) & (out > 0), out, 1.0)


#: a non-significant R: the N, B, K, Q intervals span the fits with and without R (see
#: fit_ls and :func:`_span_without_r`)
_SPAN_WITHOUT_R = True


def _subset_solutions(A, B, free, nonneg):
    """Least squares of ``B ~ A c`` on every support ``free + S``, ``S`` a subset of
    ``nonneg`` columns, for a stack of designs at once.

    ``A``: (n_design, k, p) scaled weighted designs; ``B``: (n_b, k) weighted right-hand
    sides. Returns ``(c, chi)`` with ``c``: (n_design, n_b, p) and ``chi``: (n_design, n_b),
    the least chi-square over the supports whose ``nonneg`` coefficients are all >= 0.

    This is the exact NNLS optimum (the constrained optimum is the unconstrained one on
    its own support, and every feasible support's solution is a feasible point), found by
    enumeration: the fit has at most four sign-constrained columns (16 supports), and the
    corner profiling solves ~100 corner pairs x 200 bootstrap replicates per fit, where
    one scipy ``nnls`` call per problem cost 8 of the quick demo's 9.3 s in per-call
    overhead (measured with cProfile)."""
    nd, k, p = A.shape
    nb = B.shape[0]
    best_c = np.zeros((nd, nb, p))
    best_chi = np.full((nd, nb), math.inf)
    for r in range(len(nonneg) + 1):
        for S in itertools.combinations(nonneg, r):
            cols = list(free) + list(S)
            if not cols:
                chi = np.broadcast_to(np.sum(B * B, axis=1), (nd, nb))
                c = np.zeros((nd, nb, 0))
            else:
                As = A[:, :, cols]
                c = np.einsum("dpk,bk->dbp", _pinv(As), B)
                res = B[None, :, :] - np.einsum("dkp,dbp->dbk", As, c)
                chi = np.sum(res * res, axis=2)
                if S:
                    chi = np.where(np.all(c[:, :, len(free):] >= 0.0, axis=2), chi, math.inf)
            better = chi < best_chi
            if np.any(better):
                full = np.zeros((nd, nb, p))
                full[:, :, cols] = c
                best_c = np.where(better[:, :, None], full, best_c)
                best_chi = np.where(better, chi, best_chi)
    return best_c, best_chi


def _pinv(As) -> np.ndarray:
    """Pseudo-inverses of a stack of full-column-rank designs ``As`` (n, k, p) by QR,
    ``R^-1 Q^T`` (3-4x cheaper than numpy's SVD-based ``pinv``, which took 80 % of the
    profiled fit with the K-time grid); a stack with a (near-)singular R, which QR does
    not handle, goes through ``pinv`` with ``rcond=1e-13``."""
    q, r = np.linalg.qr(As)
    d = np.abs(np.diagonal(r, axis1=1, axis2=2))
    if not np.all(d > 1e-11 * np.max(d, axis=1, keepdims=True)):
        return np.linalg.pinv(As, rcond=1e-13)
    return np.linalg.inv(r) @ np.swapaxes(q, 1, 2)


def _wnnls_many(Xs, B, w, active):
    """Weighted NNLS of every right-hand side ``B`` (n_b, k) on every design ``Xs``
    (n_design, k, 5): ``c_k >= 0`` except the free ``c_-2``. Returns ``(c, chi2)``:
    (n_design, n_b, 5) and (n_design, n_b), ``chi2 = sum w (b - X c)^2``."""
    cols = [j for j in range(5) if active[j]]
    sw = np.sqrt(w)
    A = Xs[:, :, cols] * sw[None, :, None]
    scale = np.linalg.norm(A, axis=1)
    scale[scale == 0] = 1.0
    free = [0] if 0 in cols else []
    nonneg = [i for i, j in enumerate(cols) if j != 0]
    cs, chi = _subset_solutions(A / scale[:, None, :], np.atleast_2d(B) * sw[None, :],
                                free, nonneg)
    c = np.zeros(cs.shape[:2] + (5,))
    c[:, :, cols] = cs / scale[:, None, :]
    return c, chi


def _solve_many(X, B, edf_tab, active, weighted: bool, n_iter: int, shapes=None, model=None,
                edf=None):
    """Reweighted LS of every row of ``B`` (n_b, k) on ``X c`` with ``c_k >= 0`` except
    the signed ``c_-2``; with ``shapes`` (:func:`_shapes_for`) the B column is the
    band-limited shape and the K column the Gauss–Markov-limited random walk, and their
    corners and correlation time are profiled: each pass solves every grid point with the
    same weights and keeps the least chi-square, a finite K time paying
    :data:`K_TIME_PENALTY` (the first point on a tie).
    ``model``, ``edf``: the AVAR and EDF the first pass's weights come from (default the
    data and the white-noise EDF; with several rows the weights are shared, so pass
    ``model`` and use one pass).

    Returns ``(c, model, dom, i_band)`` per row: coefficients (0 where inactive), the
    model, the index of its dominant term per tau and the chosen corner pair (0 without
    shapes)."""
    B = np.atleast_2d(np.asarray(B, dtype=float))
    nb, k = B.shape
    if model is None:
        if nb != 1:
            raise ValueError("several right-hand sides need a shared model for the weights")
        model = B[0].copy()
    model = np.asarray(model, dtype=float)
    edf = edf_tab[1] if edf is None else edf
    band = shapes is not None and (active[2] or active[3])
    if band:
        Xs = np.repeat(X[None, :, :], shapes.shape[0], axis=0)
        Xs[:, :, 2] = shapes[:, :, 0]
        Xs[:, :, 3] = shapes[:, :, 1]
        penalty = shapes.penalty if active[3] else np.where(shapes.penalty > 0, np.inf, 0.0)
    else:
        Xs = X[None, :, :]
    c = np.zeros((nb, 5))
    i_band = np.zeros(nb, dtype=np.int64)
    dom = np.ones((nb, k), dtype=np.int64)
    for _ in range(n_iter if weighted else 1):
        w = edf / (2.0 * model * model) if weighted else np.ones(k)
        cc, chi = _wnnls_many(Xs, B, w, active)
        if band:
            i_band = np.argmin(chi + penalty[:, None], axis=0)
        c = cc[i_band, np.arange(nb)] if band else cc[0]
        Xb = Xs[i_band] if band else np.broadcast_to(Xs[0], (nb, k, 5))
        contrib = Xb * c[:, None, :]
        new = contrib.sum(axis=2)
        dom = np.argmax(contrib, axis=2)
        if nb == 1:
            model = np.where(new[0] > 0.05 * B[0], new[0], np.maximum(B[0], 1e-300))
            if weighted:
                edf = edf_tab[dom[0], np.arange(k)]
    return c, model, dom, i_band


def _solve(X, avar, edf_tab, active, weighted: bool, n_iter: int, shapes=None, model=None,
           edf=None):
    """:func:`_solve_many` of one AVAR curve: ``(c, model, dom, i_band)``."""
    c, model, dom, i_band = _solve_many(X, avar, edf_tab, active, weighted, n_iter, shapes,
                                        model, edf)
    return c[0], model, dom[0], int(i_band[0])


def _observable(n_taus: int):
    """Active terms for ``n_taus`` points (two points per parameter): drop R, K, Q."""
    active = [True] * 5
    reasons = {}
    for j in (4, 3, 0):
        if n_taus >= 2 * sum(active):
            break
        active[j] = False
        reasons[_NAMES[j]] = (f"record too short: {n_taus} usable taus cannot separate "
                              f"{sum(active) + 1} terms")
    return active, reasons


def _fit_and_boot(X, avar, edf_tab, active, weighted, n_reweight, n_boot, seed, m, shapes):
    """Fit, misfit ratio and correlated Allan-domain bootstrap of one active-term set."""
    c, model, dom, i_band = _solve(X, avar, edf_tab, active, weighted, n_reweight, shapes)
    edf_dom = edf_tab[dom, np.arange(avar.size)]
    fit_rmse = float(np.sqrt(np.mean((0.5 * np.log(avar / model)) ** 2)))
    # misfit (Birge) ratio: ln(avar_hat) has variance ~2/edf; a model that cannot follow
    # the curve leaves larger residuals, and the bootstrap spread is widened by
    # sqrt(chi2/dof) when that exceeds 1 (the band's corners count as parameters)
    # (an absent B term has no corners: every pair then fits alike and the pair kept is
    # the first one, so its corners are not counted)
    n_par = int(np.count_nonzero(c)) + _n_shape_params(shapes, i_band, c)
    chi2 = float(np.sum(0.5 * edf_dom * np.log(avar / model) ** 2))
    misfit = math.sqrt(max(1.0, chi2 / max(avar.size - n_par, 1)))
    # parametric bootstrap in the Allan domain; each replicate profiles the corners again
    # (one pass, weighted with the fitted model: the replicates scatter around it)
    boot = None
    if n_boot > 0:
        rng = np.random.default_rng(seed)
        draws = _draw_avar(model, edf_dom, dom, m, n_boot, rng)
        boot = _solve_many(X, draws, edf_tab, active, weighted, 1, _cross(shapes, i_band),
                           model=model, edf=edf_dom)[0]
        boot = c[None, :] + misfit * (boot - c[None, :])
    return c, model, dom, boot, misfit, fit_rmse, i_band


#: a model discrepancy is added only where chi2/dof of the fit exceeds this: neighbouring
#: octaves are correlated (0.5-0.88), so chi2/dof scatters above 1 under a correct model
#: (0.15-1.53 on 38 of 40 seeds of five simulated presets, 4.8 and 26 on the other two),
#: while the real ADIS16405 logs give 27-234
DISCREPANCY_TRIGGER = 2.0


def _discrepancy_s2(r2, edf, dof: int) -> float:
    """Variance ``s2`` of a model discrepancy on ln AVAR that makes the residuals'
    chi-square equal its degrees of freedom: ``sum r_i^2 / (2/edf_i + s2) = dof``
    (0 where chi2/dof is at most :data:`DISCREPANCY_TRIGGER`)."""
    from scipy.optimize import brentq

    v = 2.0 / edf

    def excess(s2):
        return float(np.sum(r2 / (v + s2))) - dof

    if dof <= 0 or float(np.sum(r2 / v)) <= DISCREPANCY_TRIGGER * dof:
        return 0.0
    return float(brentq(excess, 0.0, float(np.sum(r2)) / dof + 1e-300, xtol=1e-12,
                        rtol=1e-10))


def _with_discrepancy(X, avar, edf_tab, active, n_reweight, shapes, n_iter: int = 4):
    """EDF table with a model discrepancy folded in, and its variance ``s2``.

    On real sensors the Allan curve at short taus carries structure no five-term model
    holds (the internal filter's ripple, quantisation, periodic disturbances), measured
    with EDFs of 10^5-10^6: weighted by those EDFs alone, a few short taus hold the whole
    fit and the long taus, where B, K and R are read, are left with model curves outside
    their 95 % intervals (docs/noise-terms.md §10). Each tau's ln AVAR is therefore given
    the variance ``2/edf_i + s2``, i.e. the effective EDF ``1/(1/edf_i + s2/2)``, with
    ``s2`` the random-effects variance that brings chi2/dof to 1 (the DerSimonian-Laird
    idea; refitted ``n_iter`` times). Where the model fits (every MEMS preset's misfit is
    near 1), ``s2`` is 0 and nothing changes."""
    tab = edf_tab
    s2 = 0.0
    for _ in range(n_iter):
        c, model, dom, i_band = _solve(X, avar, tab, active, True, n_reweight, shapes)
        edf_dom = edf_tab[dom, np.arange(avar.size)]
        n_par = int(np.count_nonzero(c)) + _n_shape_params(shapes, i_band, c)
        r2 = np.log(avar / model) ** 2
        new = _discrepancy_s2(r2, edf_dom, avar.size - n_par)
        if abs(new - s2) <= 0.05 * max(s2, 1e-12):
            s2 = new
            break
        s2 = new
        tab = 1.0 / (1.0 / edf_tab + 0.5 * s2)
    return (1.0 / (1.0 / edf_tab + 0.5 * s2) if s2 > 0 else edf_tab), s2


def _prepared(result, sel, weighted: bool, n_reweight: int, band: bool):
    """The taus the fit uses and what it needs of them: the selected taus less the long
    ones below :data:`EDF_MIN` and (weighted) the short ones :func:`_short_end_cut` leaves
    out; returns ``(idx, taus, avar, X, edf_tab, active, reasons, shapes)``, ``edf_tab``
    with the model discrepancy folded in (weighted)."""
    idx = np.nonzero(sel)[0]
    edf_tab = _edf_table(result, sel)
    taus = np.asarray(result.taus_s, dtype=float)[idx]
    avar = np.asarray(result.dev, dtype=float)[idx] ** 2
    active, reasons = _observable(taus.size)
    X = np.stack([taus**k for k in _POWERS], axis=1)
    shapes = _shapes_for(taus, band, avar, edf_tab)
    c, model, dom, _ = _solve(X, avar, edf_tab, active, weighted, n_reweight, shapes)
    # long taus whose EDF (for the model's noise type) is below EDF_MIN do not drag the fit
    edf_dom = edf_tab[dom, np.arange(taus.size)]
    keep = edf_dom >= EDF_MIN
    if keep.sum() >= 3 and not keep.all():
        idx, taus, avar, X, edf_tab = idx[keep], taus[keep], avar[keep], X[keep], edf_tab[:, keep]
        active, reasons = _observable(taus.size)
        shapes = _shapes_for(taus, band, avar, edf_tab)
    if weighted:
        raw_tab = edf_tab
        edf_tab, _ = _with_discrepancy(X, avar, edf_tab, active, n_reweight, shapes)
        n_cut = _short_end_cut(X, avar, raw_tab, edf_tab, active, n_reweight, shapes, taus)
        idx_cut = idx[:n_cut]
        if n_cut:
            idx, taus, avar, X = idx[n_cut:], taus[n_cut:], avar[n_cut:], X[n_cut:]
            active, reasons = _observable(taus.size)
            shapes = _shapes_for(taus, band, avar, raw_tab[:, n_cut:])
            edf_tab, _ = _with_discrepancy(X, avar, raw_tab[:, n_cut:], active, n_reweight,
                                           shapes)
    else:
        idx_cut = idx[:0]
    return idx, taus, avar, X, edf_tab, active, reasons, shapes, idx_cut


def short_end_cut(result, sel, n_reweight: int = 5) -> np.ndarray:
    """Curve indices of the short taus the weighted five-term fit leaves out
    (:func:`_short_end_cut`; empty where the model holds from the first tau): GMWM leaves
    them out too, so that both methods skip the same taus no noise model holds."""
    return _prepared(result, sel, True, n_reweight, True)[-1]


def fit_ls(result, sel, conv, rate_hz, method, n_reweight, confidence, n_boot, seed,
           band: bool = True):
    """The "wls"/"ols" fit of the selected taus (see :mod:`inertialab.noise.terms.fit`);
    ``band``: B as band-limited flicker with profiled corners (:func:`band_shape`)."""
    weighted = method == "wls"
    idx, taus, avar, X, edf_tab, active, reasons, shapes, _ = _prepared(
        result, sel, weighted, n_reweight, band)
    c, model, dom, boot, misfit, fit_rmse, i_band = _fit_and_boot(
        X, avar, edf_tab, active, weighted, n_reweight, n_boot, seed,
        np.asarray(result.m)[idx], shapes)
    Xc = _design(X, shapes, i_band)
    terms = _terms_from_coefficients(c, boot, active, reasons, Xc, taus, conv, rate_hz, method,
                                     confidence)
    # a rate ramp that is not significant: R and K share the long taus, and whether the
    # ramp is in the model moves K (an R read from the scatter of the last points takes
    # its share from K; a real ramp left out hands its rise to K). The values stay the
    # full fit's; the intervals of the other terms span both models (_span_without_r)
    if _SPAN_WITHOUT_R and active[4] and "upper_bound" in terms["R"].flags:
        refit = _one_term_refit(X, avar, edf_tab, active, weighted, n_reweight, n_boot, seed,
                                np.asarray(result.m)[idx], shapes, taus, conv, rate_hz,
                                method, confidence)
        named = (_name_the_rise(terms, dom, refit, X, avar, edf_tab, active, weighted,
                                n_reweight, n_boot, seed, np.asarray(result.m)[idx], shapes,
                                taus, conv, rate_hz, method, confidence)
                 if "upper_bound" in terms["K"].flags else None)
        if named is None:
            terms = _span_without_r(terms, refit[-1])
        else:
            terms, (c, model, dom, boot, misfit, fit_rmse, i_band) = named
    bias_gm = k_gm = None
    if shapes is not None and i_band != 0:
        lo, hi, t_k = shapes.grid[i_band]
        if c[2] > 0 and (lo > 0 or math.isfinite(hi)):
            bias_gm = {"t_lo_s": float(lo) if lo > 0 else None,
                       "t_hi_s": float(hi) if math.isfinite(hi) else None}
        if c[3] > 0 and math.isfinite(t_k):
            k_gm = {"t_s": float(t_k)}
            note = (f"a random walk held by a Gauss-Markov correlation time of {t_k:.4g} s "
                    f"(its Allan deviation turns over near {1.9 * t_k:.3g} s)")
            kt = terms["K"]
            terms["K"] = replace(kt, flags=kt.flags + ("gauss_markov",),
                                 reason=f"{kt.reason}; {note}" if kt.reason else note)
    dev_sel = np.sqrt(avar)
    i_min = int(np.argmin(dev_sel))
    kB = conv.factor("B")
    ci_lo = np.asarray(result.ci_low, dtype=float)[idx][i_min]
    ci_hi = np.asarray(result.ci_high, dtype=float)[idx][i_min]
    b_text = {"value": kB * dev_sel[i_min] / BI_FACTOR, "unit": _REPORT[conv.kind]["B"],
              "tau_s": float(taus[i_min]),
              "ci": [kB * ci_lo / BI_FACTOR, kB * ci_hi / BI_FACTOR],
              "ci_confidence": float(result.confidence)}
    return NoiseTerms(**terms, kind=conv.kind, unit=conv.unit, method=method,
                      coefficients=tuple(float(v) for v in c),
                      tau_range_s=(float(taus.min()), float(taus.max())),
                      fit_rmse_log=fit_rmse, rate_hz=float(rate_hz), confidence=confidence,
                      statistic=result.statistic, g_local=conv.g,
                      alpha_model=tuple(int(_TERM_ALPHA[j]) for j in dom),
                      b_textbook=b_text,
                      interval=f"bootstrap-allan/{n_boot}" if n_boot > 0 else "none",
                      misfit=misfit, bias_gm=bias_gm, k_gm=k_gm)


#: the short-end cut stops at this tau (s): the sensor's own filter and the disturbances
#: above a few hertz act below it (the same limit as the static check's filter peak)
SHORT_END_MAX_S = STATIC_PEAK_MAX_S
#: z of the data's own interval a short tau must leave to be cut (two-sided 95 %)
SHORT_END_Z = 1.96
#: the cut looks at the first three fitted taus (two octaves) each time
SHORT_END_SPAN = 3


def _short_end_cut(X, avar, raw_tab, edf_tab, active, n_reweight, shapes, taus) -> int:
    """How many of the shortest fitted taus to leave out because the model cannot hold
    them: the sensor's filter and disturbances above a few hertz shape the first octaves
    of a real MEMS curve at the 1 % level (the ADIS16405 accelerometers of
    docs/noise-terms.md §10: -0.7 %, +2 %, -0.6 % at 4, 8 and 16 samples), where their
    EDFs of 10^5 give intervals of +-0.3 %; no five-term model follows that, and kept in
    the fit they bend N and B.

    Starting from the discrepancy-weighted fit, the first two octaves of fitted taus are
    looked at: those whose data lie outside their own 95 % interval around the model
    (``|ln(avar/model)| > z sqrt(2/edf)`` with the raw EDF of its dominant term), below
    :data:`SHORT_END_MAX_S` and dominated by white noise (not quantisation, whose taus
    are where Q is read) are cut with
    every shorter tau, as long as white noise still dominates at least three of the taus
    left (two octaves to read N from) and every term stays observable (two taus per
    term, :func:`_observable`: a short record keeps its taus); the fit is redone and
    looked at again after each cut. A curve the
    model holds from its first tau (every MEMS preset) loses nothing."""
    n = 0
    while True:
        k = avar.size - n
        if k < 6 or taus[n] >= SHORT_END_MAX_S:
            return n
        sl = slice(n, None)
        sh = shapes if n == 0 else _shapes_for(taus[sl], shapes is not None, avar[sl],
                                               raw_tab[:, sl])
        tab = edf_tab[:, sl] if n == 0 else _with_discrepancy(
            X[sl], avar[sl], raw_tab[:, sl], active, n_reweight, sh)[0]
        c, model, dom, _ = _solve(X[sl], avar[sl], tab, active, True, n_reweight, sh)
        white = dom == 1  # white noise's taus; quantisation's (Q) are measured, not cut
        z = (np.abs(np.log(avar[sl] / model))
             / np.sqrt(2.0 / raw_tab[dom, np.arange(n, avar.size)]))
        out = (z > SHORT_END_Z) & white & (taus[sl] < SHORT_END_MAX_S)
        out[SHORT_END_SPAN:] = False
        if not out.any():
            return n
        j = int(np.flatnonzero(out)[-1]) + 1
        if int(white[j:].sum()) < 3 or avar.size - n - j < 2 * sum(active):
            return n  # N keeps two octaves, and no term becomes unobservable
        n += j


def _one_term_refit(X, avar, edf_tab, active, weighted, n_reweight, n_boot, seed, m, shapes,
                    taus, conv, rate_hz, method, confidence, drop: int = 4):
    """The fit without term ``drop`` (4: R, 3: K): ``(c, model, dom, boot, misfit,
    fit_rmse, i_band, terms)``."""
    act = list(active)
    act[drop] = False
    fit = _fit_and_boot(X, avar, edf_tab, act, weighted, n_reweight, n_boot, seed, m, shapes)
    c, boot, i_band = fit[0], fit[3], fit[6]
    terms = _terms_from_coefficients(c, boot, act, {_NAMES[drop]: ""},
                                     _design(X, shapes, i_band), taus, conv, rate_hz, method,
                                     confidence)
    return (*fit, terms)


def _chi2(avar, model, dom, edf_tab) -> float:
    edf = edf_tab[dom, np.arange(avar.size)]
    return float(np.sum(0.5 * edf * np.log(avar / model) ** 2))


def _name_the_rise(full, full_dom, without_r, X, avar, edf_tab, active, weighted, n_reweight,
                   n_boot, seed, m, shapes, taus, conv, rate_hz, method, confidence):
    """Model selection where the curve rises significantly after its minimum but K and R,
    fitted together, are both not significant (they share the rise: collinear). The two
    one-term models, K without R and R without K, have as many parameters; the one with
    the smaller chi-square on the curve (its EDFs, the model discrepancy included) names
    the rise (significant with the EDFs of the joint fit's dominant terms, ``full_dom``), and is reported when its term is significant there: ``(terms, fit)`` of
    that model, the dropped term 0 with the full fit's upper limit as its bound. None
    where the curve does not rise significantly or neither model makes its term
    significant (the intervals then span both fits, :func:`_span_without_r`)."""
    if _rise_start(taus, avar, edf_tab, full_dom) is None or not active[3]:
        return None
    without_k = _one_term_refit(X, avar, edf_tab, active, weighted, n_reweight, n_boot, seed,
                                m, shapes, taus, conv, rate_hz, method, confidence, drop=3)
    cands = [(without_r, "K", "R"), (without_k, "R", "K")]
    chi = [_chi2(avar, f[1], f[2], edf_tab) for f, _, _ in cands]
    order = np.argsort(chi)
    (fit, keep, drop), other = cands[order[0]], chi[order[1]]
    terms = dict(fit[-1])
    if "upper_bound" in terms[keep].flags or not terms[keep].value > 0:
        return None
    ub = full[drop].upper_bound
    ub = ub if np.isfinite(ub) else full[drop].ci[1]
    terms[drop] = replace(
        full[drop], value=0.0, ci=(0.0, float(ub)), upper_bound=float(ub),
        flags=("zero", "upper_bound", "not_selected"),
        reason=(f"the rise after the curve's minimum is named by {keep}: fitted together, "
                f"{keep} and {drop} share it and neither is significant; of the two "
                f"one-term models {keep}'s fits better (chi2 {chi[order[0]]:.3g} against "
                f"{other:.3g}); {drop}'s bound is the joint fit's"))
    return terms, fit[:-1]


def _span_without_r(full: dict, without_r: dict) -> dict:
    """The terms of the full fit with the N, B, K and Q intervals widened to also cover
    the fit without R (the interval carries the uncertainty of the model
    choice that a non-significant R leaves open). Measured on the MEMS presets (200
    seeds, docs/noise-terms.md §3 and §8): K coverage 87-92 % for the full fit alone, 86-96 %
    for the refit without R alone, 91-96 % for the span; its median width is 1.00-1.11x
    the refit's. The values stay the full fit's, which are the less biased (K median
    error -4 to +6 %, against +1 to +11 % without R)."""
    out = dict(full)
    for name in ("Q", "N", "B", "K"):
        a, b = full[name], without_r[name]
        if not (np.all(np.isfinite(a.ci)) and np.all(np.isfinite(b.ci))):
            continue
        ci = span_intervals(a.ci, b.ci)
        if ci == tuple(a.ci):
            continue
        ub = a.upper_bound
        if "upper_bound" in a.flags:
            ub = ci[1]
        note = "interval spans the fits with and without the non-significant R"
        out[name] = replace(a, ci=ci, upper_bound=ub, sd=max(a.sd, b.sd),
                            flags=a.flags + ("span_without_R",),
                            reason=f"{a.reason}; {note}" if a.reason else note)
    return out


def _shares(Xc, c, j):
    contrib = Xc * c[None, :]
    tot = np.sum(np.abs(contrib), axis=1)
    return np.where(tot > 0, contrib[:, j] / tot, 0.0)


def _max_share(Xc, c, j) -> float:
    return float(np.max(_shares(Xc, c, j)))


def _tau_correlation(dom, m) -> np.ndarray:
    """Correlation of the log AVAR estimates across taus: a Markov chain in log2(m) whose
    per-octave correlation is that of the dominant noise type (:data:`OCTAVE_RHO`)."""
    rho = np.array([OCTAVE_RHO[_TERM_ALPHA[j]] for j in dom])
    lm = np.log2(np.asarray(m, dtype=float))
    step = np.diff(lm) * np.log(np.sqrt(rho[1:] * rho[:-1]))
    L = np.concatenate([[0.0], np.cumsum(step)])
    return np.exp(-np.abs(L[:, None] - L[None, :]))


def _draw_avar(model, edf, dom, m, n_boot, rng):
    """Bootstrap AVARs: ``model chi2(edf)/edf`` marginals, Gaussian-copula correlation."""
    from scipy.stats import chi2, norm

    C = _tau_correlation(dom, m)
    Lc = np.linalg.cholesky(C + 1e-12 * np.eye(C.shape[0]))
    z = rng.standard_normal((n_boot, model.size)) @ Lc.T
    u = np.clip(norm.cdf(z), 1e-12, 1 - 1e-12)
    return model[None, :] * chi2.ppf(u, edf[None, :]) / edf[None, :]


def _read_range(Xc, c, taus, j):
    """Taus where term j carries >= READ_SHARE of the model (else where its share peaks)."""
    share = _shares(Xc, c, j)
    on = share >= READ_SHARE
    if not on.any():
        if c[j] <= 0:
            return (float("nan"), float("nan"))
        on = share >= share.max()
    t = taus[on]
    return (float(t.min()), float(t.max()))


def _terms_from_coefficients(c, boot, active, reasons, Xc, taus, conv, rate_hz, method, conf):
    """NoiseTerm per name from coefficients and their bootstrap replicates."""
    lo_q, hi_q = 0.5 * (1 - conf), 0.5 * (1 + conf)
    out = {}
    for j, name in enumerate(_NAMES):
        unit = _REPORT[conv.kind][name]
        k = conv.factor(name)
        if not active[j]:
            out[name] = NoiseTerm(value=float("nan"), unit=unit, ci=(float("nan"),) * 2,
                                  method=method, tau_range_s=(float("nan"),) * 2,
                                  flags=("not_observable",), reason=reasons[name])
            continue
        val = k * _GAIN[j] * math.sqrt(max(c[j], 0.0))
        flags, reason, ub, sd = [], "", float("nan"), float("nan")
        ci = (float("nan"), float("nan"))
        if c[j] <= 0:
            flags.append("zero")
        if j == 0 and c[0] < 0:
            flags.append("filter")
            reason = ("short taus show the sensor's low-pass filter (c_-2 < 0), no angle "
                      "quantisation")
        if boot is not None:
            cb = boot[:, j]
            amp = k * _GAIN[j] * np.sqrt(np.maximum(cb, 0.0))
            qlo, qhi = np.quantile(amp, [lo_q, hi_q])
            sd = float(np.std(amp, ddof=1))
            weak = _max_share(Xc, c, j) < READ_SHARE
            if np.quantile(cb, lo_q) <= 0.0 or weak:
                flags.append("upper_bound")
                ub = float(max(qhi, val))
                ci = (0.0, ub)
                if not reason:
                    reason = (f"not significant at {100 * conf:g} %: the bootstrap interval "
                              "reaches 0" if not weak else
                              f"below {100 * READ_SHARE:g} % of the curve at every fitted "
                              "tau: not read (its estimate would follow the correlated "
                              "scatter of neighbouring taus)")
            else:
                ci = (float(qlo), float(qhi))
        dens = per = None
        if name == "N":
            dens, per = conv.n_extras(val / conv.value("N", 1.0), rate_hz)
        out[name] = NoiseTerm(value=val, unit=unit, ci=ci, method=method,
                              tau_range_s=_read_range(Xc, c, taus, j), flags=tuple(flags), sd=sd,
                              density=dens, per_sample_std=per, reason=reason,
                              upper_bound=ub)
    return out


