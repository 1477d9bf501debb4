"""Report section and figures of the ``triaxial`` study (spec 002).

Figures: measured vs corrected points on the sphere, the norm error per record, and
convergence curves (best objective per generation) of CS, ACS and PSO. The
``*_figure`` functions are also used by ``inertialab calibrate triaxial --out``.
"""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt
import numpy as np

from inertialab.report.section import Figure, Section, Table


def sphere_figure(raw, corrected, g: float, *, title: str = "") -> Figure:
    """Measured (raw) and corrected record vectors in three projections, with the g-circle."""
    raw = np.asarray(raw, dtype=float)
    cor = np.asarray(corrected, dtype=float)
    fig, axes = plt.subplots(1, 3, figsize=(11, 3.8))
    ang = np.linspace(0, 2 * np.pi, 200)
    for ax, (i, j) in zip(axes, ((0, 1), (0, 2), (1, 2))):
        ax.plot(g * np.cos(ang), g * np.sin(ang), color="0.7", lw=0.8, label="|a| = g")
        ax.scatter(raw[:, i], raw[:, j], s=10, marker="x", color="tab:red", label="measured")
        ax.scatter(cor[:, i], cor[:, j], s=10, facecolors="none", edgecolors="tab:blue",
                   label="corrected")
        ax.set_xlabel("xyz"[i] + " (m/s$^2$)")
        ax.set_ylabel("xyz"[j] + " (m/s$^2$)")
        ax.set_aspect("equal", adjustable="datalim")
    axes[0].legend(fontsize=7, loc="lower left")
    fig.suptitle(title or "Static records on the sphere: measured vs corrected")
    fig.tight_layout()
    return Figure(fig, "Record means before (x) and after (o) calibration in three projections; "
                  "the grey circle is |a| = g.", name="triaxial_sphere")


def norm_error_figure(errors: dict, *, ylabel: str = "|a_hat| - g (m/s$^2$)",
                      name: str = "triaxial_norm_error", caption: str | None = None) -> Figure:
    """Per-record error curves, one line per method (``{label: array}``)."""
    fig, ax = plt.subplots(figsize=(8, 3.6))
    for label, e in errors.items():
        e = np.asarray(e, dtype=float)
        ax.plot(np.arange(1, e.size + 1), e, marker=".", lw=0.8, label=label)
    ax.axhline(0, color="0.5", lw=0.6)
    ax.set_xlabel("record")
    ax.set_ylabel(ylabel)
    ax.legend(fontsize=7)
    fig.tight_layout()
    return Figure(fig, caption or "Norm error of each corrected record (field-mode check, "
                  "no references needed).", name=name)


def convergence_figure(histories: dict, *, floor: float = 1e-16) -> Figure:
    """Best objective per generation (log scale), one line per run, colour per method."""
    fig, ax = plt.subplots(figsize=(8, 3.8))
    colours = {"cs": "tab:orange", "acs": "tab:blue", "pso": "tab:green"}
    for m, runs in histories.items():
        for k, h in enumerate(runs):
            h = np.maximum(np.asarray(h, dtype=float), floor)
            ax.semilogy(np.arange(h.size), h, color=colours.get(m, None), lw=0.9, alpha=0.8,
                        label=m.upper() if k == 0 else None)
    ax.axhline(1e-10, color="0.4", ls="--", lw=0.7, label="target 1e-10")
    ax.set_xlabel("generation")
    ax.set_ylabel("best J (m/s$^2$)$^2$")
    ax.legend(fontsize=8)
    fig.tight_layout()
    return Figure(fig, "Convergence of CS, ACS and PSO from shared initial populations "
                  "(objective S9, noise-free sphere, spec 002 §3.9).", name="triaxial_convergence")


def section(result) -> Section:
    """The ``triaxial`` demo section from :func:`inertialab.studies.triaxial.run_demo`."""
    t = result.tables
    d = result.data
    rows = [[r["method"], r["rmse_mps2"], r["sd_mps2"], r["max_param_error"], r["iterations"]]
            for r in t["turntable62_realistic"]]
    rows.append(["paper: laboratory", 0.1103, 0.0643, None, None])
    rows.append(["paper: ACS", 0.0826, 0.0487, None, None])
    t1 = Table("turntable62-realistic: eq.-21 vector error against the rig references",
               ["method", "RMSE (m/s^2)", "SD (m/s^2)", "max |x - x_true|", "iterations"], rows,
               note="S12 fits the mount rotation phi; S9/six-position/norm cannot. The paper's "
                    "numbers come from a real MPU6050 and a real laboratory calibration.")
    cs = t["cs_acs"]
    t2 = Table(f"Generations to J <= 1e-10 ({cs['seeds']} seeds, {cs['points']} points)",
               ["method", "mean generations", "paper"],
               [["CS", cs["mean_cs"], "≈ 636 (100 pts) / 750 (1000 pts)"],
                ["ACS", cs["mean_acs"], "≈ 496 / 630 (-22 % / -16 %)"],
                ["PSO", cs["mean_pso"], "trapped in a local optimum"]])
    rl = t["rawlog62_counts"]
    t3 = Table("Raw 100 Hz log in counts with gyro (rawlog62-counts)",
               ["quantity", "value"],
               [["static intervals detected", rl["static_intervals"]],
                ["threshold multiplier k_thr (sweep)", rl["k_thr"]],
                ["accelerometer max |x - x_true|", rl["accel_max_abs_error"]],
                ["gyro max |M_g - M_true| (rad/s per rad/s)", rl["gyro_matrix_max_abs_error"]],
                ["gyro direction residual RMS (rad)", rl["gyro_residual_rms"]]])
    figs = [
        sphere_figure(d["sphere_raw"], d["sphere_corrected"], d["g"],
                      title="turntable62-realistic: measured vs LM-S12 corrected"),
        norm_error_figure(d["norm_error"]),
        norm_error_figure(d["vector_error"], ylabel="e_l (eq. 21, m/s$^2$)",
                          name="triaxial_vector_error",
                          caption="Eq.-21 vector error per turntable position (the paper's "
                                  "Fig. 7 comparison)."),
        convergence_figure(d["histories"]),
    ]
    return Section(key="triaxial", title=result.title, paragraphs=list(result.text),
                   tables=[t1, t2, t3], figures=figs, results=result.tables,
                   settings=result.settings)
