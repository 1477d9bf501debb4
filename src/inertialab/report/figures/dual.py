"""Figures and report section of the ``dual`` study (spec 003).

Three figures, built from calib/study results only (no numerics beyond plotting):
residuals per position and method, coefficient estimates with their SDs per method
(against truth in simulation), and the head-error sensitivity of K2 per method.
"""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt
import numpy as np

from inertialab.report.section import Figure, Section, Table
from inertialab.sensors.dual_meter import COEF_NAMES, PAPER_ALIASES, g2_design, single_design

__all__ = ["coefficient_figure", "residual_figure", "section", "sensitivity_figure"]

_COLORS = {"single-ls": "tab:red", "ls": "tab:blue", "ebr": "tab:green",
           "ridge-hkb": "tab:orange", "ridge-gcv": "tab:purple"}


def residual_figure(fit) -> Figure:
    """Residuals per position (ug) of every fitted method."""
    red = fit.reduced
    deg = np.rad2deg(red.theta)
    fig, ax = plt.subplots(figsize=(7.5, 3.6))
    for m, r in fit.methods.items():
        if m == "single-ls":
            for meter, u, mk in (("A", red.u_a, "o"), ("B", red.u_b, "s")):
                X, off = single_design(red.theta, meter, s=red.s_a if meter == "A" else red.s_b)
                names = ("KA0", "kA1", "delta_A", "KA2", "KAx") if meter == "A" else (
                    "KB0", "kB1", "delta_B", "KB2", "KBx")
                e = u - off - X @ np.array([r.coef[n] for n in names])
                ax.plot(deg, e * 1e6, mk + "-", ms=3, lw=0.8, color=_COLORS[m],
                        label=f"single-meter LS ({meter})")
        else:
            A = g2_design(red.theta, s_a=red.s_a, s_b=red.s_b)
            e = red.y - A @ np.array([r.coef[n] for n in COEF_NAMES])
            ax.plot(deg, e * 1e6, ".-", lw=0.8, color=_COLORS.get(m, "k"), label=f"{m} (g^2)")
    ax.axhline(0, color="k", lw=0.5)
    ax.set_xlabel("head angle (deg)")
    ax.set_ylabel("residual (ug)")
    ax.legend(fontsize=7, ncol=2)
    return Figure(fig, "Residuals per position: single-meter fits carry the head angle "
                       "error, the g^2 fits do not.", name="dual_residuals")


def coefficient_figure(fit, truth: dict | None = None,
                       names=("KA0", "KA2", "KAx", "KB0", "KB2", "KBx")) -> Figure:
    """Estimates +- 1 SD per method (ug or ug/g^2); SD missing = not estimable."""
    fig, axes = plt.subplots(1, len(names), figsize=(11, 3.4))
    methods = list(fit.methods)
    for ax, n in zip(np.atleast_1d(axes), names):
        for i, m in enumerate(methods):
            r = fit.methods[m]
            v = r.coef.get(n)
            if v is None:
                continue
            sd = r.sd.get(n)
            ok = sd is not None and np.isfinite(sd)
            ax.errorbar(i, v * 1e6, yerr=sd * 1e6 if ok else None, fmt="o" if ok else "x",
                        color=_COLORS.get(m, "k"), capsize=3)
        if truth is not None and n in truth:
            ax.axhline(truth[n] * 1e6, color="k", lw=0.8, ls="--")
        ax.set_title(f"{n} ({PAPER_ALIASES[n]})" if n in PAPER_ALIASES else n, fontsize=9)
        ax.set_xticks(range(len(methods)))
        ax.set_xticklabels(methods, rotation=60, fontsize=7)
        ax.tick_params(axis="y", labelsize=7)
    fig.supylabel("estimate (ug or ug/g^2)", fontsize=8)
    cap = ("Coefficient estimates with 1-SD bars per method (x: not estimable, no SD)"
           + ("; dashed: truth." if truth is not None else "."))
    return Figure(fig, cap, name="dual_coefficients")


def sensitivity_figure(sens: dict) -> Figure:
    """K2 change per method for a first-harmonic head error of a1 arc-seconds vs phase."""
    fig, ax = plt.subplots(figsize=(6.5, 3.4))
    psi = np.asarray(sens["psi_deg"])
    for m, rows in sens.items():
        if not isinstance(rows, dict):
            continue
        ax.plot(psi, np.asarray(rows["KA2"]) * 1e6, "-", color=_COLORS.get(m, "k"),
                label=f"{m}: KA2")
        ax.plot(psi, np.asarray(rows["KB2"]) * 1e6, "--", color=_COLORS.get(m, "k"),
                label=f"{m}: KB2")
    ax.set_xlabel("phase psi of the head error (deg)")
    ax.set_ylabel("change of K2 (ug/g^2)")
    ax.legend(fontsize=7, ncol=2)
    return Figure(fig, f"Head-error sensitivity: change of K2 for a {sens['a1_arcsec']:g}\" "
                       "first-harmonic dividing-head error; single-meter LS moves by "
                       "a1 sin(psi), the g^2 methods by ~0.", name="dual_head_sensitivity")


def section(result) -> Section:
    """The report section of the ``dual`` study from its :class:`StudyResult`."""
    fit = result.data["fit"]
    truth = result.data.get("truth")
    sens = result.data["sensitivity"]  # computed by studies.dual (the report only draws)
    figs = [residual_figure(fit), coefficient_figure(fit, truth), sensitivity_figure(sens)]
    rows = [[r["method"], r["residual_ug"], r["r_val_ug"], r["KA2_err"] * 1e6,
             r["KB2_err"] * 1e6, r["kA1_err"] * 1e6, r["eta_err"] * 1e6]
            for r in result.tables["single_run"]]
    t1 = Table("One virtual tumble (S1, historical prior): residuals and errors vs truth",
               ["method", "R (ug)", "R_val (ug)", "KA2 err (ug/g^2)", "KB2 err (ug/g^2)",
                "kA1 err (ppm)", "eta err (urad)"], rows)
    sw = result.tables["head_error_sweep"]
    t2 = Table("Head-error scale h: RMS error of KA2 (ug/g^2) and median residual",
               ["h", "single LS KA2", "EBR KA2", "prior only", "single LS R (ug)", "EBR R (ug)"],
               [[float(h), v["single_ls_KA2_rms"] * 1e6, v["ebr_KA2_rms"] * 1e6,
                 v["prior_KA2_rms"] * 1e6, v["single_ls_R_median_ug"], v["ebr_R_median_ug"]]
                for h, v in sw.items()])
    return Section(key="dual", title=result.title, paragraphs=list(result.text),
                   tables=[t1, t2], figures=figs,
                   results={k: v for k, v in result.tables.items()},
                   settings=result.settings)
