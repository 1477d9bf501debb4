"""Figures of ``thermal fit --imu``: per sensor instance, the offset of each axis against
temperature, the binned data (heating and cooling in their own colours) and the model
(at dT/dt = 0, and the order-3 form the PX4 file carries)."""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt
import numpy as np

from inertialab.report.section import Figure

__all__ = ["imu_figures"]

_UNIT = {"accel": "m/s²", "gyro": "rad/s"}


def _sensor_figure(model, s: dict, b) -> Figure:
    fig, axs = plt.subplots(3, 1, figsize=(7.5, 7.5), sharex=True)
    d = b.direction
    grid = np.linspace(s["t_min"], s["t_max"], 200)
    for a, ax in enumerate(axs):
        ref = s["axes"][a]["offset_ref"]
        y = b.y[:, a] - ref
        if b.grav is not None:  # several orientations: the fitted scale part taken out
            y = y - model.axis_scale(s, a, b.temp, b.dtdt) * b.grav[:, a]
        for mask, col, lab in ((d == 1, "tab:red", "heating"), (d == -1, "tab:blue", "cooling"),
                               (d == 0, "0.6", "still")):
            if mask.any():
                ax.plot(b.temp[mask], y[mask], ".", ms=2, color=col, alpha=0.5,
                        label=f"data, {lab}")
        ax.plot(grid, model.axis_offset(s, a, grid, np.zeros_like(grid)) - ref, "k-", lw=1.2,
                label="model (dT/dt = 0)")
        x = np.asarray(s["px4"]["x"])[:, a]
        ax.plot(grid, np.polynomial.polynomial.polyval(grid - s["t_ref"], x), "g--", lw=1,
                label=f"order-3 form ({s['px4']['forms'][a]})")
        ax.set_ylabel(f"{s['axes'][a]['axis']} offset ({_UNIT[s['kind']]})")
        ax.grid(alpha=0.3)
    axs[0].legend(fontsize=7, ncol=2)
    axs[-1].set_xlabel("de-quantised temperature (°C)")
    title = f"{s['kind']} {s['instance']} (device {s['device_id']})"
    fig.suptitle(title, fontsize=10)
    return Figure(fig, f"Offset against temperature, {title}: data in 5-s bins (heating red, "
                       "cooling blue), model and the firmware's order-3 form.",
                  name=f"thermal_imu_{s['kind']}{s['instance']}")


def imu_figures(res) -> list:
    """One figure per sensor instance of an ``ImuFitResult``."""
    m = res.fit.model
    return [_sensor_figure(m, s, res.fit.binned[(s["kind"], s["instance"])])
            for s in m.sensors]
