"""Report section and figures of the ``triaxial`` study (spec 002).

Figures: measured vs corrected points on the sphere, the norm error per record, and
convergence curves (best objective per generation) of CS, ACS and PSO. The
``*_figure`` functions are also used by ``inertialab triaxial fit --out``.
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
        ax.set_xlabel("xyz"[i] + " (m/s²)")
        ax.set_ylabel("xyz"[j] + " (m/s²)")
        ax.set_aspect("equal", adjustable="datalim")
    axes[0].legend(fontsize=7, loc="lower left")
    fig.suptitle(title or "Static records on the sphere: measured vs corrected")
    return Figure(fig, "Record means before (x) and after (o) calibration in three projections; "
                  "the grey circle is |a| = g.", name="triaxial_sphere")


def norm_error_figure(errors: dict, *, ylabel: str = "|a_hat| - g (m/s²)",
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
    ax.set_ylabel("best J ((m/s²)²)")
    ax.legend(fontsize=8)
    return Figure(fig, "Convergence of CS, ACS and PSO from shared initial populations "
                  "(objective S9, noise-free sphere; Qiao, Gao, Li and Zhao, ACS field "
                  "calibration).", name="triaxial_convergence")


def section(result) -> Section:
    """The ``triaxial`` demo section from :func:`inertialab.studies.triaxial.run_demo`."""
    t = result.tables
    d = result.data
    rows = [[r["method"], r["rmse_mps2"], r["sd_mps2"], r["max_param_error"], r["iterations"]]
            for r in t["turntable62_realistic"]]
    rows.append(["paper: laboratory", 0.1103, 0.0643, None, None])
    rows.append(["paper: ACS", 0.0826, 0.0487, None, None])
    t1 = Table("turntable62-realistic: eq.-21 vector error against the sensor-frame truth",
               ["method", "RMSE (m/s^2)", "SD (m/s^2)", "max |x - x_true|", "iterations"], rows,
               note="Every method scored against the same truth: the true gravity vectors in the "
                    "sensor frame. S12 fits the mount rotation phi; S9/six-position/norm cannot. "
                    "The paper's numbers come from a real MPU6050 and a real laboratory "
                    "calibration.")
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
        norm_error_figure(d["vector_error"], ylabel="e_l (eq. 21, m/s²)",
                          name="triaxial_vector_error",
                          caption="Eq.-21 vector error per turntable position (the paper's "
                                  "Fig. 7 comparison)."),
        convergence_figure(d["histories"]),
    ]
    return Section(key="triaxial", title=result.title, paragraphs=list(result.text),
                   tables=[t1, t2, t3], figures=figs, results=result.tables,
                   settings=result.settings)


def sections_figure(t, acc, gyro, sections: dict, *, detection=None, title: str = "") -> Figure:
    """A Ferraris session with its sections shaded (faces blue, turns orange) over the raw
    accelerometer and gyro, and, for detected sections, the detector's two statistics
    against their thresholds (so that the user checks the detection)."""
    t = np.asarray(t, dtype=float)
    acc = np.asarray(acc, dtype=float)
    gyro = np.asarray(gyro, dtype=float)
    rows = 3 if detection is not None else 2
    fig, axes = plt.subplots(rows, 1, figsize=(11, 2.4 * rows), sharex=True)
    for j, c in enumerate("xyz"):
        axes[0].plot(t, acc[:, j], lw=0.6, label=f"a{c}")
        axes[1].plot(t, gyro[:, j], lw=0.6, label=f"g{c}")
    for name, (i0, i1) in sections.items():
        turn = name.endswith("_rot")
        for ax in axes[:2]:
            ax.axvspan(t[i0], t[min(i1, len(t)) - 1], color="tab:orange" if turn else "tab:blue",
                       alpha=0.15, lw=0)
        axes[0].text((t[i0] + t[min(i1, len(t)) - 1]) / 2, axes[0].get_ylim()[1], name,
                     ha="center", va="top", fontsize=7)
    axes[0].set_ylabel("accelerometer (raw)")
    axes[1].set_ylabel("gyro (raw)")
    axes[0].legend(fontsize=7, ncol=3, loc="lower right")
    axes[1].legend(fontsize=7, ncol=3, loc="lower right")
    if detection is not None:
        ax = axes[2]
        ax.semilogy(t, np.maximum(detection.acc_var / detection.thresholds["acc_var"], 1e-6),
                    lw=0.6, label="accelerometer moving variance / threshold")
        ax.semilogy(t, np.maximum(detection.gyro_dev / detection.thresholds["gyro_dev"], 1e-6),
                    lw=0.6, label="|gyro - rest| / threshold")
        ax.axhline(1.0, color="k", lw=0.8)
        ax.fill_between(t, 1e-6, 1.0, where=detection.rest_mask, color="0.85", step="mid",
                        label="rest")
        ax.set_ylabel("detector")
        ax.legend(fontsize=7, loc="upper right")
    axes[-1].set_xlabel("time (s)")
    fig.suptitle(title or "Ferraris session: sections")
    return Figure(fig, "The session's sections (blue: static faces, orange: turns) over the raw "
                  "channels; with detection, the two detector statistics over their thresholds "
                  "(rest = both below 1).", name="ferraris_sections")


def coverage_figure(directions, *, title: str = "") -> Figure:
    """Pose coverage: the calibrated gravity directions of the records in the sensor frame
    as longitude (atan2(y, x)) and latitude (asin z), with the six faces marked."""
    d = np.asarray(directions, dtype=float)
    d = d / np.linalg.norm(d, axis=1)[:, None]
    lon = np.degrees(np.arctan2(d[:, 1], d[:, 0]))
    lat = np.degrees(np.arcsin(np.clip(d[:, 2], -1, 1)))
    fig, ax = plt.subplots(figsize=(8, 4))
    ax.scatter(lon, lat, s=14, color="tab:blue", label="poses")
    for name, (lo, la) in {"+x": (0, 0), "-x": (180, 0), "+y": (90, 0), "-y": (-90, 0),
                           "+z": (0, 90), "-z": (0, -90)}.items():
        ax.plot(lo, la, marker="+", color="0.4", ms=10)
        ax.annotate(name, (lo, la), textcoords="offset points", xytext=(4, 4), fontsize=7)
    ax.set_xlim(-185, 185)
    ax.set_ylim(-95, 95)
    ax.set_xlabel("longitude of gravity-up in the sensor frame (deg)")
    ax.set_ylabel("latitude (deg)")
    ax.set_title(title or "Pose coverage on the sphere")
    return Figure(fig, "Gravity-up direction of every record in the sensor frame; gaps on the "
                  "sphere are directions no pose constrains.", name="triaxial_coverage")


def method_errors_figure(poses, *, title: str = "") -> Figure:
    """Error of every pose under every method (the paper's Fig. 8 six-face
    comparison): grouped bars of the eq.-21 vector error when the table has it, else of
    ``|a_cal| - g``. ``poses`` is :func:`inertialab.calib.triaxial_compare.pose_error_table`."""
    col = "vector_error_mps2" if "vector_error_mps2" in poses and \
        poses["vector_error_mps2"].notna().all() else "norm_error_mps2"
    methods = list(dict.fromkeys(poses["method"]))
    labels = list(dict.fromkeys(poses["pose"]))
    n = len(labels)
    fig, ax = plt.subplots(figsize=(max(6.0, min(16.0, 0.25 * n * len(methods) + 3)), 3.8))
    width = 0.8 / max(len(methods), 1)
    x = np.arange(n)
    for i, m in enumerate(methods):
        e = poses.loc[poses["method"] == m].set_index("pose")[col].reindex(labels).to_numpy()
        ax.bar(x + (i - (len(methods) - 1) / 2) * width, e, width, label=m)
    ax.axhline(0, color="0.5", lw=0.6)
    ax.set_xticks(x)
    ax.set_xticklabels(labels, fontsize=7 if n <= 20 else 5, rotation=0 if n <= 20 else 90)
    ax.set_xlabel("face" if labels and labels[0][:1] in "+-" else "pose")
    ylabel = ("eq. 21 vector error (m/s²)" if col == "vector_error_mps2"
              else "|a_hat| - g (m/s²)")
    ax.set_ylabel(ylabel)
    ax.legend(fontsize=7, ncol=min(len(methods), 6))
    ax.set_title(title or "Error per pose and method")
    what = ("eq. 21 vector error |r - a_hat| against the records' references"
            if col == "vector_error_mps2" else "norm error |a_hat| - g (no references)")
    return Figure(fig, f"Each pose's {what}, one bar per method (paper Fig. 8, six-face "
                  "comparison, from the user's data).", name="triaxial_methods_errors")
