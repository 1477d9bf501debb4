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
        for a in (x for x in result.axes if x.kind == kind):
            d = a.deviation
            c = _COLORS[a.axis[1]]
            f = U.convert(1.0, a.unit, si, g_local=a.terms.g_local)
            ax.loglog(d.taus_s, d.dev * f, "-", color=c, label=a.axis)
            ax.fill_between(d.taus_s, d.ci_low * f, d.ci_high * f, color=c, alpha=0.15)
            ax.loglog(d.taus_s, a.terms.model_dev(d.taus_s) * f, "--", color=c, lw=1)
        ax.set_xlabel("tau (s)")
        ax.set_ylabel(f"Allan deviation ({label})")
        ax.set_title("gyroscope" if kind == "gyro" else "accelerometer")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend()
    return Figure(figure=fig, caption="Overlapping Allan deviation per axis (solid, band: "
                  f"{100 * result.axes[0].deviation.confidence:.1f} % interval) and the fitted "
                  "five-term model (dashed)", name="imu_allan")


def imu_table(result) -> Table:
    cols, rows = result.table()
    return Table("IMU noise per axis (densities continuous-time, SI)", cols, rows)


def figure_rows(result) -> list[list]:
    return [list(r) for r in result.table()[1]]


__all__ = ["figure_rows", "imu_figure", "imu_table", "np"]
