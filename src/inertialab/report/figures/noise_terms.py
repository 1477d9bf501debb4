"""Figures of the noise-term fit and the GMWM.

:func:`allan_terms_figure`: the Allan deviation with its confidence intervals, the fitted
sum over the fitted taus, each term's own line drawn only over the tau range it was
read on (dotted where the term is only an upper bound), and the textbook B marker
``min(sigma)`` (= 0.6643 B_textbook) beside the IEEE 952 flat-region line.
:func:`gmwm_figure`: the Haar wavelet variance with its intervals, the fitted model and
each latent process. Both only draw: the numbers come from the fitted objects.
"""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt
import numpy as np

from inertialab.report.section import Figure

_STYLE = {"Q": ("tab:purple", "Q"), "N": ("tab:blue", "N"), "B": ("tab:green", "B"),
          "K": ("tab:orange", "K"), "R": ("tab:red", "R")}
_PROC = {"WN": "tab:blue", "QN": "tab:purple", "RW": "tab:orange", "DR": "tab:red",
         "GM": "tab:green", "BL": "tab:olive", "FL": "0.5"}


def allan_terms_figure(result, terms, *, unit_label: str | None = None, truth=None,
                       name: str = "noise-terms") -> Figure:
    """Allan deviation, fitted sum, per-term lines over their read ranges, textbook B.

    ``result``: the :class:`~inertialab.noise.statistics.allan.DeviationResult` the terms were
    fitted on; ``terms``: its :class:`~inertialab.noise.terms.fit.NoiseTerms`; ``truth``: an
    optional ``(taus_s, dev)`` curve (virtual lab).
    """
    fig, ax = plt.subplots(figsize=(7.5, 5.2))
    lo = np.clip(result.dev - result.ci_low, 0, None)
    hi = np.clip(result.ci_high - result.dev, 0, None)
    ok = np.isfinite(lo) & np.isfinite(hi) & (result.dev > 0)
    ax.errorbar(result.taus_s[ok], result.dev[ok], yerr=[lo[ok], hi[ok]], fmt="o", ms=4,
                capsize=2, lw=1, color="k",
                label=f"{result.statistic.upper()} ({result.confidence:.1%} CI)")
    t0, t1 = terms.tau_range_s
    taus = np.geomspace(t0, t1, 200)
    ax.plot(taus, terms.model_dev(taus), "-", color="0.2", lw=1.6,
            label=f"fitted sum ({terms.method})")
    lines = terms.term_devs(np.geomspace(result.taus_s[0], result.taus_s[-1], 400))
    grid = np.geomspace(result.taus_s[0], result.taus_s[-1], 400)
    for k, line in lines.items():
        term = getattr(terms, k)
        a, b = term.tau_range_s
        if not (np.isfinite(a) and np.isfinite(b)) or np.all(~np.isfinite(line)):
            continue
        on = (grid >= a * 0.999) & (grid <= b * 1.001)
        if on.sum() < 2:  # a single read tau: a short segment of half an octave each way
            on = (grid >= a / 1.41) & (grid <= b * 1.41)
        color, lab = _STYLE[k]
        bound = "upper_bound" in term.flags
        val = term.upper_bound if bound else term.value
        ax.plot(grid[on], line[on], ":" if bound else "--", color=color, lw=1.4,
                label=f"{lab} {'< ' if bound else '= '}{val:.3g} {term.unit}")
    if terms.b_textbook:
        tb = terms.b_textbook
        i = int(np.argmin(np.abs(np.log(result.taus_s / tb["tau_s"]))))
        ax.plot([result.taus_s[i]], [result.dev[i]], marker="*", ms=13, color="tab:green",
                ls="none", label=f"textbook B = min σ/0.664 = {tb['value']:.3g} {tb['unit']}")
    if truth is not None:
        ax.plot(truth[0], truth[1], ":", color="0.5", lw=1.2, label="truth (model)")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("averaging time τ (s)")
    ax.set_ylabel(f"Allan deviation ({unit_label or terms.unit})")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=7, loc="best")
    return Figure(fig, "Allan deviation with intervals; the fitted sum over the fitted taus; "
                  "each term drawn only where it was read (dotted: upper bound); star: the "
                  "textbook B reading min(σ)/0.664.", name)


def gmwm_figure(fit, *, unit_label: str = "", name: str = "gmwm") -> Figure:
    """Haar wavelet variance with intervals, the GMWM model and each latent process.

    ``fit``: a :class:`~inertialab.noise.gmwm.fit.GmwmFit`."""
    wv = fit.wv
    fig, ax = plt.subplots(figsize=(7.5, 5.2))
    lo = np.clip(wv.wv - wv.ci_low, 0, None)
    hi = np.clip(wv.ci_high - wv.wv, 0, None)
    ax.errorbar(wv.taus_s, wv.wv, yerr=[lo, hi], fmt="o", ms=4, capsize=2, lw=1, color="k",
                label=f"Haar wavelet variance ({wv.confidence:.0%} CI)")
    taus = np.geomspace(wv.taus_s[0], wv.taus_s[-1], 300)
    ax.plot(taus, fit.model_wv(taus), "-", color="0.2", lw=1.6,
            label=f"GMWM model {fit.name} (WIC {fit.wic:.1f})")
    for i, (kind, line) in enumerate(fit.process_wv(taus)):
        if kind == "FL":  # the filter remainder is negative: drawn as its magnitude
            line = np.abs(line)
        p = fit.processes[i]
        par = ", ".join(f"{k}={v:.3g}" for k, v in p.params.items())
        ax.plot(taus, line, "--", color=_PROC.get(kind, "0.5"), lw=1.1, label=f"{kind} ({par})")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("scale τ (s)")
    ax.set_ylabel(f"wavelet variance ({unit_label}²)" if unit_label else "wavelet variance")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=7, loc="best")
    return Figure(fig, "Haar wavelet variance with intervals, the GMWM model selected by "
                  "the wavelet information criterion and each latent process.", name)


__all__ = ["allan_terms_figure", "gmwm_figure"]
