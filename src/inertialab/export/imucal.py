"""imucal's calibration JSON (format 2.0.0, ``cal_type`` ``"Ferraris"``), as
``imucal.management.load_calibration_info`` reads it.

imucal's documented model: ``a = R_a^-1 K_a^-1 (u_a - b_a)`` in m/s^2 and
``omega = R_g^-1 K_g^-1 (u_g - K_ga a - b_g)`` in deg/s, with K diagonal. Ours is
``a = M_a (u_a - b_a)`` and ``omega = M_g (u_g - b_g - K_ga a)`` in rad/s, so with
``T_a = M_a^-1``: ``K_a = diag(row norms of T_a)``, ``R_a = K_a^-1 T_a``; and with
``T_g = (180/pi · M_g)^-1`` likewise for the gyro. ``b``, ``K_ga`` carry over. The
conversion is exact: imucal's formula gives our numbers to round-off (tested).
"""

from __future__ import annotations

import json

import numpy as np

from inertialab.export.triad import UNIT_TEXT, accel_T, gyro_T, refuse_flagged
from inertialab.io.writers import atomic_write_text

FORMAT_VERSION = "2.0.0"
"""imucal's calibration format version written here."""


def _split(T):
    k = np.linalg.norm(T, axis=1)
    return np.diag(k), T / k[:, None]


def to_imucal(model, *, comment: str | None = None, force: bool = False) -> dict:
    """The imucal ``FerrarisCalibrationInfo`` dict of a triaxial calibration with a gyro."""
    refuse_flagged(model, force)
    T_a, b_a = accel_T(model)
    T_g_rad, b_g, K_ga = gyro_T(model)
    T_g = T_g_rad * (np.pi / 180.0)  # raw per deg/s
    K_a, R_a = _split(T_a)
    K_g, R_g = _split(T_g)
    return {
        "acc_unit": "m/s^2", "gyr_unit": "deg/s",
        "from_acc_unit": UNIT_TEXT.get(model.raw_unit, model.raw_unit),
        "from_gyr_unit": UNIT_TEXT.get(model.gyro["raw_unit"], model.gyro["raw_unit"]),
        "comment": comment if comment is not None else
        f"inertialab triaxial-calibration, method {model.method}",
        "K_a": K_a.tolist(), "R_a": R_a.tolist(), "b_a": b_a.tolist(),
        "K_g": K_g.tolist(), "R_g": R_g.tolist(), "K_ga": K_ga.tolist(), "b_g": b_g.tolist(),
        "cal_type": "Ferraris", "_format_version": FORMAT_VERSION,
    }


def write_imucal(model, path, **kw) -> dict:
    """Write :func:`to_imucal` to ``path`` (atomically); returns the dict."""
    d = to_imucal(model, **kw)
    atomic_write_text(path, json.dumps(d, indent=4) + "\n")
    return d


def imucal_apply(d: dict, acc, gyr):
    """imucal's documented formulas on a dict of this format (for tests without imucal):
    returns ``(acc m/s^2, gyr deg/s)``."""
    K_a, R_a, b_a = (np.asarray(d[k], dtype=float) for k in ("K_a", "R_a", "b_a"))
    K_g, R_g, b_g, K_ga = (np.asarray(d[k], dtype=float) for k in ("K_g", "R_g", "b_g", "K_ga"))
    a = (np.linalg.inv(R_a) @ np.linalg.inv(K_a) @ (np.asarray(acc) - b_a).T).T
    w = (np.linalg.inv(R_g) @ np.linalg.inv(K_g) @ (np.asarray(gyr) - a @ K_ga.T - b_g).T).T
    return a, w
