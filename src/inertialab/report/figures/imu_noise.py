"""Figure of a six-axis noise analysis: Allan deviation curves with their five-term fits."""

from __future__ import annotations

import numpy as np

from inertialab import units as U
from inertialab.report.section import Figure, Table

_SI = {"gyro": ("rps", "rad/s"), "accel": ("mps2", "m/s^2")}
_COLORS = {"x": "#4c72b0", "y": "#55a868", "z": "#c44e52"}


def imu_figure(result) -> Figure:
    """One figure, gyro and accelerometer panels, six OADEV curves (SI) with CI bands and
    the fitted five-term model dashed."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    kinds = [k for k in ("gyro", "accel") if any(a.kind == k for a in result.axes)]
    fig, axes = plt.subplots(1, len(kinds), figsize=(5.2 * len(kinds), 4.0), squeeze=False)
    for ax, kind in zip(axes[0], kinds):
        si, label = _SI[kind]
        for a in (x for x in result.axes if x.kind == kind and x.deviation is not None):
            d = a.deviation
            c = _COLORS[a.axis[1]]
            g = a.terms.g_local if a.terms is not None else U.G_STANDARD
            f = U.convert(1.0, a.unit, si, g_local=g)
            lab = a.axis if a.status == "ok" else f"{a.axis} ({a.status})"
            ax.loglog(d.taus_s, d.dev * f, "-", color=c, label=lab)
            ax.fill_between(d.taus_s, d.ci_low * f, d.ci_high * f, color=c, alpha=0.15)
            if a.terms is not None:
                ax.loglog(d.taus_s, a.terms.model_dev(d.taus_s) * f, "--", color=c, lw=1)
        ax.set_xlabel("tau (s)")
        ax.set_ylabel(f"Allan deviation ({label})")
        ax.set_title("gyroscope" if kind == "gyro" else "accelerometer")
        ax.grid(True, which="both", alpha=0.3)
        # the line styles explained beside the axis colours
        ax.plot([], [], "-", color="0.3", label="measured (band: interval)")
        ax.plot([], [], "--", color="0.3", lw=1, label="fitted model")
        ax.legend(fontsize="small")
    wu = (result.settings.get("warmup") or {}).get("span_s") or 0.0
    if wu > 0:  # the warm-up span left out of every fit, marked on the figure
        fig.text(0.01, 0.01, f"warm-up {wu:.0f} s at the start left out of every axis",
                 fontsize=8, color="#aa3333")
    note = f"; a {wu:.0f}-s warm-up at the start left out" if wu > 0 else ""
    conf = next((a.deviation.confidence for a in result.axes if a.deviation is not None), 0.95)
    return Figure(figure=fig, caption="Overlapping Allan deviation per axis (solid, band: "
                  f"{100 * conf:.1f} % interval) and the fitted "
                  f"five-term model (dashed){note}", name="imu_allan")


def drift_figure(result) -> Figure | None:
    """Predicted integrated error (RMS, solid) per horizon and axis,
    the Kalibr/imu_utils reading's prediction (dotted) and, when checked, the observed
    RMS (dots); the 95 % half-width dash-dotted. None without a drift prediction."""
    axes_ = [a for a in result.axes if a.drift is not None]
    if not axes_:
        return None
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    kinds = [k for k in ("gyro", "accel") if any(a.kind == k for a in axes_)]
    fig, axes = plt.subplots(1, len(kinds), figsize=(5.2 * len(kinds), 4.0), squeeze=False)
    for ax, kind in zip(axes[0], kinds):
        unit = "deg" if kind == "gyro" else "m/s"
        for a in (x for x in axes_ if x.kind == kind):
            d = a.drift
            c = _COLORS[a.axis[1]]
            h = d["horizons_s"]
            ax.loglog(h, d["predicted_rms"], "-", color=c, label=a.axis)
            ax.loglog(h, d["band_95"], "-.", color=c, lw=0.8, alpha=0.6)
            ax.loglog(h, d["kalibr"]["predicted_rms"], ":", color=c, lw=1)
            ci = d.get("predicted_rms_ci")
            if ci:
                ax.fill_between(h, ci["low"], ci["high"], color=c, alpha=0.12)
            if "check" in d:
                ax.loglog(h, d["check"]["observed_rms"], "o", color=c, ms=4)
        ax.set_xlabel("horizon after the bias window (s)")
        ax.set_ylabel(f"integrated error RMS ({unit})")
        ax.set_title("gyroscope (angle)" if kind == "gyro" else "accelerometer (velocity)")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend()
    w = axes_[0].drift["bias_window_s"]
    return Figure(figure=fig, name="imu_drift",
                  caption=f"Error integrated after a {w:g}-s bias window: the fitted model's "
                          "RMS (solid) and 95 % half-width (dash-dot), the Kalibr/imu_utils "
                          "reading's RMS (dotted), the model RMS's 95 % interval (band), the "
                          "observed RMS (dots)")


def imu_figures(result) -> list:
    """The Allan figure and, with a drift prediction, the drift figure."""
    return [f for f in (imu_figure(result), drift_figure(result)) if f is not None]


def imu_table(result) -> Table:
    cols, rows = result.table()
    return Table("IMU noise per axis (densities continuous-time, SI)", cols, rows)


def figure_rows(result) -> list[list]:
    return [list(r) for r in result.table()[1]]


__all__ = ["drift_figure", "figure_rows", "imu_figure", "imu_figures", "imu_table", "np"]
