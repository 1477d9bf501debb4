"""Figures and report section of the ``thermal`` study (spec 000).

Layouts are computed once by :func:`inertialab.report.layout.fit` when the figure is
written. Figures are built from workflow results only: drift against temperature per input
level before and after compensation (Fu et al., spec 000, Figs. 2-4 and 9), test residuals per model,
and the transfer to a second unit with its bootstrap band when there is one.
"""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt
import numpy as np

from inertialab.report.section import Figure, Section, Table

__all__ = ["bias_figure", "drift_figure", "residual_figure", "scale_factor_figure", "section"]

_LABELS = {"ann": "ANN", "fis": "FIS", "anfis": "ANFIS (grid)", "scm-anfis": "SCM-ANFIS",
           "iafsa-scm-anfis": "IAFSA-SCM-ANFIS", "poly-sep": "POLY-SEP", "poly-2d": "POLY-2D"}
_PAPER_MG = {"ann": 0.138, "fis": 0.101, "anfis": 0.034, "iafsa-scm-anfis": 0.004}


def drift_figure(samples, d, *, title: str = "", band=None, name: str = "thermal_drift") -> Figure:
    """Raw drift (mg, left) and compensated drift (µg, right) against the set point, one
    line per input level a_i (positions with the same a_i averaged)."""
    fig, (a0, a1) = plt.subplots(1, 2, figsize=(10, 3.8))
    up = samples.ramp_dir == samples.ramp_dir[0]
    levels = np.unique(np.round(samples.a_in_g[up], 3))
    cmap = plt.get_cmap("coolwarm")
    for k, lev in enumerate(levels):
        m = up & np.isclose(np.round(samples.a_in_g, 3), lev)
        sp = np.unique(samples.set_point_c[m])
        raw = [np.mean(d.raw_ug[m & (samples.set_point_c == s)]) for s in sp]
        comp = [np.mean(d.comp_ug[m & (samples.set_point_c == s)]) for s in sp]
        col = cmap(k / max(len(levels) - 1, 1))
        a0.plot(sp, np.asarray(raw) / 1e3, color=col, lw=0.9, label=f"{lev:+.3f} g")
        a1.plot(sp, comp, color=col, lw=0.9)
    if band is not None:
        lo = [np.min(band.band_lo_ug[up & (samples.set_point_c == s)])
              for s in np.unique(samples.set_point_c[up])]
        hi = [np.max(band.band_hi_ug[up & (samples.set_point_c == s)])
              for s in np.unique(samples.set_point_c[up])]
        a1.fill_between(np.unique(samples.set_point_c[up]), lo, hi, color="0.8", zorder=0,
                        label=f"95 % bootstrap band ({band.n_boot})")
        a1.legend(fontsize=7)
    a0.set_xlabel("set point (°C)")
    a0.set_ylabel("raw drift vs 55 °C (mg)")
    a0.set_title(f"before: max {d.raw_max_ug / 1e3:.2f} mg", fontsize=9)
    a1.set_xlabel("set point (°C)")
    a1.set_ylabel("compensated drift (µg)")
    a1.set_title(f"after: max {d.comp_max_ug:.1f} µg", fontsize=9)
    a0.legend(fontsize=6, ncol=2, title="a_i", title_fontsize=7)
    if title:
        fig.suptitle(title, fontsize=10)
    return Figure(fig, f"Drift against temperature per input level, before and after "
                       f"compensation{': ' + title if title else ''}.", name=name)


def bias_figure(bsf, *, title: str = "", name: str = "thermal_bias") -> Figure:
    """The seed's Fig. 3: bias (0°/180° mean) against temperature, drift vs the reference
    set point in mg. ``bsf``: :class:`inertialab.sensors.pendulous.BiasScaleFactorDrift`."""
    fig, ax = plt.subplots(figsize=(5.5, 3.6))
    ax.plot(bsf.temp_c, bsf.bias_drift_mg, "o-", ms=3, lw=1.0, color="C0")
    ax.axhline(0, color="k", lw=0.5)
    ax.axvline(bsf.reference_temp_c, color="0.6", lw=0.6, ls="--")
    ax.set_xlabel("temperature (°C)")
    ax.set_ylabel(f"bias drift vs {bsf.reference_temp_c:g} °C (mg)")
    mx = np.nanmax(np.abs(bsf.bias_drift_mg))
    ax.set_title(f"{title + ': ' if title else ''}bias drift, max {mx:.3f} mg", fontsize=9)
    return Figure(fig, "Bias (mean of the 0° and 180° positions) against temperature, "
                       f"relative to {bsf.reference_temp_c:g} °C (Fu et al., spec 000, Fig. 3).", name=name)


def scale_factor_figure(bsf, *, title: str = "", name: str = "thermal_scale_factor") -> Figure:
    """The seed's Fig. 4: eq.-3 scale factor against temperature, one line per input level,
    drift vs the reference set point in mV/g."""
    fig, ax = plt.subplots(figsize=(6.5, 3.8))
    cmap = plt.get_cmap("coolwarm")
    n = bsf.levels_g.size
    for j, lev in enumerate(bsf.levels_g):
        ax.plot(bsf.temp_c, bsf.scale_factor_drift_mv_per_g[:, j], lw=0.9,
                color=cmap(j / max(n - 1, 1)), label=f"{lev:+.3f} g")
    ax.axhline(0, color="k", lw=0.5)
    ax.set_xlabel("temperature (°C)")
    ax.set_ylabel(f"scale-factor drift vs {bsf.reference_temp_c:g} °C (mV/g)")
    mx = np.nanmax(np.abs(bsf.scale_factor_drift_mv_per_g))
    ax.set_title(f"{title + ': ' if title else ''}eq. 3 scale factor per input level, "
                 f"max |drift| {mx:.2f} mV/g", fontsize=9)
    ax.legend(fontsize=6, ncol=2, title="a_i", title_fontsize=7)
    return Figure(fig, "Scale factor (U - K0)/a_i (eq. 3) against temperature per input "
                       f"level, relative to {bsf.reference_temp_c:g} °C (Fu et al., spec 000, Fig. 4).",
                  name=name)


def residual_figure(fit, name: str = "thermal_residuals") -> Figure:
    """Test residuals (µg) against temperature, one panel per model (symmetric-log scale)."""
    s = fit.samples
    idx = fit.test_index
    models = list(fit.predictions)
    n = len(models)
    cols = min(n, 4)
    rows = int(np.ceil(n / cols))
    fig, axes = plt.subplots(rows, cols, figsize=(3.0 * cols, 2.6 * rows), squeeze=False,
                             sharey=True)
    for ax, m in zip(axes.ravel(), models):
        e = (fit.predictions[m] - s.y_mv[idx]) / s.k1 * 1e6
        ax.scatter(s.temp_c[idx], e, s=4, c=s.a_in_g[idx], cmap="coolwarm", vmin=-1, vmax=1)
        ax.set_yscale("symlog", linthresh=10.0)
        ax.axhline(0, color="k", lw=0.5)
        ax.set_title(f"{_LABELS.get(m, m)}: RMSE {fit.metrics[m].rmse_ug:.1f} µg", fontsize=8)
        ax.set_xlabel("T (°C)", fontsize=8)
    for ax in axes.ravel()[n:]:
        ax.axis("off")
    for ax in axes[:, 0]:
        ax.set_ylabel("residual (µg)", fontsize=8)
    return Figure(fig, f"Test residuals per model ({fit.config.split} split), colour = input "
                       "level a_i (blue -1 g, red +1 g).", name=name)


def metrics_table(fit) -> Table:
    rows = []
    for m, v in fit.metrics.items():
        paper = _PAPER_MG.get(m)
        rows.append([_LABELS.get(m, m), v.rmse_ug, None if paper is None else paper * 1e3,
                     v.me_ug, v.ae_ug, v.maxe_ppm, v.mare_ppm, v.rmse_truth_ug, v.rules, v.wall_s])
    return Table(title=f"Test metrics ({fit.config.split} split)",
                 columns=["model", "RMSE µg", "paper RMSE µg", "ME µg", "AE µg", "MAXE ppm",
                          "MARE ppm", "RMSE vs truth µg", "rules", "wall s"],
                 rows=rows, note=f"Raw (uncompensated) RMS drift on the test set: "
                                 f"{fit.raw_rms_ug:.0f} µg.")


def section(result) -> Section:
    """The thermal study's report section."""
    d = result.data
    fit = d["fit"]
    figs = [drift_figure(d["samples"], d["own"], title=f"unit 0, {_LABELS[d['best']]}",
                         band=d.get("bootstrap")),
            residual_figure(fit),
            drift_figure(d["samples_b"], d["transfer"],
                         title="unit 1 with unit 0's model (transfer)", name="thermal_transfer")]
    tables = [metrics_table(fit)]
    if fit.search:
        s = fit.search
        tables.append(Table(title="IAFSA search", columns=["quantity", "value"], rows=[
            ["F* (validation RMSE, µg)", s["fun"] * 1e3],
            ["F at default SCM parameters (µg)", s["f_default"] * 1e3],
            ["radius", str(s["params"]["radius"])], ["squash", s["params"]["squash"]],
            ["accept", s["params"]["accept"]], ["reject", s["params"]["reject"]],
            ["rules", s["n_rules"]], ["objective evaluations", s["nfev"]],
            ["generations", s["nit"]], ["wall s", s["wall_s"]]]))
    return Section(key="thermal", title=result.title, paragraphs=list(result.text),
                   tables=tables, figures=figs, results=result.tables, settings=result.settings)
