"""Report section and figures of the Allan study (the noise core: IEEE Std 952 noise
terms, NIST SP 1065 statistics).

:func:`deviation_figure` draws the log-log deviation curves with their confidence bars,
the fitted five-term model and each term's own line; the ``allan`` CLI writes it with
``--out`` and the demo report embeds it. :func:`recovery_figure` shows the per-seed
relative errors of N, K and B against the acceptance bands.
"""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt
import numpy as np

from inertialab.report.section import Figure, Section, Table
from inertialab.studies.base import StudyResult

_UNIT_LABEL = {"dph": "deg/h", "dps": "deg/s", "rps": "rad/s", "mps2": "m/s²", "g": "g", "1": "1",
               "mg": "mg", "ug": "µg"}
_TERM_STYLE = {"Q": ("tab:purple", "Q (slope −1)"), "N": ("tab:blue", "N (slope −½)"),
               "B": ("tab:green", "B (flat)"), "K": ("tab:orange", "K (slope +½)"),
               "R": ("tab:red", "R (slope +1)")}


def deviation_figure(analysis, *, truth_curve=None, name: str = "allan") -> Figure:
    """Log-log deviations with CI bars, fitted model and term lines.

    ``analysis`` is a :class:`inertialab.workflows.allan.AllanAnalysis`; ``truth_curve``
    an optional ``(taus_s, dev)`` pair (virtual lab). Statistics in another unit (TDEV,
    TTOT, MTIE, TIE rms: the phase unit) get their own panel; a curve of more than
    :data:`BAND_ABOVE` taus (``taus="all"``/"many") draws its interval as a band instead
    of bars, so that the figure stays readable.
    """
    groups: dict = {}
    for r in analysis.results:
        groups.setdefault(analysis.dev_unit(r.statistic), []).append(r)
    if analysis.unit in groups:  # the rate-unit panel first (it carries the terms)
        groups = {analysis.unit: groups.pop(analysis.unit), **groups}
    n = len(groups)
    fig, axes = plt.subplots(1, n, figsize=(7.5 if n == 1 else 6.0 * n, 5.2), squeeze=False)
    markers = "osd^v<>"
    i = 0
    for ax, (unit_key, results) in zip(axes[0], groups.items()):
        for r in results:
            lo = np.clip(r.dev - r.ci_low, 0, None)
            hi = np.clip(r.ci_high - r.dev, 0, None)
            ok = np.isfinite(lo) & np.isfinite(hi)
            has_ci = bool(ok.any())
            lab = r.statistic.upper() + (f" ({r.confidence:.1%} CI)" if has_ci else "")
            if r.taus_s.size > BAND_ABOVE:
                line, = ax.plot(r.taus_s, r.dev, "-", lw=1.2, label=lab)
                if has_ci:
                    ax.fill_between(r.taus_s[ok], r.ci_low[ok], r.ci_high[ok],
                                    color=line.get_color(), alpha=0.2, lw=0)
            elif has_ci:
                ax.errorbar(r.taus_s[ok], r.dev[ok], yerr=[lo[ok], hi[ok]],
                            fmt=markers[i % 7], ms=4, capsize=2, lw=1, label=lab)
            else:
                ax.plot(r.taus_s, r.dev, markers[i % 7] + "-", ms=4, lw=1, label=lab)
            i += 1
        if unit_key == analysis.unit:
            _terms_and_truth(ax, analysis, truth_curve)
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel("averaging time τ (s)")
        ax.set_ylabel(f"deviation ({_UNIT_LABEL.get(unit_key, unit_key)})")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=7, loc="best")
    terms = analysis.terms is not None
    axes[0][0].set_title("Allan family with confidence intervals"
                         + (" and noise terms" if terms else ""))
    return Figure(fig, "Deviations with EDF-based confidence bars (bands for dense tau sets)"
                  + ("; the fitted five-term model (solid) and each term's line (dashed)."
                     if terms else "."), name=name)


#: More taus than this: intervals drawn as a band, not bars.
BAND_ABOVE = 40


def _terms_and_truth(ax, analysis, truth_curve) -> None:
    t = analysis.terms
    if t is not None and analysis.oadev is not None:
        taus = np.geomspace(analysis.oadev.taus_s[0], analysis.oadev.taus_s[-1], 200)
        ax.plot(taus, t.model_dev(taus), "k-", lw=1.4, label=f"five-term fit ({t.method})")
        for k, line in t.term_devs(taus).items():
            if np.all(~np.isfinite(line)):
                continue
            color, lab = _TERM_STYLE[k]
            term = getattr(t, k)
            lo_hi = np.asarray(term.tau_range_s, dtype=float)
            if np.all(np.isfinite(lo_hi)):  # each term only over the taus it was read on
                line = np.where((taus >= lo_hi[0]) & (taus <= lo_hi[1]), line, np.nan)
            ax.plot(taus, line, "--", color=color, lw=1,
                    label=f"{lab} = {term.value:.3g} {term.unit}")
    if truth_curve is not None:
        ax.plot(truth_curve[0], truth_curve[1], ":", color="0.4", lw=1.5, label="truth (model)")


def recovery_figure(rec: dict, name: str = "allan_recovery") -> Figure:
    """Per-seed relative errors of N, K (allan-rrw) and N, B (allan-bi)."""
    fig, ax = plt.subplots(figsize=(7.5, 3.8))
    series = [("N, allan-rrw", rec["allan-rrw"]["N"], 0.05, "tab:blue"),
              ("K, allan-rrw", rec["allan-rrw"]["K"], 0.05, "tab:orange"),
              ("N, allan-bi", rec["allan-bi"]["N"], 0.05, "tab:cyan"),
              ("B, allan-bi", rec["allan-bi"]["B"], 0.20, "tab:green")]
    for i, (_lab, vals, tol, color) in enumerate(series):
        v = np.array([np.nan if x is None else x for x in vals], dtype=float) * 100
        ax.plot(np.full(v.size, i) + np.linspace(-0.2, 0.2, v.size), v, "o", ms=4,
                color=color)
        ax.hlines([-tol * 100, tol * 100], i - 0.35, i + 0.35, colors="0.3", linestyles="--",
                  lw=1)
    ax.set_xticks(range(len(series)), [s[0] for s in series])
    ax.axhline(0, color="0.6", lw=0.8)
    ax.set_ylabel("relative error (%)")
    ax.set_title("Noise-term recovery over seeds (10-h records, WLS); dashed: acceptance band")
    ax.grid(True, axis="y", alpha=0.3)
    return Figure(fig, "Relative error of the WLS noise terms per seed on the identification "
                       "presets of the FOG vibration study (Fang, Shen and Chen); the "
                       "acceptance target is N and K within 5 % and B within 20 % in at "
                       "least 18 of 20 seeds.", name=name)


def section(result: StudyResult) -> Section:
    """The ``allan`` section of the demo report."""
    d = result.data
    tables = []
    rows = [[r["term"], r["unit"], r["truth"], r["wls"], f"[{r['wls_ci'][0]:.3g}, "
             f"{r['wls_ci'][1]:.3g}]", r["slope"]] for r in result.tables["allan_test"]["terms"]]
    tables.append(Table("Noise terms of the allan-test record (truth, WLS with 68.3 % "
                        "interval, slope reading)",
                        ["term", "unit", "truth", "WLS", "WLS interval", "slope"], rows,
                        note="Slope reading is biased where two terms overlap (Q and N "
                             "here); WLS fits all five at once."))
    rec = result.tables["recovery"]
    tables.append(Table("Recovery over seeds (WLS)",
                        ["check", "within band", "seeds"],
                        [["N within 5 %", rec["N_within_5pct"][0], rec["N_within_5pct"][1]],
                         ["K within 5 % (allan-rrw)", rec["K_within_5pct"][0],
                          rec["K_within_5pct"][1]],
                         ["B within 20 % (allan-bi)", rec["B_within_20pct"][0],
                          rec["B_within_20pct"][1]]], fmt="d"))
    figs = []
    if "analysis" in d:
        figs.append(deviation_figure(d["analysis"], truth_curve=d.get("truth_curve")))
    if "recovery" in d:
        figs.append(recovery_figure(d["recovery"]))
    return Section(key="allan", title=result.title, paragraphs=list(result.text),
                   tables=tables, figures=figs, results=result.tables,
                   settings=result.settings)


__all__ = ["deviation_figure", "recovery_figure", "section"]
